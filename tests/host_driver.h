// Drives the whole firmware loop on the host fake (tools/host/host_hal.h): send bytes, run
// app::run_once() while advancing simulated time, collect what the firmware printed. Reusable for
// whole-pipeline tests: it never assumes that motion completes instantly.
#pragma once

#include <stdint.h>

#include <string>

namespace ll {
namespace test {

struct HostDriver {
    /// Simulated time between two main-loop iterations, CPU cycles (100 us).
    uint64_t quantum = 1600;
    /// Safety limit of every run_* call, simulated CPU cycles (60 s).
    uint64_t limit = 60ull * 16000000ull;

    /// Power-up: host::reset_model(erase_eeprom) then app::init(). Returns what init printed.
    std::string boot(bool erase_eeprom = false);
    /// Queues bytes on the receive line (they arrive at once).
    void send(const std::string& bytes);
    /// One main-loop iteration, then simulated time moves on by `quantum` (or to the next step
    /// event, whichever is first).
    void step();
    /// Runs until `n` more responses (`ok` / `error:N` lines) have been printed. Returns
    /// everything printed meanwhile.
    std::string run_until_responses(unsigned n);
    /// Runs until every sent byte has been answered and motion is idle.
    std::string run_until_idle();
    /// Sends one line (a "\n" is appended) and runs until it is answered.
    std::string command(const std::string& line);
    /// Runs for `cycles` of simulated time.
    std::string run_for(uint64_t cycles);

    /// Output printed since the last call that returned output (kept across calls).
    std::string pending;
    std::string take();
};

/// Number of `ok` and `error:` lines in `text`.
unsigned count_responses(const std::string& text);

} // namespace test
} // namespace ll
