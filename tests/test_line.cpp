// Lines in tick space (seed §7) and the micro-stepper (§2.2, §8.3).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "lowlevel/line.h"
#include "lowlevel/microstep.h"
#include "motion_util.h"

namespace {

// Bound on the deviation of any visited position from the ideal line, per axis, measured at the
// same reference-axis coordinate (docs/motion.md, "Deviation bound"):
//   -9/16 < x_j - s_j x_1 <= 9/16 + L s_j (1 - s_j)
// where L is the length of the macro segment the position belongs to.
constexpr double kMacroBound = 9.0 / 16.0;

struct Walk {
    double worst_excess = -1e9; // max over positions of deviation minus its bound
    double worst_dev = 0;       // max |deviation|
    uint64_t steps = 0;
};

// Walks a line with the given segment lengths (cycled), micro step by micro step.
Walk walk_line(const int32_t delta[ll::kAxes], const std::vector<uint8_t>& seg_lengths,
               bool* ok_end, bool* ok_successive) {
    ll::LineGeometry g;
    EXPECT_TRUE(ll::line_setup(g, delta));
    ll::LineCursor c;
    ll::line_start(g, c);
    const double d1 = g.dist[0];
    double slope[ll::kAxes];
    for (uint8_t j = 0; j < g.m; ++j) slope[j] = g.dist[j] / d1;
    uint32_t p[ll::kAxes] = {}; // micro position per sorted position
    Walk w;
    *ok_successive = true;
    size_t si = 0;
    while (c.x1 < g.dist[0]) {
        uint32_t left = g.dist[0] - c.x1;
        uint8_t len = seg_lengths[si++ % seg_lengths.size()];
        if (len > left) len = static_cast<uint8_t>(left);
        uint8_t e[ll::kAxes];
        ll::line_advance(g, c, len, e);
        ll::MicroRun runs[ll::kAxes];
        uint8_t n = ll::micro_split(e, g.m, runs);
        uint32_t total = 0;
        for (uint8_t r = 0; r < n; ++r) {
            if (!(runs[r].set & 1)) *ok_successive = false; // the reference axis always moves
            for (uint8_t k = 0; k < runs[r].count; ++k) {
                for (uint8_t j = 0; j < g.m; ++j) {
                    if (runs[r].set & (1u << j)) ++p[j]; // one tick at most per axis
                }
                ++w.steps;
                for (uint8_t j = 1; j < g.m; ++j) {
                    double dev = p[j] - slope[j] * p[0];
                    double bound = kMacroBound + len * slope[j] * (1 - slope[j]);
                    w.worst_excess = std::max(w.worst_excess, dev - bound);
                    w.worst_excess = std::max(w.worst_excess, -kMacroBound - dev);
                    w.worst_dev = std::max(w.worst_dev, std::fabs(dev));
                }
            }
            total += runs[r].count;
        }
        if (total != len) *ok_successive = false;
        for (uint8_t j = 0; j < g.m; ++j) {
            if (p[j] != c.pos[j]) *ok_successive = false; // micro path ends on the macro point
        }
    }
    *ok_end = true;
    for (uint8_t j = 0; j < g.m; ++j) {
        if (p[j] != g.dist[j]) *ok_end = false;
    }
    return w;
}

} // namespace

TEST(Line, StillAxesAreDroppedAndTheRestSortedByDistance) {
    int32_t delta[ll::kAxes] = {-30, 0, 700, 30};
    ll::LineGeometry g;
    ASSERT_TRUE(ll::line_setup(g, delta));
    ASSERT_EQ(g.m, 3);
    EXPECT_EQ(g.axis[0], 2);
    EXPECT_EQ(g.dist[0], 700u);
    EXPECT_EQ(g.axis[1], 0); // ties keep machine order
    EXPECT_EQ(g.axis[2], 3);
    EXPECT_EQ(g.dirs, 0x01);
    EXPECT_GE(1ul << g.shift, 8ul * 700);
}

TEST(Line, ZeroAndOverlongLinesAreRefused) {
    int32_t zero[ll::kAxes] = {};
    ll::LineGeometry g;
    EXPECT_FALSE(ll::line_setup(g, zero));
    int32_t huge[ll::kAxes] = {static_cast<int32_t>(ll::kMaxLineTicks) + 1};
    EXPECT_FALSE(ll::line_setup(g, huge));
    int32_t longest[ll::kAxes] = {-static_cast<int32_t>(ll::kMaxLineTicks), 3};
    EXPECT_TRUE(ll::line_setup(g, longest));
}

