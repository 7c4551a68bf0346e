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

#if defined(__AVR__)
// parse() on the chip, as one routine (the portable C below is the reference, which the host
// tests check): three of them a G-code line, about 200 cycles each instead of 325 (nothing
// saved or pushed). p in r24:r25 (then Z), &out in r22:r23 (then X); ipart in r18..r21 while the
// integer part is read (x10 by the multiplier, r23 = 10 and r22 = 0 meanwhile), stored at the
// point, then frac r18:r19, sub r20 and the place r21; flags r25, with the sign (0x40), "a digit
// was read" (0x80) and "a non-zero one" (0x20) until the end; the digit r24.
asm(".section .text._ZN2ll3num5parseEPKcRNS0_7DecimalE,\"ax\",@progbits\n"
    ".global _ZN2ll3num5parseEPKcRNS0_7DecimalE\n"
    ".type _ZN2ll3num5parseEPKcRNS0_7DecimalE, @function\n"
    "_ZN2ll3num5parseEPKcRNS0_7DecimalE:\n"
    "movw r26, r22\n"
    "movw r30, r24\n"
    "clr  r25\n"
    "ld   r24, Z\n"
    "cpi  r24, '-'\n"
    "brne 1f\n"
    "ldi  r25, 0x40\n"
    "rjmp 2f\n"
    "1:\n"
    "cpi  r24, '+'\n"
    "brne 3f\n"
    "2:\n"
    "adiw r30, 1\n"
    "3:\n"
    "clr  r18\n"
    "clr  r19\n"
    "movw r20, r18\n"
    "ldi  r23, 10\n"
    "clr  r22\n"
    ".Lpi_int:\n" // the integer part
    "ld   r24, Z\n"
    "subi r24, '0'\n"
    "cpi  r24, 10\n"
    "brsh .Lpi_point\n"
    "adiw r30, 1\n"
    "ori  r25, 0x80\n" // a digit was read
    "cpse r24, r1\n"
    "ori  r25, 0x20\n" // a non-zero one
    "mov  r0, r18\n"   // ipart 0 (a first or a leading zero digit): ipart = d, no x10
    "or   r0, r19\n"
    "or   r0, r20\n"
    "or   r0, r21\n"
    "brne 7f\n"
    "mov  r18, r24\n"
    "rjmp .Lpi_int\n"
    "7:\n"
    "cpi  r18, 0x00\n" // ipart >= 10^8 (0x05F5E100): a 10th significant digit
    "ldi  r22, 0xE1\n"
    "cpc  r19, r22\n"
    "ldi  r22, 0xF5\n"
    "cpc  r20, r22\n"
    "ldi  r22, 0x05\n"
    "cpc  r21, r22\n"
    "brlo 6f\n"
    "rjmp .Lpi_fail\n"
    "6:\n"
    "clr  r22\n"
    "mul  r21, r23\n" // ipart x 10 + d, from the top byte (ipart < 10^8: no carry out)
    "mov  r21, r0\n"
    "mul  r20, r23\n"
    "mov  r20, r0\n"
    "add  r21, r1\n"
    "mul  r19, r23\n"
    "mov  r19, r0\n"
    "add  r20, r1\n"
    "adc  r21, r22\n"
    "mul  r18, r23\n"
    "mov  r18, r0\n"
    "add  r19, r1\n"
    "adc  r20, r22\n"
    "adc  r21, r22\n"
    "clr  r1\n"
    "add  r18, r24\n"
    "adc  r19, r1\n"
    "adc  r20, r1\n"
    "adc  r21, r1\n"
    "rjmp .Lpi_int\n"
    ".Lpi_point:\n"
    "st   X+, r18\n" // ipart, final
    "st   X+, r19\n"
    "st   X+, r20\n"
    "st   X+, r21\n"
    "clr  r18\n"
    "clr  r19\n"
    "movw r20, r18\n"
    "cpi  r24, '.' - '0'\n"
    "brne .Lpi_end\n"
    "adiw r30, 1\n"
    ".Lpi_frac:\n" // the decimals: frac r18:r19 (1-3), sub r20 (4-5), place r21
    "ld   r24, Z\n"
    "subi r24, '0'\n"
    "cpi  r24, 10\n"
    "brsh .Lpi_end\n"
    "adiw r30, 1\n"
    "ori  r25, 0x80\n" // a digit was read
    "cpse r24, r1\n"
    "ori  r25, 0x20\n" // a non-zero one
    "cpi  r21, 5\n"
    "brsh .Lpi_beyond\n"
    "mov  r22, r24\n" // d x 1
    "cpi  r21, 2\n"
    "breq .Lpi_frac_add\n"
    "cpi  r21, 4\n"
    "breq .Lpi_sub_add\n"
    "ldi  r23, 10\n" // d x 10
    "mul  r24, r23\n"
    "mov  r22, r0\n"
    "clr  r1\n"
    "cpi  r21, 1\n"
    "breq .Lpi_frac_add\n"
    "cpi  r21, 3\n"
    "breq .Lpi_sub_add\n"
    "mul  r22, r23\n" // d x 100 (place 0)
    "add  r18, r0\n"
    "adc  r19, r1\n"
    "clr  r1\n"
    "rjmp .Lpi_next\n"
    ".Lpi_frac_add:\n"
    "add  r18, r22\n"
    "adc  r19, r1\n"
    "rjmp .Lpi_next\n"
    ".Lpi_sub_add:\n"
    "add  r20, r22\n"
    "rjmp .Lpi_next\n"
    ".Lpi_beyond:\n" // the 6th decimal rounds the 5th; any non-zero one from the 6th is inexact
    "brne 4f\n"
    "cpi  r24, 5\n"
    "brlo 4f\n"
    "ori  r25, 2\n" // kRound6
    "4:\n"
    "cpse r24, r1\n"
    "ori  r25, 4\n" // kInexact
    "cpi  r21, 6\n"
    "breq .Lpi_frac\n"
    ".Lpi_next:\n"
    "inc  r21\n"
    "rjmp .Lpi_frac\n"
    ".Lpi_end:\n" // frac, sub, flags (ipart is stored)
    "sbrs r25, 7\n"
    "rjmp .Lpi_fail\n"
    // The sign counts once a digit is not zero ("-0" is not negative).
    "sbrc r25, 5\n"
    "sbrs r25, 6\n"
    "rjmp 9f\n"
    "ori  r25, 1\n" // kNegative
    "9:\n"
    "st   X+, r18\n"
    "st   X+, r19\n"
    "st   X+, r20\n"
    "andi r25, 7\n"
    "st   X, r25\n"
    "movw r24, r30\n"
    "ret\n"
    ".Lpi_fail:\n"
    "clr  r1\n"
    "clr  r24\n"
    "clr  r25\n"
    "ret\n"
    ".size _ZN2ll3num5parseEPKcRNS0_7DecimalE, .-_ZN2ll3num5parseEPKcRNS0_7DecimalE\n"
    ".text\n");
