// The run queue: the only data the step interrupt consumes (seed §2.2 micro movement, §6 compute
// windows). The main loop produces runs ahead of time; the interrupt pulses them.
#pragma once

#include "lowlevel/config.h"

namespace ll {

/// A run: `count` step events on the same axis set, each one preceded by the same wait.
/// Semantics, shared by the AVR interrupt and the host model: for each of the `count` events,
/// wait `period` CPU cycles, then pulse the step pins of `steps`. A run with `steps == 0` is an
/// idle wait (used for waits longer than 65535 cycles, i.e. below 245 steps/s).
struct Run {
    uint8_t steps;   ///< axis bits (bit 0 = X) that step at each event; 0 = wait only
    uint8_t dirs;    ///< axis bits travelling towards negative coordinates
    uint8_t count;   ///< events in this run, 1..255
    uint16_t period; ///< CPU cycles before each event, >= the configured minimum period
};

/// Single-producer (main loop) / single-consumer (step interrupt) ring. Indices are single
/// bytes, so each side's update is atomic on the AVR without disabling interrupts.
template <uint8_t N>
struct RunRing {
    static_assert((N & (N - 1)) == 0, "power of two");
    Run buf[N];
    volatile uint8_t head; ///< next run to consume (written by the consumer only)
    volatile uint8_t tail; ///< next free slot (written by the producer only)

    void clear() { head = tail = 0; }
    uint8_t used() const { return static_cast<uint8_t>((tail - head) & (N - 1)); }
    bool empty() const { return head == tail; }
    bool full() const { return used() == N - 1; }
    uint8_t free_slots() const { return static_cast<uint8_t>(N - 1 - used()); }

    /// Producer side. Precondition: !full().
    void push(const Run& r) {
        uint8_t t = tail;
        buf[t] = r;
        tail = static_cast<uint8_t>((t + 1) & (N - 1));
    }
    /// Consumer side. Precondition: !empty().
    const Run& front() const { return buf[head]; }
    void pop() { head = static_cast<uint8_t>((head + 1) & (N - 1)); }
};

using RunQueue = RunRing<kRunQueueSize>;

/// What the step interrupt is executing right now. Written by the interrupt (and by the main
/// loop only while the timer is stopped); read by the main loop with interrupts off, to derive
/// the current position from the queue (see stepgen.h: the interrupt itself never counts).
struct StepExec {
    volatile uint8_t remaining; ///< events left in the current run (0: no run loaded)
    volatile uint8_t steps;     ///< axis bits of the current run
    volatile uint8_t dirs;      ///< direction bits of the current run
    volatile uint8_t running;   ///< 1 while the step timer runs
    volatile uint8_t starved;   ///< set by the interrupt when it found the queue empty mid-move
};

extern RunQueue g_runs;
extern StepExec g_exec;
/// Times the step timer stopped for want of runs while a move was still being produced (the
/// queue ran dry mid-move). Counted by the main loop; a named global so that the simavr checks
/// can read it from the chip's RAM by symbol.
extern volatile uint16_t g_starvations;

} // namespace ll
