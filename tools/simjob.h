// Helpers shared by the host programs that run the real firmware in simavr (llbench, lldemo):
// GRBL streaming with an optional per-instruction hook, step traces rebuilt from the recorded
// pin edges, and a call profiler driven by ELF symbols. Everything here derives from exact
// simavr cycle counts, so the same firmware and inputs always give the same figures.
#pragma once

#include <stdint.h>

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "grbl_client.h"
#include "harness.h"

extern "C" {
#include <avr_timer.h>
}

namespace ll {
namespace tools {

constexpr int kTraceAxes = 4; ///< X, Y, Z, A: the CNC-shield signals the harness records

/// Step events rebuilt from the recorded step and direction pins.
struct Trace {
    /// One entry per instant at which at least one axis stepped (axes toggled by the same
    /// instruction share it): the cycle of the step edge and the position after it, in steps.
    std::vector<uint64_t> cycle;
    std::vector<std::array<int32_t, kTraceAxes>> pos;
    /// Step edges per axis (start of each pulse), in order.
    std::array<std::vector<uint64_t>, kTraceAxes> edges;
    std::array<int32_t, kTraceAxes> final_pos{};

    uint64_t first() const { return cycle.empty() ? 0 : cycle.front(); }
    uint64_t last() const { return cycle.empty() ? 0 : cycle.back(); }
    uint64_t steps(int axis) const { return edges[axis].size(); }
};

/// Rebuilds the step events from the edges recorded so far. `step_invert` / `dir_invert` are
/// axis masks as GRBL's $2 / $3. With $3 = 0 a high direction pin means negative travel.
Trace trace_steps(const sim::Sim& sim, uint8_t step_invert = 0, uint8_t dir_invert = 0);

/// Simple order statistics of a list of cycle counts.
struct Stats {
    size_t n = 0;
    uint64_t min = 0, median = 0, max = 0;
    double mean = 0;
};
Stats stats_of(std::vector<uint64_t> v);

/// The host side of GRBL's serial protocol, like sim::Grbl, but every simulated instruction
/// goes through `hook` (if set), so that a profiler can watch a whole job.
class Host {
  public:
    explicit Host(sim::Sim& sim) : sim_(sim) {}
    std::function<void()> hook;

    /// Runs until `done()` (checked after each instruction) or `max_cycles` elapse.
    bool run_until(const std::function<bool()>& done, uint64_t max_cycles);
    void run_for(uint64_t cycles);

    /// Waits for the banner ("Grbl ..."); false on timeout.
    bool wait_banner(uint64_t max_cycles);
    /// Sends one line and waits for its ok / error:N. Returns the error number (0 = ok,
    /// -1 = no answer).
    int send_line(const std::string& line, uint64_t max_cycles);
    /// Sends every line, waiting for each answer (send_and_wait) or keeping at most 128
    /// unanswered bytes in flight (GRBL's character counting). Returns the number of lines
    /// answered with an error; -1 when the firmware stalled: no answer came for `max_wait`
    /// cycles (see answered()).
    int stream(const std::vector<std::string>& lines, bool send_and_wait, uint64_t max_wait);
    /// Lines of the last stream() that got an answer (all of them unless it returned -1).
    size_t answered() const { return answered_; }
    /// Sends '?' and returns the next status report ("" on timeout).
    std::string status(uint64_t max_cycles);
    /// Output lines that were neither "ok" nor "error:N", in order.
    const std::vector<sim::OutputLine>& others() const { return others_; }
    /// Every answer ("ok" / "error:N") with its cycle, in order.
    const std::vector<sim::OutputLine>& answers() const { return answers_; }

  private:
    size_t take(); ///< consumes new output lines; returns the number of answers among them

