// Speed as a function of travelled distance (seed §4, §8), square-root free.
//
// Along a move, distance is counted in ticks of its reference axis (x, seed §8.1). With
// constant acceleration the squared speed is affine in x (§4.4: V^2 = V_d^2 +- 2 a l), so the
// profile works on A(x) = s * (l_d + x), the seed's "fictive distance from rest" l_d + x scaled
// by s = 2 * 4^m. Then V is proportional to sqrt(A) and the wait time of the reference axis is
// Delta_1 = D / sqrt(A) (§4.5, §8.1). sqrt(A) is never computed: an integer R with R^2 <= A
// follows A as it moves (§8.2: "quand x_1 dépasse C, R += 1, C = R.R"), and Delta_1 = D / R is
// one division, done only when R changes. The scale s refines the seed's scheme (which
// changes speed only at perfect squares of x): with s = 2 * 4^m, R changes 2^m * sqrt(2) times
// as often. Each macro segment is timed at its midpoint (A evaluated at x + L/2), which is what
// makes the first steps right. docs/motion.md quantifies both schemes.
//
// The profile has the seed's shape (§4.1): the speed changes (up or down) at the start of the
// move, then cruises, and only decelerates at the end; the deceleration point and, when the
// cruise speed cannot be reached, the peak come from the closed form
//   A_peak = (A_entry + A_exit + s d) / 2      (v_p^2 = (v_0^2 + v_1^2) / 2 + a L)
//   x_meet = (A_exit - A_entry + s d) / (2 s)   (where the two meet: the deceleration point when
//                                             the cruise speed is out of reach)
#pragma once

#include <stdint.h>

#include "lowlevel/fixmath.h"

namespace ll {

struct Profile {
    uint32_t d;        ///< reference-axis ticks of the profile
    uint8_t log_s;     ///< scale s = 2^log_s (log_s odd: s = 2 * 4^m); A grows by s per tick
    uint32_t a_entry;  ///< A at x = 0
    uint32_t a_cruise; ///< A at the nominal (cruise) speed
    uint32_t a_exit;   ///< A at x = d
    uint32_t d_num;    ///< numerator: Delta_1 = d_num / sqrt(A), CPU cycles x 256
    uint32_t cruise;   ///< Delta_1 at cruise, CPU cycles x 256 (exact: one division per move)
};

/// Where the end deceleration starts, in half ticks, from the closed form (seed §4.1,
/// docs/motion.md "Peak and deceleration point"): with x_d = d - (A_cruise - A_exit) / s the
/// point where the end line leaves cruise and x* = (A_exit - A_entry + s d) / (2 s) the point
/// where the start and end lines meet, the move decelerates from max(x_d, x*) when it
/// accelerates at its start (x* > x_d exactly when the cruise speed is out of reach, and the
/// peak is then A(x*) = (A_entry + A_exit + s d) / 2), and from x_d otherwise.
/// (The tests' reference: StepGen::raise_exit() makes the same test in A values, without the
/// variable shifts, test_stepgen's RaisedExitIsTakenUntilTheEndDecelerationBegins.)
inline uint32_t profile_x2_decel(const Profile& p) {
    const uint8_t half = static_cast<uint8_t>(p.log_s - 1); // s / 2 = 2^half
    uint32_t drop = (p.a_cruise - p.a_exit) >> half;        // half ticks to decelerate from cruise
    uint32_t x2 = drop >= 2 * p.d ? 0 : 2 * p.d - drop;
    if (p.a_entry <= p.a_cruise) {
        uint32_t meet = (add_sat(p.a_exit, shl_sat(p.d, p.log_s)) - p.a_entry) >> p.log_s;
        if (meet > x2) x2 = meet;
    }
    return x2;
}

/// A at half-tick position x2 = 2 x (so that segment midpoints are exact):
///   A(x) = min(start(x), A_exit + s (d - x)), start(x) = A_entry +- s x clamped at A_cruise.
/// The profile must be feasible: A_entry <= A_exit + s d (the planner guarantees it). Sums and
/// shifts are not saturated: the A values are at most kMaxA = 2^31 (StepGen::a_of() clamps
/// them), and s d <= 2^31 at the scale the step generator picks (at its smallest, s = 2, s d <
/// 2^24 for d <= kMaxLineTicks), so every sum stays below 2^32; x2 at most a little past 2 d.
uint32_t profile_a(const Profile& p, uint32_t x2);

/// The integer square root that follows A (seed §8.2), with C = R^2 kept so that a step of R
/// costs two additions.
struct SqrtTracker {
    uint16_t r; ///< floor(sqrt(A))
    uint32_t c; ///< r^2

    void reset(uint32_t a);
    /// Moves R to floor(sqrt(a)) one square at a time (a full square root after a jump).
    /// Returns true when R changed.
    bool seek(uint32_t a);
};

} // namespace ll
