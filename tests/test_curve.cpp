// Curves walked in tick space (seed part IV): every visited position within 1.0 tick of the
// true curve (Euclidean, in ticks), strictly successive positions, exact end point.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>

#include "lowlevel/curve.h"

namespace {

const double kPi = std::acos(-1.0);

struct Result {
    double worst = 0; // largest distance to the curve, ticks
    long samples = 0;
    bool successive = true;
    bool ended = false;
};

// Walks the curve, measuring each visited position's distance with `dist`.
Result walk(ll::CurveWalker& w, const int32_t end[3],
            const std::function<double(const int32_t p[3])>& dist) {
    Result r;
    int32_t prev[3] = {w.pos[0], w.pos[1], w.pos[2]};
    uint8_t moved, neg;
    while (w.next(moved, neg)) {
        ++r.samples;
        for (int a = 0; a < 3; ++a) {
            int32_t d = w.pos[a] - prev[a];
            if (d < -1 || d > 1) r.successive = false;
            bool m = (moved >> a) & 1, n = (neg >> a) & 1;
            if (m != (d != 0) || (m && n != (d < 0))) r.successive = false;
            prev[a] = w.pos[a];
        }
        r.worst = std::max(r.worst, dist(w.pos));
    }
    r.ended = w.pos[0] == end[0] && w.pos[1] == end[1] && w.pos[2] == end[2];
    return r;
}

// Closest distance from (x, y) to the ellipse (cx + a cos t, cy + b sin t), by Newton on t from
// `t` (the previous solution: the walk moves along the curve) or, when that does not land close,
// from a coarse scan. `t` is updated.
double ellipse_distance(double x, double y, double cx, double cy, double a, double b, double& t0) {
    double px = x - cx, py = y - cy;
    auto newton = [&](double t) {
        for (int i = 0; i < 8; ++i) {
            double ex = a * std::cos(t), ey = b * std::sin(t);
            double dx = -a * std::sin(t), dy = b * std::cos(t);
            double f = (ex - px) * dx + (ey - py) * dy;
            double df =
                dx * dx + dy * dy + (ex - px) * (-a * std::cos(t)) + (ey - py) * (-b * std::sin(t));
            if (df <= 0) break;
            t -= f / df;
        }
        return t;
    };
    double t = newton(t0);
    double d = std::hypot(a * std::cos(t) - px, b * std::sin(t) - py);
    if (d < 0.5) {
        t0 = t;
        return d;
    }
    double best_t = 0, best = 1e300;
    for (int i = 0; i < 256; ++i) {
        double u = 2 * kPi * i / 256;
        double e = std::hypot(a * std::cos(u) - px, b * std::sin(u) - py);
        if (e < best) {
            best = e;
            best_t = u;
        }
    }
    t = best_t;
    for (int i = 0; i < 30; ++i) {
        double ex = a * std::cos(t), ey = b * std::sin(t);
        double dx = -a * std::sin(t), dy = b * std::cos(t);
        double f = (ex - px) * dx + (ey - py) * dy;
        double df =
            dx * dx + dy * dy + (ex - px) * (-a * std::cos(t)) + (ey - py) * (-b * std::sin(t));
        if (df == 0) break;
        t -= f / df;
    }
    double e = std::hypot(a * std::cos(t) - px, b * std::sin(t) - py);
    t0 = e < best ? t : best_t;
    return std::min(best, e);
}

// The machine's rounded positions and the commanded (exact) points of a curve's ends.
ll::CurveWalker::Ends ends(const int32_t start[3], const int32_t end[3], double sx, double sy,
                           double ex, double ey) {
    ll::CurveWalker::Ends e;
    for (int a = 0; a < 3; ++a) {
        e.start[a] = start[a];
        e.end[a] = end[a];
    }
    e.start_q8[0] = static_cast<int32_t>(std::lround(sx * 256));
    e.start_q8[1] = static_cast<int32_t>(std::lround(sy * 256));
    e.end_q8[0] = static_cast<int32_t>(std::lround(ex * 256));
    e.end_q8[1] = static_cast<int32_t>(std::lround(ey * 256));
    return e;
}

double log_uniform(std::mt19937& rng, double lo, double hi) {
    std::uniform_real_distribution<double> u(std::log(lo), std::log(hi));
    return std::exp(u(rng));
}

} // namespace

