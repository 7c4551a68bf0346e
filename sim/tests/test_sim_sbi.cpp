// SBI/CBI on PINx and TIFRn, and TIFRn writes (found while writing these tests), against
// selftest_sbi. The ATmega328P applies SBI/CBI to the addressed bit only (datasheet 7.4, 14.2.2)
// and clears exactly the timer flags written as one (15.11.9). simavr 1.6 does a read-modify-write
// of the whole register for SBI/CBI, and clears every flag of TIFRn on any write.
#include "selftest_elf.h"

using namespace ll::sim;
using ll::sim::test::all_but;
using ll::sim::test::options;

namespace {

constexpr uint16_t kGpior1 = 0x4A, kGpior2 = 0x4B; // data-space addresses
constexpr uint8_t kOcf1b = 1 << 2;

struct SbiRun {
    uint64_t sbi = 0, cbi = 0;
    std::vector<std::pair<std::string, Edge>> edges; ///< from sbi_toggle on
    uint8_t after_out = 0; ///< TIFR1 after OUT TIFR1,1<<OCF1A with OCF1A and OCF1B pending
    uint8_t after_sbi = 0; ///< TIFR1 after SBI TIFR1,OCF1A with OCF1A and OCF1B pending
};

SbiRun run_sbi(const Corrections& c) {
    Sim sim(options("selftest_sbi", c));
    SbiRun r;
    EXPECT_TRUE(sim.run_until_pc(sim.symbol("sbi_toggle"), ms(1)));
    r.sbi = sim.cycle();
    EXPECT_TRUE(sim.run_until_pc(sim.symbol("cbi_nop"), ms(1)));
    r.cbi = sim.cycle();
    EXPECT_TRUE(sim.run_until_pc(sim.symbol("tifr_sbi"), ms(1)));
    sim.run_for(10);
    r.after_out = sim.peek(kGpior2);
    r.after_sbi = sim.peek(kGpior1);
    for (const Edge& e : sim.edges())
        if (e.cycle >= r.sbi) r.edges.emplace_back(sim.signals()[e.signal].name, e);
    return r;
}

} // namespace

TEST(SimSbiCbi, CorrectedActOnOneBit) {
    REQUIRE_SELFTEST("selftest_sbi");
    const SbiRun r = run_sbi(Corrections::all());
    ASSERT_EQ(r.edges.size(), 1u); // SBI PIND,2 toggles step_x only; CBI PIND,4 toggles nothing
    EXPECT_EQ(r.edges[0].first, "step_x");
    EXPECT_EQ(r.edges[0].second.cycle, r.sbi);
    EXPECT_EQ(r.edges[0].second.level, 1);
    EXPECT_EQ(r.after_sbi, kOcf1b); // OCF1A cleared, OCF1B still pending
}

TEST(SimSbiCbi, StockSimavrRewritesTheWholeRegister) {
    REQUIRE_SELFTEST("selftest_sbi");
    const SbiRun r = run_sbi(all_but(&Corrections::sbi_cbi_single_bit));
    // SBI PIND,2 writes 0b00001100 (PD3 read high): step_y toggles too. CBI PIND,4 then writes
    // back every high pin (PD2, now high): step_x toggles again.
    ASSERT_EQ(r.edges.size(), 3u);
    EXPECT_EQ(r.edges[0].first, "step_x");
    EXPECT_EQ(r.edges[1].first, "step_y");
    EXPECT_EQ(r.edges[1].second.cycle, r.sbi);
    EXPECT_EQ(r.edges[1].second.level, 0);
    EXPECT_EQ(r.edges[2].first, "step_x");
    EXPECT_EQ(r.edges[2].second.cycle, r.cbi);
    EXPECT_EQ(r.after_sbi, 0);      // SBI wrote OCF1B as one too
    EXPECT_EQ(r.after_out, kOcf1b); // the OUT is not an SBI: unaffected
}

TEST(SimTimerFlags, CorrectedClearOnlyTheFlagsWrittenAsOne) {
    REQUIRE_SELFTEST("selftest_sbi");
    const SbiRun r = run_sbi(Corrections::all());
    EXPECT_EQ(r.after_out, kOcf1b);
}

TEST(SimTimerFlags, StockSimavrClearsEveryFlagOnAnyWrite) {
    REQUIRE_SELFTEST("selftest_sbi");
    const SbiRun r = run_sbi(all_but(&Corrections::timer_flags_write_one_to_clear));
    EXPECT_EQ(r.after_out, 0);
    EXPECT_EQ(r.after_sbi, 0);
}
