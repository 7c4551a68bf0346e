/* SIMAVR-NOTES 1 and the interrupt timing: Timer1 in CTC mode at prescaler 1.
 *
 * Phase A, OCR1A = 0: the compare flag rises on every timer tick (datasheet 15.9.2), so
 * TIMER1_COMPA runs back to back: response 4 + ISR 13 (jmp 3, push 2, ldi 1, out 1, pop 2,
 * reti 4) + the one main instruction the CPU runs after RETI (a nop, 1) = one step_x toggle
 * every 18 cycles. The first toggle comes at timer_start + 12: the flag rises 1 cycle after the
 * start, the STS ends at +2, then response 4 and 6 cycles of vector + ISR before the OUT.
 * Main keeps running one instruction per ISR and then writes OCR1A = 299 (label ocr_write).
 * 20 nops + 2 ldi + sts H come before it, so phase A has 20 + 3 + 2 = 25 toggles.
 *
 * Phase B, OCR1A = 299: one compare every 300 cycles, the first 300 cycles after the counter was
 * last cleared (at ocr_write); step_x toggles 4 + 6 cycles after each flag (the main code is a
 * sled of 1-cycle nops, so the flag never waits for a longer instruction). */
#include "selftest.h"

#define PHASE_A_NOPS 20
#define PHASE_B_OCR 299

TOGGLE_ISR(TIMER1_COMPA_vect, PIND, STEP_X)

int main(void) {
    DDRD = STEP_X | STEP_Y | STEP_Z | DIR_X | DIR_Y | DIR_Z;
    OCR1A = 0;
    TCCR1A = 0;
    TIMSK1 = 1 << OCIE1A;
    sei();
    /* clang-format off */
    asm volatile(
        "ldi r24, %[start]\n\t"
        LABEL(timer_start)
        "sts %[tccr1b], r24\n\t"      /* Timer1 on: CTC, prescaler 1, OCR1A = 0 */
        SLED(PHASE_A_NOPS)
        "ldi r24, lo8(%[ocr])\n\t"
        "ldi r25, hi8(%[ocr])\n\t"
        "sts %[ocr1ah], r25\n\t"      /* 16-bit write: high byte first (TEMP) */
        LABEL(ocr_write)
        "sts %[ocr1al], r24\n\t"
        SLED(2000)
        :: [start] "M"((1 << WGM12) | (1 << CS10)),
           [tccr1b] "n"(_SFR_MEM_ADDR(TCCR1B)), [ocr1ah] "n"(_SFR_MEM_ADDR(OCR1AH)),
           [ocr1al] "n"(_SFR_MEM_ADDR(OCR1AL)), [ocr] "n"(PHASE_B_OCR)
        : "r24", "r25");
    /* clang-format on */
    idle_forever();
}
