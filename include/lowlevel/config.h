// Compile-time configuration of the portable core (seed §1: N axes, fixed for a machine).
#pragma once

#include <stdint.h>

#ifndef LL_AXES
#define LL_AXES 4
#endif

namespace ll {

/// Number of stepper axes (X, Y, Z, A, B, C in that order). The Uno build uses 4.
constexpr uint8_t kAxes = LL_AXES;
static_assert(kAxes >= 1 && kAxes <= 6, "Low Level drives 1 to 6 axes");

/// CPU clock. Timer1 counts at prescaler 1, so one timer tick is one CPU cycle (62.5 ns):
/// the finest period resolution the chip offers, and the unit of every `period` in the core.
constexpr uint32_t kCpuHz = 16000000UL;

/// Capacity of the run queue between the producer (main loop) and the step interrupt.
constexpr uint8_t kRunQueueSize = 16;
static_assert((kRunQueueSize & (kRunQueueSize - 1)) == 0, "power of two");

/// Blocks in the look-ahead planner ring.
constexpr uint8_t kPlannerSize = 16;

/// Software version reported by `$I`.
#define LL_VERSION_STRING "0.1.0"

} // namespace ll
