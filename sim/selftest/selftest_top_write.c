/* SIMAVR-NOTES 2, CTC case: OCR1A lowered below the running count. Datasheet 15.9.2: "If the new
 * value written to OCR1A is lower than the current value of TCNT1, the counter will miss the
 * compare match. The counter will then have to count to its maximum value (0xFFFF) and wrap
 * around starting at 0x0000 before the compare match can occur." simavr 1.6 compares at once,
 * which hides this classic step-timer bug (a period shorter than the interrupt's own latency).
 *
 * Timer1, CTC, OCR1A = 999, prescaler 1, started at t1_start (count 0). At top_write (606 cycles
 * later: STS 2 + 600 nops + 2 LDI + STS OCR1AH 2) OCR1A becomes 100: the counter runs from 606
 * to 0xFFFF, wraps, and matches 100: the flag rises 65536 - 606 + 101 = 65031 cycles after
 * top_write, then every 101. OCR1B = 5000 is above the count: OCF1B (TIMER1_COMPB, step_y)
 * still rises on the way up, 5000 - 606 + 1 = 4395 cycles after top_write.
 * The CPU sleeps (idle) meanwhile, so each ISR starts 8 cycles after its flag (response from
 * sleep, datasheet 6.7.1) and toggles 6 cycles later. */
#include "selftest.h"

#include <avr/sleep.h>

TOGGLE_ISR(TIMER1_COMPA_vect, PIND, STEP_X)
TOGGLE_ISR(TIMER1_COMPB_vect, PIND, STEP_Y)

int main(void) {
    DDRD = STEP_X | STEP_Y | STEP_Z | DIR_X | DIR_Y | DIR_Z;
    OCR1A = 999;
    OCR1B = 5000;
    TCCR1A = 0;
    TIMSK1 = (1 << OCIE1A) | (1 << OCIE1B);
    set_sleep_mode(SLEEP_MODE_IDLE);
    sleep_enable();
    sei();
    /* clang-format off */
    asm volatile(
        "ldi r24, %[start]\n\t"
        LABEL(t1_start)
        "sts %[tccr1b], r24\n\t"
        SLED(600)
        "ldi r24, lo8(100)\n\t"
        "ldi r25, hi8(100)\n\t"
        "sts %[ocr1ah], r25\n\t"
        LABEL(top_write)
        "sts %[ocr1al], r24\n\t"
        :: [start] "M"((1 << WGM12) | (1 << CS10)), [tccr1b] "n"(_SFR_MEM_ADDR(TCCR1B)),
           [ocr1ah] "n"(_SFR_MEM_ADDR(OCR1AH)), [ocr1al] "n"(_SFR_MEM_ADDR(OCR1AL))
        : "r24", "r25");
    /* clang-format on */
    for (;;) sleep_cpu();
}
