// SIMAVR-NOTES 2 (a timer counter keeps its value), against selftest_preload and
// selftest_top_write.
// Each step_x / step_y toggle comes 10 cycles after its flag: response 4 + jmp 3 + push 2 + ldi 1
// (the main code is 1-cycle nops, so a flag never waits for a longer instruction).
#include "selftest_elf.h"

using namespace ll::sim;
using ll::sim::test::all_but;
using ll::sim::test::options;

namespace {

constexpr uint64_t kToOut = 4 + 6;
constexpr uint64_t kT1Period = 200; // OCR1A = 199, prescaler 1
constexpr uint64_t kT1Preload = 120;
constexpr uint64_t kT0Tick = 8; // prescaler 8
constexpr uint64_t kT0Preload = 236;
constexpr uint64_t kT0Written = 200;
constexpr uint16_t kGpior1 = 0x4A, kGpior2 = 0x4B; // data-space addresses

struct PreloadRun {
    uint64_t t1_start, t1_stop, t1_restart, t1_off, t0_start, t0_write;
    uint16_t read_back; ///< TCNT1 read right after the stop
    std::vector<uint64_t> x, y;
};

PreloadRun run_preload(const Corrections& c) {
    Sim sim(options("selftest_preload", c));
    PreloadRun r{};
    uint64_t* marks[] = {&r.t1_start, &r.t1_stop,  &r.t1_restart,
                         &r.t1_off,   &r.t0_start, &r.t0_write};
    const char* labels[] = {"t1_start", "t1_stop", "t1_restart", "t1_off", "t0_start", "t0_write"};
    for (size_t i = 0; i < 6; ++i) {
        EXPECT_TRUE(sim.run_until_pc(sim.symbol(labels[i]), ms(1))) << labels[i];
        *marks[i] = sim.cycle();
        if (i == 1) {
            sim.run_for(20); // past the two LDS and OUTs
            r.read_back = static_cast<uint16_t>(sim.peek(kGpior1) | sim.peek(kGpior2) << 8);
        }
    }
    sim.run_until_cycle(r.t0_write + 590);
    for (const Edge& e : sim.edges_of("step_x")) r.x.push_back(e.cycle);
    for (const Edge& e : sim.edges_of("step_y")) r.y.push_back(e.cycle);
    return r;
}

std::vector<uint64_t> between(const std::vector<uint64_t>& v, uint64_t from, uint64_t to) {
    std::vector<uint64_t> out;
    for (uint64_t c : v)
        if (c > from && c <= to) out.push_back(c);
    return out;
}

} // namespace

TEST(SimTimerKeepsCount, CorrectedStartsFromThePreloadedValue) {
    REQUIRE_SELFTEST("selftest_preload");
    const PreloadRun r = run_preload(Corrections::all());
    const std::vector<uint64_t> x = between(r.x, r.t1_start, r.t1_stop);
    ASSERT_GE(x.size(), 3u);
    // TCNT1 = 120 -> compare at 199 after 80 cycles, then every 200.
    for (size_t k = 0; k < x.size(); ++k)
        EXPECT_EQ(x[k], r.t1_start + (kT1Period - kT1Preload) + k * kT1Period + kToOut) << k;
    // GRBL's pulse idiom on Timer0: TCNT0 = 236 at prescaler 8 overflows after 20 ticks.
    ASSERT_FALSE(r.y.empty());
    EXPECT_EQ(r.y.front(), r.t0_start + (256 - kT0Preload) * kT0Tick + kToOut);
}

TEST(SimTimerKeepsCount, CorrectedStoppedTimerHoldsItsCount) {
    REQUIRE_SELFTEST("selftest_preload");
    const PreloadRun r = run_preload(Corrections::all());
    // The counter was at 120 at t1_start and counts one per cycle modulo 200.
    const uint64_t count = (r.t1_stop - r.t1_start + kT1Preload) % kT1Period;
    EXPECT_EQ(r.read_back, count);
    EXPECT_TRUE(between(r.x, r.t1_stop + kToOut, r.t1_restart).empty()); // no compare while off
    const std::vector<uint64_t> x = between(r.x, r.t1_restart, r.t1_off);
    ASSERT_GE(x.size(), 2u);
    EXPECT_EQ(x[0], r.t1_restart + (kT1Period - count) + kToOut);
    EXPECT_EQ(x[1] - x[0], kT1Period);
}

