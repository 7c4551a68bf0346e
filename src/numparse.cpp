// Decimal parsing and exact fixed-point scaling. See numparse.h.
#include "lowlevel/numparse.h"

namespace ll {
namespace num {

namespace {
constexpr uint32_t kMaxIpart = 999999999; // 9 digits: ipart * 10 never overflows
constexpr uint32_t kInt32Max = 0x7FFFFFFFu;

bool finish(bool negative, uint32_t magnitude, int32_t& out) {
    if (magnitude > kInt32Max) return false;
    out = negative ? -static_cast<int32_t>(magnitude) : static_cast<int32_t>(magnitude);
    return true;
}
} // namespace

bool parse(const char* s, uint8_t& pos, Decimal& out) {
    uint8_t i = pos;
    out.ipart = 0;
    out.frac = 0;
    out.sub = 0;
    out.flags = 0;
    bool negative = false;
    if (s[i] == '-') {
        negative = true;
        ++i;
    } else if (s[i] == '+') {
        ++i;
    }
    bool any_digit = false;
    uint8_t decimals = 0; // digits seen after the point, counted up to 6
    bool point = false;
    for (;; ++i) {
        char c = s[i];
        if (c == '.' && !point) {
            point = true;
            continue;
        }
        uint8_t d = static_cast<uint8_t>(c - '0');
        if (d > 9) break;
        any_digit = true;
        if (!point) {
            if (out.ipart > kMaxIpart / 10) return false;        // a 10th significant digit
            out.ipart = (out.ipart << 3) + (out.ipart << 1) + d; // x10 without a call
        } else {
            if (decimals < 3) {
                out.frac = static_cast<uint16_t>(out.frac * 10 + d);
            } else if (decimals < 5) {
                out.sub = static_cast<uint8_t>(out.sub * 10 + d);
            } else {
                if (decimals == 5 && d >= 5) out.flags |= Decimal::kRound6;
                if (d != 0) out.flags |= Decimal::kInexact;
            }
            if (decimals < 6) ++decimals;
        }
    }
    if (!any_digit) return false;
    // Missing decimals are zeros: "1.5" is 1 and 500 thousandths, "0.0001" has sub = 10.
    for (uint8_t k = decimals; k < 3; ++k) out.frac = static_cast<uint16_t>(out.frac * 10);
    if (decimals == 4) out.sub = static_cast<uint8_t>(out.sub * 10);
    if (negative && (out.ipart | out.frac | out.sub | (out.flags & Decimal::kInexact)) != 0)
        out.flags |= Decimal::kNegative;
    pos = i;
    return true;
}

bool to_milli(const Decimal& d, int32_t& out) {
    if (d.ipart > kInt32Max / 1000) return false;
    uint32_t m = d.ipart * 1000u + d.frac + (d.sub >= 50 ? 1u : 0u);
    return finish(d.negative(), m, out);
}

bool inch_to_milli(const Decimal& d, int32_t& out) {
    // 25400 per inch; the five decimals are 1e-5 in = 0.254 units of the result.
    if (d.ipart > kInt32Max / 25400) return false;
    uint32_t frac5 =
        static_cast<uint32_t>(d.frac) * 100u + d.sub + ((d.flags & Decimal::kRound6) ? 1u : 0u);
    uint32_t m = d.ipart * 25400u + (frac5 * 254u + 500u) / 1000u;
    return finish(d.negative(), m, out);
}

bool to_uint(const Decimal& d, uint32_t max, uint32_t& out) {
    if (d.negative() || !d.integral() || d.ipart > max) return false;
    out = d.ipart;
    return true;
}

// 16x16 -> 32 bits. Kept out of line so that the compiler sees 16-bit operands and calls the
// chip's short widening routine (__umulhisi3) instead of a full 32x32 multiplication.
__attribute__((noinline)) uint32_t mul16(uint16_t a, uint16_t b) {
    return static_cast<uint32_t>(a) * b;
}

void mul64(uint32_t a, uint32_t b, uint32_t& hi, uint32_t& lo) {
    uint16_t al = static_cast<uint16_t>(a), ah = static_cast<uint16_t>(a >> 16);
    uint16_t bl = static_cast<uint16_t>(b), bh = static_cast<uint16_t>(b >> 16);
    uint32_t l = mul16(al, bl);
    uint32_t mid1 = mul16(al, bh);
    uint32_t mid2 = mul16(ah, bl);
    uint32_t h = mul16(ah, bh);
    uint32_t mid = mid1 + mid2;
    if (mid < mid1) h += 0x10000u; // the carry out of the middle sum is worth 2^48
    uint32_t t = l + (mid << 16);
    if (t < l) ++h;
    lo = t;
    hi = h + (mid >> 16);
}

uint32_t div64(uint32_t hi, uint32_t lo, uint32_t c, uint32_t& rem) {
    // Restoring division, one quotient bit per turn; r < c < 2^31, so r << 1 never overflows.
    uint32_t r = hi;
    for (uint8_t k = 0; k < 32; ++k) {
        r = (r << 1) | (lo >> 31);
        lo <<= 1;
        if (r >= c) {
            r -= c;
            lo |= 1u;
        }
    }
    rem = r;
    return lo;
}

bool mul_div_round(int32_t a, uint32_t b, uint32_t c, int32_t& out) {
    bool negative = a < 0;
    uint32_t m = negative ? 0u - static_cast<uint32_t>(a) : static_cast<uint32_t>(a);
    uint32_t hi, lo;
    mul64(m, b, hi, lo);
    // + c/2: half away from zero on the magnitude.
    uint32_t t = lo + (c >> 1);
    if (t < lo) ++hi;
    lo = t;
    uint32_t rem;
    if (hi >= c || !finish(negative, div64(hi, lo, c, rem), out)) {
        out = negative ? -static_cast<int32_t>(kInt32Max) - 1 : static_cast<int32_t>(kInt32Max);
        return false;
    }
    return true;
}

} // namespace num
} // namespace ll
