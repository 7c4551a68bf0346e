// The same pseudo-random workload of fixmath.h's operations, hashed, on the host and on the
// ATmega328P (firmware/fixmath_check.cpp): the AVR assembly paths (mul_wide, the division and
// square root loops) must give exactly the results of the portable C that the host tests check.
#pragma once

#include <stdint.h>

#include "lowlevel/fixmath.h"
#include "lowlevel/numparse.h"

namespace ll {
namespace check {

struct Hash {
    uint32_t h = 2166136261ul;
    void add(uint32_t v) {
        for (uint8_t i = 0; i < 4; ++i) {
            h = (h ^ (v & 0xFF)) * 16777619ul;
            v >>= 8;
        }
    }
    void add(const Num& n) {
        add(n.m);
        add(static_cast<uint32_t>(static_cast<uint8_t>(n.e)));
    }
};

inline uint32_t xorshift(uint32_t& s) {
    s ^= s << 13;
    s ^= s >> 17;
    s ^= s << 5;
    return s;
}

/// A value of any magnitude: the top bits cleared at random.
inline uint32_t any(uint32_t& s) {
    uint32_t v = xorshift(s);
    return v >> (xorshift(s) & 31);
}

inline Num any_num(uint32_t& s) {
    uint32_t m = any(s) | 1;
    int8_t e = static_cast<int8_t>(static_cast<int16_t>(xorshift(s) % 60) - 30);
    return Num(m, e);
}

inline uint32_t fixmath_hash(uint16_t rounds) {
    Hash h;
    uint32_t s = 0x12345678ul;
    for (uint16_t i = 0; i < rounds; ++i) {
        uint32_t a = any(s), b = any(s);
        uint32_t lo, hi = mul_wide(a, b, lo);
        h.add(hi);
        h.add(lo);
        h.add(mul_shr(a, b, static_cast<uint8_t>(xorshift(s) & 63)));
        h.add(isqrt32(a));
        uint32_t den = (b & 0xFFFFFF) | 1;
        uint32_t num = a % (den + 1);
        h.add(div_frac(num, den, static_cast<uint8_t>(20 + (xorshift(s) & 7))));
        Num x = any_num(s), y = any_num(s);
        Num p = x, q = x, r = x, t = x;
        p.mul(y);
        q.div(y);
        r.sqrt();
        t.add(y);
        h.add(p);
        h.add(q);
        h.add(r);
        h.add(t);
        h.add(x.u32());
        h.add(x.of(b));
        h.add(Num(a).div(b | 1).of(a));
        h.add(static_cast<uint32_t>(x.cmp(y)));
        h.add(num64(any(s), any(s),
                    static_cast<int8_t>(static_cast<int16_t>(xorshift(s) % 80) - 40)));
        uint32_t v[4] = {any(s), any(s), 0, any(s) >> (xorshift(s) & 7)};
        h.add(sum_squares(v, 4));
        h.add(sum_squares(v, static_cast<uint8_t>(xorshift(s) % 5),
                          static_cast<uint8_t>(xorshift(s))));
        h.add(div32_16(any(s), static_cast<uint16_t>((any(s) & 0xFFFF) | 1)));
        // Zeros and equal exponents.
        Num z(0), w = x;
        w.e = y.e;
        h.add(static_cast<uint32_t>(z.cmp(x)) ^ static_cast<uint32_t>(x.cmp(z)) << 8 ^
              static_cast<uint32_t>(z.cmp(z)) << 16 ^ static_cast<uint32_t>(w.cmp(y)) << 24);
        Num u = z, v2 = x;
        h.add(u.add(x));
        h.add(v2.add(z));
        h.add(w.add(y));
        h.add(z.mul(x));
        h.add(Num(x).div(z));
        h.add(Num(x).mul(b));
        h.add(Num(a | 1, static_cast<int8_t>(-40 - static_cast<int8_t>(xorshift(s) & 31))).of(b));
        h.add(z.of(b) ^ x.of(0));
        h.add(Num(y).mul(b >> (xorshift(s) & 31)));
        h.add(Num(y).div(a >> (xorshift(s) & 31)));
        h.add(shl_sat(any(s), static_cast<uint8_t>(xorshift(s) % 40)));
        h.add(Num(x).mulc(a | 0x80000000ul,
                          static_cast<int8_t>(static_cast<int16_t>(xorshift(s) % 100) - 50)));
        // mul_div_round: both signs, results in and out of range, small and large divisors.
        int32_t md = static_cast<int32_t>(any(s));
        if (xorshift(s) & 1) md = static_cast<int32_t>(0u - static_cast<uint32_t>(md));
        int32_t mdo = 0;
        bool mdok = num::mul_div_round(md, any(s), (any(s) & 0x7FFFFFFFul) | 1, mdo);
        h.add(static_cast<uint32_t>(mdo) ^ (mdok ? 0x80000000ul : 0));
        // atan2 in every quadrant, on both axes and at every magnitude (|v| < 2^30).
        int32_t ya = static_cast<int32_t>(any(s) >> 2), xa = static_cast<int32_t>(any(s) >> 2);
        uint32_t signs = xorshift(s);
        if (signs & 1) ya = -ya;
        if (signs & 2) xa = -xa;
        if ((signs & 0x1C) == 0) ya = 0;
        if ((signs & 0xE0) == 0) xa = 0;
        h.add(static_cast<uint32_t>(atan2_q29(ya, xa)));
    }
    return h.h;
}

// num::parse and the unit conversions on numbers as G-code writes them, hashed: a sign or
// none, 0 to 11 integer digits (leading zeros too), a point or none, 0 to 8 decimals, then a
// letter, a space or the end. Where the chip parses in assembly (numparse.cpp), this holds it to
// the portable C that the host tests check.
inline uint32_t parse_hash(uint16_t rounds) {
    Hash h;
    uint32_t s = 0x9E3779B9ul;
    char buf[24];
    for (uint16_t i = 0; i < rounds; ++i) {
        uint8_t n = 0;
        uint32_t r = xorshift(s);
        if (r & 1) buf[n++] = (r & 2) ? '-' : '+';
        const uint8_t idigits = static_cast<uint8_t>((r >> 2) % 12);
        const uint8_t fdigits = static_cast<uint8_t>((r >> 6) % 9);
        const uint8_t zeros = static_cast<uint8_t>((r >> 10) & 3); // leading zeros
        for (uint8_t k = 0; k < idigits; ++k) {
            const uint32_t d = xorshift(s) % 10;
            buf[n++] = static_cast<char>('0' + (k < zeros ? 0 : d));
        }
        if (r & 0x1000) buf[n++] = '.';
        for (uint8_t k = 0; k < fdigits; ++k) {
            const uint32_t d = xorshift(s);
            buf[n++] = static_cast<char>('0' + ((d & 0x30) == 0   ? 9
                                                : (d & 0xC0) == 0 ? 0
                                                                  : d % 10));
        }
        const uint8_t end = static_cast<uint8_t>((r >> 13) & 3);
        if (end) buf[n++] = end == 1 ? 'X' : end == 2 ? ' ' : '.';
        buf[n] = 0;
        num::Decimal d{};
        uint8_t pos = 0;
        const bool ok = num::parse(buf, pos, d);
        h.add(static_cast<uint32_t>(ok) | static_cast<uint32_t>(pos) << 8 |
              static_cast<uint32_t>(d.flags) << 16 | static_cast<uint32_t>(d.sub) << 24);
        if (!ok) continue;
        h.add(d.ipart);
        h.add(d.frac);
        int32_t mm = 0, in = 0;
        uint32_t u = 0;
        const bool mm_ok = num::to_milli(d, mm), in_ok = num::inch_to_milli(d, in);
        const bool u_ok = num::to_uint(d, 0xFFFFFFFFul >> (r >> 27), u);
        h.add(static_cast<uint32_t>(mm) ^ (mm_ok ? 0x80000000ul : 0));
        h.add(static_cast<uint32_t>(in) ^ (in_ok ? 0x80000000ul : 0));
        h.add(u ^ (u_ok ? 0x80000000ul : 0));
    }
    return h.h;
}

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
    // shl_sat around its byte steps (the chip shifts whole bytes while the top byte is free).
    const uint32_t xs[8] = {0,         1,          0xFF,         0xFFFFFF,
                            0x1000000, 0x7FFFFFFF, 0x80000000ul, 0xFFFFFFFFul};
    const uint8_t ks[15] = {0, 1, 7, 8, 9, 15, 16, 24, 31, 32, 33, 40, 63, 64, 255};
    for (uint8_t i = 0; i < 8; ++i) {
        for (uint8_t j = 0; j < 15; ++j) h.add(shl_sat(xs[i], ks[j]));
    }
    // sum_squares at the bounds of the chip's short path (at most 4 values, each below 2^15):
    // every value 0x7FFF, one of them 0x8000, five values, and masks with bits beyond n.
    const uint32_t vs[5] = {0x7FFF, 0x7FFF, 0x7FFF, 0x7FFF, 0x7FFF};
    for (uint8_t n = 1; n <= 5; ++n) {
        for (uint8_t mask = 0; mask < 64; ++mask) h.add(ll::sum_squares(vs, n, mask));
    }
    for (uint8_t i = 0; i < 5; ++i) {
        uint32_t w[5] = {0x7FFF, 0x7FFE, 1, 0, 0x7FFF};
        w[i] = 0x8000;
        for (uint8_t n = 3; n <= 5; ++n) h.add(ll::sum_squares(w, n));
    }
    return h.h;
}

} // namespace check
} // namespace ll