TEST(Curve, RandomArcsStayWithinOneTickOfTheCircleAndEndExactly) {
    std::mt19937 rng(51);
    std::uniform_real_distribution<double> ang(-kPi, kPi), frac(0, 1);
    double worst = 0;
    long samples = 0;
    for (int i = 0; i < 600; ++i) {
        double r = log_uniform(rng, 1, 50000);
        double cx = frac(rng) * 1000 - 500, cy = frac(rng) * 1000 - 500;
        double t0 = ang(rng);
        bool full = i % 5 == 0;
        bool cw = (rng() & 1) != 0;
        double sweep = full ? 2 * kPi : frac(rng) * 2 * kPi;
        double t1 = t0 + (cw ? -sweep : sweep);
        int32_t start[3] = {static_cast<int32_t>(std::lround(cx + r * std::cos(t0))),
                            static_cast<int32_t>(std::lround(cy + r * std::sin(t0))), 0};
        int32_t end[3] = {static_cast<int32_t>(std::lround(cx + r * std::cos(t1))),
                          static_cast<int32_t>(std::lround(cy + r * std::sin(t1))), 0};
        if (full) {
            end[0] = start[0];
            end[1] = start[1];
        }
        int32_t c[2] = {static_cast<int32_t>(std::lround(cx * 256)),
                        static_cast<int32_t>(std::lround(cy * 256))};
        uint32_t rad[2] = {static_cast<uint32_t>(std::lround(r * 256)),
                           static_cast<uint32_t>(std::lround(r * 256))};
        ll::CurveWalker::Ends e = ends(start, end, cx + r * std::cos(t0), cy + r * std::sin(t0),
                                       full ? cx + r * std::cos(t0) : cx + r * std::cos(t1),
                                       full ? cy + r * std::sin(t0) : cy + r * std::sin(t1));
        ll::CurveWalker w{};
        ASSERT_TRUE(w.arc(e, c, rad, cw, 0)) << i;
        Result res = walk(w, end, [&](const int32_t p[3]) {
            return std::fabs(std::hypot(p[0] - c[0] / 256.0, p[1] - c[1] / 256.0) - rad[0] / 256.0);
        });
        ASSERT_TRUE(res.successive) << "arc " << i;
        ASSERT_TRUE(res.ended) << "arc " << i;
        ASSERT_LE(res.worst, 1.0) << "arc " << i << " r=" << r;
        worst = std::max(worst, res.worst);
        samples += res.samples;
    }
    std::printf("600 arcs, %ld samples, worst distance to the circle %.3f tick\n", samples, worst);
}

TEST(Curve, HelicalArcMovesTheNormalAxisLinearlyWithTheAngle) {
    // A full turn of radius 800 ticks rising 400 ticks, counter-clockwise.
    int32_t start[3] = {800, 0, 0}, end[3] = {800, 0, 400};
    int32_t c[2] = {0, 0};
    uint32_t rad[2] = {800 * 256, 800 * 256};
    ll::CurveWalker w{};
    ASSERT_TRUE(w.arc(ends(start, end, 800, 0, 800, 0), c, rad, false, 0));
    double worst = 0;
    Result res = walk(w, end, [&](const int32_t p[3]) {
        double t = std::atan2(p[1], p[0]);
        if (t < 0) t += 2 * kPi;
        double radial = std::hypot(p[0], p[1]) - 800;
        double z = 400 * t / (2 * kPi);
        // near the seam, the angle wraps: take the closer of both ends
        double dz = std::min(std::fabs(p[2] - z), std::fabs(p[2] - (z + 400)));
        double d = std::hypot(radial, dz);
        worst = std::max(worst, d);
        return d;
    });
    EXPECT_TRUE(res.successive);
    EXPECT_TRUE(res.ended);
    EXPECT_LE(res.worst, 1.0);
}

