// Issue 6 on the real 4-axis image: speed groups (seed §3.1) measured from the step timestamps
// of lowlevel.elf in simavr. X Y Z regulate the feed in mm/min and the rotary A follows; A alone
// takes F in degrees/min; a follower that would exceed its own maximum rate slows the move until
// it runs exactly at that maximum. Same settings as the host tests (tests/test_groups.cpp).
#include <stdio.h>

#include "fw_check.h"

using namespace ll::sim;
using namespace ll::sim::fw;

namespace {

const std::vector<std::string> kSettings = {
    "$100=80",    "$101=80",   "$102=80",   "$103=10",   "$110=6000", "$111=6000", "$112=6000",
    "$113=36000", "$120=1000", "$121=1000", "$122=1000", "$123=1000", "$140=0",    "$143=1"};

// Rising step edges of one axis on the chip, cycles.
std::vector<uint64_t> steps_of(const Trace& t, uint8_t axis) {
    std::vector<uint64_t> out;
    for (const PinEdge& e : t.edges) {
        if (e.kind == Kind::Step && e.axis == axis && e.level == 1) out.push_back(e.cycle);
    }
    return out;
}

// Average rate over the middle half of the axis' steps (cruise), steps per minute.
double cruise_rate(const std::vector<uint64_t>& t) {
    if (t.size() < 8) return 0;
    size_t a = t.size() / 4, b = 3 * t.size() / 4;
    return static_cast<double>(b - a) / (static_cast<double>(t[b] - t[a]) / 16e6) * 60;
}

Trace run(const std::vector<std::string>& extra, const std::string& line) {
    Job job;
    job.settings = kSettings;
    job.settings.insert(job.settings.end(), extra.begin(), extra.end());
    job.lines = {line};
    job.limit_ms = 20000; // G1 A90 F600 takes 9 s, G1 X10 A900 at A's 3600 deg/min 15 s
    Trace t = run_on_chip(job);
    EXPECT_TRUE(t.errors.empty()) << t.errors.front();
    return t;
}

} // namespace

TEST(FirmwareGroups, LinearAxesRegulateTheFeedAndTheRotaryAxisFollows) {
    REQUIRE_FIRMWARE();
    const Trace t = run({}, "G1 X10 A90 F600");
    const auto x = steps_of(t, 0), a = steps_of(t, 3);
    ASSERT_EQ(x.size(), 800u);
    ASSERT_EQ(a.size(), 900u);
    printf("[ measured ] G1 X10 A90 F600: X %.2f mm/min, A %.2f deg/min\n", cruise_rate(x) / 80,
           cruise_rate(a) / 10);
    EXPECT_NEAR(cruise_rate(x) / 80, 600.0, 600.0 * 0.005);
    EXPECT_NEAR(cruise_rate(a) / 10, 5400.0, 5400.0 * 0.005);
}

TEST(FirmwareGroups, RotaryAxisAloneTakesTheFeedInDegreesPerMinute) {
    REQUIRE_FIRMWARE();
    const Trace t = run({}, "G1 A90 F600");
    const auto a = steps_of(t, 3);
    ASSERT_EQ(a.size(), 900u);
    printf("[ measured ] G1 A90 F600: A %.2f deg/min\n", cruise_rate(a) / 10);
    EXPECT_NEAR(cruise_rate(a) / 10, 600.0, 600.0 * 0.005);
}

TEST(FirmwareGroups, AFollowerFasterThanItsMaximumSlowsTheMoveToThatMaximum) {
    REQUIRE_FIRMWARE();
    // 900 degrees while X does 10 mm at F600 would need 54000 deg/min: A runs at its 3600.
    const Trace t = run({"$113=3600"}, "G1 X10 A900 F600");
    const auto x = steps_of(t, 0), a = steps_of(t, 3);
    ASSERT_EQ(a.size(), 9000u);
    printf("[ measured ] G1 X10 A900 F600 with $113=3600: X %.2f mm/min, A %.2f deg/min\n",
           cruise_rate(x) / 80, cruise_rate(a) / 10);
    EXPECT_NEAR(cruise_rate(a) / 10, 3600.0, 3600.0 * 0.005);
    EXPECT_NEAR(cruise_rate(x) / 80, 40.0, 40.0 * 0.005);
}
