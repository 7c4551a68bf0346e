// Shared by the timing checks (fw_test_timing.cpp, fw_test_pulses.cpp): run one job on the host
// model and on the real image, compare every edge, check pulse width and direction setup, and
// print the measured figures (docs/verification.md collects them).
#pragma once

#include <stdio.h>

#include <string>
#include <vector>

#include "fw_check.h"
#include "lowlevel/config.h"

namespace ll {
namespace sim {
namespace fw {

/// What a job's settings say about the pins.
struct PinSettings {
    uint8_t pulse_us = 10;   ///< $0
    uint8_t step_invert = 0; ///< $2
    uint8_t dir_invert = 0;  ///< $3
};

/// A machine that moves fast enough for short simulations: 80 steps/mm, 6000 mm/min,
/// 500 mm/s^2 on X, Y, Z and A (A keeps its own speed group, $143 = 1), then `extra`.
inline std::vector<std::string> fast_machine(const std::vector<std::string>& extra = {}) {
    std::vector<std::string> s;
    for (int a = 0; a < 4; ++a) {
        s.push_back("$" + std::to_string(100 + a) + "=80");
        s.push_back("$" + std::to_string(110 + a) + "=6000");
        s.push_back("$" + std::to_string(120 + a) + "=500");
    }
    s.insert(s.end(), extra.begin(), extra.end());
    return s;
}

inline std::string joined(const std::vector<std::string>& v) {
    std::string out;
    for (const std::string& s : v) out += (out.empty() ? "" : "; ") + s;
    return out;
}

inline std::string mpos_of(const std::string& report) {
    const size_t a = report.find("MPos:");
    if (a == std::string::npos) return "(no MPos in '" + report + "')";
    return report.substr(a, report.find('|', a) - a);
}

/// The whole check for one job. Non-fatal expectations, so that every figure is printed.
inline void check_against_model(const char* label, const Job& job, const PinSettings& pins) {
    const Trace m = run_on_model(job);
    ASSERT_TRUE(m.errors.empty()) << "model: " << joined(m.errors);
    Sim sim(firmware_elf());
    const Trace c = run_on_chip(sim, job);
    EXPECT_GT(c.stack_free, 0u) << "the stack used all " << c.stack_bytes
                                << " bytes above the static RAM and went on into it";
    ASSERT_TRUE(c.errors.empty()) << "chip: " << joined(c.errors);

    const Comparison cmp = compare(m, c);
    std::string problems;
    for (const std::string& p : cmp.problems) problems += "\n  " + p;
    EXPECT_TRUE(cmp.ok()) << cmp.compared << " edges compared; first differences:" << problems;
    EXPECT_EQ(c.starts.size(), 1u) << "the step timer restarted during the job";
    EXPECT_EQ(m.starts.size(), 1u);

    const PulseStats pc = pulse_stats(c, pins.step_invert, pins.dir_invert);
    const PulseStats pm = pulse_stats(m, pins.step_invert, pins.dir_invert);
    for (uint8_t a = 0; a < 4; ++a) {
        EXPECT_EQ(pc.pulses[a], pm.pulses[a]) << "pulses on " << axis_name(a);
        EXPECT_EQ(pc.net[a], pm.net[a]) << "net steps on " << axis_name(a);
    }
    // $0 is a minimum: never shorter. Direction: set at least 1 us before the next step edge on
    // that axis, and never changed while that axis' pulse is active.
    const uint64_t set_pulse = pins.pulse_us * 16ull;
    EXPECT_GE(pc.min_pulse, set_pulse);
    EXPECT_GE(pc.min_dir_setup, 16u);
    EXPECT_EQ(pc.dir_during_pulse, 0u);
    EXPECT_EQ(c.starvations, 0u) << "the run queue ran dry in the middle of a move";
    EXPECT_EQ(m.starvations, 0u);
    EXPECT_EQ(mpos_of(c.final_status), mpos_of(m.final_status));

    size_t pulses = 0;
    for (size_t p : pc.pulses) pulses += p;
    char setup[32] = "-";
    char width[48] = "-";
    if (pulses != 0)
        snprintf(width, sizeof width, "%llu..%llu", static_cast<unsigned long long>(pc.min_pulse),
                 static_cast<unsigned long long>(pc.max_pulse));
    char lead[64] = "none (already enabled)";
    if (cmp.enable_lead >= 0)
        snprintf(lead, sizeof lead, "%lld cycles before the start (+%lld in interrupts)",
                 static_cast<long long>(cmp.enable_lead), static_cast<long long>(cmp.enable_isr));
    if (pc.dir_changes != 0)
        snprintf(setup, sizeof setup, "%llu", static_cast<unsigned long long>(pc.min_dir_setup));
    printf("[ measured ] %s: %zu edges (%zu pulses); deviation, cycles: %s; pulse %s cycles (set "
           "%llu); dir setup min %s cycles (%zu changes); enable edge %s; disable off "
           "by %lld; starvations %u; stack %u bytes (%u free); %.3f s "
           "simulated in %.2f s (model %.2f s)\n",
           label, cmp.compared, pulses, cmp.ranges().c_str(), width,
           static_cast<unsigned long long>(set_pulse), setup, pc.dir_changes, lead,
           static_cast<long long>(cmp.disable_dev), c.starvations, c.stack_bytes, c.stack_free,
           c.cycles / 16e6, c.wall_seconds, m.wall_seconds);
}

} // namespace fw
} // namespace sim
} // namespace ll
