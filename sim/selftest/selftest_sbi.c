/* Found while writing these tests: SBI and CBI on PINx and TIFRn. The ATmega328P executes them on
 * the addressed bit only (datasheet 7.4: "unlike most other AVRs, the CBI and SBI instructions
 * will only operate on the specified bit"; 14.2.2: "the SBI instruction can be used to toggle one
 * single bit in a port"). simavr 1.6 reads the register, sets or clears the bit and writes the
 * whole byte back, so every other bit that reads as one is written as one too.
 *
 * sbi_toggle: SBI PIND,2 with PD3 high: only step_x toggles (simavr also toggles step_y).
 * cbi_nop:    CBI PIND,4 with PD2 high: nothing toggles (simavr toggles every high pin).
 * tifr_clear: OCF1A and OCF1B both pending; SBI TIFR1,OCF1A clears OCF1A only (simavr clears
 *             both). TIFR1 is then copied to GPIOR1: 0x04 (OCF1B) on the datasheet. */
#include "selftest.h"

int main(void) {
    DDRD = STEP_X | STEP_Y | STEP_Z | DIR_X | DIR_Y | DIR_Z;
    PORTD = STEP_Y;
    /* Timer1 in normal mode, both compares at 10, no interrupt enabled: the flags just rise. */
    OCR1A = 10;
    OCR1B = 10;
    TCCR1A = 0;
    TCCR1B = 1 << CS10;
    /* clang-format off */
    asm volatile(
        LABEL(sbi_toggle)
        "sbi %[pind], 2\n\t"          /* step_x toggles; step_y (high) must not */
        SLED(10)
        LABEL(cbi_nop)
        "cbi %[pind], 4\n\t"          /* nothing toggles */
        SLED(10)
        LABEL(tifr_clear)
        "sbi %[tifr1], %[ocf1a]\n\t"  /* clears OCF1A only */
        "in r24, %[tifr1]\n\t"
        "out %[gpior1], r24\n\t"
        :: [pind] "I"(_SFR_IO_ADDR(PIND)), [tifr1] "I"(_SFR_IO_ADDR(TIFR1)),
           [ocf1a] "I"(OCF1A), [gpior1] "I"(_SFR_IO_ADDR(GPIOR1))
        : "r24");
    /* clang-format on */
    idle_forever();
}
