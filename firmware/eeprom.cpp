// Settings storage: the 1 KiB EEPROM through its registers (update semantics: an unchanged byte
// is not rewritten). A write waits for the previous one (3.4 ms) with interrupts on; they are
// off only for the EEMPE/EEPE pair, which must come within 4 cycles. (avr-libc's
// eeprom_read_byte and eeprom_update_byte and the calls to them took 18 B more.)
#include <avr/io.h>

#include "fw.h"
#include "lowlevel/hal.h"

namespace ll {
namespace hal {

static_assert(kEepromSize == E2END + 1, "hal::kEepromSize matches the part");

__attribute__((noinline)) uint8_t eeprom_read(uint16_t addr) {
    while (EECR & _BV(EEPE)) {
    }
    EEAR = addr % kEepromSize;
    EECR |= _BV(EERE);
    return EEDR;
}

uint8_t eeprom_write(uint16_t addr, uint8_t value) {
    // Leaves EEAR at addr and the previous write finished.
    if (eeprom_read(addr) == value) return value;
    EEDR = value;
    {
        fw::IrqGuard g;
        EECR = _BV(EEMPE); // erase and write in one operation (EEPM = 0)
        EECR |= _BV(EEPE);
    }
    return value; // (the caller's transfer() returns it: no register kept for it there)
}

} // namespace hal
} // namespace ll
