#include "lowlevel/fixmath.h"

#include "lowlevel/pgm.h"

namespace ll {

uint16_t isqrt32(uint32_t v) {
    uint32_t res = 0;
    uint32_t one = 1ul << 30;
    while (one > v) one >>= 2;
    while (one != 0) {
        if (v >= res + one) {
            v -= res + one;
            res = (res >> 1) + one;
        } else {
            res >>= 1;
        }
        one >>= 2;
    }
    return static_cast<uint16_t>(res);
}

uint32_t div_frac(uint32_t num, uint32_t den, uint8_t bits) {
    uint32_t q = num / den;
    uint32_t rem = num - q * den;
    for (uint8_t i = 0; i < bits; ++i) {
        rem <<= 1;
        q <<= 1;
        if (rem >= den) {
            rem -= den;
            q |= 1;
        }
    }
    return q;
}

uint32_t mul_shr(uint32_t a, uint32_t b, uint8_t shift) {
    uint64_t p = static_cast<uint64_t>(a) * b;
    p >>= shift;
    return p > 0xFFFFFFFFull ? 0xFFFFFFFFul : static_cast<uint32_t>(p);
}

uint32_t shl_sat(uint32_t x, uint8_t k) {
    if (k >= 32) return x ? 0xFFFFFFFFul : 0;
    return x > (0xFFFFFFFFul >> k) ? 0xFFFFFFFFul : x << k;
}

namespace {

// atan(2^-i) in radians x 2^29 for i < 10; beyond, atan(2^-i) = 2^-i to the last bit.
const uint32_t kAtanQ29[10] LL_PROGMEM = {421657428, 248918915, 131521918, 66762579, 33510843,
                                          16771758,  8387925,   4194219,   2097141,  1048575};

// (a * b) >> 30 for Q30 operands.
int32_t mul_q30(int32_t a, int32_t b) {
    return static_cast<int32_t>((static_cast<int64_t>(a) * b) >> 30);
}

// 1 - x * r * t in Q30, with r a Q30 reciprocal constant: one step of a Horner series.
int32_t horner(int32_t x, int32_t r, int32_t t) {
    return (1l << 30) - mul_q30(mul_q30(x, r), t);
}

} // namespace

int32_t atan2_q29(int32_t y, int32_t x) {
    if (x == 0 && y == 0) return 0;
    // Bring the vector into the right half plane with a quarter turn, then normalise it to
    // 29 bits so that the CORDIC gain (1.647) cannot overflow.
    int32_t z = 0;
    if (x < 0) {
        int32_t t = x;
        if (y >= 0) {
            x = y;
            y = -t;
            z = kPiQ29 / 2;
        } else {
            x = -y;
            y = t;
            z = -kPiQ29 / 2;
        }
    }
    uint32_t big = abs32(x) > abs32(y) ? abs32(x) : abs32(y);
    while (big >= (1ul << 29)) {
        x >>= 1;
        y >>= 1;
        big >>= 1;
    }
    while (big < (1ul << 28)) {
        x *= 2;
        y *= 2;
        big <<= 1;
    }
    for (uint8_t i = 0; i < 30; ++i) {
        int32_t a = i < 10 ? static_cast<int32_t>(flash_read_u32(&kAtanQ29[i]))
                           : static_cast<int32_t>(1l << (29 - i));
        int32_t xs = x >> i, ys = y >> i;
        if (y > 0) {
            x += ys;
            y -= xs;
            z += a;
        } else {
            x -= ys;
            y += xs;
            z -= a;
        }
    }
    return z;
}

void small_angle_q30(int32_t h, int32_t& c, int32_t& s, int32_t& k) {
    // Reciprocals 1/n in Q30 for the series' coefficient ratios.
    const int32_t r2 = 536870912, r6 = 178956971, r12 = 89478485, r20 = 53687091, r30 = 35791394,
                  r42 = 25565282, r56 = 19173961, r72 = 14913081;
    int32_t h2 = mul_q30(h, h);
    // cos h = 1 - h^2/2 (1 - h^2/12 (1 - h^2/30 (1 - h^2/56)))
    c = horner(h2, r2, horner(h2, r12, horner(h2, r30, horner(h2, r56, 1l << 30))));
    // sin h = h (1 - h^2/6 (1 - h^2/20 (1 - h^2/42 (1 - h^2/72))))
    s = mul_q30(h, horner(h2, r6, horner(h2, r20, horner(h2, r42, horner(h2, r72, 1l << 30)))));
    // tan x = x (1 + x^2/3 + 2 x^4/15 + 17 x^6/315) with x = h/4; k = 4/3 tan(h/4).
    int32_t x = h / 4;
    int32_t x2 = mul_q30(x, x);
    const int32_t r3 = 357913941, c5 = 143165577, c7 = 57947971; // 1/3, 2/15, 17/315
    int32_t poly = (1l << 30) + mul_q30(x2, r3 + mul_q30(x2, c5 + mul_q30(x2, c7)));
    k = mul_q30(mul_q30(x, poly), 1431655765); // x 4/3
}

namespace {

// floor(hi * 2^32 / d) for hi < d, d >= 2^31: the 32 quotient bits of a normalised division.
uint32_t div_hi(uint32_t hi, uint32_t d) {
    uint32_t q = 0;
    for (uint8_t i = 0; i < 32; ++i) {
        bool carry = (hi & 0x80000000ul) != 0;
        hi <<= 1;
        q <<= 1;
        if (carry || hi >= d) {
            hi -= d;
            q |= 1;
        }
    }
    return q;
}

} // namespace

namespace {

// Exponents live in [-128, 127]: values beyond 2^158 saturate, below 2^-97 become zero.
Num& finish(Num& n, uint32_t m, int16_t ex) {
    if (ex > 127) {
        n.m = 0xFFFFFFFFul;
        n.e = 127;
    } else if (ex < -128) {
        n.m = 0;
        n.e = 0;
    } else {
        n.m = m;
        n.e = static_cast<int8_t>(ex);
    }
    return n;
}

} // namespace

Num& Num::set(uint32_t v, int8_t exp) {
    if (v == 0) {
        m = 0;
        e = 0;
        return *this;
    }
    int16_t ex = exp;
    while (!(v & 0x80000000ul)) {
        v <<= 1;
        --ex;
    }
    return finish(*this, v, ex);
}

Num& Num::mul(const Num& o) {
    if (m == 0 || o.m == 0) return set(0);
    uint64_t p = static_cast<uint64_t>(m) * o.m; // in [2^62, 2^64)
    int16_t ex = static_cast<int16_t>(e + o.e + 32);
    if (!(p >> 63)) {
        p <<= 1;
        --ex;
    }
    return finish(*this, static_cast<uint32_t>(p >> 32), ex);
}

Num& Num::mul(uint32_t v) {
    return mul(Num(v));
}

Num& Num::div(const Num& o) {
    if (m == 0 || o.m == 0) return set(0);
    int16_t ex = static_cast<int16_t>(e - o.e - 32);
    if (m < o.m) {
        // quotient in (1/2, 1): one normalising shift at most
        uint32_t q = div_hi(m, o.m);
        if (!(q & 0x80000000ul)) {
            q <<= 1;
            --ex;
        }
        return finish(*this, q, ex);
    }
    // m / o.m in [1, 2): 1 + (m - o.m) / o.m, with the fraction's 32 bits shifted in.
    uint32_t frac = div_hi(m - o.m, o.m);
    return finish(*this, static_cast<uint32_t>(0x80000000ul | (frac >> 1)),
                  static_cast<int16_t>(ex + 1));
}

Num& Num::div(uint32_t v) {
    return div(Num(v));
}

Num& Num::add(const Num& o) {
    if (o.m == 0) return *this;
    if (m == 0) return *this = o;
    Num big = *this, small = o;
    if (big.e < small.e) {
        big = o;
        small = *this;
    }
    uint8_t gap = static_cast<uint8_t>(big.e - small.e);
    uint32_t sm = gap >= 32 ? 0 : small.m >> gap;
    uint32_t sum = big.m + sm;
    if (sum < big.m) {
        m = static_cast<uint32_t>(0x80000000ul | (sum >> 1));
        e = static_cast<int8_t>(big.e + 1);
        return *this;
    }
    return set(sum, big.e);
}

Num& Num::sqrt() {
    if (m == 0) return *this;
    // Make the exponent even: value = m' * 2^e' with m' in [2^30, 2^32).
    uint32_t v = m;
    int8_t ex = e;
    if (ex & 1) {
        v >>= 1;
        ++ex;
    }
    // sqrt(v * 2^ex) = sqrt(v) * 2^(ex/2); r = sqrt(v) * 2^16 to 16 bits from isqrt32, then one
    // Newton step r' = (r + v * 2^32 / r) / 2 (2^-31 relative). r is a floor, so v * 2^32 / r
    // can reach 2^32 just below v = 2^32.
    uint32_t r = static_cast<uint32_t>(isqrt32(v)) << 16;
    uint64_t q = v >= r ? (1ull << 32) + div_hi(v - r, r) : div_hi(v, r);
    uint64_t next = (static_cast<uint64_t>(r) + q) >> 1;
    if (next >> 32) return set(1, static_cast<int8_t>(ex / 2 + 16));
    return set(static_cast<uint32_t>(next), static_cast<int8_t>(ex / 2 - 16));
}

uint32_t Num::u32() const {
    if (m == 0 || e <= -32) return 0;
    if (e > 0) return 0xFFFFFFFFul;
    return m >> static_cast<uint8_t>(-e);
}

uint32_t Num::of(uint32_t x) const {
    Num t(x);
    return t.mul(*this).u32();
}

int8_t Num::cmp(const Num& o) const {
    if (m == 0 || o.m == 0) return m == o.m ? 0 : (m == 0 ? -1 : 1);
    if (e != o.e) return e < o.e ? -1 : 1;
    if (m != o.m) return m < o.m ? -1 : 1;
    return 0;
}

} // namespace ll
