// Millisecond clock: Timer2 in CTC mode, prescaler 64, OCR2A = 249 -> one interrupt per ms.
// The compare flag clears itself when the vector runs, so the handler re-enables interrupts
// first (ISR_NOBLOCK): it can delay a step edge by its 4-cycle entry, the jmp and the sei only.
#include <avr/interrupt.h>
#include <avr/io.h>

#include "fw.h"
#include "lowlevel/hal.h"

namespace ll {
namespace {
volatile uint32_t s_millis; // ms since clock_init(), wraps after 49.7 days
} // namespace
} // namespace ll

ISR(TIMER2_COMPA_vect, ISR_NOBLOCK) {
    ll::s_millis = ll::s_millis + 1;
}

namespace ll {
namespace fw {

void clock_init() {
    TCCR2A = _BV(WGM21); // CTC
    OCR2A = 249;         // 250 ticks of 4 µs
    TCNT2 = 0;
    TIFR2 = _BV(OCF2A);
    TIMSK2 = _BV(OCIE2A);
    TCCR2B = _BV(CS22); // clk/64
}

} // namespace fw

namespace hal {

uint32_t millis() {
    // Lock-free: read until two reads agree (the interrupt changes it once per ms).
    uint32_t a = s_millis;
    for (;;) {
        uint32_t b = s_millis;
        if (a == b) return a;
        a = b;
    }
}

} // namespace hal
} // namespace ll
