// Timing contract of the AVR step interrupt (firmware/stepper.cpp) for the producer (the
// minimum period) and the simavr checks (where real edges sit relative to the host model).
// CPU cycles at 16 MHz, counted from the model's event time = the timer's compare match.
// docs/firmware.md derives each value and gives the measurements.
#pragma once

#include <stdint.h>

namespace ll {
namespace step_timing {

/// Shortest pulse the firmware produces as set: $0 = 3 µs, GRBL's minimum. A shorter
/// StepperConfig::pulse_cycles is raised to this (a pulse is never shorter than set).
constexpr uint16_t kMinPulseCycles = 48;

/// Pulse widening: a pulse stays at least as long as set when its step edge is delayed by up
/// to this many cycles (another interrupt's entry, or a critical section in the main loop).
/// The receive interrupt's non-interruptible entry is 15 cycles; hal::Critical sections must
/// keep interrupts off for no longer than this, calls included.
constexpr uint16_t kPulseGuard = 16;

/// The shortest period the step interrupt honours is `pulse + kPeriodMargin` (see
/// min_period()): a run's last event holds COMPA until max(144, pulse + kPulseGuard + 76)
/// cycles after the match, and the next match must come after it. The producer never queues
/// less; the interrupt raises a shorter period to it (a guard against a broken producer, after
/// which the edges no longer follow the model).
constexpr uint16_t kPeriodMargin = 104;

/// Cycles from a compare match to the first instruction of its handler on silicon, with the
/// CPU on a one-cycle instruction: interrupt response 4, the vector's rjmp 2 (the image is
/// linked with --relax, which turns the table's jmp into rjmp; cmake/check_step_isr.cmake
/// checks the linked table). (simavr 1.6 charges 0 for the response: subtract 4 from every
/// offset below when reading its traces.)
constexpr uint8_t kVectorEntryCycles = 6;

/// Step edge (start of pulse) after the event: X/Y/Z (port D) and A (port B, 3 cycles later).
/// Later by the time the CPU needs to accept the interrupt: up to 3 cycles of a multi-cycle
/// instruction, up to kPulseGuard when another interrupt or a critical section is running.
constexpr uint8_t kStepEdgeOffsetD = 9;
constexpr uint8_t kStepEdgeOffsetB = 12;

/// Pulse end after the model's pulse end (event + pulse): the same entry path as the step
/// edge, kPulseGuard later. At a run's last event COMPA ends the pulse itself 0..2 cycles
/// later than that. Direction pins that change at a run boundary change in the same write.
constexpr uint8_t kPulseEndOffsetD = kStepEdgeOffsetD + kPulseGuard;
constexpr uint8_t kPulseEndOffsetB = kStepEdgeOffsetB + kPulseGuard;

/// hal::stepper_start(): direction pins are written this many cycles after the timer starts
/// (the model's "now"); the first event follows one period after the start.
constexpr uint8_t kStartDirOffsetD = 5;
constexpr uint8_t kStartDirOffsetB = 9;

/// Effective pulse width for a requested one, CPU cycles.
constexpr uint16_t effective_pulse(uint16_t pulse_cycles) {
    return pulse_cycles < kMinPulseCycles ? kMinPulseCycles : pulse_cycles;
}

/// Shortest run period the step interrupt honours for a pulse width, CPU cycles.
constexpr uint16_t min_period(uint16_t pulse_cycles) {
    return static_cast<uint16_t>(effective_pulse(pulse_cycles) + kPeriodMargin);
}

static_assert(min_period(kMinPulseCycles) >= 148, "the run-change path needs 148 cycles");

} // namespace step_timing
} // namespace ll