TEST(Curve, SteepHelicesStepEveryTickOfTheNormalAxis) {
    // Pieces are also bounded by the normal axis' travel: a short arc or Bezier that rises far
    // (a steep helix) used to get pieces of 2^16 samples, whose 16-bit count wrapped to 0 and
    // lost the rise (the walker jumped to the end).
    for (int32_t rise : {40000, 200000, -70000}) {
        // A quarter arc of radius 100 ticks.
        int32_t start[3] = {100, 0, 0}, end[3] = {0, 100, rise};
        int32_t c[2] = {0, 0};
        uint32_t rad[2] = {100 * 256, 100 * 256};
        ll::CurveWalker w{};
        ASSERT_TRUE(w.arc(ends(start, end, 100, 0, 0, 100), c, rad, false, 0)) << rise;
        Result res = walk(w, end, [](const int32_t*) { return 0.0; });
        EXPECT_TRUE(res.successive) << rise;
        EXPECT_TRUE(res.ended) << rise;
        EXPECT_GE(res.samples, std::abs(rise)) << rise; // one tick of w at most per sample
        // A Bezier of about 80 ticks with the same rise.
        int32_t bstart[3] = {0, 0, 0}, bend[3] = {80, 0, rise};
        ll::CurveWalker b{};
        ll::CurveWalker::Ends e = ends(bstart, bend, 0, 0, 80, 0);
        int32_t p1[2] = {20 * 256, 30 * 256}, p2[2] = {60 * 256, 30 * 256};
        ASSERT_TRUE(b.bezier(e, p1, p2)) << rise;
        Result rb = walk(b, bend, [](const int32_t*) { return 0.0; });
        EXPECT_TRUE(rb.successive) << rise;
        EXPECT_TRUE(rb.ended) << rise;
        EXPECT_GE(rb.samples, std::abs(rise)) << rise;
    }
}

TEST(Curve, ExtraTurnsAddFullCircles) {
    int32_t start[3] = {100, 0, 0}, end[3] = {0, 100, 0};
    int32_t c[2] = {0, 0};
    uint32_t rad[2] = {100 * 256, 100 * 256};
    ll::CurveWalker w{};
    ASSERT_TRUE(w.arc(ends(start, end, 100, 0, 0, 100), c, rad, false, 2)); // a quarter + 2 turns
    long x_steps = 0;
    uint8_t moved, neg;
    while (w.next(moved, neg)) x_steps += moved & 1;
    // X travels 4 r per turn and r on the quarter: about 900 ticks.
    EXPECT_NEAR(x_steps, 900, 4);
}

TEST(Curve, RandomEllipsesStayWithinOneTickAndEndExactly) {
    std::mt19937 rng(52);
    std::uniform_real_distribution<double> ang(-kPi, kPi), frac(0, 1);
    double worst = 0;
    for (int i = 0; i < 200; ++i) {
        double a = log_uniform(rng, 2, 20000), b = a * (0.1 + 3 * frac(rng));
        double cx = frac(rng) * 100, cy = frac(rng) * 100;
        double t0 = ang(rng), sweep = (i % 4 == 0) ? 2 * kPi : frac(rng) * 2 * kPi;
        bool cw = (rng() & 1) != 0;
        double t1 = t0 + (cw ? -sweep : sweep);
        int32_t start[3] = {static_cast<int32_t>(std::lround(cx + a * std::cos(t0))),
                            static_cast<int32_t>(std::lround(cy + b * std::sin(t0))), 0};
        int32_t end[3] = {static_cast<int32_t>(std::lround(cx + a * std::cos(t1))),
                          static_cast<int32_t>(std::lround(cy + b * std::sin(t1))), 0};
        if (i % 4 == 0) {
            end[0] = start[0];
            end[1] = start[1];
        }
        int32_t c[2] = {static_cast<int32_t>(std::lround(cx * 256)),
                        static_cast<int32_t>(std::lround(cy * 256))};
        uint32_t rad[2] = {static_cast<uint32_t>(std::lround(a * 256)),
                           static_cast<uint32_t>(std::lround(b * 256))};
        bool closed = i % 4 == 0;
        ll::CurveWalker::Ends e = ends(start, end, cx + a * std::cos(t0), cy + b * std::sin(t0),
                                       closed ? cx + a * std::cos(t0) : cx + a * std::cos(t1),
                                       closed ? cy + b * std::sin(t0) : cy + b * std::sin(t1));
        ll::CurveWalker w{};
        ASSERT_TRUE(w.arc(e, c, rad, cw, 0)) << i;
        double track = t0;
        Result res = walk(w, end, [&](const int32_t p[3]) {
            return ellipse_distance(p[0], p[1], c[0] / 256.0, c[1] / 256.0, rad[0] / 256.0,
                                    rad[1] / 256.0, track);
        });
        ASSERT_TRUE(res.successive) << "ellipse " << i;
        ASSERT_TRUE(res.ended) << "ellipse " << i;
        ASSERT_LE(res.worst, 1.0) << "ellipse " << i << " a=" << a << " b=" << b;
        worst = std::max(worst, res.worst);
    }
    std::printf("200 ellipses, worst distance %.3f tick\n", worst);
}

