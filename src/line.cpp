#include "lowlevel/line.h"

#include "lowlevel/fixmath.h"

namespace ll {

void line_advance(const LineGeometry& g, LineCursor& c, uint8_t len, uint8_t e[kAxes]) {
    c.pos[0] += len; // (x1 too)
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
