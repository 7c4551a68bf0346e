// fixmath_check.elf: computes tools/fixmath_check.h's hash on the chip, for the host test
// tools/test_fixmath_avr.cpp (simavr reads the result from RAM by symbol).
#include "fixmath_check.h"

namespace {

// The same as tools/test_fixmath_avr.cpp's (which computes it on the host).
// The edges that the random workload of fixmath_check.h rarely reaches, hashed: every root
// s >= 2^15 at s^2 and at (s + 1)^2 - 1 (where isqrt32's Newton step on the chip overshoots
// most) through isqrt32 and Num::sqrt, and Num::div by divisors at both ends of every top byte
// (the byte-wise division's estimates fall furthest short there), of dividends just below and
// above them and at the ends of the range.
inline uint32_t fixmath_edges() {
    ll::check::Hash h;
    for (uint32_t s = 0x8000; s <= 0xFFFF; ++s) {
        uint32_t lo = s * s, hi = s == 0xFFFF ? 0xFFFFFFFFul : (s + 1) * (s + 1) - 1;
        h.add(ll::isqrt32(lo));
        h.add(ll::isqrt32(hi));
        h.add(ll::Num(hi).sqrt());
    }
    const uint32_t lows[3] = {0, 0x7FFFFFul, 0xFFFFFFul};
    for (uint32_t top = 0x80; top <= 0xFF; ++top) {
        for (uint8_t k = 0; k < 3; ++k) {
            uint32_t d = top << 24 | lows[k];
            const uint32_t as[4] = {d - 1, d == 0xFFFFFFFFul ? d : d + 1, 0x80000000ul,
                                    0xFFFFFFFFul};
            for (uint8_t j = 0; j < 4; ++j) {
                h.add(ll::Num(as[j]).div(ll::Num(d)));
                h.add(ll::Num(as[j]).div(d));
            }
        }
    }
    // Products and quotients at the ends of the exponent range: saturated, zero, just inside.
    const int8_t es[7] = {-128, -97, -64, 0, 64, 95, 127};
    for (uint8_t i = 0; i < 7; ++i) {
        for (uint8_t j = 0; j < 7; ++j) {
            ll::Num x(0xC0000001ul, es[i]), y(0x80000003ul, es[j]);
            h.add(ll::Num(x).mul(y));
            h.add(ll::Num(y).mul(x));
            h.add(ll::Num(x).div(y));
            h.add(ll::Num(y).div(x));
        }
    }
    return h.h;
}

} // namespace

volatile uint32_t g_fixmath_hash;
volatile uint32_t g_fixmath_edges;
volatile uint8_t g_fixmath_done;

int main() {
    g_fixmath_hash = ll::check::fixmath_hash(LL_FIXMATH_CHECK_ROUNDS);
    g_fixmath_edges = fixmath_edges();
    g_fixmath_done = 1;
    for (;;) {
    }
}
