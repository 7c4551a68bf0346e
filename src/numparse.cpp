// Decimal parsing and exact fixed-point scaling. See numparse.h.
#include "lowlevel/numparse.h"

#include "lowlevel/fixmath.h"
#include "lowlevel/pgm.h"

namespace ll {
namespace num {

namespace {
constexpr uint32_t kMaxIpart = 999999999; // 9 digits: ipart * 10 never overflows
constexpr uint32_t kInt32Max = 0x7FFFFFFFu;

bool finish(bool negative, uint32_t magnitude, int32_t& out) {
    if (magnitude > kInt32Max) return false;
    out = static_cast<int32_t>(negative ? 0u - magnitude : magnitude);
    return true;
}
} // namespace

const char* parse(const char* p, Decimal& out) {
    uint8_t flags = 0;
    if (*p == '-') flags = Decimal::kNegative;
    if (*p == '-' || *p == '+') ++p;
    uint32_t ipart = 0;
    uint16_t frac = 0;
    uint8_t sub = 0;
    // Place of the next digit: 0xFF before the point, then 0 (tenths) to 6 (beyond the 6th).
    uint8_t place = 0xFF;
    bool any_digit = false;
    for (;; ++p) {
        uint8_t d = static_cast<uint8_t>(*p - '0');
        if (d > 9) {
            if (*p != '.' || place != 0xFF) break;
            place = 0;
            continue;
        }
        any_digit = true;
        if (place == 0xFF) {
            if (ipart > kMaxIpart / 10) return nullptr; // a 10th significant digit
            ipart = (ipart << 3) + (ipart << 1) + d;    // x10 without a call
            continue;
        }
        // Decimals 1-3 make `frac` (0..999), 4-5 `sub` (0..99), each weighted by its place.
        static const uint8_t kWeight[5] LL_PROGMEM = {100, 10, 1, 10, 1};
        if (place < 3) {
            frac = static_cast<uint16_t>(
                frac + static_cast<uint16_t>(d * flash_read_byte(&kWeight[place])));
        } else if (place < 5) {
            sub = static_cast<uint8_t>(sub +
                                       static_cast<uint8_t>(d * flash_read_byte(&kWeight[place])));
        } else {
            if (place == 5 && d >= 5) flags |= Decimal::kRound6;
            if (d != 0) flags |= Decimal::kInexact;
            if (place == 6) continue;
        }
        ++place;
    }
    if (!any_digit) return nullptr;
    // "-0" is not negative.
    if (ipart == 0 && frac == 0 && sub == 0 && !(flags & Decimal::kInexact)) flags = 0;
    out.ipart = ipart;
    out.frac = frac;
    out.sub = sub;
    out.flags = flags;
    return p;
}

bool length_to_milli(const Decimal& d, bool inches, int32_t& out) {
    // ipart x unit + what the decimals make, with one multiplication and one range check.
    uint16_t unit = 1000;
    uint32_t limit = kInt32Max / 1000, decimals = d.frac + (d.sub >= 50 ? 1u : 0u);
    if (inches) {
        // 25400 per inch; the five decimals are 1e-5 in = 0.254 units of the result.
        unit = 25400;
        limit = kInt32Max / 25400;
        uint32_t frac5 =
            static_cast<uint32_t>(d.frac) * 100u + d.sub + ((d.flags & Decimal::kRound6) ? 1u : 0u);
        decimals = (frac5 * 254u + 500u) / 1000u;
    }
    if (d.ipart > limit) return false;
    return finish(d.negative(), d.ipart * unit + decimals, out);
}

bool to_uint(const Decimal& d, uint32_t max, uint32_t& out) {
    if (d.negative() || !d.integral() || d.ipart > max) return false;
    out = d.ipart;
    return true;
}

// (r:q) / c for r < c < 2^31: the quotient replaces q, the remainder r. A restoring division,
// one quotient bit per turn, the quotient bits shifting into q from the right (r << 1 never
// overflows as r < 2^31). While r < c / 256, the next 8 quotient bits are zero: those are
// taken a byte at a time (a position in um times steps/um usually needs 12 to 20 bit turns).
// The chip gets the same algorithm in assembly: 19 cycles a bit instead of 40.
inline void divide(uint32_t& r, uint32_t& q, uint32_t c) {
#ifdef __AVR__
    uint8_t k;
    asm("ldi %[k], 32\n\t"
        "0: cpi %[k], 9\n\t" // bytes: while k > 8 and r < c >> 8
        "brlo 1f\n\t"
        "cp %A[r], %B[c]\n\t"
        "cpc %B[r], %C[c]\n\t"
        "cpc %C[r], %D[c]\n\t"
        "cpc %D[r], __zero_reg__\n\t"
        "brsh 1f\n\t"
        "mov %D[r], %C[r]\n\t"
        "mov %C[r], %B[r]\n\t"
        "mov %B[r], %A[r]\n\t"
        "mov %A[r], %D[q]\n\t"
        "mov %D[q], %C[q]\n\t"
        "mov %C[q], %B[q]\n\t"
        "mov %B[q], %A[q]\n\t"
        "clr %A[q]\n\t"
        "subi %[k], 8\n\t"
        "rjmp 0b\n\t"
        "1: lsl %A[q]\n\t" // bits
        "rol %B[q]\n\t"
        "rol %C[q]\n\t"
        "rol %D[q]\n\t"
        "rol %A[r]\n\t"
        "rol %B[r]\n\t"
        "rol %C[r]\n\t"
        "rol %D[r]\n\t"
        "cp %A[r], %A[c]\n\t"
        "cpc %B[r], %B[c]\n\t"
        "cpc %C[r], %C[c]\n\t"
        "cpc %D[r], %D[c]\n\t"
        "brlo 2f\n\t"
        "sub %A[r], %A[c]\n\t"
        "sbc %B[r], %B[c]\n\t"
        "sbc %C[r], %C[c]\n\t"
        "sbc %D[r], %D[c]\n\t"
        "ori %A[q], 1\n\t"
        "2: dec %[k]\n\t"
        "brne 1b"
        : [r] "+r"(r), [q] "+d"(q), [k] "=&d"(k)
        : [c] "r"(c));
#else
    uint8_t k = 32;
    while (k > 8 && r < (c >> 8)) {
        r = (r << 8) | (q >> 24);
        q <<= 8;
        k = static_cast<uint8_t>(k - 8);
    }
    do {
        r = (r << 1) | (q >> 31);
        q <<= 1;
        if (r >= c) {
            r -= c;
            q |= 1u;
        }
    } while (--k != 0);
#endif
}

bool mul_div_round(int32_t a, uint32_t b, uint32_t c, int32_t& out) {
    bool negative = a < 0;
    uint32_t m = negative ? 0u - static_cast<uint32_t>(a) : static_cast<uint32_t>(a);
    uint32_t q, r = mul_wide(m, b, q); // the exact product r * 2^32 + q
    // + c/2: half away from zero on the magnitude.
    uint32_t half = c >> 1;
    q += half;
    if (q < half) ++r;
    if (r < c) {
        divide(r, q, c);
        if (finish(negative, q, out)) return true;
    }
    out = static_cast<int32_t>(negative ? 0x80000000u : kInt32Max);
    return false;
}

} // namespace num
} // namespace ll
