#include "lowlevel/profile.h"

#include "lowlevel/fixmath.h"

namespace ll {

ProfileShape profile_shape(const Profile& p) {
    ProfileShape sh;
    const uint8_t half = static_cast<uint8_t>(p.log_s - 1); // s / 2 = 2^half
    uint32_t sd = shl_sat(p.d, p.log_s);
    // Start change: accelerate (or decelerate) until A reaches A_cruise.
    uint32_t change = p.a_entry <= p.a_cruise ? p.a_cruise - p.a_entry : p.a_entry - p.a_cruise;
    // End deceleration: from A_cruise down to A_exit.
    uint32_t decel = p.a_cruise - p.a_exit;
    if (p.a_entry <= p.a_cruise && add_sat(change, decel) > sd) {
        // Too short to reach cruise: the start and end lines meet at the closed-form peak.
        sh.reaches_cruise = false;
        sh.a_peak = (add_sat(p.a_entry, p.a_exit) >> 1) + (sd >> 1);
        // 2 x_decel = (A_exit + s d - A_entry) / s
        sh.x_change = sh.x_decel = (add_sat(p.a_exit, sd) - p.a_entry) >> p.log_s;
        return sh;
    }
    sh.reaches_cruise = true;
    sh.a_peak = p.a_cruise;
    sh.x_change = change >> half;
    sh.x_decel = 2 * p.d - (decel >> half);
    return sh;
}

uint32_t profile_a(const Profile& p, uint32_t x2) {
    const uint8_t half = static_cast<uint8_t>(p.log_s - 1); // s * x2 / 2 = x2 << half
    uint32_t travelled = shl_sat(x2, half);
    uint32_t start;
    if (p.a_entry <= p.a_cruise) {
        start = add_sat(p.a_entry, travelled);
        if (start > p.a_cruise) start = p.a_cruise;
    } else {
        start = travelled >= p.a_entry - p.a_cruise ? p.a_cruise : p.a_entry - travelled;
    }
    uint32_t to_go2 = 2 * p.d >= x2 ? 2 * p.d - x2 : 0;
    uint32_t end = add_sat(p.a_exit, shl_sat(to_go2, half));
    return start < end ? start : end;
}

void SqrtTracker::reset(uint32_t a) {
    r = isqrt32(a);
    c = r * r;
    c_next = c + 2 * r + 1;
    steps = 0;
}

bool SqrtTracker::seek(uint32_t a) {
    uint32_t before = r;
    if (a >= c_next) {
        // Moving up: at most a few steps per macro segment; a long way means a jump (new move
        // or feed hold), where one full square root is cheaper than walking.
        if (a - c_next > 64 * (r + 1)) {
            reset(a);
        } else {
            while (a >= c_next) {
                c = c_next;
                c_next += 2 * ++r + 1;
            }
        }
    } else if (a < c) {
        if (c - a > 64 * r) {
            reset(a);
        } else {
            while (a < c) {
                c_next = c;
                c -= 2 * --r + 1;
            }
        }
    }
    if (r != before) {
        ++steps;
        return true;
    }
    return false;
}

} // namespace ll
