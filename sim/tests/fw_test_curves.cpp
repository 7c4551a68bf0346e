// Issue 5 on the real image: curves stepped natively by lowlevel.elf in simavr. A full circle
// (the issue's `G2 X0 Y0 I10 J0 F1000` at 80 steps/mm), an ellipse and a Bezier: every position
// the step pins visit is within 1.0 step of the exact curve, the move ends exactly where it must,
// and every edge matches the host model's (the same core on the host) within the timing
// tolerance of the other firmware checks.
#include <math.h>
#include <stdio.h>

#include <algorithm>
#include <functional>

#include "fw_check.h"
#include "path_check.h"

using namespace ll::sim;
using namespace ll::sim::fw;

namespace {

const double kPi = acos(-1.0);

using Point = lltest::PlanePoint;

// The positions (X, Y steps) the step pins visit, X and Y edges of the same cycle (one port
// write) taken together.
std::vector<Point> visited(const Trace& t) {
    std::vector<Point> out;
    uint8_t dir = t.dir_levels0;
    int32_t p[2] = {0, 0};
    uint64_t last = UINT64_MAX;
    for (const PinEdge& e : t.edges) {
        if (e.axis > 1) continue;
        if (e.kind == Kind::Dir) {
            dir = static_cast<uint8_t>(e.level ? dir | (1u << e.axis) : dir & ~(1u << e.axis));
        } else if (e.kind == Kind::Step && e.level == 1) {
            p[e.axis] += (dir >> e.axis) & 1 ? -1 : 1; // $3 = 0: high = negative
            Point q{static_cast<double>(p[0]), static_cast<double>(p[1])};
            if (e.cycle == last && !out.empty()) {
                out.back() = q;
            } else {
                out.push_back(q);
            }
            last = e.cycle;
        }
    }
    return out;
}

const std::vector<std::string> kSettings = {"$100=80",   "$101=80",   "$110=6000",
                                            "$111=6000", "$120=1000", "$121=1000"};

// Runs `line` on the chip and the model: the chip's path within 1.0 step of `curve`, ending at
// `end` (steps), every edge as the model's.
void check_curve(const std::string& line, const std::function<Point(double)>& curve, Point end) {
    Job job;
    job.settings = kSettings;
    job.lines = {line};
    const Trace chip = run_on_chip(job);
    ASSERT_TRUE(chip.errors.empty()) << chip.errors.front();
    const std::vector<Point> pts = visited(chip);
    ASSERT_GT(pts.size(), 100u);
    const double worst = lltest::worst_distance(pts, curve);
    printf("[ measured ] %s: %zu positions, worst distance %.3f step, end (%g, %g), "
           "%.3f s, starvations %u, stack %u bytes (%u never touched)\n",
           line.c_str(), pts.size(), worst, pts.back().x, pts.back().y,
           static_cast<double>(chip.cycles) / 16e6, chip.starvations, chip.stack_bytes,
           chip.stack_free);
    EXPECT_GT(chip.stack_free, 0u) << "the stack reached the static RAM";
    EXPECT_LE(worst, 1.0);
    EXPECT_EQ(pts.back().x, end.x);
    EXPECT_EQ(pts.back().y, end.y);
    EXPECT_EQ(chip.starvations, 0u);
    const Trace model = run_on_model(job);
    const Comparison cmp = compare(model, chip);
    EXPECT_TRUE(cmp.ok()) << cmp.problems.front();
    printf("[ measured ] against the model: %s\n", cmp.ranges().c_str());
}

} // namespace

TEST(FirmwareCurves, FullCircleStaysWithinOneStepAndEndsWhereItStarted) {
    REQUIRE_FIRMWARE();
    check_curve(
        "G2 X0 Y0 I10 J0 F1000",
        [](double u) {
            return Point{800 - 800 * cos(2 * kPi * u), 800 * sin(2 * kPi * u)};
        },
        Point{0, 0});
}

TEST(FirmwareCurves, FullEllipseStaysWithinOneStepAndEndsWhereItStarted) {
    REQUIRE_FIRMWARE();
    check_curve(
        "G3.1 I15 J0 P15 Q6 F1500",
        [](double u) {
            return Point{1200 - 1200 * cos(2 * kPi * u), -480 * sin(2 * kPi * u)};
        },
        Point{0, 0});
}

TEST(FirmwareCurves, BezierStaysWithinOneStepAndEndsOnItsTarget) {
    REQUIRE_FIRMWARE();
    // From (0, 0) to (30, 5) mm through (5, 20) and (20, -15).
    check_curve(
        "G5 X30 Y5 I5 J20 P-10 Q-20 F1500",
        [](double u) {
            const double c[4][2] = {{0, 0}, {5, 20}, {20, -15}, {30, 5}};
            double v = 1 - u, b0 = v * v * v, b1 = 3 * v * v * u, b2 = 3 * v * u * u,
                   b3 = u * u * u;
            return Point{80 * (b0 * c[0][0] + b1 * c[1][0] + b2 * c[2][0] + b3 * c[3][0]),
                         80 * (b0 * c[0][1] + b1 * c[1][1] + b2 * c[2][1] + b3 * c[3][1])};
        },
        Point{2400, 400});
}
