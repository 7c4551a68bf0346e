#include "lowlevel/profile.h"

#include "lowlevel/fixmath.h"

namespace ll {

uint32_t profile_a(const Profile& p, uint32_t x2) {
    const uint8_t half = static_cast<uint8_t>(p.log_s - 1); // s * x2 / 2 = x2 << half
    // (Plain shifts and sums: s d <= 2^31 (the step generator picks s so), A values are below
    // 2^31, and x2 passes 2 d by a curve's last samples at most, so nothing overflows. Computed
    // end line first, so that few values are live at once: few registers to save.)
    // A_exit + s (d - x)
    const uint32_t to_go2 = 2 * p.d >= x2 ? 2 * p.d - x2 : 0;
    const uint32_t end = p.a_exit + (to_go2 << half);
    // start(x): from A_entry towards A_cruise, clamped there (compared before adding or
    // subtracting).
    const uint32_t travelled = x2 << half;
    const uint32_t entry = p.a_entry;
    uint32_t start = p.a_cruise;
    if (entry <= start) {
        if (travelled < start - entry) start = entry + travelled;
    } else if (travelled < entry - start) {
        start = entry - travelled;
    }
    return end < start ? end : start;
}

void SqrtTracker::reset(uint32_t a) {
    r = isqrt32(a);
    c = static_cast<uint32_t>(r) * r;
}

bool SqrtTracker::seek(uint32_t a) {
    const uint16_t before = r;
    // A few steps of R per macro segment; a long way (a new move, a feed hold) is a jump, where
    // one full square root is cheaper than walking: beyond 64 (R + 1) of A.
    uint32_t far = ((before + 1ul) << 8) >> 2; // byte move and two shifts, not a 6-turn loop
    uint32_t cc = c;
    if ((a > cc ? a - cc : cc - a) > far) {
        reset(a);
    } else {
        // Walked in registers on step = 2 R + 1 = (R + 1)^2 - R^2 alone, R = step / 2.
        uint32_t step = 2ul * before + 1;
        for (; a >= cc + step; step += 2) cc += step;
        while (a < cc) cc -= step -= 2;
        r = static_cast<uint16_t>(step >> 1);
        c = cc;
    }
    return r != before;
}

} // namespace ll