TEST(SimTimerKeepsCount, CorrectedCounterWriteIsExact) {
    REQUIRE_SELFTEST("selftest_preload");
    const PreloadRun r = run_preload(Corrections::all());
    const std::vector<uint64_t> y = between(r.y, r.t0_write, r.t0_write + 600);
    ASSERT_EQ(y.size(), 1u);
    EXPECT_EQ(y[0], r.t0_write + (256 - kT0Written) * kT0Tick + kToOut); // 56 ticks = 448
}

TEST(SimTimerKeepsCount, StockSimavrCountsFromZero) {
    REQUIRE_SELFTEST("selftest_preload");
    const PreloadRun r = run_preload(all_but(&Corrections::timer_keeps_count));
    const std::vector<uint64_t> x = between(r.x, r.t1_start, r.t1_stop);
    ASSERT_FALSE(x.empty());
    EXPECT_EQ(x[0], r.t1_start + kT1Period + kToOut); // the preload is ignored
    EXPECT_EQ(r.read_back, 0);                        // a stopped timer reads 0
    const std::vector<uint64_t> after = between(r.x, r.t1_restart, r.t1_off);
    ASSERT_FALSE(after.empty());
    EXPECT_EQ(after[0], r.t1_restart + kT1Period + kToOut); // restarts from 0
    // Timer0: the 236 preload is ignored (no overflow within 400 cycles, 256 ticks = 2048)...
    EXPECT_TRUE(between(r.y, r.t0_start, r.t0_write).empty());
    // ...and TCNT0 = 200 is rescaled by 256/255: 1606 cycles counted instead of 1600.
    const std::vector<uint64_t> y = between(r.y, r.t0_write, r.t0_write + 600);
    ASSERT_EQ(y.size(), 1u);
    EXPECT_EQ(y[0], r.t0_write + (2048 - 1606) + kToOut);
}

namespace {

struct TopWriteRun {
    uint64_t start, write;
    std::vector<uint64_t> x, y; ///< TIMER1_COMPA / TIMER1_COMPB toggles
};

TopWriteRun run_top_write(const Corrections& c) {
    Sim sim(options("selftest_top_write", c));
    TopWriteRun r{};
    EXPECT_TRUE(sim.run_until_pc(sim.symbol("t1_start"), ms(1)));
    r.start = sim.cycle();
    EXPECT_TRUE(sim.run_until_pc(sim.symbol("top_write"), ms(1)));
    r.write = sim.cycle();
    sim.run_until_cycle(r.write + 65600);
    for (const Edge& e : sim.edges_of("step_x")) r.x.push_back(e.cycle);
    for (const Edge& e : sim.edges_of("step_y")) r.y.push_back(e.cycle);
    return r;
}

constexpr uint64_t kFromSleep = 8 + 6; // response from idle sleep + vector/ISR up to the OUT

} // namespace

TEST(SimTimerKeepsCount, CorrectedLoweredTopWaitsForTheWrap) {
    REQUIRE_SELFTEST("selftest_top_write");
    const TopWriteRun r = run_top_write(Corrections::all());
    const uint64_t count = r.write - r.start; // prescaler 1 from 0
    ASSERT_EQ(count, 606u);
    ASSERT_GE(r.x.size(), 3u);
    // Up to 0xFFFF, wrap, up to the new TOP = 100: then every 101 cycles.
    EXPECT_EQ(r.x[0], r.write + (0x10000 - count) + 101 + kFromSleep);
    EXPECT_EQ(r.x[1] - r.x[0], 101u);
    // OCR1B = 5000 lies on the way up: its compare still happens.
    ASSERT_FALSE(r.y.empty());
    EXPECT_EQ(r.y[0], r.write + (5000 - count + 1) + kFromSleep);
}

TEST(SimTimerKeepsCount, StockSimavrComparesAtOnce) {
    REQUIRE_SELFTEST("selftest_top_write");
    const TopWriteRun r = run_top_write(all_but(&Corrections::timer_keeps_count));
    ASSERT_FALSE(r.x.empty());
    EXPECT_LT(r.x[0], r.write + 101); // no 4 ms wait: the firmware bug would go unnoticed
    EXPECT_TRUE(r.y.empty() || r.y[0] > r.write + 0x10000); // and no compare B on the way up
}
