/* SIMAVR-NOTES 3: UART0 frame time, set up as GRBL does (U2X0 = 1, UBRR0 = 16, 8N1): one bit is
 * (16 + 1) x 8 = 136 cycles and a frame is start + 8 data + stop = 10 bits = 1360 cycles
 * (datasheet 20.3.1 and 20.4). simavr 1.6 counts a parity bit as well: 11 bits = 1496 cycles.
 *
 * Transmit: the UDRE interrupt sends "0123456789" back to back; in steady state one byte leaves
 * every frame. Receive: each byte received toggles step_y in the RX interrupt; bytes sent back to
 * back by the host arrive one frame apart.
 *
 * Between interrupts the CPU sleeps in idle mode: an interrupt then always finds the CPU in the
 * same state (no instruction to finish), so the cycles between two ISRs are exactly the cycles
 * between their flags. A busy loop (RJMP, 2 cycles) would add a cycle of jitter. */
#include "selftest.h"

#include <avr/sleep.h>

static const char message[] = "0123456789";
static volatile uint8_t next_index;

ISR(USART_UDRE_vect) {
    const uint8_t i = next_index;
    if (i < sizeof message - 1) {
        UDR0 = (uint8_t)message[i];
        next_index = (uint8_t)(i + 1);
    } else {
        UCSR0B &= (uint8_t) ~(1 << UDRIE0);
    }
}

ISR(USART_RX_vect) {
    (void)UDR0;
    PIND = STEP_Y;
}

int main(void) {
    DDRD = STEP_X | STEP_Y | STEP_Z | DIR_X | DIR_Y | DIR_Z;
    UCSR0A = 1 << U2X0;
    UBRR0H = 0;
    UBRR0L = 16;
    UCSR0B = (1 << RXEN0) | (1 << TXEN0) | (1 << RXCIE0) | (1 << UDRIE0);
    set_sleep_mode(SLEEP_MODE_IDLE);
    sleep_enable();
    sei();
    for (;;) sleep_cpu();
}
