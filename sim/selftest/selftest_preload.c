/* SIMAVR-NOTES 2: a timer counter keeps its value (datasheet 15.11 / 14.9: TCNTn is the counter
 * itself; the clock select only gates its clock).
 *
 * Timer1, CTC, TOP = OCR1A = 199, prescaler 1 (step_x toggles in TIMER1_COMPA, 10 cycles after
 * each flag: response 4 + jmp 3 + push 2 + ldi 1):
 *   t1_start:   TCNT1 was preloaded with 120 while stopped: first flag after 80 cycles, then 200.
 *   t1_stop:    clock stopped; the count read back into GPIOR1 (low) / GPIOR2 (high) must be the
 *               value at the stop, not 0.
 *   t1_restart: counting goes on from that value.
 *   t1_off:     stopped for good.
 * Timer0, normal mode, prescaler 8 (step_y toggles in TIMER0_OVF, 10 cycles after each flag):
 *   t0_start:   TCNT0 preloaded with 236 (GRBL's pulse-timer idiom): overflow after 20 ticks =
 *               160 cycles, then every 256 ticks.
 *   t0_write:   TCNT0 = 200 written while running: overflow 56 ticks = 448 cycles later.
 * Code between labels is sleds of 1-cycle nops, so interrupt latency never varies. */
#include "selftest.h"

TOGGLE_ISR(TIMER1_COMPA_vect, PIND, STEP_X)
TOGGLE_ISR(TIMER0_OVF_vect, PIND, STEP_Y)

int main(void) {
    DDRD = STEP_X | STEP_Y | STEP_Z | DIR_X | DIR_Y | DIR_Z;
    OCR1A = 199;
    TCCR1A = 0;
    TCNT1 = 120;
    TIMSK1 = 1 << OCIE1A;
    TCCR0A = 0;
    TCNT0 = 236;
    TIMSK0 = 1 << TOIE0;
    sei();
    /* clang-format off */
    asm volatile(
        "ldi r24, %[t1on]\n\t"
        "ldi r25, %[t1off]\n\t"
        LABEL(t1_start)
        "sts %[tccr1b], r24\n\t"      /* Timer1 on with TCNT1 = 120 preloaded */
        SLED(650)
        LABEL(t1_stop)
        "sts %[tccr1b], r25\n\t"      /* clock off: the count must stay */
        "lds r26, %[tcnt1l]\n\t"
        "lds r27, %[tcnt1h]\n\t"
        "out %[gpior1], r26\n\t"
        "out %[gpior2], r27\n\t"
        SLED(100)
        LABEL(t1_restart)
        "sts %[tccr1b], r24\n\t"      /* clock on again: counting goes on */
        SLED(500)
        LABEL(t1_off)
        "sts %[tccr1b], r25\n\t"
        "ldi r24, %[t0on]\n\t"
        LABEL(t0_start)
        "out %[tccr0b], r24\n\t"      /* Timer0 on, prescaler 8, TCNT0 = 236 preloaded */
        SLED(400)
        "ldi r24, 200\n\t"
        LABEL(t0_write)
        "out %[tcnt0], r24\n\t"       /* TCNT0 = 200 while running */
        SLED(600)
        "out %[tccr0b], r1\n\t"
        :: [t1on] "M"((1 << WGM12) | (1 << CS10)), [t1off] "M"(1 << WGM12),
           [t0on] "M"(1 << CS01), [tccr1b] "n"(_SFR_MEM_ADDR(TCCR1B)),
           [tcnt1l] "n"(_SFR_MEM_ADDR(TCNT1L)), [tcnt1h] "n"(_SFR_MEM_ADDR(TCNT1H)),
           [gpior1] "I"(_SFR_IO_ADDR(GPIOR1)), [gpior2] "I"(_SFR_IO_ADDR(GPIOR2)),
           [tccr0b] "I"(_SFR_IO_ADDR(TCCR0B)), [tcnt0] "I"(_SFR_IO_ADDR(TCNT0))
        : "r24", "r25", "r26", "r27");
    /* clang-format on */
    idle_forever();
}
