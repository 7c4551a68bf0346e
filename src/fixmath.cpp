#include "lowlevel/fixmath.h"

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

uint32_t isqrt64(uint64_t v) {
    uint64_t res = 0;
    uint64_t one = 1ull << 62;
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
    return static_cast<uint32_t>(res);
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

uint8_t bit_length(uint64_t v) {
    uint8_t n = 0;
    while (v != 0) {
        v >>= 1;
        ++n;
    }
    return n;
}

uint32_t Ratio::apply(uint32_t x) const {
    return saturate32(apply64(x));
}

uint64_t Ratio::apply64(uint32_t x) const {
    uint64_t p = static_cast<uint64_t>(x) * mant;
    if (shift >= 0) return shift >= 64 ? 0 : p >> shift;
    uint8_t left = static_cast<uint8_t>(-shift);
    if (left >= 64 || (p >> (64 - left)) != 0) return ~0ull;
    return p << left;
}

Ratio make_ratio(uint64_t num, uint64_t den) {
    // Keep the divisor within 32 bits (relative loss < 2^-31), then scale the dividend so that
    // the quotient has 32 significant bits: num * 2^s / den in [2^31, 2^33).
    uint8_t dl = bit_length(den);
    int16_t s = 0;
    if (dl > 32) {
        uint8_t t = static_cast<uint8_t>(dl - 32);
        den >>= t;
        s = static_cast<int16_t>(s - t); // value = (num / 2^t) / (den / 2^t): track t on num
        dl = 32;
    }
    // We want q = floor(num * 2^(s + k) / den) with k chosen so q has 32 bits.
    uint8_t nl = bit_length(num);
    int16_t k = static_cast<int16_t>(32 + dl - nl); // num * 2^k has 32 + dl bits
    uint64_t n = num;
    if (k >= 0) {
        // 32 + dl <= 64 bits: fits.
        n <<= k;
    } else {
        n >>= -k;
    }
    uint64_t q = n / den;
    while (q >= (1ull << 32)) {
        q >>= 1;
        --k;
    }
    // value = num / den_original = q * 2^-(k) * 2^(s) ... den was divided by 2^t, i.e. the
    // quotient is 2^t too large: value = q * 2^-(k + t) = q * 2^-(k - s).
    Ratio r;
    r.mant = static_cast<uint32_t>(q);
    int16_t shift = static_cast<int16_t>(k - s);
    if (shift > 127) shift = 127;
    if (shift < -127) shift = -127;
    r.shift = static_cast<int8_t>(shift);
    return r;
}

} // namespace ll
