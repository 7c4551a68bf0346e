// Integer arithmetic helpers for the motion core. No floating point anywhere (seed §6: "on
// PROSCRIRA les float"): square roots, quotients and scaled ratios are computed on integers.
#pragma once

#include <stdint.h>

namespace ll {

/// floor(sqrt(v)).
uint16_t isqrt32(uint32_t v);
/// floor(sqrt(v)).
uint32_t isqrt64(uint64_t v);

/// floor(num * 2^bits / den), by shift-and-subtract on 32-bit words.
/// Preconditions: 0 < den < 2^31 and the quotient fits in 32 bits.
uint32_t div_frac(uint32_t num, uint32_t den, uint8_t bits);

/// Number of significant bits of v (0 for v == 0).
uint8_t bit_length(uint64_t v);

/// min(v, 2^32 - 1).
inline uint32_t saturate32(uint64_t v) {
    return v > 0xFFFFFFFFull ? 0xFFFFFFFFul : static_cast<uint32_t>(v);
}

/// floor(a * b / 2^shift), shift < 64.
inline uint64_t mul_shr64(uint32_t a, uint32_t b, uint8_t shift) {
    return (static_cast<uint64_t>(a) * b) >> shift;
}

/// A positive rational kept as a 32-bit mantissa and a binary exponent: value = mant * 2^-shift,
/// with mant in [2^31, 2^32) (31 significant bits at least). It carries the per-move conversion
/// factors of the step generator (ticks per (mm/min)^2, ...), whose range spans many decades,
/// without a float. Computed where a move is prepared, applied with one multiplication.
struct Ratio {
    uint32_t mant;
    int8_t shift;

    /// floor(x * value), saturated to 2^32 - 1.
    uint32_t apply(uint32_t x) const;
    /// floor(x * value) on 64 bits, saturated.
    uint64_t apply64(uint32_t x) const;
};

/// num / den with 31 significant bits. Preconditions: num > 0, den > 0.
Ratio make_ratio(uint64_t num, uint64_t den);

} // namespace ll
