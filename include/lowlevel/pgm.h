// Constant strings and tables kept in flash on the chip, portable to the host.
// On the ATmega328P a `const` object is copied to RAM at start-up unless it is marked PROGMEM and
// read back with LPM; on the host both are ordinary constants. This is the one core header that
// may include an AVR header, and only under __AVR__.
#pragma once

#include <stdint.h>

#ifdef __AVR__
#include <avr/pgmspace.h>
#define LL_PROGMEM PROGMEM
/// A string literal kept in flash: `out::str(LL_PSTR("ok"))`.
#define LL_PSTR(s) (reinterpret_cast<const ::ll::FlashChar*>(PSTR(s)))
#else
#define LL_PROGMEM
#define LL_PSTR(s) (reinterpret_cast<const ::ll::FlashChar*>(s))
#endif

namespace ll {

/// A character stored in flash. Incomplete on purpose: it can only be read through
/// flash_read_byte(), so a flash string is never passed where a RAM string is expected.
struct FlashChar;

// Named flash_read_* rather than pgm_read_*: avr/pgmspace.h defines pgm_read_byte as a macro,
// which would rewrite any function of that name.
inline uint8_t flash_read_byte(const void* p) {
#ifdef __AVR__
    return pgm_read_byte(p);
#else
    return *static_cast<const uint8_t*>(p);
#endif
}

inline uint32_t flash_read_u32(const uint32_t* p) {
#ifdef __AVR__
    return pgm_read_dword(p);
#else
    return *p;
#endif
}

/// Copies `n` bytes from flash to RAM.
inline void flash_copy(void* dst, const void* src, uint8_t n) {
    uint8_t* d = static_cast<uint8_t*>(dst);
    const uint8_t* s = static_cast<const uint8_t*>(src);
    while (n--) *d++ = flash_read_byte(s++);
}

} // namespace ll
