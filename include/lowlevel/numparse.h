// Integer-only decimal numbers for G-code words and `$` settings, and exact fixed-point scaling.
//
// A value is read once into a Decimal that keeps every digit the conversions need: the integer
// part, the first five decimals and how the rest rounds. The unit is not known while a word is
// read (`X1 G20` is inches), so the conversion to a fixed-point field happens later:
//   - to_milli(): value x1000 (mm -> um, mm/min -> mm/min x1000, s -> ms), rounded half away
//     from zero on the 4th decimal, i.e. exact for up to 3 decimals;
//   - inch_to_milli(): inches x25400 (in -> um, in/min -> mm/min x1000), from the first five
//     decimals (the 6th rounds the 5th, half away from zero), then rounded half away from zero
//     to an integer: exact single rounding for values with up to 5 decimals.
// Overflow is reported, never wrapped.
#pragma once

#include <stdint.h>

namespace ll {
namespace num {

struct Decimal {
    enum : uint8_t {
        kNegative = 1, ///< a '-' sign and a non-zero value
        kRound6 = 2,   ///< the 6th decimal is 5 or more
        kInexact = 4,  ///< a non-zero digit after the 5th decimal
    };
    uint32_t ipart; ///< integer part, magnitude, < 10^9
    uint16_t frac;  ///< decimals 1 to 3 as an integer, 0..999
    uint8_t sub;    ///< decimals 4 and 5 as an integer, 0..99
    uint8_t flags;

    bool negative() const { return (flags & kNegative) != 0; }
    /// True when the value has no non-zero decimal at all.
    bool integral() const { return (frac | sub | (flags & kInexact)) == 0; }
};

/// Reads `[+|-]digits[.digits]` (at least one digit; GRBL's read_float without its float) at
/// `p`. Returns the character after it, or nullptr when no digit is present or the integer
/// part has more than 9 digits; `out` is then unspecified (the chip's assembly may have written
/// part of it, the host's C leaves it as it was).
const char* parse(const char* p, Decimal& out);
/// The same with a position in `s`, advanced past the number (unchanged on failure).
inline bool parse(const char* s, uint8_t& pos, Decimal& out) {
    const char* end = parse(s + pos, out);
    if (end == nullptr) return false;
    pos = static_cast<uint8_t>(end - s);
    return true;
}

/// inch_to_milli() when `inches`, else to_milli(): a length or feed in the units of a block.
bool length_to_milli(const Decimal& d, bool inches, int32_t& out);
/// value x1000, half away from zero. False when |value x1000| would exceed INT32_MAX.
inline bool to_milli(const Decimal& d, int32_t& out) {
    return length_to_milli(d, false, out);
}
/// value x25400 (inches to um), see above. False when the result would exceed INT32_MAX.
inline bool inch_to_milli(const Decimal& d, int32_t& out) {
    return length_to_milli(d, true, out);
}
/// The value as an integer in [0, max]. False when negative, not integral or above max.
bool to_uint(const Decimal& d, uint32_t max, uint32_t& out);

/// round_half_away_from_zero(a * b / c), exactly: one 32x32->64 product and a restoring
/// division that skips leading zero quotient bytes (no 64-bit library division on the chip).
/// Preconditions: 0 < c < 2^31. Returns false (and saturates `out`) when the result does not
/// fit in an int32 (INT32_MIN included: only magnitudes up to INT32_MAX are produced).
bool mul_div_round(int32_t a, uint32_t b, uint32_t c, int32_t& out);

} // namespace num
} // namespace ll
