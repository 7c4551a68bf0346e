// Pin directions and limit inputs (board.h has the map; the critical sections are inline in
// lowlevel/hal.h).
#include <avr/io.h>

#include "board.h"
#include "fw.h"
#include "lowlevel/hal.h"
#include "lowlevel/settings.h"

namespace ll {
namespace hal {

uint8_t limits() {
    // Pull-ups: an open switch reads high. $5 = 0: a switch closing to ground triggers.
    uint8_t pins = static_cast<uint8_t>(PINB >> board::LimitX::kBit) & 0x07;
    return g_settings.limit_invert ? pins : static_cast<uint8_t>(pins ^ 0x07);
}

// irq_save() / irq_restore(): inline in hal.h.

} // namespace hal
} // namespace ll
