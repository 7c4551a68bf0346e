// Checks of a stepped path against an exact plane curve, shared by the host pipeline tests
// (tests/test_curve_gcode.cpp) and the simavr checks of the real image
// (sim/tests/fw_test_curves.cpp).
#pragma once

#include <math.h>

#include <algorithm>
#include <functional>
#include <vector>

namespace lltest {

struct PlanePoint {
    double x, y; ///< steps
};

/// Largest distance (steps) from `pts` to the curve c(u), u in [0, 1], sampled at 200,000
/// points: for each position the nearest sample, searched from the previous match first (the
/// path advances along the curve), then all around.
inline double worst_distance(const std::vector<PlanePoint>& pts,
                             const std::function<PlanePoint(double)>& c) {
    const size_t n = 200000;
    std::vector<PlanePoint> curve(n + 1);
    for (size_t i = 0; i <= n; ++i) curve[i] = c(static_cast<double>(i) / n);
    double worst = 0;
    size_t hint = 0;
    for (const PlanePoint& p : pts) {
        double best = 1e30;
        for (size_t k = 0; k < curve.size(); ++k) {
            size_t i = (hint + k) % curve.size();
            double d = hypot(p.x - curve[i].x, p.y - curve[i].y);
            if (d < best) {
                best = d;
                hint = i;
            }
            if (k > 4000 && best < 1.0) break;
        }
        worst = std::max(worst, best);
    }
    return worst;
}

/// Accumulates the angle of successive points around a centre without wrapping (radians, signed:
/// positive anticlockwise).
struct AngleTracker {
    double cx, cy, prev, swept = 0;
    AngleTracker(double centre_x, double centre_y, double x0, double y0)
        : cx(centre_x), cy(centre_y), prev(atan2(y0 - centre_y, x0 - centre_x)) {}
    double add(double x, double y) {
        const double pi = acos(-1.0);
        double t = atan2(y - cy, x - cx), d = t - prev;
        while (d > pi) d -= 2 * pi;
        while (d < -pi) d += 2 * pi;
        swept += d;
        prev = t;
        return swept;
    }
};

} // namespace lltest
