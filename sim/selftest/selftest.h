/* Helpers shared by the self-test firmwares of the simavr harness.
 *
 * Timing-critical parts are inline assembly, so their cycle counts come from the AVR Instruction
 * Set Manual and not from the compiler: nop/ldi/out = 1 cycle, push/pop/sts/lds = 2, jmp = 3,
 * reti = 4, and the interrupt response = 4 (ATmega328P datasheet 6.7.1). Global labels in the
 * assembly become ELF symbols, which the host tests use to find the cycle of an instruction. */
#ifndef LL_SIM_SELFTEST_H
#define LL_SIM_SELFTEST_H

#include <avr/interrupt.h>
#include <avr/io.h>

#define LL_STR2(x) #x
#define LL_STR(x) LL_STR2(x)

/* n one-cycle nops: a delay with no branch, so an interrupt is always taken 1 cycle after its
 * flag rises (a 2-cycle branch would add a cycle of jitter). */
#define SLED(n) ".rept " LL_STR(n) "\n\tnop\n\t.endr\n\t"

/* A global label: the test reads its address with Sim::symbol() and runs to it. */
#define LABEL(name) ".global " #name "\n" #name ":\n\t"

/* An interrupt handler of known length that toggles pins through a PINx write (OUT, so the
 * simavr SBI/CBI deviation plays no part): jmp 3 (vector) + push 2 + ldi 1, the OUT starts 6
 * cycles after the vector is entered; pop 2 + reti 4 follow. SREG is not touched. */
/* clang-format off */
#define TOGGLE_ISR(vect, pinreg, mask)                                  \
    ISR(vect, ISR_NAKED) {                                              \
        asm volatile("push r24\n\t"                                     \
                     "ldi r24, %1\n\t"                                  \
                     "out %0, r24\n\t"                                  \
                     "pop r24\n\t"                                      \
                     "reti"                                             \
                     :: "I"(_SFR_IO_ADDR(pinreg)), "M"(mask));          \
    }
/* clang-format on */

/* Pin masks of the Arduino CNC shield map (sim/recorder.cpp). */
#define STEP_X (1 << PD2)
#define STEP_Y (1 << PD3)
#define STEP_Z (1 << PD4)
#define DIR_X (1 << PD5)
#define DIR_Y (1 << PD6)
#define DIR_Z (1 << PD7)
#define ENABLE (1 << PB0)
#define STEP_A (1 << PB4)
#define DIR_A (1 << PB5)

/* The end of a self-test: the CPU keeps running (a SLEEP with interrupts off would stop simavr). */
static inline void idle_forever(void) {
    for (;;) {
    }
}

#endif
