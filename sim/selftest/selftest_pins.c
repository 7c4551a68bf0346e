/* Recorder self-test: toggles every pin of the CNC-shield map, then PC0, at cycles fixed by the
 * instruction counts below. Offsets from the first instruction of pin_sequence (cycle E):
 *   step_x +9, step_y +11, step_z +14, dir_x +18, dir_y +23, dir_z +29, enable +36,
 *   step_a +44, dir_a +53 (all rise); PD2..PD7 fall together at +56, PB0/PB4/PB5 at +57;
 *   PC0 rises at +59. */
#include "selftest.h"

void pin_sequence(void) __attribute__((naked, noinline, used));
void pin_sequence(void) {
    /* clang-format off */
    asm volatile(
        "ldi r18, %[x]\n\t"      /* E+0 */
        "ldi r19, %[y]\n\t"
        "ldi r20, %[z]\n\t"
        "ldi r21, %[dx]\n\t"
        "ldi r22, %[dy]\n\t"
        "ldi r23, %[dz]\n\t"
        "ldi r24, %[en]\n\t"
        "ldi r25, %[a]\n\t"
        "ldi r26, %[da]\n\t"     /* E+8 */
        "out %[pind], r18\n\t"   /* E+9   step_x */
        SLED(1)
        "out %[pind], r19\n\t"   /* E+11  step_y */
        SLED(2)
        "out %[pind], r20\n\t"   /* E+14  step_z */
        SLED(3)
        "out %[pind], r21\n\t"   /* E+18  dir_x */
        SLED(4)
        "out %[pind], r22\n\t"   /* E+23  dir_y */
        SLED(5)
        "out %[pind], r23\n\t"   /* E+29  dir_z */
        SLED(6)
        "out %[pinb], r24\n\t"   /* E+36  enable */
        SLED(7)
        "out %[pinb], r25\n\t"   /* E+44  step_a */
        SLED(8)
        "out %[pinb], r26\n\t"   /* E+53  dir_a */
        "ldi r18, %[alld]\n\t"   /* E+54 */
        "ldi r19, %[allb]\n\t"   /* E+55 */
        "out %[pind], r18\n\t"   /* E+56  PD2..PD7 fall */
        "out %[pinb], r19\n\t"   /* E+57  PB0, PB4, PB5 fall */
        "ldi r27, 1\n\t"         /* E+58 */
        "out %[pinc], r27\n\t"   /* E+59  PC0 rises */
        "ret"
        :: [pind] "I"(_SFR_IO_ADDR(PIND)), [pinb] "I"(_SFR_IO_ADDR(PINB)),
           [pinc] "I"(_SFR_IO_ADDR(PINC)),
           [x] "M"(STEP_X), [y] "M"(STEP_Y), [z] "M"(STEP_Z),
           [dx] "M"(DIR_X), [dy] "M"(DIR_Y), [dz] "M"(DIR_Z),
           [en] "M"(ENABLE), [a] "M"(STEP_A), [da] "M"(DIR_A),
           [alld] "M"(STEP_X | STEP_Y | STEP_Z | DIR_X | DIR_Y | DIR_Z),
           [allb] "M"(ENABLE | STEP_A | DIR_A));
    /* clang-format on */
}

int main(void) {
    DDRD = STEP_X | STEP_Y | STEP_Z | DIR_X | DIR_Y | DIR_Z;
    DDRB = ENABLE | STEP_A | DIR_A;
    DDRC = 1 << PC0;
    pin_sequence();
    idle_forever();
}
