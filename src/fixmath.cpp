#include "lowlevel/fixmath.h"

#include "lowlevel/pgm.h"

namespace ll {

namespace {

#if defined(__AVR__)
// The full product a * b = hi * 2^32 + lo with the hardware 8x8 multiplier, as a routine with
// its own register convention (one copy in flash, about 95 cycles with the call): a in
// r22..r25, b in r18..r21; returns lo in r18..r21 and hi in r22..r25; uses r14..r17, r26,
// r27, r30, r31 and r0 (r1 back to zero). Column k of the byte products (i + j = k) is summed
// into a 3-byte window, the result bytes k..k + 2 (a column's sum plus the carry from below
// stays under 2^24): byte k is then final where it lies, no move out. b is copied to X and Z to
// free r18..r21 for the low bytes; the high ones build in r14..r17 (moved at the end), r17
// being the zero of the carries until column 5 (then r22, a0 no longer needed).
// __ll_mul32s: the same keeping r14..r17, for the assembly routines whose own operands are there
// or that would otherwise save them (4 pushes here instead of in each caller).
asm(".section .text.__ll_mul32,\"ax\",@progbits\n"
    ".global __ll_mul32s\n"
    "__ll_mul32s:\n"
    "push r14\n"
    "push r15\n"
    "push r16\n"
    "push r17\n"
    "rcall __ll_mul32\n"
    "pop  r17\n"
    "pop  r16\n"
    "pop  r15\n"
    "pop  r14\n"
    "ret\n"
    ".global __ll_mul32\n"
    "__ll_mul32:\n"
    "movw r26, r18\n"
    "movw r30, r20\n"
    "clr  r17\n"
    "mul  r22, r26\n"
    "movw r18, r0\n"
    "clr  r20\n"
    "clr  r21\n"
    "mul  r22, r27\n"
    "add  r19, r0\n"
    "adc  r20, r1\n"
    "adc  r21, r17\n"
    "mul  r23, r26\n"
    "add  r19, r0\n"
    "adc  r20, r1\n"
    "adc  r21, r17\n"
    "clr  r14\n"
    "mul  r22, r30\n"
    "add  r20, r0\n"
    "adc  r21, r1\n"
    "adc  r14, r17\n"
    "mul  r23, r27\n"
    "add  r20, r0\n"
    "adc  r21, r1\n"
    "adc  r14, r17\n"
    "mul  r24, r26\n"
    "add  r20, r0\n"
    "adc  r21, r1\n"
    "adc  r14, r17\n"
    "clr  r15\n"
    "mul  r22, r31\n"
    "add  r21, r0\n"
    "adc  r14, r1\n"
    "adc  r15, r17\n"
    "mul  r23, r30\n"
    "add  r21, r0\n"
    "adc  r14, r1\n"
    "adc  r15, r17\n"
    "mul  r24, r27\n"
    "add  r21, r0\n"
    "adc  r14, r1\n"
    "adc  r15, r17\n"
    "mul  r25, r26\n"
    "add  r21, r0\n"
    "adc  r14, r1\n"
    "adc  r15, r17\n"
    "clr  r16\n"
    "mul  r23, r31\n"
    "add  r14, r0\n"
    "adc  r15, r1\n"
    "adc  r16, r17\n"
    "mul  r24, r30\n"
    "add  r14, r0\n"
    "adc  r15, r1\n"
    "adc  r16, r17\n"
    "mul  r25, r27\n"
    "add  r14, r0\n"
    "adc  r15, r1\n"
    "adc  r16, r17\n"
    "clr  r22\n"
    "mul  r24, r31\n"
    "add  r15, r0\n"
    "adc  r16, r1\n"
    "adc  r17, r22\n"
    "mul  r25, r30\n"
    "add  r15, r0\n"
    "adc  r16, r1\n"
    "adc  r17, r22\n"
    "mul  r25, r31\n"
    "add  r16, r0\n"
    "adc  r17, r1\n"
    "movw r22, r14\n"
    "movw r24, r16\n"
    "clr  r1\n"
    "ret\n"
    ".text\n");

__attribute__((always_inline)) inline uint32_t mul64(uint32_t a, uint32_t b, uint32_t& lo) {
    register uint32_t ra asm("r22") = a;
    register uint32_t rb asm("r18") = b;
    asm("call __ll_mul32"
        : "+r"(ra), "+r"(rb)
        :
        : "r14", "r15", "r16", "r17", "r26", "r27", "r30", "r31");
    lo = rb;
    return ra;
}

// floor((hi * 2^32 + lo) / 2^shift), saturated: whole bytes by moves, then bit by bit.
__attribute__((always_inline)) inline uint32_t shr_sat(uint32_t hi, uint32_t lo, uint8_t shift) {
    asm("1:\n\t"
        "cpi  %[s], 8\n\t"
        "brlo 2f\n\t"
        "mov  %A[lo], %B[lo]\n\t"
        "mov  %B[lo], %C[lo]\n\t"
        "mov  %C[lo], %D[lo]\n\t"
        "mov  %D[lo], %A[hi]\n\t"
        "mov  %A[hi], %B[hi]\n\t"
        "mov  %B[hi], %C[hi]\n\t"
        "mov  %C[hi], %D[hi]\n\t"
        "clr  %D[hi]\n\t"
        "subi %[s], 8\n\t"
        "rjmp 1b\n"
        "2:\n\t"
        "tst  %[s]\n\t"
        "breq 4f\n"
        "3:\n\t"
        "lsr  %D[hi]\n\t"
        "ror  %C[hi]\n\t"
        "ror  %B[hi]\n\t"
        "ror  %A[hi]\n\t"
        "ror  %D[lo]\n\t"
        "ror  %C[lo]\n\t"
        "ror  %B[lo]\n\t"
        "ror  %A[lo]\n\t"
        "dec  %[s]\n\t"
        "brne 3b\n"
        "4:"
        : [lo] "+r"(lo), [hi] "+r"(hi), [s] "+d"(shift));
    return hi ? 0xFFFFFFFFul : lo;
}
#else
inline uint32_t mul64(uint32_t a, uint32_t b, uint32_t& lo) {
    uint64_t p = static_cast<uint64_t>(a) * b;
    lo = static_cast<uint32_t>(p);
    return static_cast<uint32_t>(p >> 32);
}

inline uint32_t shr_sat(uint32_t hi, uint32_t lo, uint8_t shift) {
    uint64_t p = (static_cast<uint64_t>(hi) << 32 | lo) >> shift;
    return p >> 32 ? 0xFFFFFFFFul : static_cast<uint32_t>(p);
}
#endif

} // namespace

uint16_t isqrt32(uint32_t v) {
#if defined(__AVR__)
    // Bit by bit from the top, with hardware squares: the high byte sh against the top 16 bits
    // of v (one 8x8 product per bit), then the low byte t against rem = v - sh^2 2^16, in place
    // of v (t^2 + 2 sh t 2^8 <= rem: two products per bit, subtracted from a copy of rem).
    // Twelve upper registers, all call-clobbered: no register saved.
    uint8_t sh, sl, t, bit;
    uint32_t sq;
    asm("clr  %[sh]\n\t"
        "ldi  %[bit], 0x80\n"
        "1:\n\t"
        "mov  %[t], %[sh]\n\t"
        "or   %[t], %[bit]\n\t"
        "mul  %[t], %[t]\n\t"
        "cp   %C[v], r0\n\t"
        "cpc  %D[v], r1\n\t"
        "brcs 2f\n\t"
        "mov  %[sh], %[t]\n"
        "2:\n\t"
        "lsr  %[bit]\n\t"
        "brne 1b\n\t"
        "mul  %[sh], %[sh]\n\t" // rem < 2^25
        "sub  %C[v], r0\n\t"
        "sbc  %D[v], r1\n\t"
        "clr  %[sl]\n\t"
        "sbrs %[sh], 7\n\t"
        "rjmp 7f\n\t"
        // sh >= 128 (v >= 2^30, as for Num::sqrt): the low byte from one Newton step instead,
        // t = min(255, floor(rem / 2^9 / sh)), which is the root's low byte or one above it
        // (the step never falls short; checked for the largest v of every root, where the
        // overshoot is largest), so one test decides between t and t - 1. rem's bits 9..24 in
        // %C:%B[sq], divided by sh by restoring division (the quotient shifted into %B[sq]);
        // bit is 0 after the first loop: the second ends after that test.
        "mov  %B[sq], %B[v]\n\t"
        "mov  %C[sq], %C[v]\n\t"
        "mov  %D[sq], %D[v]\n\t"
        "lsr  %D[sq]\n\t"
        "ror  %C[sq]\n\t"
        "ror  %B[sq]\n\t"
        "ldi  %[t], 0xFF\n\t" // when the quotient has 9 bits
        "cp   %C[sq], %[sh]\n\t"
        "brsh 6f\n\t"
        "ldi  %[t], 8\n"
        "5:\n\t"
        "lsl  %B[sq]\n\t"
        "rol  %C[sq]\n\t"
        "brcs 8f\n\t"
        "cp   %C[sq], %[sh]\n\t"
        "brcs 9f\n"
        "8:\n\t"
        "sub  %C[sq], %[sh]\n\t"
        "inc  %B[sq]\n"
        "9:\n\t"
        "dec  %[t]\n\t"
        "brne 5b\n\t"
        "mov  %[t], %B[sq]\n"
        "6:\n\t"
        "mov  %[sl], %[t]\n\t"
        "dec  %[sl]\n\t"
        "rjmp 10f\n"
        "7:\n\t"
        "ldi  %[bit], 0x80\n"
        "3:\n\t"
        "mov  %[t], %[sl]\n\t"
        "or   %[t], %[bit]\n"
        "10:\n\t"
        "mul  %[t], %[t]\n\t" // rem - t^2 - sh t 2^8 - sh t 2^8 >= 0, or a borrow
        "movw %A[sq], %A[v]\n\t"
        "movw %C[sq], %C[v]\n\t"
        "sub  %A[sq], r0\n\t"
        "sbc  %B[sq], r1\n\t"
        "sbci %C[sq], 0\n\t"
        "sbci %D[sq], 0\n\t"
        "brcs 4f\n\t"
        "mul  %[t], %[sh]\n\t"
        "sub  %B[sq], r0\n\t"
        "sbc  %C[sq], r1\n\t"
        "sbci %D[sq], 0\n\t"
        "brcs 4f\n\t"
        "sub  %B[sq], r0\n\t"
        "sbc  %C[sq], r1\n\t"
        "sbci %D[sq], 0\n\t"
        "brcs 4f\n\t"
        "mov  %[sl], %[t]\n"
        "4:\n\t"
        "lsr  %[bit]\n\t"
        "brne 3b\n\t"
        "clr  __zero_reg__"
        : [sh] "=&d"(sh), [sl] "=&d"(sl), [t] "=&d"(t), [bit] "=&d"(bit), [sq] "=&d"(sq),
          [v] "+d"(v));
    return static_cast<uint16_t>(sh << 8 | sl);
#else
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
#endif
}

#if !defined(__AVR__) // AVR: Num::sqrt in fixmath_avr.cpp
namespace {

// floor(rem * 2^15 / s) for 2^15 <= s < 2^16 and rem <= 2 s: the Newton correction of a
// square root (a quotient below 2^17).
uint32_t sqrt_step(uint32_t rem, uint16_t s) {
    // rem = q0 s + r with q0 <= 2, then 15 quotient bits of r * 2^15 / s.
    uint8_t q0 = 0;
    while (rem >= s) {
        rem -= s;
        ++q0;
    }
    uint16_t r = static_cast<uint16_t>(rem);
    uint16_t q = 0;
    for (uint8_t i = 0; i < 15; ++i) {
        bool carry = (r & 0x8000u) != 0;
        r = static_cast<uint16_t>(r << 1);
        q = static_cast<uint16_t>(q << 1);
        if (carry || r >= s) {
            r = static_cast<uint16_t>(r - s);
            q = static_cast<uint16_t>(q | 1);
        }
    }
    return static_cast<uint32_t>(q0) << 15 | q;
}

} // namespace
#endif

uint32_t div_frac(uint32_t num, uint32_t den, uint8_t bits) {
    uint32_t q = 0, rem = num;
    if (num >= den) { // short lines: num < den, no library division
        q = num / den;
        rem = num % den; // the same library call
    }
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

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
uint32_t div32_16(uint32_t n, uint16_t d) {
    return n / d;
}
#endif

#if defined(__AVR__)
// a in r22..r25, b in r18..r21, &lo in r16:r17 (kept by __ll_mul32s); hi returned in r22..r25.
asm(".section .text._ZN2ll8mul_wideEmmRm,\"ax\",@progbits\n"
    ".global _ZN2ll8mul_wideEmmRm\n"
    ".type _ZN2ll8mul_wideEmmRm, @function\n"
    "_ZN2ll8mul_wideEmmRm:\n"
    "call __ll_mul32s\n"
    "movw r30, r16\n"
    "st   Z, r18\n"
    "std  Z+1, r19\n"
    "std  Z+2, r20\n"
    "std  Z+3, r21\n"
    "ret\n"
    ".size _ZN2ll8mul_wideEmmRm, .-_ZN2ll8mul_wideEmmRm\n"
    ".text\n");
#else
uint32_t mul_wide(uint32_t a, uint32_t b, uint32_t& lo) {
    return mul64(a, b, lo);
}
#endif

uint32_t shr64_sat(uint32_t hi, uint32_t lo, uint8_t shift) {
    return shr_sat(hi, lo, shift);
}

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
uint32_t mul_shr(uint32_t a, uint32_t b, uint8_t shift) {
    uint32_t lo, hi = mul64(a, b, lo);
    return shr_sat(hi, lo, shift);
}
#endif

uint32_t shl_sat(uint32_t x, uint8_t k) {
    // Whole bytes while the top byte is free (a feed hold's deceleration in delta_at() and
    // profile_x2_decel() shift by s / 2 or s, 8 or 9 for short moves: 105 -> 33 cycles a call),
    // then a bit at a time; a test against 2^32 >> k would be a second variable
    // shift (a loop on the ATmega328P). Zero stays zero (no bit ever reaches the top: no test
    // for it); anything else saturates within 32 turns.
#if defined(__AVR__)
    asm("0:\n\t"
        "cpi  %[k], 8\n\t"
        "brlo 1f\n\t"
        "tst  %D[x]\n\t"
        "brne 2f\n\t"
        "mov  %D[x], %C[x]\n\t"
        "mov  %C[x], %B[x]\n\t"
        "mov  %B[x], %A[x]\n\t"
        "clr  %A[x]\n\t"
        "subi %[k], 8\n\t"
        "rjmp 0b\n"
        "1:\n\t"
        "tst  %[k]\n\t"
        "breq 3f\n\t"
        "sbrc %D[x], 7\n\t"
        "rjmp 2f\n\t"
        "lsl  %A[x]\n\t"
        "rol  %B[x]\n\t"
        "rol  %C[x]\n\t"
        "rol  %D[x]\n\t"
        "dec  %[k]\n\t"
        "rjmp 1b\n"
        "2:\n\t"
        "ldi  %A[x], 0xFF\n\t"
        "ldi  %B[x], 0xFF\n\t"
        "movw %C[x], %A[x]\n"
        "3:"
        : [x] "+d"(x), [k] "+d"(k));
    return x;
#else
    if (x == 0) return 0;
    for (; k != 0; --k) {
        if (x & 0x80000000ul) return 0xFFFFFFFFul;
        x <<= 1;
    }
    return x;
#endif
}

namespace {

#if !defined(__AVR__) // AVR: atan2_q29 in fixmath_avr.cpp, with its copy
// atan(2^-i) in radians x 2^29 for i <= 10; beyond, atan(2^-i) = 2^-i to the last bit (and
// 2^-10 already is: the last entry is 2^19, halved from there on).
const uint32_t kAtanQ29[11] LL_PROGMEM = {421657428, 248918915, 131521918, 66762579,
                                          33510843,  16771758,  8387925,   4194219,
                                          2097141,   1048575,   524288};
#endif

// (a * b) >> 30 for Q30 operands (the arithmetic shift of the exact 64-bit product). From the
// unsigned product: a negative operand subtracts the other one times 2^32.
int32_t mul_q30(int32_t a, int32_t b) {
    uint32_t ua = static_cast<uint32_t>(a), ub = static_cast<uint32_t>(b);
    uint32_t lo, hi = mul64(ua, ub, lo);
    if (a < 0) hi -= ub;
    if (b < 0) hi -= ua;
    uint8_t top = static_cast<uint8_t>(lo >> 24); // lo >> 30 without a 30-turn shift loop
    return static_cast<int32_t>(hi << 2 | static_cast<uint8_t>(top >> 6));
}

// 1 - x * r * t in Q30, with r a Q30 reciprocal constant: one step of a Horner series.
int32_t horner(int32_t x, int32_t r, int32_t t) {
    return (1l << 30) - mul_q30(mul_q30(x, r), t);
}

} // namespace

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
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
    // max(|x|, |y|) matters only through its top bit, which |x| | |y| has too.
    uint32_t big = abs32(x) | abs32(y);
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
    uint32_t a = 0;
    for (uint8_t i = 0; i < 30; ++i) {
        a = i <= 10 ? flash_read_u32(&kAtanQ29[i]) : a >> 1;
        int32_t xs = x >> i, ys = y >> i;
        if (y > 0) {
            x += ys;
            y -= xs;
            z += static_cast<int32_t>(a);
        } else {
            x -= ys;
            y += xs;
            z -= static_cast<int32_t>(a);
        }
    }
    return z;
}
#endif

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

#if !defined(__AVR__) // AVR: Num::div in fixmath_avr.cpp
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
#endif

} // namespace