#else
const char* parse(const char* p, Decimal& out) {
    // The sign counts once a digit is not zero ("-0" is not negative).
    uint8_t flags = 0, negative = 0;
    if (*p == '-') negative = Decimal::kNegative;
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
        if (d != 0) flags |= negative;
        if (place == 0xFF) {
            if (ipart > kMaxIpart / 10) return nullptr; // a 10th significant digit
            ipart = (ipart << 3) + (ipart << 1) + d;    // x10 without a call
            continue;
        }
        // Decimals 1-3 make `frac` (0..999), 4-5 `sub` (0..99), each weighted by its place.
        static const uint8_t kWeight[5] LL_PROGMEM = {100, 10, 1, 10, 1};
        if (place < 5) {
            uint16_t dw = static_cast<uint16_t>(d * flash_read_byte(&kWeight[place]));
            if (place < 3) {
                frac = static_cast<uint16_t>(frac + dw);
            } else {
                sub = static_cast<uint8_t>(sub + dw);
            }
        } else {
            if (place == 5 && d >= 5) flags |= Decimal::kRound6;
            if (d != 0) flags |= Decimal::kInexact;
            if (place == 6) continue;
        }
        ++place;
    }
    if (!any_digit) return nullptr;
    out.ipart = ipart;
    out.frac = frac;
    out.sub = sub;
    out.flags = flags;
    return p;
}
#endif

bool length_to_milli(const Decimal& d, bool inches, int32_t& out) {
    // ipart x unit + what the decimals make, with one multiplication and one range check.
    // Below 2^22 (inches: 2^17), ipart x unit + decimals cannot wrap, and finish() refuses
    // what exceeds INT32_MAX (from ipart 2147484, inches 84547, on); at or above it the value
    // is refused at once. (A mask of the top half, not a 32-bit limit: fewer saved registers.)
    uint16_t unit = 1000, top_mask = 0xFFC0;
    uint32_t decimals = d.frac + (d.sub >= 50 ? 1u : 0u);
    if (inches) {
        // 25400 per inch; the five decimals are 1e-5 in = 0.254 units of the result.
        unit = 25400;
        top_mask = 0xFFFE;
        uint32_t frac5 =
            static_cast<uint32_t>(d.frac) * 100u + d.sub + ((d.flags & Decimal::kRound6) ? 1u : 0u);
        decimals = (frac5 * 254u + 500u) / 1000u;
    }
    if (static_cast<uint16_t>(d.ipart >> 16) & top_mask) return false;
    return finish(d.negative(), d.ipart * unit + decimals, out);
}

bool to_uint(const Decimal& d, uint32_t max, uint32_t& out) {
    // Not negative and integral, in one test of the flags.
    if ((d.flags & (Decimal::kNegative | Decimal::kInexact)) != 0 || (d.frac | d.sub) != 0 ||
        d.ipart > max) {
        return false;
    }
    out = d.ipart;
    return true;
}