    sim::Sim& sim_;
    size_t cursor_ = 0;
    size_t answered_ = 0;
    std::vector<sim::OutputLine> others_;
    std::vector<sim::OutputLine> answers_;
};

/// Inclusive call timings of chosen functions, found by ELF symbol. Call `step()` after every
/// instruction (Host::hook). A call starts when the program counter reaches the function's
/// first instruction and ends when the stack pointer climbs above its value at that moment
/// (the return address popped) with the program counter at that return address. Interrupts that
/// run during a call are recorded separately (`isr_cycles_in`) so that they can be taken out.
class Profiler {
  public:
    struct Call {
        int fn;         ///< index in the symbol list
        int parent;     ///< index in calls() of the innermost enclosing profiled call, or -1
        uint64_t start; ///< cycle of the function's first instruction
        uint64_t end;   ///< cycle after its return (0 while running)
    };

    /// Symbols missing from the ELF are ignored (their calls are never seen).
    Profiler(sim::Sim& sim, const std::vector<std::string>& symbols);
    void step();

    const std::vector<Call>& calls() const { return calls_; }
    /// Index of a symbol given to the constructor.
    int index_of(const std::string& symbol) const;
    /// Cycles spent in interrupt handlers (every vector) between `from` and `to`.
    uint64_t isr_cycles_in(uint64_t from, uint64_t to) const;
    /// Inclusive cycles of a call without the interrupts that ran meanwhile.
    uint64_t own_cycles(const Call& c) const {
        return c.end - c.start - isr_cycles_in(c.start, c.end);
    }

  private:
    struct Frame {
        int call;
        uint16_t sp;  ///< stack pointer at the function's first instruction
        uint32_t ret; ///< return address (flash byte address)
    };
    sim::Sim& sim_;
    std::vector<std::string> names_;
    std::vector<int16_t> fn_at_; ///< function index by flash word address, -1 if none
    std::vector<Frame> stack_;
    std::vector<Call> calls_;
};

/// Stack watermark by painting: fills the free RAM between the end of .bss and the stack
/// pointer with a pattern; peak() then finds the lowest byte the program changed.
class StackProbe {
  public:
    explicit StackProbe(sim::Sim& sim);
    /// Bytes of stack used at the deepest point since construction (from RAMEND down).
    unsigned peak() const;
    /// The stack reached the end of .bss: it probably overwrote static variables.
    bool overflowed() const;
    unsigned static_end() const { return bss_end_; }

  private:
    const sim::Sim& sim_;
    unsigned bss_end_;
    unsigned painted_to_;
};

/// Cycles at which a timer's compare flag is set (Timer1 COMPA by default: the moment the step
/// timer asks for the next step, in our firmware and in GRBL alike). Recorded from simavr's
/// "interrupt pending" signal of the vector, so it works without symbols (a GRBL .hex) and
/// whatever sets the flag (simavr's timer or the harness's corrections). In CTC mode simavr sets
/// the flag from its period boundary, `tov_base`, which is then the exact match cycle; the
/// signal itself comes at the end of the instruction under way.
class CompareLog {
  public:
    explicit CompareLog(sim::Sim& sim, uint8_t vector = 11, char timer = '1');
    ~CompareLog();
    CompareLog(const CompareLog&) = delete;
    CompareLog& operator=(const CompareLog&) = delete;

    const std::vector<uint64_t>& matches() const { return matches_; }
    /// The latest match at or before `cycle`; false when there is none.
    bool latest_at(uint64_t cycle, uint64_t* match) const;

  private:
    static void on_pending(avr_irq_t* irq, uint32_t value, void* param);
    sim::Sim& sim_;
    avr_irq_t* irq_ = nullptr;
    avr_timer_t* timer_ = nullptr;
    std::vector<uint64_t> matches_;
};

/// A data-space variable of the firmware by symbol (little endian, up to 4 bytes).
uint32_t peek_var(const sim::Sim& sim, const std::string& symbol, unsigned bytes,
                  unsigned offset = 0);

/// Flash and static RAM of an AVR ELF image, as avr-size counts them.
struct ImageSize {
    uint32_t flash = 0; ///< .text + .data
    uint32_t ram = 0;   ///< .data + .bss (+ .noinit)
};
ImageSize image_size(const std::string& elf);

/// A circle of `radius` mm through the origin (centre (-radius, 0)), counterclockwise from the
/// origin, as G1 chords of about `segment` mm; the first line carries the feed (mm/min).
std::vector<std::string> circle_job(double radius, double segment, double feed);

} // namespace tools
} // namespace ll