TEST(Line, TenThousandRandomLinesEndExactlyMoveByUnitStepsAndStayWithinTheBound) {
    std::mt19937 rng(20261121);
    double worst_excess = -1e9;
    double worst_dev_l1 = 0;
    uint64_t steps = 0;
    for (int i = 0; i < 10000; ++i) {
        int32_t delta[ll::kAxes];
        lltest::random_delta(rng, delta);
        // Alternate between the fine regime (L = 1) and random segment lengths up to 16.
        std::vector<uint8_t> lens;
        if (i % 2 == 0) {
            lens = {1};
        } else {
            for (int k = 0; k < 7; ++k) lens.push_back(static_cast<uint8_t>(1 + rng() % 16));
        }
        bool end_ok = false, successive_ok = false;
        Walk w = walk_line(delta, lens, &end_ok, &successive_ok);
        ASSERT_TRUE(end_ok) << "line " << i;
        ASSERT_TRUE(successive_ok) << "line " << i;
        worst_excess = std::max(worst_excess, w.worst_excess);
        if (i % 2 == 0) worst_dev_l1 = std::max(worst_dev_l1, w.worst_dev);
        steps += w.steps;
    }
    EXPECT_LT(worst_excess, 0.0);
    // With one-tick segments (every position computed), Bresenham-grade fidelity.
    EXPECT_LT(worst_dev_l1, kMacroBound);
    RecordProperty("micro_steps", std::to_string(steps));
    RecordProperty("worst_deviation_L1", std::to_string(worst_dev_l1));
    std::printf("10000 lines, %llu micro steps, worst deviation with L=1: %.4f tick, worst "
                "(deviation - bound): %+.4f tick\n",
                static_cast<unsigned long long>(steps), worst_dev_l1, worst_excess);
}

TEST(MicroStep, RunsGoFromAllAxesDownToTheReferenceAxis) {
    uint8_t e[] = {8, 5, 3};
    ll::MicroRun runs[3];
    ASSERT_EQ(ll::micro_split(e, 3, runs), 3);
    EXPECT_EQ(runs[0].set, 0b111);
    EXPECT_EQ(runs[0].count, 3);
    EXPECT_EQ(runs[1].set, 0b011);
    EXPECT_EQ(runs[1].count, 2);
    EXPECT_EQ(runs[2].set, 0b001);
    EXPECT_EQ(runs[2].count, 3);
}

TEST(MicroStep, EqualIncrementsShareOneRunAndZeroIncrementsAreLeftOut) {
    uint8_t e[] = {4, 4, 0, 2};
    ll::MicroRun runs[4];
    ASSERT_EQ(ll::micro_split(e, 4, runs), 2);
    EXPECT_EQ(runs[0].set, 0b1011);
    EXPECT_EQ(runs[0].count, 2);
    EXPECT_EQ(runs[1].set, 0b0011);
    EXPECT_EQ(runs[1].count, 2);
}

// DESIGN.md's counterexample to seed §8.3: slopes 0.5 and 0.49. Between two macro positions the
// axis with the smaller slope can move while the other does not, so the run set {1, 3} occurs
// although it is not a prefix of the slope order.
TEST(MicroStep, SeedOrderClaimCounterexampleGivesANonPrefixRun) {
    uint8_t e[] = {1, 0,
                   1}; // x_1 from 2 to 3: floor(1.5)-floor(1.0) = 0, floor(1.47)-floor(0.98) = 1
    ll::MicroRun runs[3];
    ASSERT_EQ(ll::micro_split(e, 3, runs), 1);
    EXPECT_EQ(runs[0].set, 0b101);
    EXPECT_EQ(runs[0].count, 1);

    // The same on a whole line: d = (100, 50, 49) with one-tick segments visits {1,3} runs.
    int32_t delta[ll::kAxes] = {100, 50, 49};
    ll::LineGeometry g;
    ASSERT_TRUE(ll::line_setup(g, delta));
    ll::LineCursor c;
    ll::line_start(g, c);
    int non_prefix = 0;
    while (c.x1 < g.dist[0]) {
        uint8_t inc[ll::kAxes];
        ll::line_advance(g, c, 1, inc);
        ll::MicroRun r[ll::kAxes];
        uint8_t n = ll::micro_split(inc, g.m, r);
        for (uint8_t k = 0; k < n; ++k) {
            if (r[k].set == 0b101) ++non_prefix;
        }
    }
    EXPECT_GT(non_prefix, 0);
}
