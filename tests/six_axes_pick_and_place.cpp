// The seed's pick-and-place machine (§3.1): an XYZ carriage, a rotary nozzle axis A, and a
// second XY carriage (B, C) that selects components. Each group has its own maximum speed and
// acceleration; a move regulates one group and the others follow the path. 6-axis host build.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "host_driver.h"
#include "host_hal.h"
#include "lowlevel/config.h"

static_assert(ll::kAxes == 6, "built against the 6-axis core");

namespace {

constexpr double kF = 16e6;

struct PickAndPlace : ::testing::Test {
    ll::test::HostDriver d;
    void SetUp() override {
        d.boot(true);
        // X Y Z and B C: 80 steps/mm. A: 10 steps/deg. Groups: XYZ = 0, A = 1, B C = 2.
        // Maximum rates: XYZ 6000 mm/min, A 36000 deg/min, B C 3000 mm/min.
        for (const char* s :
             {"$100=80",   "$101=80",   "$102=80",   "$103=10",    "$104=80",   "$105=80",
              "$110=6000", "$111=6000", "$112=6000", "$113=36000", "$114=3000", "$115=3000",
              "$120=1000", "$121=1000", "$122=1000", "$123=1000",  "$124=500",  "$125=500",
              "$140=0",    "$141=0",    "$142=0",    "$143=1",     "$144=2",    "$145=2"}) {
            ASSERT_EQ(d.command(s), "ok\r\n") << s;
        }
        ll::host::clear_edges();
    }
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
    void run(const char* line) {
        ll::host::clear_edges();
        ASSERT_EQ(d.command(line), "ok\r\n") << line;
        d.run_until_idle();
    }
};

} // namespace

TEST_F(PickAndPlace, SelectionCarriageRegulatesItsOwnPathSpeed) {
    run("G1 B50 C30 F1200");
    // |(50, 30)| = 58.31 mm at 1200 mm/min: B at 1029 mm/min, C at 617 mm/min.
    double l = std::hypot(50.0, 30.0);
    EXPECT_NEAR(cruise_rate(4) / 80, 1200 * 50 / l, 1200 * 50 / l * 0.005);
    EXPECT_NEAR(cruise_rate(5) / 80, 1200 * 30 / l, 1200 * 30 / l * 0.005);
    EXPECT_EQ(steps_of(0).size(), 0u);
}

TEST_F(PickAndPlace, PlacementCarriageRegulatesAndTheSelectionCarriageFollows) {
    run("G1 X20 Y10 B20 F1200");
    // XYZ moves 22.36 mm at 1200 mm/min; B covers its 20 mm in the same time.
    double l = std::hypot(20.0, 10.0);
    EXPECT_NEAR(cruise_rate(0) / 80, 1200 * 20 / l, 1200 * 20 / l * 0.005);
    EXPECT_NEAR(cruise_rate(1) / 80, 1200 * 10 / l, 1200 * 10 / l * 0.005);
    EXPECT_NEAR(cruise_rate(4) / 80, 1200 * 20 / l, 1200 * 20 / l * 0.005);
}

TEST_F(PickAndPlace, NozzleAloneRegulatesInDegreesPerMinute) {
    run("G1 A180 F3600");
    EXPECT_NEAR(cruise_rate(3) / 10, 3600.0, 3600 * 0.005);
}

TEST_F(PickAndPlace, EachGroupStaysWithinItsOwnMaximumSpeed) {
    // Rapids: every group at its own limit, independently.
    run("G0 B100");
    EXPECT_NEAR(cruise_rate(4) / 80, 3000.0, 3000 * 0.005); // $114
    run("G0 X100");
    EXPECT_NEAR(cruise_rate(0) / 80, 6000.0, 6000 * 0.005); // $110, not limited by B C
    // A placement move dragging the selection carriage: slowed until B keeps to 3000 mm/min.
    run("G91 G1 X10 B80 F6000"); // relative: X +10 mm, B +80 mm
    EXPECT_NEAR(cruise_rate(4) / 80, 3000.0, 3000 * 0.005);
    EXPECT_NEAR(cruise_rate(0) / 80, 3000.0 * 10 / 80, 3000.0 * 10 / 80 * 0.005);
}