TEST(Curve, RandomBeziersStayWithinOneTickAndEndExactly) {
    std::mt19937 rng(53);
    std::uniform_real_distribution<double> u(-1, 1);
    double worst = 0;
    for (int i = 0; i < 200; ++i) {
        double scale = log_uniform(rng, 3, 30000);
        double p[4][2];
        for (auto& q : p) {
            q[0] = u(rng) * scale;
            q[1] = u(rng) * scale;
        }
        int32_t start[3] = {static_cast<int32_t>(std::lround(p[0][0])),
                            static_cast<int32_t>(std::lround(p[0][1])), 0};
        int32_t end[3] = {static_cast<int32_t>(std::lround(p[3][0])),
                          static_cast<int32_t>(std::lround(p[3][1])), 0};
        ll::CurveWalker::Ends e = ends(start, end, p[0][0], p[0][1], p[3][0], p[3][1]);
        for (int k = 0; k < 2; ++k) { // the commanded points, as the walker sees them
            p[0][k] = e.start_q8[k] / 256.0;
            p[3][k] = e.end_q8[k] / 256.0;
        }
        int32_t c1[2] = {static_cast<int32_t>(std::lround(p[1][0] * 256)),
                         static_cast<int32_t>(std::lround(p[1][1] * 256))};
        int32_t c2[2] = {static_cast<int32_t>(std::lround(p[2][0] * 256)),
                         static_cast<int32_t>(std::lround(p[2][1] * 256))};
        p[1][0] = c1[0] / 256.0;
        p[1][1] = c1[1] / 256.0;
        p[2][0] = c2[0] / 256.0;
        p[2][1] = c2[1] / 256.0;
        auto at = [&](double t, int k) {
            double s = 1 - t;
            return s * s * s * p[0][k] + 3 * s * s * t * p[1][k] + 3 * s * t * t * p[2][k] +
                   t * t * t * p[3][k];
        };
        ll::CurveWalker w{};
        ASSERT_TRUE(w.bezier(e, c1, c2)) << i;
        // Distance: Newton on the parameter from the last solution (the walk moves along the
        // curve); where that does not land close (a tight turn), a global scan refined by golden
        // section.
        auto d1 = [&](double t, int k) {
            double s = 1 - t;
            return 3 * s * s * (p[1][k] - p[0][k]) + 6 * s * t * (p[2][k] - p[1][k]) +
                   3 * t * t * (p[3][k] - p[2][k]);
        };
        auto d2 = [&](double t, int k) {
            return 6 * (1 - t) * (p[2][k] - 2 * p[1][k] + p[0][k]) +
                   6 * t * (p[3][k] - 2 * p[2][k] + p[1][k]);
        };
        double last_t = 0;
        Result res = walk(w, end, [&](const int32_t q[3]) {
            auto dist = [&](double t) { return std::hypot(at(t, 0) - q[0], at(t, 1) - q[1]); };
            auto newton = [&](double t) {
                for (int k = 0; k < 12; ++k) {
                    double f = 0, df = 0;
                    for (int c = 0; c < 2; ++c) {
                        double err = at(t, c) - q[c];
                        f += err * d1(t, c);
                        df += d1(t, c) * d1(t, c) + err * d2(t, c);
                    }
                    if (df <= 0) break;
                    t = std::min(1.0, std::max(0.0, t - f / df));
                }
                return t;
            };
            double t = newton(last_t);
            double best = dist(t);
            if (best >= 0.5) { // a tight turn: Newton from many starting points
                for (int k = 0; k <= 200; ++k) {
                    double cand = newton(k / 200.0);
                    if (dist(cand) < best) {
                        best = dist(cand);
                        t = cand;
                    }
                }
            }
            last_t = t;
            return best;
        });
        ASSERT_TRUE(res.successive) << "bezier " << i;
        ASSERT_TRUE(res.ended) << "bezier " << i;
        ASSERT_LE(res.worst, 1.0) << "bezier " << i << " scale " << scale;
        worst = std::max(worst, res.worst);
    }
    std::printf("200 Beziers, worst distance %.3f tick\n", worst);
}

