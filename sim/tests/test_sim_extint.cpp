// SIMAVR-NOTES 7 (INT0/INT1 level polling), against selftest_extint: PD2/PD3 are low outputs, as
// idle X/Y step pins are. Stock simavr keeps a cycle timer firing every cycle for each of them
// (avr_extint's level poll) although INT0/INT1 are disabled. The correction keeps the poll only
// while the firmware enables the interrupt, where the datasheet (13.1) needs it: a low-level
// INT0 fires again and again while the pin is low.
#include <chrono>
#include <iostream>

#include "selftest_elf.h"

using namespace ll::sim;
using ll::sim::test::all_but;
using ll::sim::test::options;

namespace {

/// Cycle timers pending in simavr (the idle loop arms none of its own).
size_t pending_cycle_timers(Sim& sim) {
    size_t n = 0;
    for (avr_cycle_timer_slot_p s = sim.avr()->cycle_timers.timer; s; s = s->next) ++n;
    return n;
}

struct ExtintRun {
    size_t timers_while_idle = 0;
    size_t int0_toggles = 0; ///< step_z toggles in the 2000 cycles after INT0 is enabled
    double idle_speed = 0;   ///< simulated cycles per second over the idle loop
};

ExtintRun run_extint(const Corrections& c) {
    Sim sim(options("selftest_extint", c));
    ExtintRun r;
    EXPECT_TRUE(sim.run_until_pc(sim.symbol("idle_loop"), ms(1)));
    sim.run_for(1000);
    r.timers_while_idle = pending_cycle_timers(sim);
    const uint64_t c0 = sim.cycle();
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_TRUE(sim.run_until_pc(sim.symbol("int0_enable"), ms(100)));
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.idle_speed = (sim.cycle() - c0) / wall;
    const uint64_t enabled = sim.cycle();
    sim.run_until_cycle(enabled + 2000);
    r.int0_toggles = sim.edges_of("step_z").size();
    return r;
}

} // namespace

TEST(SimExtintPolling, CorrectedNoPollWhileInt0Disabled) {
    REQUIRE_SELFTEST("selftest_extint");
    const ExtintRun r = run_extint(Corrections::all());
    EXPECT_EQ(r.timers_while_idle, 0u);
    // INT0 enabled, level mode, pin low: the ISR (response 4 + 13) runs back to back.
    EXPECT_GT(r.int0_toggles, 50u);
    RecordProperty("idle_mcycles_per_s", std::to_string(r.idle_speed / 1e6));
}

TEST(SimExtintPolling, StockSimavrPollsEveryCycle) {
    REQUIRE_SELFTEST("selftest_extint");
    const ExtintRun stock = run_extint(all_but(&Corrections::extint_idle_poll_off));
    const ExtintRun fixed = run_extint(Corrections::all());
    EXPECT_EQ(stock.timers_while_idle, 2u); // one poll each for PD2 (INT0) and PD3 (INT1)
    EXPECT_EQ(stock.int0_toggles, fixed.int0_toggles); // same firmware behaviour
    std::cout << "idle loop with PD2/PD3 low: stock " << stock.idle_speed / 1e6
              << " M cycles/s, corrected " << fixed.idle_speed / 1e6 << " M cycles/s\n";
    RecordProperty("stock_mcycles_per_s", std::to_string(stock.idle_speed / 1e6));
    RecordProperty("corrected_mcycles_per_s", std::to_string(fixed.idle_speed / 1e6));
}
