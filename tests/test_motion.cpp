// Whole motion pipeline on the host model: motion API in, recorded pin edges out.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "motion_host.h"

using ll::motion::State;

namespace {

struct MotionTest : ::testing::Test {
    ll::Settings s;
    void SetUp() override {
        lltest::default_settings(s);
        lltest::reset_motion(s);
    }
};

} // namespace

TEST_F(MotionTest, RandomMovesEndExactlyWhereTheEdgesSayTheyAre) {
    std::mt19937 rng(3);
    double x = 0, y = 0, z = 0;
    for (int i = 0; i < 40; ++i) {
        x = (static_cast<int>(rng() % 4000) - 2000) / 100.0;
        y = (static_cast<int>(rng() % 4000) - 2000) / 100.0;
        z = (static_cast<int>(rng() % 400) - 200) / 100.0;
        lltest::line_to({x, y, z, 0}, 500 + rng() % 5000);
    }
    ASSERT_TRUE(lltest::run_until(State::Idle));
    int32_t pos[ll::kAxes], edges[ll::kAxes];
    ll::motion::position(pos);
    lltest::count_steps(edges);
    EXPECT_EQ(pos[0], std::lround(x * 80));
    EXPECT_EQ(pos[1], std::lround(y * 80));
    EXPECT_EQ(pos[2], std::lround(z * 80));
    for (uint8_t a = 0; a < ll::kAxes; ++a) EXPECT_EQ(edges[a], pos[a]);
    EXPECT_EQ(ll::motion::starvations(), 0u);
}

TEST_F(MotionTest, PositionDuringMotionCountsOnlyExecutedSteps) {
    lltest::line_to({100, 50, 0, 0}, 3000);
    for (int k = 0; k < 5; ++k) {
        lltest::run_for(16000000 / 5); // 0.2 s
        int32_t pos[ll::kAxes], edges[ll::kAxes];
        ll::motion::position(pos);
        lltest::count_steps(edges);
        for (uint8_t a = 0; a < ll::kAxes; ++a) EXPECT_EQ(pos[a], edges[a]) << "axis " << int(a);
    }
}

TEST_F(MotionTest, FeedHoldStopsAlongThePathLosesNoStepAndResumes) {
    lltest::line_to({100, 50, 0, 0}, 3000);
    lltest::line_to({150, 20, 0, 0}, 3000);
    lltest::run_for(16000000); // 1 s into the first move
    ll::motion::feed_hold();
    EXPECT_EQ(ll::motion::state(), State::Holding);
    ASSERT_TRUE(lltest::run_until(State::Held));
    int32_t held[ll::kAxes];
    ll::motion::position(held);
    // Decelerating from 50 mm/s at 1000 mm/s^2 takes 1.25 mm: stopped on the first line,
    // near 50 mm along it.
    double along = std::hypot(held[0] / 80.0, held[1] / 80.0);
    EXPECT_GT(along, 48.0);
    EXPECT_LT(along, 53.0);
    EXPECT_NEAR(held[1] * 2.0, held[0], 2.0); // on the line y = x / 2
    // Nothing moves while held.
    size_t edges_at_hold = ll::host::edges().size();
    ll::host::advance_to(ll::host::now() + 16000000);
    ll::motion::poll();
    EXPECT_EQ(ll::host::edges().size(), edges_at_hold);
    ll::motion::cycle_start();
    ASSERT_TRUE(lltest::run_until(State::Idle));
    int32_t pos[ll::kAxes], edges[ll::kAxes];
    ll::motion::position(pos);
    lltest::count_steps(edges);
    EXPECT_EQ(pos[0], 150 * 80);
    EXPECT_EQ(pos[1], 20 * 80);
    EXPECT_EQ(edges[0], 150 * 80);
    EXPECT_EQ(edges[1], 20 * 80);
}

TEST_F(MotionTest, FeedHoldWhileIdleQueuesMovesUntilCycleStart) {
    ll::motion::feed_hold();
    EXPECT_EQ(ll::motion::state(), State::Held);
    for (int i = 1; i <= 10; ++i) lltest::line_to({i * 1.0, 0, 0, 0}, 3000);
    lltest::run_for(16000000 / 10);
    EXPECT_TRUE(ll::host::edges().empty()); // nothing moved, not even the enable pin
    EXPECT_EQ(ll::motion::state(), State::Held);
    EXPECT_EQ(ll::motion::blocks_free(), ll::kPlannerSize - 10);
    ll::motion::cycle_start();
    ASSERT_TRUE(lltest::run_until(State::Idle));
    int32_t edges[ll::kAxes];
    lltest::count_steps(edges);
    EXPECT_EQ(edges[0], 800);
    // With all ten moves planned before the start, they run as one: no stop at the joints, so
    // 10 mm at F3000 and 1000 mm/s^2 take 0.2 s plus 0.05 s of acceleration and deceleration.
    double seconds =
        static_cast<double>(ll::host::edges().back().cycle - ll::host::edges().front().cycle) /
        16e6;
    EXPECT_NEAR(seconds, 0.25, 0.01);
}

