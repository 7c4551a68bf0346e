/* SIMAVR-NOTES 7: PD2/PD3 (INT0/INT1, the X/Y step pins) held low as outputs. Stock simavr then
 * polls the INT0/INT1 level condition with a cycle timer on every cycle, although the firmware
 * never enabled INT0/INT1; the harness correction keeps that polling for enabled interrupts only.
 *
 * At int0_enable the firmware enables INT0 in low-level mode: the datasheet (13.1) makes a low
 * level interrupt fire again and again while the pin stays low, also for an output pin, so the
 * INT0 handler (which toggles step_z) then runs back to back. The correction must keep that. */
#include "selftest.h"

TOGGLE_ISR(INT0_vect, PIND, STEP_Z)

int main(void) {
    DDRD = STEP_X | STEP_Y | STEP_Z | DIR_X | DIR_Y | DIR_Z; /* PD2/PD3 low outputs */
    /* About 200 000 cycles with INT0/INT1 disabled and PD2/PD3 low. */
    for (uint16_t i = 0; i < 50000; ++i) asm volatile(LABEL(idle_loop) "nop");
    EICRA = 0; /* ISC01:0 = 00, low level */
    asm volatile(LABEL(int0_enable) "nop");
    EIMSK = 1 << INT0;
    sei();
    idle_forever();
}
