// Speed groups (seed §3.1, issue 6): a move regulates the speed of one group of axes; the other
// axes follow the path, and no axis exceeds its own maximum rate. Measured from the step edges
// the host model records, through the whole G-code pipeline.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "host_driver.h"
#include "host_hal.h"

namespace {

constexpr double kF = 16e6;

struct Groups : ::testing::Test {
    ll::test::HostDriver d;
    void SetUp() override {
        d.boot(true);
        // X Y Z: 80 steps/mm, 6000 mm/min, 1000 mm/s^2. A (rotary): 10 steps/deg,
        // 36000 deg/min, 1000 deg/s^2, its own speed group (the default: $143=1).
        for (const char* s : {"$100=80", "$101=80", "$102=80", "$103=10", "$110=6000", "$111=6000",
                              "$112=6000", "$113=36000", "$120=1000", "$121=1000", "$122=1000",
                              "$123=1000", "$140=0", "$143=1"}) {
            ASSERT_EQ(d.command(s), "ok\r\n") << s;
        }
        ll::host::clear_edges();
    }

    // Rising step edges of one axis, in CPU cycles.
    static std::vector<uint64_t> steps_of(uint8_t axis) {
        std::vector<uint64_t> t;
        for (const auto& e : ll::host::edges()) {
            if (e.kind == ll::host::EdgeKind::Step && e.axis == axis && e.level == 1) {
                t.push_back(e.cycle);
            }
        }
        return t;
    }
    // Average rate over the middle half of the axis' steps (cruise), steps per minute.
    static double cruise_rate(uint8_t axis) {
        auto t = steps_of(axis);
        if (t.size() < 8) return 0;
        size_t a = t.size() / 4, b = 3 * t.size() / 4;
        return (b - a) / (static_cast<double>(t[b] - t[a]) / kF) * 60;
    }
};

} // namespace

TEST_F(Groups, LinearAxesRegulateTheFeedAndTheRotaryAxisFollows) {
    ASSERT_EQ(d.command("G1 X10 A90 F600"), "ok\r\n");
    d.run_until_idle();
    ASSERT_EQ(steps_of(0).size(), 800u);
    ASSERT_EQ(steps_of(3).size(), 900u);
    // X at F600 mm/min; A covers its 90 degrees in the same time: 5400 deg/min.
    std::printf("X %.2f mm/min, A %.2f deg/min\n", cruise_rate(0) / 80, cruise_rate(3) / 10);
    EXPECT_NEAR(cruise_rate(0) / 80, 600.0, 600.0 * 0.005);
    EXPECT_NEAR(cruise_rate(3) / 10, 5400.0, 5400.0 * 0.005);
    // The follower moves at its average rate, not in bursts: its step intervals at cruise stay
    // within a factor of two of each other.
    auto a = steps_of(3);
    uint64_t lo = ~0ull, hi = 0;
    for (size_t i = a.size() / 4; i < 3 * a.size() / 4; ++i) {
        lo = std::min(lo, a[i + 1] - a[i]);
        hi = std::max(hi, a[i + 1] - a[i]);
    }
    EXPECT_LE(hi, 2 * lo);
}

TEST_F(Groups, RotaryAxisAloneTakesTheFeedInDegreesPerMinute) {
    ASSERT_EQ(d.command("G1 A90 F600"), "ok\r\n");
    d.run_until_idle();
    ASSERT_EQ(steps_of(3).size(), 900u);
    EXPECT_NEAR(cruise_rate(3) / 10, 600.0, 600.0 * 0.005);
}

TEST_F(Groups, AFollowerFasterThanItsMaximumSlowsTheMoveToThatMaximum) {
    ASSERT_EQ(d.command("$113=3600"), "ok\r\n"); // A: 3600 deg/min at most
    ll::host::clear_edges();
    // 900 degrees while X does 10 mm at F600 would need 54000 deg/min: the move is slowed so
    // that A runs exactly at 3600 deg/min (15 s), and X at 10 mm / 15 s = 40 mm/min.
    ASSERT_EQ(d.command("G1 X10 A900 F600"), "ok\r\n");
    d.run_until_idle();
    ASSERT_EQ(steps_of(3).size(), 9000u);
    EXPECT_NEAR(cruise_rate(3) / 10, 3600.0, 3600.0 * 0.005);
    EXPECT_NEAR(cruise_rate(0) / 80, 40.0, 40.0 * 0.005);
}
