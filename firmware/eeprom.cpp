// Settings storage: the 1 KiB EEPROM through avr-libc (update semantics: an unchanged byte is
// not rewritten). A write waits for the previous one (3.3 ms) with interrupts on; avr-libc
// disables them only for the 4-cycle EEMPE/EEPE sequence.
#include <avr/eeprom.h>

#include "lowlevel/hal.h"

namespace ll {
namespace hal {

static_assert(kEepromSize == E2END + 1, "hal::kEepromSize matches the part");

uint8_t eeprom_read(uint16_t addr) {
    return eeprom_read_byte(reinterpret_cast<const uint8_t*>(addr % kEepromSize));
}

void eeprom_write(uint16_t addr, uint8_t value) {
    eeprom_update_byte(reinterpret_cast<uint8_t*>(addr % kEepromSize), value);
}

} // namespace hal
} // namespace ll