#if !defined(__AVR__)
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
#endif

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
Num& Num::set(uint32_t v, int8_t exp) {
    if (v == 0) {
        m = 0;
        e = 0;
        return *this;
    }
    int16_t ex = exp;
    while (!(v >> 24)) { // whole bytes first (byte moves on the ATmega328P)
        v <<= 8;
        ex = static_cast<int16_t>(ex - 8);
    }
    while (!(v & 0x80000000ul)) {
        v <<= 1;
        --ex;
    }
    return finish(*this, v, ex);
}
#endif

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
Num& Num::mul(const Num& o) {
    if (m == 0 || o.m == 0) return set(0);
    uint32_t lo, hi = mul64(m, o.m, lo); // product in [2^62, 2^64)
    int16_t ex = static_cast<int16_t>(e + o.e + 32);
    if (!(hi & 0x80000000ul)) {
        hi = hi << 1 | lo >> 31;
        --ex;
    }
    return finish(*this, hi, ex);
}
#endif

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
Num& Num::mulc(uint32_t mant, int8_t exp) {
    Num c;
    c.m = mant;
    c.e = exp;
    return mul(c);
}
#endif

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
Num& Num::mul(uint32_t v) {
    return mul(Num(v));
}
#endif

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
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
#endif

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
Num& Num::div(uint32_t v) {
    return div(Num(v));
}
#endif

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
Num& Num::add(const Num& o) {
    if (o.m == 0) return *this;
    if (m == 0) return *this = o;
    Num big = *this, small = o;
    if (big.e < small.e) {
        big = o;
        small = *this;
    }
    uint8_t gap = static_cast<uint8_t>(big.e - small.e);
    uint32_t sm = gap >= 32 ? 0 : shr_sat(0, small.m, gap);
    uint32_t sum = big.m + sm;
    if (sum < big.m) {
        m = static_cast<uint32_t>(0x80000000ul | (sum >> 1));
        e = static_cast<int8_t>(big.e + 1);
        return *this;
    }
    m = sum; // >= big.m >= 2^31: normalised
    e = big.e;
    return *this;
}
#endif

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
Num& Num::sqrt() {
    if (m == 0) return *this;
    // Make the exponent even: value = m' * 2^e' with m' in [2^30, 2^32).
    uint32_t v = m;
    int8_t ex = e;
    if (ex & 1) {
        v >>= 1;
        ++ex;
    }
    // sqrt(v * 2^ex) = sqrt(v) * 2^(ex/2). s = floor(sqrt(v)) to 16 bits, then one Newton step
    // from r = s * 2^16: r' = (r + v * 2^32 / r) / 2 = s * 2^16 + (v - s^2) * 2^15 / s, within
    // one unit of sqrt(v) * 2^16 (2^-31 relative). It reaches 2^32 just below v = 2^32.
    uint16_t s = isqrt32(v);
    uint32_t rem = v - static_cast<uint32_t>(s) * s;
    // s * 2^16 + q, q < 2^17: the top half s + (q >> 16) (s >= 2^15: normalised), which
    // wraps to 0 only when the sum is 2^32.
    uint32_t q = sqrt_step(rem, s);
    uint16_t hi = static_cast<uint16_t>(s + static_cast<uint16_t>(q >> 16));
    ex = static_cast<int8_t>(ex / 2 - 16); // ex is even
    if (hi < s) {                          // 2^32
        m = 0x80000000ul;
        e = static_cast<int8_t>(ex + 1);
        return *this;
    }
    m = static_cast<uint32_t>(hi) << 16 | static_cast<uint16_t>(q);
    e = ex;
    return *this;
}