TEST_F(MotionTest, ShortSegmentCircleRunsAtFullFeed) {
    // The benchmark's circle: radius 10 mm, 0.1 mm chords, F3000, 1000 mm/s^2.
    const double r = 10, pi = std::acos(-1.0);
    const int n = static_cast<int>(std::lround(2 * pi * r / 0.1));
    lltest::line_to({r, 0, 0, 0}, 3000, true);
    ASSERT_TRUE(lltest::run_until(State::Idle));
    uint64_t start = ll::host::now();
    for (int i = 1; i <= n; ++i) {
        double t = 2 * pi * i / n;
        lltest::line_to({r * std::cos(t), r * std::sin(t), 0, 0}, 3000);
    }
    ASSERT_TRUE(lltest::run_until(State::Idle));
    // The last step edge ends the motion.
    uint64_t end = ll::host::edges().back().cycle;
    double seconds = static_cast<double>(end - start) / 16e6;
    double ideal = 2 * pi * r / 50.0 + 50.0 / 1000.0; // cruise + accel/decel (v/a)
    std::printf("circle of %d segments: %.4f s, ideal %.4f s (x%.3f)\n", n, seconds, ideal,
                seconds / ideal);
    EXPECT_LT(seconds, 1.02 * ideal);
    EXPECT_EQ(ll::motion::starvations(), 0u);
}

TEST_F(MotionTest, AbortStopsAtOnceAndKeepsTheExecutedPosition) {
    lltest::line_to({100, 0, 0, 0}, 3000);
    lltest::run_for(16000000 / 2);
    EXPECT_TRUE(ll::motion::abort());
    int32_t pos[ll::kAxes], edges[ll::kAxes];
    ll::motion::position(pos);
    lltest::count_steps(edges);
    EXPECT_EQ(pos[0], edges[0]);
    EXPECT_GT(pos[0], 0);
    EXPECT_LT(pos[0], 8000);
    EXPECT_EQ(ll::motion::state(), State::Idle);
    // The next move starts from where the machine really is.
    lltest::line_to({10, 0, 0, 0}, 3000);
    ASSERT_TRUE(lltest::run_until(State::Idle));
    ll::motion::position(pos);
    lltest::count_steps(edges);
    EXPECT_EQ(pos[0], 800);
    EXPECT_EQ(edges[0], 800);
}

TEST_F(MotionTest, DriversAreEnabledWhileMovingAndReleasedAfterTheIdleDelay) {
    lltest::line_to({1, 0, 0, 0}, 3000);
    ASSERT_TRUE(lltest::run_until(State::Idle));
    const auto& e = ll::host::edges();
    ASSERT_FALSE(e.empty());
    EXPECT_EQ(e.front().kind, ll::host::EdgeKind::Enable);
    EXPECT_EQ(e.front().level, 0); // active low
    uint64_t stop = ll::host::now();
    ll::host::advance_to(stop + 16000ull * 30);
    ll::motion::poll();
    EXPECT_EQ(ll::host::edges().back().kind, ll::host::EdgeKind::Enable);
    EXPECT_EQ(ll::host::edges().back().level, 1);
    EXPECT_GE(ll::host::edges().back().cycle - stop, 16000ull * 25);
}

TEST_F(MotionTest, LookAheadArrivingLateNeverMakesTheSpeedJump) {
    // X10 and X10.5 queued together: the short second move is planned to stop. X20.5 arrives
    // 0.215 s later, while the first move already slows down for it: the second move's exit is
    // raised but it is too short to reach that speed, so the third must start from the speed
    // actually reached, not the planned one (which jumped from 3518 to 4000 steps/s in one step).
    // Over any 8 steps the squared step rate may grow by 2 a x 8 (a = 80,000 steps/s^2), with
    // room for the square-root tracker's quantisation (single steps reach 1.75 x 2 a).
    lltest::line_to({10, 0, 0, 0}, 3000);
    lltest::line_to({10.5, 0, 0, 0}, 3000);
    lltest::run_for(static_cast<uint64_t>(0.215 * 16e6));
    lltest::line_to({20.5, 0, 0, 0}, 3000);
    ASSERT_TRUE(lltest::run_until(State::Idle));
    std::vector<uint64_t> t;
    for (const auto& e : ll::host::edges()) {
        if (e.kind == ll::host::EdgeKind::Step && e.level == 1 && e.axis == 0) t.push_back(e.cycle);
    }
    ASSERT_EQ(t.size(), 1640u);
    auto rate = [&](size_t k) { return 16e6 / static_cast<double>(t[k] - t[k - 1]); };
    double worst = 0;
    for (size_t k = 1; k + 8 < t.size(); ++k) {
        double r0 = rate(k), r1 = rate(k + 8);
        worst = std::max(worst, (r1 * r1 - r0 * r0) / (2 * 80000.0 * 8));
    }
    std::printf("largest squared-rate gain over 8 steps: %.2f x 2a\n", worst);
    EXPECT_LE(worst, 1.3);
}