namespace {

ll::CurveParams arc_params(double sx, double sy, double ex, double ey, double cx, double cy,
                           double ru, double rv, bool cw, uint8_t turns = 0) {
    ll::CurveParams p{};
    p.kind = ll::kCurveArc;
    p.clockwise = cw;
    p.turns = turns;
    p.start_um[0] = static_cast<int32_t>(std::lround(sx * 1000));
    p.start_um[1] = static_cast<int32_t>(std::lround(sy * 1000));
    p.end_um[0] = static_cast<int32_t>(std::lround(ex * 1000));
    p.end_um[1] = static_cast<int32_t>(std::lround(ey * 1000));
    p.a_um[0] = static_cast<int32_t>(std::lround(cx * 1000));
    p.a_um[1] = static_cast<int32_t>(std::lround(cy * 1000));
    p.b_um[0] = static_cast<int32_t>(std::lround(ru * 1000));
    p.b_um[1] = static_cast<int32_t>(std::lround(rv * 1000));
    return p;
}

double ellipse_arc_length(double a, double b, double t0, double t1) {
    double s = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
        double t = t0 + (t1 - t0) * (i + 0.5) / n;
        s += std::hypot(a * std::sin(t), b * std::cos(t)) * std::fabs(t1 - t0) / n;
    }
    return s;
}

} // namespace

TEST(CurveShape, CircleLengthIsRadiusTimesSweepAndTangentsArePerpendicular) {
    // Quarter circle of radius 10 mm from (10, 0) to (0, 10), anticlockwise.
    ll::CurveShape sh;
    ASSERT_TRUE(ll::curve_shape(arc_params(10, 0, 0, 10, 0, 0, 10, 10, false), 0, true, sh));
    EXPECT_NEAR(sh.len_q8 / 256000.0, 10 * kPi / 2, 1e-5);
    EXPECT_EQ(sh.min_radius_um, 10000u);
    const double q = std::ldexp(1.0, 29);
    EXPECT_NEAR(sh.start_dir[0] / q, 0, 1e-6); // going up (+v) at (10, 0)
    EXPECT_NEAR(sh.start_dir[1] / q, 1, 1e-6);
    EXPECT_NEAR(sh.end_dir[0] / q, -1, 1e-6); // going left at (0, 10)
    // Clockwise the other way round: three quarters, tangent reversed.
    ASSERT_TRUE(ll::curve_shape(arc_params(10, 0, 0, 10, 0, 0, 10, 10, true), 0, true, sh));
    EXPECT_NEAR(sh.len_q8 / 256000.0, 10 * kPi * 1.5, 1e-5);
    EXPECT_NEAR(sh.start_dir[1] / q, -1, 1e-6);
    // Full circle plus one turn: 4 pi r.
    ASSERT_TRUE(ll::curve_shape(arc_params(10, 0, 10, 0, 0, 0, 10, 10, false, 1), 0, true, sh));
    EXPECT_NEAR(sh.len_q8 / 256000.0, 10 * kPi * 4, 1e-4);
}

TEST(CurveShape, HelixLengthAddsTheRiseInQuadrature) {
    ll::CurveShape sh;
    ASSERT_TRUE(ll::curve_shape(arc_params(10, 0, 10, 0, 0, 0, 10, 10, false), 5000, true, sh));
    EXPECT_NEAR(sh.len_q8 / 256000.0, std::hypot(2 * kPi * 10, 5.0), 1e-4);
    // The rise per radian is kept in whole µm: the direction is good to 1e-4 (it only sets the
    // junction speed with the neighbouring moves).
    EXPECT_NEAR(sh.start_dir[2] / std::ldexp(1.0, 29), 5.0 / std::hypot(2 * kPi * 10, 5.0), 1e-4);
}