#endif

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
Num sum_squares(const uint32_t v[], uint8_t n, uint8_t mask) {
    // Exact 64-bit sums while every value is below 2^30 (6 squares below 2^63); larger values
    // (travel beyond 4 km) lose their two low bits first.
    uint8_t drop = 0;
    for (uint8_t i = 0; i < n; ++i) {
        if (static_cast<uint8_t>(v[i] >> 24) >= 0x40) drop = 2;
    }
    uint32_t hi = 0, lo = 0;
    for (; n != 0; --n, ++v, mask >>= 1) {
        uint32_t x = *v;
        if (x == 0 || !(mask & 1)) continue;
        if (drop) x >>= 2;
        uint32_t l, h = mul64(x, x, l);
        lo += l;
        if (lo < l) ++h; // h <= 2^32 - 2
        hi += h;
    }
    return num64(hi, lo, static_cast<int8_t>(2 * drop));
}
#endif

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
Num num64(uint32_t hi, uint32_t lo, int8_t exp) {
    // Normalise the top word, then shift in the bits of the low word it makes room for.
    Num r;
    if (hi == 0) return r.set(lo, exp);
    r.set(hi, static_cast<int8_t>(32 + exp));
    uint8_t k = static_cast<uint8_t>(32 + exp - r.e);
    if (k) r.m |= shr_sat(0, lo, static_cast<uint8_t>(32 - k));
    return r;
}
#endif

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
Num& Num::shift(int8_t k) {
    if (m) e = static_cast<int8_t>(e + k);
    return *this;
}
#endif

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
uint32_t Num::u32() const {
    if (m == 0 || e <= -32) return 0;
    if (e > 0) return 0xFFFFFFFFul;
    return shr64_sat(0, m, static_cast<uint8_t>(-e));
}
#endif

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
uint32_t Num::of(uint32_t x) const {
    // floor(x * m * 2^e), from the exact 64-bit product.
    if (m == 0 || x == 0 || e <= -64) return 0;
    if (e > 0) return 0xFFFFFFFFul;
    return mul_shr(x, m, static_cast<uint8_t>(-e));
}
#endif

#if !defined(__AVR__) // AVR: fixmath_avr.cpp
int8_t Num::cmp(const Num& o) const {
    if (m == 0 || o.m == 0) return m == o.m ? 0 : (m == 0 ? -1 : 1);
    if (e != o.e) return e < o.e ? -1 : 1;
    if (m != o.m) return m < o.m ? -1 : 1;
    return 0;
}
#endif

} // namespace ll
