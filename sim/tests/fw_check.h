// Checks of the real firmware image (build/avr/firmware/lowlevel.elf) in simavr against the host
// model that the same portable core implements (tools/host/host_hal.h, tests/host_driver.h).
//
// A job is a list of `$` settings and G-code lines. Both sides boot from a blank EEPROM, take the
// same settings, then get `!` (feed hold while idle: moves are planned but none starts), the job
// lines (every `ok` awaited), and `~`. Both sides therefore plan the whole job before any step, so
// the run sequences are the same, and the step timer runs from one start to the end of the job.
// The time origin of each side is that timer start: the model's "now" in hal::stepper_start()
// and the cycle of the chip's TCCR1B write that starts Timer1. Every edge is then compared with
// the model's, offsets from include/lowlevel/step_timing.h removed (docs/verification.md).
#pragma once

#include <stdint.h>

#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "grbl_client.h"

namespace ll {
namespace sim {
namespace fw {

/// build/avr/firmware/lowlevel.elf, from the LL_FIRMWARE_DIR cache variable.
std::string firmware_elf();
bool firmware_exists();

/// Signals of the CNC shield, as the host model names them.
enum class Kind : uint8_t { Step, Dir, Enable };
const char* kind_name(Kind k);

/// A pin edge: physical level after the edge.
struct PinEdge {
    uint64_t cycle;
    Kind kind;
    uint8_t axis; ///< 0 = X, 1 = Y, 2 = Z, 3 = A; 0 for Enable
    uint8_t level;
};

/// The chip's edges from recorder index `from` on, as PinEdges.
std::vector<PinEdge> chip_edges(const Sim& sim, size_t from = 0);

struct Job {
    std::vector<std::string> settings; ///< `$N=v` lines, sent first (each must answer ok)
    std::vector<std::string> lines;    ///< the job: at most 16 moves (the planner's capacity)
    /// Chip only: `?` every this many ms while the job runs, as senders poll (0: none). Status
    /// reports take the receive interrupt and the main loop's critical sections; the model's
    /// edges do not depend on them.
    uint32_t status_every_ms = 0;
    /// Simulated time the job may take from `~` to its last step, ms (both sides): a job that
    /// has not ended by then fails. The timing jobs take up to 1.5 s; the speed-group jobs run
    /// 9 and 15 s at the rates they check.
    uint32_t limit_ms = 5000;
};

/// What one side did with a job.
struct Trace {
    std::vector<PinEdge> edges;      ///< every step / dir / enable edge from `~` on
    std::vector<uint64_t> starts;    ///< cycles at which the step timer started (from `~` on)
    std::vector<uint64_t> stops;     ///< cycles at which it stopped by itself (queue empty)
    uint8_t dir_levels0 = 0;         ///< direction pin levels (axis bits) when `~` was sent
    std::vector<std::string> errors; ///< lines (settings or job) not answered `ok`
    uint16_t starvations = 0;        ///< ll::g_starvations after the job
    std::string final_status;        ///< `?` report after the job
    /// Chip only: deepest main-loop + interrupt stack seen (bytes below RAMEND, from a painted
    /// RAM), and the bytes that stayed free above the static RAM (0: the stack reached .bss).
    uint16_t stack_bytes = 0;
    uint16_t stack_free = 0;
    /// Chip only: every interrupt handler accepted between `~` and the first timer start, as
    /// [accepted, returned) cycles. The enable edge and the timer start are two main-loop
    /// statements apart; a handler that runs between them (Timer2's millis tick, a received
    /// byte) is not part of that path (compare()).
    std::vector<std::pair<uint64_t, uint64_t>> isr_before_start;
    double wall_seconds = 0; ///< host time spent (chip side: in simavr)
    uint64_t cycles = 0;     ///< simulated cycles from `~` to the end of the job
};

/// After the last step, how long both sides keep running: longer than the default idle delay
/// ($1 = 25 ms) so that the drivers' disable edge is part of the record.
constexpr uint64_t kTail = 40ull * 16000;

/// Fills the RAM between the static data (__bss_end) and RAMEND with a pattern, so that
/// stack_high_water() finds the deepest stack use. Call before the firmware runs.
void paint_stack(Sim& sim);
/// {bytes used below RAMEND, bytes never touched above __bss_end} since paint_stack().
std::pair<uint16_t, uint16_t> stack_high_water(const Sim& sim);

/// Runs `job` on the real image in simavr. `sim` is a freshly constructed simulator (or one the
/// caller prepared, e.g. with extra signals); it is booted here.
Trace run_on_chip(Sim& sim, const Job& job);
Trace run_on_chip(const Job& job);
/// Runs the same bytes through the host model (app::run_once on the host fake).
Trace run_on_model(const Job& job);

/// Deviation range of one kind of edge, cycles (offsets removed).
struct DevRange {
    size_t n = 0;
    int64_t min = 0;
    int64_t max = 0;
    void add(int64_t d) {
        min = n == 0 || d < min ? d : min;
        max = n == 0 || d > max ? d : max;
        ++n;
    }
};

/// The kinds of edges compared, each with its own offset from step_timing.h.
enum Category : uint8_t {
    kStepStart,  ///< pulse start: kStepEdgeOffsetD/B after the model's event
    kStepEnd,    ///< pulse end: kPulseEndOffsetD/B after the model's pulse end
    kDirAtStart, ///< direction set by stepper_start(): kStartDirOffsetD/B after the start
    kDirAtRun,   ///< direction change at a run boundary: kPulseEndOffsetD/B (same write)
    kCategories
};
const char* category_name(uint8_t c);

/// Result of comparing the chip's edges with the model's.
struct Comparison {
    size_t compared = 0;               ///< edge pairs compared (enable included)
    DevRange dev[kCategories];         ///< per kind of step / direction edge
    int64_t enable_lead = -1;          ///< main-loop cycles from the chip's enable edge to the
                                       ///< timer start, interrupt handlers that ran between
                                       ///< them excluded (-1: the drivers were already enabled)
    int64_t enable_isr = 0;            ///< cycles of those handlers
    int64_t disable_dev = 0;           ///< |deviation| of the idle-delay disable edge, cycles
    std::vector<std::string> problems; ///< first differences, human readable
    bool ok() const { return problems.empty(); }
    /// "step start 0..16, step end ..." for the logs.
    std::string ranges() const;
};

/// Edge-by-edge comparison. Step and direction edges must be the same pin and level, in the same
/// order, within `tolerance` cycles of the model after the step_timing.h offsets; the enable edge
/// at the start must lead the timer start (the firmware enables the drivers, then starts the
/// timer) by at most `enable_window` cycles of main-loop code (the interrupt handlers that ran in
/// between, chip.isr_before_start, are not counted: they can land anywhere); the idle-delay disable
/// edge must match within `disable_window` (millis() ticks are 1 ms, the model's main loop runs
/// every 100 us).
Comparison compare(const Trace& model, const Trace& chip, int64_t tolerance = 16,
                   int64_t enable_window = 200, int64_t disable_window = 16000 + 2 * 1600);

/// Pulse width and direction setup measured on a record (chip or model).
struct PulseStats {
    size_t pulses[4] = {0, 0, 0, 0}; ///< complete step pulses per axis
    int64_t net[4] = {0, 0, 0, 0};   ///< steps per axis, signed by the direction pin
    uint64_t min_pulse = UINT64_MAX; ///< shortest step pulse, cycles
    uint64_t max_pulse = 0;
    uint64_t min_dir_setup = UINT64_MAX; ///< shortest direction edge -> next step edge, cycles
    size_t dir_changes = 0;              ///< direction edges followed by a step on that axis
    size_t dir_during_pulse = 0;         ///< direction edges while that axis' pulse was active
};

/// `step_invert` / `dir_invert`: $2 / $3 axis bits (levels are physical).
/// `dir_levels0`: direction pin levels (axis bits) before the first edge.
PulseStats pulse_stats(const std::vector<PinEdge>& edges, uint8_t step_invert, uint8_t dir_invert,
                       uint8_t dir_levels0);
/// The same for a trace.
inline PulseStats pulse_stats(const Trace& t, uint8_t step_invert, uint8_t dir_invert) {
    return pulse_stats(t.edges, step_invert, dir_invert, t.dir_levels0);
}

/// "X" for axis 0 ...
char axis_name(uint8_t axis);

} // namespace fw
} // namespace sim
} // namespace ll

/// Fails the test (never skips) when the avr preset has not built lowlevel.elf.
#define REQUIRE_FIRMWARE()                                                                         \
    ASSERT_TRUE(::ll::sim::fw::firmware_exists())                                                  \
        << "missing " << ::ll::sim::fw::firmware_elf()                                             \
        << ": build the firmware first (cmake --preset avr && cmake --build --preset avr), or "    \
           "point LL_FIRMWARE_DIR at the directory holding lowlevel.elf"
