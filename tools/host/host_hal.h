// Host implementation of the hardware boundary (include/lowlevel/hal.h): a simulated CPU-cycle
// clock, a step timer that consumes g_runs with exactly the semantics of the AVR interrupt, and
// a record of every step / direction / enable pin edge with its cycle. This record is the "host
// model schedule" that the simavr checks compare the real firmware against.
#pragma once

#include <stdint.h>

#include <string>
#include <vector>

#include "lowlevel/hal.h"

namespace ll {
namespace host {

enum class EdgeKind : uint8_t { Step, Dir, Enable };

/// A pin edge: the physical level after the edge (inversion settings applied).
struct Edge {
    uint64_t cycle;
    EdgeKind kind;
    uint8_t axis; ///< 0 = X ... (unused for Enable)
    uint8_t level;
};

/// Simulated time, CPU cycles since reset.
uint64_t now();
/// Runs the step timer up to cycle `t` (inclusive) and sets the clock to `t`.
void advance_to(uint64_t t);
/// Cycle of the next step event, or UINT64_MAX when the timer is stopped.
uint64_t next_event();
bool timer_running();

/// Every edge since the last reset_model(), in time order.
const std::vector<Edge>& edges();
void clear_edges();

/// Number of times the timer stopped because the queue was empty (includes the normal stop at
/// the end of motion; the producer tells the difference).
uint32_t timer_stops();

/// Bytes that arrive on the simulated receive line: the k-th byte arrives at
/// now() + (k + 1) * cycles_per_byte (0 = all at once). Real-time bytes are filtered on arrival,
/// as the receive interrupt does.
void send(const std::string& bytes, uint32_t cycles_per_byte = 0);
/// Arrival cycle of the next byte not yet delivered, or UINT64_MAX.
uint64_t next_arrival();
/// Everything transmitted since the last call.
std::string take_output();

/// Receive buffer capacity of the model (same as the firmware's).
constexpr uint16_t kRxCapacity = 128;

/// Back to power-up state: clock 0, queue and timer cleared, edges cleared, serial empty.
/// The EEPROM keeps its contents unless `erase_eeprom` (blank = 0xFF, as a new chip).
void reset_model(bool erase_eeprom = false);

/// The EEPROM contents (for tests that corrupt it on purpose).
uint8_t* eeprom();

} // namespace host
} // namespace ll
