// Curves through the whole pipeline (seed part IV, issue 5): G2/G3 arcs (GRBL's checks and error
// codes), G2.1/G3.1 ellipses and G5 Beziers, parsed, planned and stepped on the host model. The
// path is rebuilt from the recorded step edges and compared with the exact curve; speeds are
// measured along the path.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "host_driver.h"
#include "host_hal.h"
#include "path_check.h"

namespace {

constexpr double kF = 16e6;
constexpr double kPi = 3.14159265358979323846;
constexpr double kStepsPerMm = 80;

struct Sample {
    uint64_t cycle;
    int32_t p[3]; ///< X Y Z, steps
};

struct Curves : ::testing::Test {
    ll::test::HostDriver d;
    void SetUp() override {
        d.boot(true);
        // X Y Z: 80 steps/mm, 6000 mm/min, 1000 mm/s^2, one speed group.
        for (const char* s :
             {"$100=80", "$101=80", "$102=80", "$110=6000", "$111=6000", "$112=6000", "$120=1000",
              "$121=1000", "$122=1000", "$140=0", "$141=0", "$142=0"}) {
            ASSERT_EQ(d.command(s), "ok\r\n") << s;
        }
        ll::host::clear_edges();
    }

    std::string run(const std::string& line) { return d.command(line); }

    // The positions visited from the `from`-th recorded edge on (X Y Z, steps from the power-up
    // position), replaying every edge before it for the direction pins ($3 = 0: a high direction
    // pin steps towards negative coordinates).
    static std::vector<Sample> path(size_t from = 0) {
        std::vector<Sample> out;
        uint8_t dir[3] = {};
        Sample s{0, {0, 0, 0}};
        const auto& edges = ll::host::edges();
        for (size_t i = 0; i < edges.size(); ++i) {
            const auto& e = edges[i];
            if (e.axis >= 3) continue;
            if (e.kind == ll::host::EdgeKind::Dir) dir[e.axis] = e.level;
            if (e.kind != ll::host::EdgeKind::Step || e.level != 1) continue;
            s.p[e.axis] += dir[e.axis] ? -1 : 1;
            if (i < from) continue;
            // Axes stepping together (one sample of the walker) make one position.
            if (!out.empty() && out.back().cycle == e.cycle) {
                out.back() = s;
            } else {
                s.cycle = e.cycle;
                out.push_back(s);
            }
        }
        return out;
    }

    // Largest distance (steps) from the visited positions to the plane curve c(u), u in [0, 1].
    template <class F>
    static double worst_distance(const std::vector<Sample>& p, F c) {
        std::vector<lltest::PlanePoint> pts;
        for (const auto& s : p)
            pts.push_back({static_cast<double>(s.p[0]), static_cast<double>(s.p[1])});
        return lltest::worst_distance(pts, [&](double u) {
            auto q = c(u);
            return lltest::PlanePoint{q.first, q.second};
        });
    }

    // Lowest speed along the path in the middle of the job, mm/min: the distance between
    // positions `w` apart over their time, leaving out the first and last `skip` of the
    // positions (acceleration and deceleration).
    static double lowest_speed(const std::vector<Sample>& p, double skip, size_t w = 100) {
        size_t a = static_cast<size_t>(p.size() * skip), b = p.size() - a;
        double low = 1e30;
        for (size_t i = a; i + w < b; ++i) {
            double dx = p[i + w].p[0] - p[i].p[0], dy = p[i + w].p[1] - p[i].p[1];
            double t = static_cast<double>(p[i + w].cycle - p[i].cycle) / kF;
            low = std::min(low, std::hypot(dx, dy) / kStepsPerMm / t * 60);
        }
        return low;
    }