TEST(CurveShape, EllipseLengthComesFromQuadratureWithinTenToTheMinusFive) {
    // Quarter of the ellipse 30 x 10 from (30, 0) to (0, 10), and a whole 50 x 5 one.
    ll::CurveShape sh;
    ASSERT_TRUE(ll::curve_shape(arc_params(30, 0, 0, 10, 0, 0, 30, 10, false), 0, true, sh));
    double want = ellipse_arc_length(30, 10, 0, kPi / 2);
    EXPECT_NEAR(sh.len_q8 / 256000.0 / want, 1.0, 1e-5);
    EXPECT_NEAR(sh.min_radius_um, 10000.0 * 10 / 30, 1); // b^2 / a
    ASSERT_TRUE(ll::curve_shape(arc_params(50, 0, 50, 0, 0, 0, 50, 5, true), 0, true, sh));
    want = ellipse_arc_length(50, 5, 0, 2 * kPi);
    std::printf("ellipse 50x5: %.6f mm, exact %.6f mm (%.1e)\n", sh.len_q8 / 256000.0, want,
                sh.len_q8 / 256000.0 / want - 1);
    EXPECT_NEAR(sh.len_q8 / 256000.0 / want, 1.0, 1e-5);
}

TEST(CurveShape, BezierLengthAndCurvatureMatchNumericReferences) {
    ll::CurveParams p{};
    p.kind = ll::kCurveBezier;
    const double pts[4][2] = {{0, 0}, {10, 20}, {30, -10}, {40, 10}};
    p.start_um[0] = 0;
    p.start_um[1] = 0;
    p.a_um[0] = 10000;
    p.a_um[1] = 20000;
    p.b_um[0] = 30000;
    p.b_um[1] = -10000;
    p.end_um[0] = 40000;
    p.end_um[1] = 10000;
    ll::CurveShape sh;
    ASSERT_TRUE(ll::curve_shape(p, 0, true, sh));
    double len = 0, rmin = 1e300;
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
        double t = (i + 0.5) / n, s = 1 - t;
        double dx = 3 * s * s * (pts[1][0] - pts[0][0]) + 6 * s * t * (pts[2][0] - pts[1][0]) +
                    3 * t * t * (pts[3][0] - pts[2][0]);
        double dy = 3 * s * s * (pts[1][1] - pts[0][1]) + 6 * s * t * (pts[2][1] - pts[1][1]) +
                    3 * t * t * (pts[3][1] - pts[2][1]);
        double ddx = 6 * s * (pts[2][0] - 2 * pts[1][0] + pts[0][0]) +
                     6 * t * (pts[3][0] - 2 * pts[2][0] + pts[1][0]);
        double ddy = 6 * s * (pts[2][1] - 2 * pts[1][1] + pts[0][1]) +
                     6 * t * (pts[3][1] - 2 * pts[2][1] + pts[1][1]);
        len += std::hypot(dx, dy) / n;
        double r = std::pow(std::hypot(dx, dy), 3) / std::fabs(dx * ddy - dy * ddx);
        rmin = std::min(rmin, r);
    }
    std::printf("bezier: %.5f mm (exact %.5f), min radius %.3f mm (exact %.3f)\n",
                sh.len_q8 / 256000.0, len, sh.min_radius_um / 1000.0, rmin);
    EXPECT_NEAR(sh.len_q8 / 256000.0 / len, 1.0, 1e-5);
    // Sampled at every quadrature node, the smallest radius is found to within the sampling.
    EXPECT_NEAR(sh.min_radius_um / 1000.0 / rmin, 1.0, 0.1);
}

namespace {

double sq(double x) {
    return x * x;
}

// Arc length of a parametric curve (x'(t), y'(t), w'(t)) by the midpoint rule on n points.
template <class Speed>
double numeric_length(const Speed& speed, double t0, double t1, int n) {
    double s = 0, h = (t1 - t0) / n;
    for (int i = 0; i < n; ++i) s += speed(t0 + (i + 0.5) * h);
    return s * std::fabs(h);
}

} // namespace

