// Code-region measurements: symbols, program-counter stops, register-write markers and ISR spans.
#include "selftest_elf.h"

using namespace ll::sim;
using ll::sim::test::options;

TEST(SimMarkers, SymbolsAreFlashOrDataAddresses) {
    REQUIRE_SELFTEST("selftest_echo");
    Sim sim(options("selftest_echo"));
    EXPECT_TRUE(sim.has_symbol("main"));
    EXPECT_LT(sim.symbol("main"), 0x8000u); // flash byte address
    EXPECT_FALSE(sim.has_symbol("no_such_symbol"));
    EXPECT_THROW(sim.symbol("no_such_symbol"), SimError);
}

TEST(SimMarkers, RegisterWritesCarryTheirCycle) {
    REQUIRE_SELFTEST("selftest_preload");
    Sim sim(options("selftest_preload"));
    sim.watch_register(0x4A); // GPIOR1
    sim.watch_register(0x4B); // GPIOR2
    ASSERT_TRUE(sim.run_until_pc(sim.symbol("t1_stop"), ms(1)));
    const uint64_t stop = sim.cycle();
    sim.run_for(100);
    const std::vector<RegWrite>& w = sim.register_writes();
    ASSERT_EQ(w.size(), 2u);
    // STS TCCR1B 2 + LDS 2 + LDS 2, then OUT GPIOR1 and OUT GPIOR2 (1 each).
    EXPECT_EQ(w[0].addr, 0x4A);
    EXPECT_EQ(w[0].cycle, stop + 6);
    EXPECT_EQ(w[1].addr, 0x4B);
    EXPECT_EQ(w[1].cycle, stop + 7);
    EXPECT_EQ(w[0].value, sim.peek(0x4A)); // the write still reaches the register
}

TEST(SimMarkers, IsrSpansCoverResponseBodyAndReti) {
    REQUIRE_SELFTEST("selftest_timer");
    Sim sim(options("selftest_timer"));
    sim.record_isr(11); // TIMER1_COMPA_vect_num on the ATmega328P
    ASSERT_TRUE(sim.run_until_pc(sim.symbol("ocr_write"), ms(1)));
    const uint64_t w = sim.cycle();
    sim.run_until_cycle(w + 1000);
    std::vector<IsrSpan> phase_b;
    for (const IsrSpan& s : sim.isr_spans())
        if (s.accepted > w + 100) phase_b.push_back(s);
    ASSERT_EQ(phase_b.size(), 3u);
    for (size_t k = 0; k < phase_b.size(); ++k) {
        EXPECT_EQ(phase_b[k].vector, 11);
        EXPECT_EQ(phase_b[k].accepted, w + 300 * (k + 1)); // the flag cycle: no wait in a sled
        EXPECT_EQ(phase_b[k].returned - phase_b[k].accepted, 4u + 13u); // response + ISR
    }
}

TEST(SimMarkers, RunUntilStopsAtThePredicate) {
    REQUIRE_SELFTEST("selftest_timer");
    Sim sim(options("selftest_timer"));
    EXPECT_TRUE(sim.run_until([&] { return sim.edges().size() == 3; }, ms(1)));
    EXPECT_EQ(sim.edges().size(), 3u);
    EXPECT_FALSE(sim.run_until([] { return false; }, 1000));
}
