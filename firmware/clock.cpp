// Millisecond clock: Timer0 in CTC mode, prescaler 64, OCR0A = 249 -> one interrupt per ms.
// The compare flag clears itself when the vector runs, so the handler re-enables interrupts
// first: it can delay a step edge by its 4-cycle entry, the jmp, the sei and one nop only.
// Timer0, not Timer2: its vector (14) ranks below the step interrupts' (11, 12), so when the
// tick and a step compare match are pending together the step goes first. With Timer2
// (vector 7) the tick went first and the step edge waited for the rest of the instruction under
// way plus the tick's 9 cycles (measured: 11). OCR0B stays free (serial.cpp's receive stub uses
// it as scratch: compare B only sets a flag, OCIE0B and COM0B are off).
#include <avr/interrupt.h>
#include <avr/io.h>

#include "fw.h"
#include "lowlevel/hal.h"

namespace ll {
namespace {
volatile uint32_t s_millis; // ms since clock_init(), wraps after 49.7 days
} // namespace
} // namespace ll

// s_millis + 1, a byte at a time through Z, stopping at the first byte that does not wrap (C's
// version saves r0, r1 and four registers for a 32-bit add; the unrolled form took 22 B more).
ISR(TIMER0_COMPA_vect, ISR_NAKED) {
    asm volatile("sei\n\t"
                 "nop\n\t" // runs before any interrupt (as any instruction after sei): 1 cycle
                 "push r24\n\t"
                 "in   r24, __SREG__\n\t"
                 "push r24\n\t"
                 "push r30\n\t"
                 "push r31\n\t"
                 "ldi  r30, lo8(%[ms])\n\t"
                 "ldi  r31, hi8(%[ms])\n\t"
                 "1:\n\t"
                 "ld   r24, Z\n\t"
                 "inc  r24\n\t"
                 "st   Z+, r24\n\t"
                 "brne 2f\n\t"
                 "cpi  r30, lo8(%[ms]+4)\n\t" // the 4th byte wrapped too (after 49.7 days)
                 "brne 1b\n\t"
                 "2:\n\t"
                 "pop  r31\n\t"
                 "pop  r30\n\t"
                 "pop  r24\n\t"
                 "out  __SREG__, r24\n\t"
                 "pop  r24\n\t"
                 "reti\n\t"
                 :
                 : [ms] "i"(&ll::s_millis));
}

namespace ll {
namespace hal {

uint32_t millis() {
    // Without a critical section (it kept interrupts off 10 cycles): the four bytes low to high,
    // then the low byte again. Every tick changes the low byte, so if it is unchanged no tick
    // came between the loads (256 ticks, 256 ms, in between cannot happen), and the bytes
    // belong together; otherwise read again. In assembly: C's loop was 34 B, this one 2 B more
    // than the cli version.
    uint32_t t;
    uint8_t again;
    asm volatile("1:\n\t"
                 "lds  %A0, %[ms]\n\t"
                 "lds  %B0, %[ms]+1\n\t"
                 "lds  %C0, %[ms]+2\n\t"
                 "lds  %D0, %[ms]+3\n\t"
                 "lds  %[again], %[ms]\n\t"
                 "cpse %[again], %A0\n\t"
                 "rjmp 1b\n\t"
                 : "=&r"(t), [again] "=&r"(again)
                 : [ms] "i"(&s_millis)
                 : "memory");
    return t;
}

} // namespace hal
} // namespace ll
