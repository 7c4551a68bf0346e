/* Found while writing these tests: SBI/CBI on PINx and TIFRn, and writes to TIFRn.
 *
 * The ATmega328P executes SBI and CBI on the addressed bit only (datasheet 7.4: "unlike most other
 * AVRs, the CBI and SBI instructions will only operate on the specified bit"; 14.2.2: "the SBI
 * instruction can be used to toggle one single bit in a port"). simavr 1.6 reads the register,
 * sets or clears the bit and writes the whole byte back. A timer flag is cleared by writing a one
 * to it (15.11.9); simavr 1.6 clears every flag of TIFRn on any write.
 *
 * sbi_toggle: SBI PIND,2 with PD3 high: only step_x toggles (simavr also toggles step_y).
 * cbi_nop:    CBI PIND,4 with PD2 high: nothing toggles (simavr toggles every high pin).
 * tifr_out:   OCF1A and OCF1B pending; OUT TIFR1 = 1 << OCF1A clears OCF1A only; TIFR1 is then
 *             copied to GPIOR2: 0x04 (OCF1B) on the datasheet.
 * tifr_sbi:   both pending again; SBI TIFR1,OCF1A: TIFR1 copied to GPIOR1, 0x04 as well. */
#include "selftest.h"

/* Timer1 in normal mode from 0, both compares at 10, no interrupt enabled: after 100 cycles
 * OCF1A and OCF1B are set; then the clock is stopped. */
static void raise_both_flags(void) {
    TCNT1 = 0;
    TCCR1B = 1 << CS10;
    asm volatile(SLED(100));
    TCCR1B = 0;
}

int main(void) {
    DDRD = STEP_X | STEP_Y | STEP_Z | DIR_X | DIR_Y | DIR_Z;
    PORTD = STEP_Y;
    OCR1A = 10;
    OCR1B = 10;
    TCCR1A = 0;
    raise_both_flags();
    /* clang-format off */
    asm volatile(
        LABEL(sbi_toggle)
        "sbi %[pind], 2\n\t"          /* step_x toggles; step_y (high) must not */
        SLED(10)
        LABEL(cbi_nop)
        "cbi %[pind], 4\n\t"          /* nothing toggles */
        SLED(10)
        "ldi r24, %[ocf1a_mask]\n\t"
        LABEL(tifr_out)
        "out %[tifr1], r24\n\t"       /* clears OCF1A only */
        "in r24, %[tifr1]\n\t"
        "out %[gpior2], r24\n\t"
        :: [pind] "I"(_SFR_IO_ADDR(PIND)), [tifr1] "I"(_SFR_IO_ADDR(TIFR1)),
           [ocf1a_mask] "M"(1 << OCF1A), [gpior2] "I"(_SFR_IO_ADDR(GPIOR2))
        : "r24");
    raise_both_flags();
    asm volatile(
        LABEL(tifr_sbi)
        "sbi %[tifr1], %[ocf1a]\n\t"  /* clears OCF1A only */
        "in r24, %[tifr1]\n\t"
        "out %[gpior1], r24\n\t"
        :: [tifr1] "I"(_SFR_IO_ADDR(TIFR1)), [ocf1a] "I"(OCF1A),
           [gpior1] "I"(_SFR_IO_ADDR(GPIOR1))
        : "r24");
    /* clang-format on */
    idle_forever();
}
