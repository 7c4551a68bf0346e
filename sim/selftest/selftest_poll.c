/* SIMAVR-NOTES 5: a firmware polling UCSR0A. With AVR_UART_FLAG_POLL_SLEEP set, simavr calls
 * usleep(1) on the host for every read of UCSR0A while nothing is received and TXC0 is clear;
 * this firmware does exactly POLLS such reads (TXC0 is never set: nothing is transmitted). The
 * simulated cycles are the same either way; only wall time differs. */
#include "selftest.h"

#define POLLS 5000

int main(void) {
    DDRD = STEP_X | STEP_Y | STEP_Z | DIR_X | DIR_Y | DIR_Z;
    UCSR0A = 1 << U2X0;
    UBRR0H = 0;
    UBRR0L = 16;
    UCSR0B = 1 << RXEN0;
    for (uint16_t i = 0; i < POLLS; ++i) {
        if (UCSR0A & (1 << RXC0)) (void)UDR0;
    }
    asm volatile(LABEL(poll_done) "nop");
    PIND = STEP_X;
    idle_forever();
}