    // Speed along a circle centred on (cx, cy) mm, of radius r mm, between the positions at 30 %
    // and 70 % of the steps, mm/min: the swept angle (unwrapped) times r over the time.
    static double circle_speed(const std::vector<Sample>& p, double cx, double cy, double r) {
        size_t a = p.size() * 3 / 10, b = p.size() * 7 / 10;
        lltest::AngleTracker ang(cx * kStepsPerMm, cy * kStepsPerMm, p[a].p[0], p[a].p[1]);
        double swept = 0;
        for (size_t i = a + 1; i <= b; ++i) swept = ang.add(p[i].p[0], p[i].p[1]);
        return std::fabs(swept) * r / (static_cast<double>(p[b].cycle - p[a].cycle) / kF) * 60;
    }
};

// GRBL's arc errors, same codes, and the same for our extensions. A refused line changes
// nothing: the next line still starts from the old position.
TEST_F(Curves, BadArcsGetGrblsErrorCodes) {
    EXPECT_EQ(run("G2 I5 F600"), "error:26\r\n");        // no axis word
    EXPECT_EQ(run("G2 Z5 I5 F600"), "error:32\r\n");     // none in the plane
    EXPECT_EQ(run("G2 X10 F600"), "error:35\r\n");       // neither offsets nor R
    EXPECT_EQ(run("G2 X10 R4 F600"), "error:34\r\n");    // radius shorter than half the chord
    EXPECT_EQ(run("G2 X0 Y0 R5 F600"), "error:33\r\n");  // R mode, target = position
    EXPECT_EQ(run("G2 X10 I4 J0 F600"), "error:33\r\n"); // end 2 mm off the circle
    EXPECT_EQ(run("G2 X10 I5 P0 F600"), "error:33\r\n"); // zero turns
    EXPECT_EQ(run("G2 X10 I5 P1.5 F600"), "error:23\r\n");
    EXPECT_EQ(run("G2 X10 I5 Q1 F600"), "error:36\r\n"); // Q means nothing to an arc
    EXPECT_EQ(run("G2 X10 A1 I5 F600"), "error:31\r\n"); // an axis outside the plane
    EXPECT_EQ(run("G2 X10 I5"), "error:22\r\n");         // no feed yet
    EXPECT_EQ(run("G53 G2 X10 I5 F600"), "error:30\r\n");
    EXPECT_EQ(run("G1 X1 P-1 F600"), "error:4\r\n"); // P is negative only in a G5
    // Beyond the step generator's range: a centre 2^22 steps away, a path over 2^23 um.
    EXPECT_EQ(run("G2 X0 Y0 I60000 J0 F600"), "error:33\r\n");
    EXPECT_EQ(run("G2 X0 Y0 I1000 J0 P2 F600"), "error:33\r\n");
    // Ellipses: semi-axes positive, both ends on the ellipse, the centre given.
    EXPECT_EQ(run("G2.1 X10 I5 J0 P5 Q0 F600"), "error:4\r\n");
    EXPECT_EQ(run("G2.1 X10 I5 J0 P4 Q3 F600"), "error:33\r\n");
    EXPECT_EQ(run("G2.1 X10 I5 J0 F600"), "error:28\r\n");
    EXPECT_EQ(run("G2.1 X10 P5 Q3 F600"), "error:35\r\n");
    // Values that round to zero: an R0 (too short, whatever its sign), a semi-axis 0.
    EXPECT_EQ(run("G2 X10 R-0.0001 F600"), "error:34\r\n");
    EXPECT_EQ(run("G2.1 X10 I5 J0 P-5 Q3 F600"), "error:4\r\n");
    EXPECT_EQ(run("G2.1 X10 I5 J0 P5 Q0.0001 F600"), "error:4\r\n");
    // G5: P Q required; I J required unless it continues a G5.
    EXPECT_EQ(run("G5 X10 I1 J1 F600"), "error:28\r\n");
    EXPECT_EQ(run("G5 X10 P-1 Q1 F600"), "error:28\r\n");
    d.run_until_idle();
    EXPECT_TRUE(path().empty());
    EXPECT_EQ(run("G1 X1 F600"), "ok\r\n");
    d.run_until_idle();
    auto p = path();
    ASSERT_FALSE(p.empty());
    EXPECT_EQ(p.back().p[0], 80);
    EXPECT_EQ(p.back().p[1], 0);
}

// The ends of an ellipse must be on it within a step (12.5 um here) + 2 um, as an arc's within
// GRBL's tolerance. Checked in check mode ($C): nothing moves.
TEST_F(Curves, EllipseEndsMustLieOnTheEllipseWithinAStep) {
    ASSERT_EQ(run("$C"), "[MSG:Enabled]\r\nok\r\n");
    EXPECT_EQ(run("G2.1 X10.014 I5 J0 P5 Q3 F600"), "ok\r\n");
    EXPECT_EQ(run("G0 X0 Y0"), "ok\r\n");
    EXPECT_EQ(run("G2.1 X10.015 I5 J0 P5 Q3 F600"), "error:33\r\n");
    EXPECT_EQ(run("G2.1 X5 Y3.014 I5 J0 P5 Q3 F600"), "ok\r\n");
    EXPECT_EQ(run("G0 X0 Y0"), "ok\r\n");
    EXPECT_EQ(run("G2.1 X5 Y2.985 I5 J0 P5 Q3 F600"), "error:33\r\n");
    EXPECT_EQ(run("G2.1 X10 I5.015 J0 P5 Q3 F600"), "error:33\r\n"); // the start is off
}

// GRBL's tolerance for an arc's end: within 0.005 mm of the circle, or else within 0.5 mm and
// 0.1 % of the radius (here 20 mm: 0.020 mm). Checked in check mode ($C): nothing moves.
TEST_F(Curves, ArcEndsMustLieOnTheCircleWithinGrblsTolerance) {
    ASSERT_EQ(run("$C"), "[MSG:Enabled]\r\nok\r\n");
    EXPECT_EQ(run("G2 X40.020 I20 J0 F600"), "ok\r\n");
    EXPECT_EQ(run("G0 X0 Y0"), "ok\r\n");
    EXPECT_EQ(run("G2 X40.021 I20 J0 F600"), "error:33\r\n");
    EXPECT_EQ(run("G2 X39.980 I20 J0 F600"), "ok\r\n");
    EXPECT_EQ(run("G0 X0 Y0"), "ok\r\n");
    EXPECT_EQ(run("G2 X39.979 I20 J0 F600"), "error:33\r\n");
    EXPECT_EQ(run("G2 X4.005 I2 J0 F600"), "ok\r\n"); // r 2 mm: 0.005 mm
    EXPECT_EQ(run("G0 X0 Y0"), "ok\r\n");
    EXPECT_EQ(run("G2 X4.006 I2 J0 F600"), "error:33\r\n");
}

// Radius mode: the centre is on the chord's bisector, on the right of the way for G2 with R > 0,
// on the left for G3 or R < 0 (the longer arc).
TEST_F(Curves, RadiusModePicksTheCentreAsGrblDoes) {
    struct Case {
        const char* line;
        double cx, cy, sweep; ///< expected centre (mm) and signed sweep (turns)
    } cases[] = {
        {"G2 X10 R5 F3000", 5, 0, -0.5},        {"G3 X10 R5 F3000", 5, 0, 0.5},
        {"G2 X10 Y10 R10 F3000", 10, 0, -0.25}, {"G2 X10 Y10 R-10 F3000", 0, 10, -0.75},
        {"G3 X10 Y10 R10 F3000", 0, 10, 0.25},
    };
    for (const auto& c : cases) {
        ASSERT_EQ(run("G90 G0 X0 Y0"), "ok\r\n");
        d.run_until_idle();
        size_t from = ll::host::edges().size();
        ASSERT_EQ(run(c.line), "ok\r\n") << c.line;
        d.run_until_idle();
        auto p = path(from);
        ASSERT_FALSE(p.empty()) << c.line;
        double r = std::hypot(c.cx, c.cy) * kStepsPerMm;
        double worst = 0, swept = 0;
        lltest::AngleTracker ang(c.cx * kStepsPerMm, c.cy * kStepsPerMm, 0, 0);
        for (const auto& s : p) {
            double x = s.p[0] - c.cx * kStepsPerMm, y = s.p[1] - c.cy * kStepsPerMm;
            worst = std::max(worst, std::fabs(std::hypot(x, y) - r));
            swept = ang.add(s.p[0], s.p[1]);
        }
        EXPECT_LT(worst, 0.75) << c.line;
        EXPECT_NEAR(swept / (2 * kPi), c.sweep, 0.01) << c.line;
    }
}

// `G2 X0 Y0 I10 J0` from the origin is a full circle (as GRBL): one move, 4 r steps on each
// axis, every position within 0.75 step of the circle, back exactly at the start, at the
// programmed speed.
TEST_F(Curves, FullCircleIsOneMoveAtTheFeedWithinThreeQuartersOfAStep) {
    ASSERT_EQ(run("G2 X0 Y0 I10 J0 F1200"), "ok\r\n");
    d.run_until_idle();
    auto p = path();
    size_t steps[2] = {};
    {
        Sample prev{0, {0, 0, 0}};
        for (const auto& s : p) {
            for (int a = 0; a < 2; ++a) steps[a] += s.p[a] != prev.p[a];
            prev = s;
        }
    }
    EXPECT_EQ(steps[0], 4u * 800);
    EXPECT_EQ(steps[1], 4u * 800);
    ASSERT_FALSE(p.empty());
    EXPECT_EQ(p.back().p[0], 0);
    EXPECT_EQ(p.back().p[1], 0);
    double worst = 0;
    for (const auto& s : p) {
        worst = std::max(worst, std::fabs(std::hypot(s.p[0] - 800.0, s.p[1]) - 800.0));
    }
    std::printf("full circle: worst %.3f step, speed %.1f mm/min\n", worst,
                circle_speed(p, 10, 0, 10));
    EXPECT_LT(worst, 0.75);
    EXPECT_NEAR(circle_speed(p, 10, 0, 10), 1200.0, 1200.0 * 0.01);
    // G2 is clockwise: from the circle's leftmost point it goes up first.
    EXPECT_GT(p[100].p[1], 0);
}

// G18 (Z, X) and G19 (Y, Z) as GRBL orders their axes: the centre offsets are K I and J K, and
// G2 turns clockwise in (first axis, second axis), so from the circle's low point on the first
// axis it heads along +second axis.
TEST_F(Curves, ArcsInG18AndG19UseTheirPlanesAxesAndSense) {
    struct Case {
        const char* line;
        int u, v; ///< the plane's axes (0 X, 1 Y, 2 Z)
    } cases[] = {
        {"G18 G2 X0 Z0 K10 I0 F3000", 2, 0},
        {"G19 G2 Y0 Z0 J10 K0 F3000", 1, 2},
        {"G17 G2 X0 Y0 I10 J0 F3000", 0, 1},
    };
    for (const auto& c : cases) {
        size_t from = ll::host::edges().size();
        ASSERT_EQ(run(c.line), "ok\r\n") << c.line;
        d.run_until_idle();
        auto p = path(from);
        ASSERT_GT(p.size(), 100u) << c.line;
        double worst = 0;
        for (const auto& s : p) {
            worst = std::max(worst, std::fabs(std::hypot(s.p[c.u] - 800.0, s.p[c.v]) - 800.0));
            EXPECT_EQ(s.p[3 - c.u - c.v], 0) << c.line; // the third axis stays put
        }
        EXPECT_LT(worst, 0.75) << c.line;
        EXPECT_GT(p[50].p[c.v], 0) << c.line;
        EXPECT_EQ(p.back().p[c.u], 0) << c.line;
        EXPECT_EQ(p.back().p[c.v], 0) << c.line;
    }
}

// P counts turns (LinuxCNC): P2 adds one full circle to the arc.
TEST_F(Curves, ArcTurnsWordAddsFullCircles) {
    ASSERT_EQ(run("G3 X10 I5 P2 F3000"), "ok\r\n");
    d.run_until_idle();
    auto p = path();
    ASSERT_FALSE(p.empty());
    EXPECT_EQ(p.back().p[0], 800);
    EXPECT_EQ(p.back().p[1], 0);
    size_t x_steps = 0;
    for (size_t i = 1; i < p.size(); ++i) x_steps += p[i].p[0] != p[i - 1].p[0];
    EXPECT_NEAR(static_cast<double>(x_steps), 4 * 400 + 2 * 400, 2); // 1.5 turns of r = 400
}

// A helix: Z follows the angle linearly, and the feed is along the 3D path.
TEST_F(Curves, HelixRaisesTheNormalAxisWithTheAngleAtThePathFeed) {
    ASSERT_EQ(run("G17 G2 X0 Y0 Z5 I10 J0 F1200"), "ok\r\n");
    d.run_until_idle();
    auto p = path();
    ASSERT_FALSE(p.empty());
    EXPECT_EQ(p.back().p[2], 400);
    double worst = 0;
    lltest::AngleTracker ang(800, 0, 0, 0);
    for (const auto& s : p) {
        double swept = ang.add(s.p[0], s.p[1]);
        worst = std::max(worst, std::fabs(s.p[2] - 400 * (-swept) / (2 * kPi)));
    }
    EXPECT_LT(worst, 1.0);
    // Path speed: sqrt(plane^2 + z^2) scales the plane's angular speed.
    double plane = circle_speed(p, 10, 0, 10);
    double len = std::hypot(2 * kPi * 10, 5.0);
    EXPECT_NEAR(plane * len / (2 * kPi * 10), 1200.0, 1200.0 * 0.01);
}

// G2.1 / G3.1: an elliptic arc (centre I J from the start, semi-axes P Q along X and Y); with no
// end point, the full ellipse.
TEST_F(Curves, FullEllipseStaysWithinThreeQuartersOfAStep) {
    ASSERT_EQ(run("G3.1 I20 J0 P20 Q8 F3000"), "ok\r\n");
    d.run_until_idle();
    auto p = path();
    ASSERT_FALSE(p.empty());
    EXPECT_EQ(p.back().p[0], 0);
    EXPECT_EQ(p.back().p[1], 0);
    double worst = worst_distance(p, [](double t) {
        double a = 2 * kPi * t;
        return std::make_pair(1600.0 - 1600.0 * std::cos(a), -640.0 * std::sin(a));
    });
    std::printf("full ellipse: worst %.3f step over %zu steps\n", worst, p.size());
    EXPECT_LT(worst, 0.75);
    // G3.1 is anticlockwise: from the left end it goes down first.
    EXPECT_LT(p[50].p[1], 0);
}

// A G5's path bound is its control polygon (start, a, b, end): 8379 mm passes, 8400 mm is over
// 2^23 um (error:33). In check mode: no move of a few metres.
TEST_F(Curves, BezierPathBoundIsItsControlPolygon) {
    ASSERT_EQ(run("$C"), "[MSG:Enabled]\r\nok\r\n");
    EXPECT_EQ(run("G5 X1 I4190 J0 P4189 Q0 F600"), "ok\r\n");
    EXPECT_EQ(run("G5 X1 I4200 J0 P4199 Q0 F600"), "error:33\r\n");
    EXPECT_EQ(run("G5 X1 I0 J4190 P0 Q4189 F600"), "ok\r\n");
    EXPECT_EQ(run("G5 X1 I0 J4195 P0 Q4195 F600"), "error:33\r\n");
}

// G5 (Marlin's cubic Bezier): I J the first control point from the start, P Q the second from
// the end; a G5 without I J continues the previous one smoothly (its first arm mirrors the last
// one's), with no stop at the joint.
TEST_F(Curves, BezierChainFollowsBothCurvesWithoutStopping) {
    ASSERT_EQ(run("G5 X20 Y0 I5 J10 P-5 Q10 F1500"), "ok\r\n");
    ASSERT_EQ(run("G5 X40 Y0 P-5 Q-10"), "ok\r\n");
    d.run_until_idle();
    auto p = path();
    ASSERT_FALSE(p.empty());
    EXPECT_EQ(p.back().p[0], 3200);
    EXPECT_EQ(p.back().p[1], 0);
    auto bez = [](const double c[4][2], double t) {
        double u = 1 - t;
        double b0 = u * u * u, b1 = 3 * u * u * t, b2 = 3 * u * t * t, b3 = t * t * t;
        return std::make_pair(
            kStepsPerMm * (b0 * c[0][0] + b1 * c[1][0] + b2 * c[2][0] + b3 * c[3][0]),
            kStepsPerMm * (b0 * c[0][1] + b1 * c[1][1] + b2 * c[2][1] + b3 * c[3][1]));
    };
    const double first[4][2] = {{0, 0}, {5, 10}, {15, 10}, {20, 0}};
    const double second[4][2] = {{20, 0}, {25, -10}, {35, -10}, {40, 0}};
    std::vector<Sample> a, b;
    // The first curve ends exactly on its end point (20, 0) mm: the second starts there.
    bool second_part = false;
    for (const auto& s : p) {
        (second_part ? b : a).push_back(s);
        if (s.p[0] == 1600 && s.p[1] == 0) second_part = true;
    }
    ASSERT_TRUE(second_part);
    double worst = std::max(worst_distance(a, [&](double t) { return bez(first, t); }),
                            worst_distance(b, [&](double t) { return bez(second, t); }));
    std::printf("G5 chain: worst %.3f step\n", worst);
    EXPECT_LT(worst, 0.75);
    // The joint is smooth: no slowdown anywhere between the two ends' ramps.
    double low = lowest_speed(p, 0.1);
    std::printf("G5 chain: lowest speed %.1f mm/min\n", low);
    EXPECT_GT(low, 1500 * 0.97);
}

// The junction with an arc uses its tangent: a line running into an arc tangentially keeps its
// speed, a line meeting it at a right angle slows down to the junction deviation's speed.
TEST_F(Curves, LineIntoArcJunctionUsesTheArcsTangent) {
    ASSERT_EQ(run("G1 X10 F1200"), "ok\r\n");
    ASSERT_EQ(run("G3 X20 Y10 I0 J10"), "ok\r\n"); // starts along +X
    d.run_until_idle();
    double tangent = lowest_speed(path(), 0.15);
    ASSERT_EQ(run("G0 X0 Y0"), "ok\r\n");
    d.run_until_idle();
    size_t from = ll::host::edges().size();
    ASSERT_EQ(run("G1 X10 F1200"), "ok\r\n");
    ASSERT_EQ(run("G2 X20 Y0 I5 J0"), "ok\r\n"); // starts along +Y
    d.run_until_idle();
    double corner = lowest_speed(path(from), 0.15);
    std::printf("lowest speed: tangent %.1f, corner %.1f mm/min\n", tangent, corner);
    // Speeds are averaged over 100 positions (1.25 mm), each within 0.71 step of the path: 1.4 %
    // of noise. A 90 degree corner with $11 = 0.010 mm and 1000 mm/s^2 is taken at about
    // 295 mm/min, which brings a 1.25 mm window down to 750 mm/min.
    EXPECT_GT(tangent, 1200 * 0.975);
    EXPECT_LT(corner, 1200 * 0.7);
}

// Speed on a tight curve respects the centripetal acceleration: v^2 / r <= a. With r = 1 mm and
// a = 100 mm/s^2 the circle is run at 10 mm/s (600 mm/min) whatever F asks.
TEST_F(Curves, TightArcIsSlowedToItsCentripetalLimit) {
    ASSERT_EQ(run("$120=100"), "ok\r\n");
    ASSERT_EQ(run("$121=100"), "ok\r\n");
    ASSERT_EQ(run("G2 X0 Y0 I1 J0 P3 F3000"), "ok\r\n");
    d.run_until_idle();
    double v = circle_speed(path(), 1, 0, 1);
    std::printf("r = 1 mm, a = 100 mm/s^2: %.1f mm/min\n", v);
    EXPECT_NEAR(v, 600.0, 600.0 * 0.02);
}

} // namespace
