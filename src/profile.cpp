#include "lowlevel/profile.h"

#include "lowlevel/fixmath.h"

namespace ll {

ProfileShape profile_shape(const Profile& p) {
    ProfileShape sh;
    uint64_t sd = static_cast<uint64_t>(p.s) * p.d;
    // Start change: accelerate (or decelerate) until A reaches A_cruise.
    uint64_t change = p.a_entry <= p.a_cruise ? p.a_cruise - p.a_entry : p.a_entry - p.a_cruise;
    // End deceleration: from A_cruise down to A_exit.
    uint64_t decel = p.a_cruise - p.a_exit;
    uint64_t x2_change = 2 * change / p.s;
    uint64_t x2_decel = 2 * p.d - 2 * decel / p.s;
    if (p.a_entry <= p.a_cruise && change + decel > sd) {
        // Too short to reach cruise: the start and end lines meet at the closed-form peak.
        sh.reaches_cruise = false;
        sh.a_peak = static_cast<uint32_t>((p.a_entry + p.a_exit + sd) / 2);
        uint64_t x2 = (static_cast<uint64_t>(p.a_exit) + sd - p.a_entry) / p.s; // 2 x_decel
        sh.x_change = sh.x_decel = static_cast<uint32_t>(x2);
        return sh;
    }
    sh.reaches_cruise = true;
    sh.a_peak = p.a_cruise;
    sh.x_change = static_cast<uint32_t>(x2_change);
    sh.x_decel = static_cast<uint32_t>(x2_decel);
    return sh;
}

uint32_t profile_a(const Profile& p, uint32_t x2) {
    // s is even, so s * x2 / 2 is an integer.
    uint32_t half_s = p.s >> 1;
    uint64_t travelled = static_cast<uint64_t>(half_s) * x2;
    uint64_t start;
    if (p.a_entry <= p.a_cruise) {
        start = p.a_entry + travelled;
        if (start > p.a_cruise) start = p.a_cruise;
    } else {
        start = travelled >= p.a_entry - p.a_cruise ? p.a_cruise : p.a_entry - travelled;
    }
    uint64_t to_go2 = 2ull * p.d >= x2 ? 2ull * p.d - x2 : 0;
    uint64_t end = p.a_exit + static_cast<uint64_t>(half_s) * to_go2;
    return static_cast<uint32_t>(start < end ? start : end);
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