TEST(CurveShape, RandomEllipseArcsAndHelicesWithinTenToTheMinusFive) {
    // Eccentricities up to 100:1, partial arcs, extra turns and helices: the panels follow
    // |P'| / |P''|, so the tight ends of the major axis get narrow ones.
    std::mt19937 rng(61);
    std::uniform_real_distribution<double> ang(-kPi, kPi), frac(0, 1);
    double worst = 0;
    for (int i = 0; i < 300; ++i) {
        double a = log_uniform(rng, 1, 200), b = a * log_uniform(rng, 0.01, 3);
        double t0 = ang(rng), sweep = frac(rng) * 2 * kPi;
        bool cw = (rng() & 1) != 0;
        uint8_t turns = i % 10 == 0 ? 1 : 0;
        double t1 = t0 + (cw ? -sweep : sweep);
        double dw = i % 3 == 0 ? (frac(rng) - 0.5) * 100 : 0; // mm
        ll::CurveParams p = arc_params(a * std::cos(t0), b * std::sin(t0), a * std::cos(t1),
                                       b * std::sin(t1), 0, 0, a, b, cw, turns);
        int32_t dw_um = static_cast<int32_t>(std::lround(dw * 1000));
        ll::CurveShape sh;
        ASSERT_TRUE(ll::curve_shape(p, dw_um, true, sh)) << i;
        // The reference from the commanded (rounded) points, as the firmware sees them.
        double ra = p.b_um[0] / 1000.0, rb = p.b_um[1] / 1000.0;
        double u0 = std::atan2(p.start_um[1] / 1000.0 / rb, p.start_um[0] / 1000.0 / ra);
        double u1 = std::atan2(p.end_um[1] / 1000.0 / rb, p.end_um[0] / 1000.0 / ra);
        double d = cw ? u0 - u1 : u1 - u0;
        while (d <= 0) d += 2 * kPi;
        while (d > 2 * kPi) d -= 2 * kPi;
        d += turns * 2 * kPi;
        double rise = dw_um / 1000.0 / d;
        double want = numeric_length(
            [&](double t) {
                return std::sqrt(sq(ra * std::sin(t)) + sq(rb * std::cos(t)) + sq(rise));
            },
            u0, u0 + (cw ? -d : d), 200000);
        // Relative, beyond the unit of the length (1/256 µm, floored), which is all that is left
        // on arcs of a few µm.
        double err = std::max(0.0, std::fabs(sh.len_q8 / 256000.0 - want) - 1 / 256000.0) / want;
        worst = std::max(worst, err);
        ASSERT_LT(err, 1e-5) << i << ": " << a << " x " << b << " mm, sweep " << d;
    }
    std::printf("300 ellipse arcs: worst relative length error %.1e\n", worst);
}

TEST(CurveShape, RandomBeziersAndTheirHelicesWithinTenToTheMinusFive) {
    std::mt19937 rng(62);
    std::uniform_real_distribution<double> u(-1, 1), frac(0, 1);
    double worst = 0, rmin_low = 1e300, rmin_high = 0;
    for (int i = 0; i < 300; ++i) {
        double scale = log_uniform(rng, 1, 300); // mm
        ll::CurveParams p{};
        p.kind = ll::kCurveBezier;
        int32_t* pts[4] = {p.start_um, p.a_um, p.b_um, p.end_um};
        double q[4][2];
        for (int k = 0; k < 4; ++k) {
            for (int j = 0; j < 2; ++j) {
                pts[k][j] = static_cast<int32_t>(std::lround(u(rng) * scale * 1000));
                q[k][j] = pts[k][j] / 1000.0;
            }
        }
        double dw = i % 3 == 0 ? (frac(rng) - 0.5) * 100 : 0; // mm
        int32_t dw_um = static_cast<int32_t>(std::lround(dw * 1000));
        ll::CurveShape sh;
        ASSERT_TRUE(ll::curve_shape(p, dw_um, true, sh)) << i;
        auto d1 = [&](double t, int k) {
            double s = 1 - t;
            return 3 * s * s * (q[1][k] - q[0][k]) + 6 * s * t * (q[2][k] - q[1][k]) +
                   3 * t * t * (q[3][k] - q[2][k]);
        };
        auto d2 = [&](double t, int k) {
            return 6 * (1 - t) * (q[2][k] - 2 * q[1][k] + q[0][k]) +
                   6 * t * (q[3][k] - 2 * q[2][k] + q[1][k]);
        };
        double want = numeric_length(
            [&](double t) { return std::sqrt(sq(d1(t, 0)) + sq(d1(t, 1)) + sq(dw_um / 1000.0)); },
            0, 1, 200000);
        double err = std::max(0.0, std::fabs(sh.len_q8 / 256000.0 - want) - 1 / 256000.0) / want;
        worst = std::max(worst, err);
        ASSERT_LT(err, 1e-5) << i << ": scale " << scale << " mm";
        // The smallest radius is the smallest of the radii at the sample points: never below
        // the true one (to the µm it is floored to), and within 10% of it where it is over
        // 10 µm (the samples crowd where the curve turns tightly).
        double rmin = 1e300;
        for (int j = 0; j <= 20000; ++j) {
            double t = j / 20000.0;
            double x = d1(t, 0), y = d1(t, 1);
            double cross = std::fabs(x * d2(t, 1) - y * d2(t, 0));
            if (cross > 0) rmin = std::min(rmin, std::pow(std::hypot(x, y), 3) / cross);
        }
        EXPECT_GT((sh.min_radius_um + 1) / 1000.0, rmin * (1 - 1e-3)) << i;
        if (rmin < 0.01) continue;
        double ratio = sh.min_radius_um / 1000.0 / rmin;
        EXPECT_NEAR(ratio, 1.0, 0.1) << i << ": smallest radius " << rmin << " mm";
        rmin_low = std::min(rmin_low, ratio);
        rmin_high = std::max(rmin_high, ratio);
    }
    std::printf("300 Beziers: worst relative length error %.1e, smallest radius (over 10 µm) "
                "found %.3f .. %.3f x the true one\n",
                worst, rmin_low, rmin_high);
}

