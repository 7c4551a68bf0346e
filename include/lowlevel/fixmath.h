// Integer arithmetic helpers for the motion core. No floating point anywhere (seed §6: "on
// PROSCRIRA les float"): square roots, quotients and scale factors are computed on integers.
//
// Where a move is prepared, quantities span many decades (ticks per (mm/min)^2, cycles per
// sqrt(tick)...), so they are carried as `Num`: a 32-bit integer mantissa with a binary
// exponent, i.e. a fixed-point value whose binary point is chosen per value. Every operation is
// an out-of-line integer routine (one 32x32 multiplication, one shift-and-subtract division,
// one Newton step for a square root), exact to 2^-30 relative; products and quotients are
// truncated (never rounded up). Values must stay within about 2^-97..2^158: beyond, they
// saturate or become zero. The methods work in place and chain (`Num(a).mul(b).div(c).u32()`),
// which keeps each call site to a few instructions on the ATmega328P. The per-segment path of the
// step generator uses 32-bit integers and shifts only.
#pragma once

#include <stdint.h>

namespace ll {

/// floor(sqrt(v)).
uint16_t isqrt32(uint32_t v);

/// floor(num * 2^bits / den), by shift-and-subtract on 32-bit words.
/// Preconditions: 0 < den < 2^31 and the quotient fits in 32 bits.
uint32_t div_frac(uint32_t num, uint32_t den, uint8_t bits);

/// The full product a * b = hi * 2^32 + lo: returns hi, writes lo. On the ATmega328P, 16
/// hardware 8x8 multiplications summed column by column (about 90 cycles, no library call).
uint32_t mul_wide(uint32_t a, uint32_t b, uint32_t& lo);

/// floor((hi * 2^32 + lo) / 2^shift), saturated to 2^32 - 1 (shift <= 63).
uint32_t shr64_sat(uint32_t hi, uint32_t lo, uint8_t shift);

/// floor(a * b / 2^shift), saturated to 2^32 - 1 (shift <= 63).
uint32_t mul_shr(uint32_t a, uint32_t b, uint8_t shift);

/// floor(n / d) for a 16-bit divisor d != 0 (the step generator's D / R): 32 turns of a 17-bit
/// remainder on the ATmega328P instead of the library's 32-bit one (24 when n's top byte is
/// below d: the first 8 quotient bits are then 0, and the remainder starts as that byte).
uint32_t div32_16(uint32_t n, uint16_t d);

/// min(x << k, 2^32 - 1).
uint32_t shl_sat(uint32_t x, uint8_t k);
/// min(a + b, 2^32 - 1).
inline uint32_t add_sat(uint32_t a, uint32_t b) {
    return a + b < a ? 0xFFFFFFFFul : a + b;
}

/// |v| as an unsigned value (also for INT32_MIN).
__attribute__((noinline)) inline uint32_t abs32(int32_t v) {
    return v < 0 ? static_cast<uint32_t>(-(v + 1)) + 1u : static_cast<uint32_t>(v);
}

/// min(a, b), unsigned (one shared copy: the planner's limits, the curves' radii).
__attribute__((noinline)) inline uint32_t min32(uint32_t a, uint32_t b) {
    return a < b ? a : b;
}

/// Angles in radians x 2^29 (pi = 1686629713): the parameter of arcs and ellipses.
constexpr int32_t kPiQ29 = 1686629713;

/// atan2(y, x) in radians x 2^29, in (-pi, pi], by CORDIC vectoring (integer shifts and adds,
/// one 10-entry table in flash). Exact to 2^-24 rad (shift truncation over 30 iterations on
/// 29-bit operands): 0.003 tick at a 50,000-tick radius. atan2(0, 0) = 0.
int32_t atan2_q29(int32_t y, int32_t x);

/// cos h and sin h, and k = 4/3 tan(h/4) (the control-arm length of a cubic arc of angle h), for
/// a small angle |h| <= 0.4 rad given in radians x 2^30; results x 2^30. Taylor series to
/// 2^-30 (no table): used where an arc is prepared, never per step.
void small_angle_q30(int32_t h, int32_t& c, int32_t& s, int32_t& k);

/// Sum of the squares of the n values whose bit is set in `mask` (bit i for v[i]), as a Num
/// (exact 64-bit sums; truncated to 32 bits once).
struct Num;
Num sum_squares(const uint32_t v[], uint8_t n, uint8_t mask = 0xFF);
/// (hi * 2^32 + lo) * 2^exp as a Num, truncated; exp <= 95.
Num num64(uint32_t hi, uint32_t lo, int8_t exp = 0);

/// value = m * 2^e, m normalised to [2^31, 2^32) (or m == 0 for zero).
struct Num {
    uint32_t m;
    int8_t e;

    Num() = default; ///< uninitialised, as a plain integer would be: write `Num x{}` for zero
    explicit Num(uint32_t v, int8_t exp = 0) { set(v, exp); }

    Num& set(uint32_t v, int8_t exp = 0); ///< v * 2^exp
    Num& mul(const Num& o);
    Num& mul(uint32_t v);
    /// Multiplies by the constant mant * 2^exp, given normalised (mant >= 2^31): constants as
    /// immediate operands (a constant Num object would be copied from RAM on the ATmega328P).
    Num& mulc(uint32_t mant, int8_t exp);
    Num& div(const Num& o); ///< o != 0
    Num& div(uint32_t v);   ///< v != 0
    Num& add(const Num& o);
    Num& sqrt();
    Num& shift(int8_t k); ///< times 2^k (zero stays zero)
    /// floor(value), saturated to 2^32 - 1.
    uint32_t u32() const;
    /// floor(value * x), saturated: applying a prepared factor to an integer.
    uint32_t of(uint32_t x) const;
    /// -1, 0, 1 as this <, ==, > o.
    int8_t cmp(const Num& o) const;
};

#if defined(__AVR__)
// The assembly entries behind set, mul(uint32_t) and div(uint32_t) (fixmath_avr.cpp), with the
// members' register layout. A constant exponent 0 (most calls) or a constant factor below 256
// takes a shorter entry that fills in the rest: 2 to 6 B less per call site.
Num& num_set(Num& n, uint32_t v, int8_t exp) asm("__ll_set");
Num& num_set0(Num& n, uint32_t v) asm("__ll_set0");
Num& num_mul(Num& n, uint32_t v) asm("__ll_mul");
Num& num_mul8(Num& n, uint8_t v) asm("__ll_mul8");
Num& num_div(Num& n, uint32_t v) asm("__ll_div");
Num& num_div8(Num& n, uint8_t v) asm("__ll_div8");

__attribute__((always_inline)) inline Num& Num::set(uint32_t v, int8_t exp) {
    if (__builtin_constant_p(exp) && exp == 0) return num_set0(*this, v);
    return num_set(*this, v, exp);
}
__attribute__((always_inline)) inline Num& Num::mul(uint32_t v) {
    if (__builtin_constant_p(v) && v < 256) return num_mul8(*this, static_cast<uint8_t>(v));
    return num_mul(*this, v);
}
__attribute__((always_inline)) inline Num& Num::div(uint32_t v) {
    if (__builtin_constant_p(v) && v < 256) return num_div8(*this, static_cast<uint8_t>(v));
    return num_div(*this, v);
}
#endif

} // namespace ll