// (r:q) / c for r < c < 2^31: the quotient replaces q, the remainder r. A restoring division,
// one quotient bit per turn, the quotient bits shifting into q from the right (r << 1 never
// overflows as r < 2^31). While r < c / 256, the next 8 quotient bits are zero: those are
// taken a byte at a time (a position in um times steps/um usually needs 12 to 20 bit turns).
// The chip gets the same algorithm in assembly: 19 cycles a bit instead of 40.
#if defined(__AVR__)
// mul_div_round on the chip, as one routine (the portable C below is the reference: the host
// tests check it, and tools/fixmath_check.h compares both): a in r22..r25, b in r18..r21, c in
// r14..r17 (kept by __ll_mul32s), &out in r12:r13; true/false in r24. The sign in T, the
// magnitude's product by __ll_mul32s (fixmath.cpp), + c/2, then divide().
asm(".section .text._ZN2ll3num13mul_div_roundElmmRl,\"ax\",@progbits\n"
    ".global _ZN2ll3num13mul_div_roundElmmRl\n"
    ".type _ZN2ll3num13mul_div_roundElmmRl, @function\n"
    "_ZN2ll3num13mul_div_roundElmmRl:\n"
    "bst  r25, 7\n" // T: a < 0
    "brtc 1f\n"
    "com  r25\n"
    "com  r24\n"
    "com  r23\n"
    "neg  r22\n"
    "sbci r23, 0xFF\n"
    "sbci r24, 0xFF\n"
    "sbci r25, 0xFF\n"
    "1:\n"
    "call __ll_mul32s\n" // q (low word) in r18..r21, r (high word) in r22..r25
    "movw r26, r14\n"    // + c/2, half away from zero on the magnitude
    "movw r30, r16\n"
    "lsr  r31\n"
    "ror  r30\n"
    "ror  r27\n"
    "ror  r26\n"
    "add  r18, r26\n"
    "adc  r19, r27\n"
    "adc  r20, r30\n"
    "adc  r21, r31\n"
    "adc  r22, r1\n" // r <= 2^32 - 2: no carry out
    "adc  r23, r1\n"
    "adc  r24, r1\n"
    "adc  r25, r1\n"
    "cp   r22, r14\n" // r >= c: the quotient needs more than 32 bits
    "cpc  r23, r15\n"
    "cpc  r24, r16\n"
    "cpc  r25, r17\n"
    "brsh .Lmdr_over\n"
    "ldi  r26, 32\n"
    "2:\n" // bytes: while k > 8 and r < c >> 8
    "cpi  r26, 9\n"
    "brlo 3f\n"
    "cp   r22, r15\n"
    "cpc  r23, r16\n"
    "cpc  r24, r17\n"
    "cpc  r25, r1\n"
    "brsh 3f\n"
    "mov  r25, r24\n"
    "mov  r24, r23\n"
    "mov  r23, r22\n"
    "mov  r22, r21\n"
    "mov  r21, r20\n"
    "mov  r20, r19\n"
    "mov  r19, r18\n"
    "clr  r18\n"
    "subi r26, 8\n"
    "rjmp 2b\n"
    "3:\n" // bits
    "lsl  r18\n"
    "rol  r19\n"
    "rol  r20\n"
    "rol  r21\n"
    "rol  r22\n"
    "rol  r23\n"
    "rol  r24\n"
    "rol  r25\n"
    "cp   r22, r14\n"
    "cpc  r23, r15\n"
    "cpc  r24, r16\n"
    "cpc  r25, r17\n"
    "brlo 4f\n"
    "sub  r22, r14\n"
    "sbc  r23, r15\n"
    "sbc  r24, r16\n"
    "sbc  r25, r17\n"
    "ori  r18, 1\n"
    "4:\n"
    "dec  r26\n"
    "brne 3b\n"
    "sbrc r21, 7\n" // above INT32_MAX
    "rjmp .Lmdr_over\n"
    "brtc 5f\n"
    "com  r21\n"
    "com  r20\n"
    "com  r19\n"
    "neg  r18\n"
    "sbci r19, 0xFF\n"
    "sbci r20, 0xFF\n"
    "sbci r21, 0xFF\n"
    "5:\n"
    "ldi  r24, 1\n"
    "6:\n"
    "movw r30, r12\n"
    "st   Z, r18\n"
    "std  Z+1, r19\n"
    "std  Z+2, r20\n"
    "std  Z+3, r21\n"
    "ret\n"
    ".Lmdr_over:\n" // INT32_MIN or INT32_MAX by the sign
    "ldi  r18, 0xFF\n"
    "ldi  r21, 0x7F\n"
    "brtc 7f\n"
    "clr  r18\n"
    "ldi  r21, 0x80\n"
    "7:\n"
    "mov  r19, r18\n"
    "mov  r20, r18\n"
    "clr  r24\n"
    "rjmp 6b\n"
    ".size _ZN2ll3num13mul_div_roundElmmRl, .-_ZN2ll3num13mul_div_roundElmmRl\n"
    ".text\n");
#else
inline void divide(uint32_t& r, uint32_t& q, uint32_t c) {
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
#endif

} // namespace num
} // namespace ll
