// Formatting of everything the firmware sends: GRBL's responses, reports and fixed-point values,
// straight to hal::serial_put (no line buffer, no printf; a number's digits come from the
// library's 32-bit division, into a 10-byte buffer: reports are cold, flash is not).
#pragma once

#include <stdint.h>

#include "lowlevel/config.h"
#include "lowlevel/hal.h"
#include "lowlevel/pgm.h"

namespace ll {
namespace out {

/// One character (inline: the call goes straight to the driver).
inline void ch(char c) {
    hal::serial_put(static_cast<uint8_t>(c));
}
/// A string kept in flash (LL_PSTR).
void str(const FlashChar* s);
/// "\r\n", GRBL's line end.
void eol();
/// A string kept in flash, then the line end.
void line(const FlashChar* s);
/// "]" and the line end: the end of every bracketed message (one string for all of them).
void bracket_eol();
/// An unsigned integer in decimal.
void u32(uint32_t v);
/// The same for a byte (a shorter call).
void u8(uint8_t v);
/// ' ', `letter`, then `v` in decimal: one word of `$G`.
void word(char letter, uint8_t v);
/// A fixed-point value `v` scaled by 10^decimals, printed with exactly `decimals` decimals:
/// fixed(-1500, 3) prints "-1.500", fixed(7, 3) prints "0.007". decimals <= 9.
void fixed(int32_t v, uint8_t decimals);
/// One length in um printed as mm with 3 decimals, or as inches with 4 decimals when $13=1
/// (exact conversion, half away from zero).
void coord(int32_t um);
/// kAxes lengths (coord()) separated by commas; nullptr prints zeros.
void coords(const int32_t* um);
/// A rate given in units/min x1000: mm/min without decimals, or in/min with 1 decimal ($13=1),
/// as GRBL prints F and FS.
void rate(uint32_t milli_per_min);
/// `ok` for status::kOk, `error:N` otherwise, then the line end.
void status(uint8_t code);
/// `[MSG:text]` and the line end.
void msg(const FlashChar* text);

} // namespace out
} // namespace ll
