#include "lowlevel/line.h"

#include "lowlevel/fixmath.h"

namespace ll {

bool line_setup(LineGeometry& g, const int32_t delta[kAxes]) {
    g.m = 0;
    g.dirs = 0;
    // §7.1: drop still axes, insertion-sort the rest by distance, decreasing. Ties keep the
    // machine-axis order so that the result is deterministic.
    uint8_t bit = 1;
    for (uint8_t a = 0; a < kAxes; ++a, bit = static_cast<uint8_t>(bit << 1)) {
        int32_t d = delta[a];
        if (d == 0) continue;
        uint32_t dist = d < 0 ? static_cast<uint32_t>(-(d + 1)) + 1u : static_cast<uint32_t>(d);
        if (d < 0) g.dirs = static_cast<uint8_t>(g.dirs | bit);
        uint8_t i = g.m;
        while (i > 0 && g.dist[i - 1] < dist) {
            g.dist[i] = g.dist[i - 1];
            g.axis[i] = g.axis[i - 1];
            --i;
        }
        g.dist[i] = dist;
        g.axis[i] = a;
        ++g.m;
    }
    if (g.m == 0 || g.dist[0] > kMaxLineTicks) {
        g.m = 0; // refused: nothing to move
        return false;
    }

    // §7.2: P = 2^k, the smallest power of two with P >= 8 d_1.
    uint32_t d1 = g.dist[0];
    uint8_t k = 3;
    for (uint32_t v = d1 - 1; v; v >>= 1) ++k; // 2^(k - 3) >= d_1: the bits of d_1 - 1
    g.shift = k;
    g.slope[0] = 1ul << kLineUnit;
    for (uint8_t j = 1; j < g.m; ++j) {
        // round(d_j * 2^k / d_1) = floor((2 d_j * 2^k / d_1 + 1) / 2), then in units of
        // 2^(kLineUnit - k) (the same value, aligned: line_advance shifts by a constant).
        uint32_t twice = div_frac(g.dist[j], d1, static_cast<uint8_t>(k + 1));
        g.slope[j] =
            shl_sat((twice + 1) >> 1, static_cast<uint8_t>(kLineUnit - k)); // (no overflow)
    }
    return true;
}

void line_advance(const LineGeometry& g, LineCursor& c, uint8_t len, uint8_t e[kAxes]) {
    c.x1 += len;
    c.pos[0] += len;
    e[0] = len;
    // The last segment needs no special case: S_j * d_1 + P/2 lands within 1/16 tick of
    // d_j + 1/2 by construction (|d_1 (S_j / P - s_j)| <= d_1 / (2P) <= 1/16), so the sum of the
    // increments is d_j exactly.
    for (uint8_t j = 1; j < g.m; ++j) {
        // < 2^26 + 2^26 * 32 < 2^32 (line.h); one tick per segment is the common case
        uint32_t acc = c.frac[j] + (len == 1 ? g.slope[j] : g.slope[j] * len);
        // acc >> 26 from the top byte: avr-gcc 5.4 makes a 26-turn loop of a 32-bit shift
        uint8_t top = static_cast<uint8_t>(acc >> 24);
        // (a division by the power of two: avr-gcc 5.4 shifts the byte; top >> 3 is promoted to
        // int and made a 16-bit loop)
        uint8_t inc = static_cast<uint8_t>(top / (1u << (kLineUnit - 24)));
        c.frac[j] = acc & ((1ul << kLineUnit) - 1);
        c.pos[j] += inc;
        e[j] = inc;
    }
}

} // namespace ll