TEST(CurveShape, NullEndArmsTakeTheDirectionOfTheNextArm) {
    // p1 = p0 and p2 = p3: the curve leaves along p2 - p0 and arrives along p3 - p1.
    ll::CurveParams p{};
    p.kind = ll::kCurveBezier;
    p.start_um[0] = 0;
    p.start_um[1] = 0;
    p.a_um[0] = 0;
    p.a_um[1] = 0;
    p.b_um[0] = 30000;
    p.b_um[1] = 40000;
    p.end_um[0] = 30000;
    p.end_um[1] = 40000;
    ll::CurveShape sh;
    ASSERT_TRUE(ll::curve_shape(p, 0, true, sh));
    const double q = std::ldexp(1.0, 29);
    EXPECT_NEAR(sh.start_dir[0] / q, 0.6, 1e-4);
    EXPECT_NEAR(sh.start_dir[1] / q, 0.8, 1e-4);
    EXPECT_NEAR(sh.end_dir[0] / q, 0.6, 1e-4);
    EXPECT_NEAR(sh.end_dir[1] / q, 0.8, 1e-4);
    EXPECT_EQ(sh.start_dir[2], 0);
    // A general one: p1 = p0, the start along p2 - p0.
    p.b_um[0] = 10000;
    p.b_um[1] = -20000;
    p.end_um[0] = 40000;
    p.end_um[1] = 10000;
    ASSERT_TRUE(ll::curve_shape(p, 0, true, sh));
    EXPECT_NEAR(sh.start_dir[0] / q, 1 / std::sqrt(5.0), 1e-3);
    EXPECT_NEAR(sh.start_dir[1] / q, -2 / std::sqrt(5.0), 1e-3);
}

TEST(CurveShape, BezierWithACuspHasItsLength) {
    // (0,0) (10,10) (0,10) (10,0) mm: B'(1/2) = 0, a cusp, where |B'| has a kink; the panels
    // narrow towards it from both sides.
    ll::CurveParams p{};
    p.kind = ll::kCurveBezier;
    p.a_um[0] = 10000;
    p.a_um[1] = 10000;
    p.b_um[0] = 0;
    p.b_um[1] = 10000;
    p.end_um[0] = 10000;
    ll::CurveShape sh;
    ASSERT_TRUE(ll::curve_shape(p, 0, true, sh));
    double q[4][2] = {{0, 0}, {10, 10}, {0, 10}, {10, 0}};
    double want = 0;
    const int n = 400000;
    for (int i = 0; i < n; ++i) {
        double t = (i + 0.5) / n, s = 1 - t, d[2];
        for (int k = 0; k < 2; ++k) {
            d[k] = 3 * s * s * (q[1][k] - q[0][k]) + 6 * s * t * (q[2][k] - q[1][k]) +
                   3 * t * t * (q[3][k] - q[2][k]);
        }
        want += std::hypot(d[0], d[1]) / n;
    }
    std::printf("cusp: %.6f mm, exact %.6f mm, smallest radius %u µm\n", sh.len_q8 / 256000.0, want,
                sh.min_radius_um);
    EXPECT_NEAR(sh.len_q8 / 256000.0 / want, 1.0, 1e-5);
    EXPECT_LT(sh.min_radius_um, 10u); // at the cusp, 0
}
