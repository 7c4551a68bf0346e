#include "lowlevel/line.h"

#include "lowlevel/fixmath.h"

namespace ll {

void line_advance(const LineGeometry& g, LineCursor& c, uint8_t len, uint8_t e[kAxes]) {
    c.pos[0] += len; // (x1 too)
    *e++ = len;
    // The last segment needs no special case: S_j * d_1 + P/2 lands within 1/16 tick of
    // d_j + 1/2 by construction (|d_1 (S_j / P - s_j)| <= d_1 / (2P) <= 1/16), so the sum of the
    // increments is d_j exactly.
    // (Walked with pointers: no index arithmetic, fewer registers to save.)
    const uint32_t* slope = g.slope + 1;
    uint32_t* frac = c.frac + 1;
    uint32_t* pos = c.pos + 1;
    for (uint8_t j = g.m; --j;) {
        // < 2^26 + 2^26 * 32 < 2^32 (line.h); one tick per segment is the common case
        const uint32_t s = *slope++;
        uint32_t acc = *frac + (len == 1 ? s : s * len);
        // acc >> 26 from the top byte: avr-gcc 5.4 makes a 26-turn loop of a 32-bit shift
        uint8_t top = static_cast<uint8_t>(acc >> 24);
        // (a division by the power of two: avr-gcc 5.4 shifts the byte; top >> 3 is promoted to
        // int and made a 16-bit loop)
        uint8_t inc = static_cast<uint8_t>(top / (1u << (kLineUnit - 24)));
        *frac++ = acc & ((1ul << kLineUnit) - 1);
        *pos++ += inc;
        *e++ = inc;
    }
}

} // namespace ll
