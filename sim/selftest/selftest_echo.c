/* Serial-protocol self-test: a small GRBL-1.1-like responder for the harness's line helpers
 * (send-and-wait, character-counting streaming, real-time bytes), EEPROM persistence and reset.
 * Same UART set-up and buffer sizes as GRBL: 115200 8N1 with U2X0, interrupt-driven, 128-byte
 * receive ring (127 usable), real-time bytes picked out in the receive interrupt.
 *
 * At boot: EEPROM byte 0 counts boots (0xFF = never booted); prints the GRBL banner and
 * "[MSG:boot N]". Lines (answered "ok" unless said otherwise):
 *   "E<n>"  -> "error:<n>"          "PIN"  -> "[PINB:hh]" (the PINB register, hex)
 *   "BOOT"  -> "[BOOT:n]"           "STAT" -> "[RXOVF:n]" (bytes lost on a full receive ring)
 *   "SLOW"  -> works 20 ms first    other  -> works 2 ms first (a G-code line being planned)
 * Real-time: '?' -> "<Idle|MPos:0.000,0.000,0.000|FS:0,0>", 0x18 -> banner again (soft reset),
 * '!' and '~' are consumed. */
#include "selftest.h"

#include <avr/eeprom.h>
#include <util/delay.h>

#define RX_SIZE 128
#define TX_SIZE 128
#define LINE_MAX 80
#define RT_STATUS 1
#define RT_RESET 2

static volatile uint8_t rx_buf[RX_SIZE];
static volatile uint8_t rx_head, rx_tail, rx_overflows;
static volatile uint8_t tx_buf[TX_SIZE];
static volatile uint8_t tx_head, tx_tail;
static volatile uint8_t rt_flags;
static uint8_t boot_count;

ISR(USART_RX_vect) {
    const uint8_t c = UDR0;
    switch (c) {
        case '?':
            rt_flags |= RT_STATUS;
            return;
        case 0x18:
            rt_flags |= RT_RESET;
            return;
        case '!':
        case '~':
            return;
        default:
            break;
    }
    const uint8_t next = (uint8_t)((rx_head + 1) & (RX_SIZE - 1));
    if (next == rx_tail) {
        ++rx_overflows;
        return;
    }
    rx_buf[rx_head] = c;
    rx_head = next;
}

ISR(USART_UDRE_vect) {
    const uint8_t t = tx_tail;
    UDR0 = tx_buf[t];
    tx_tail = (uint8_t)((t + 1) & (TX_SIZE - 1));
    if (tx_tail == tx_head) UCSR0B &= (uint8_t) ~(1 << UDRIE0);
}

static void put(char c) {
    const uint8_t next = (uint8_t)((tx_head + 1) & (TX_SIZE - 1));
    while (next == tx_tail) {
    }
    tx_buf[tx_head] = (uint8_t)c;
    tx_head = next;
    UCSR0B |= 1 << UDRIE0;
}

static void puts_(const char* s) {
    while (*s) put(*s++);
}

static void put_dec(uint8_t v) {
    if (v >= 100) put((char)('0' + v / 100));
    if (v >= 10) put((char)('0' + v / 10 % 10));
    put((char)('0' + v % 10));
}

static void put_hex(uint8_t v) {
    static const char digits[] = "0123456789abcdef";
    put(digits[v >> 4]);
    put(digits[v & 15]);
}

static void banner(void) {
    puts_("\r\nGrbl 1.1h ['$' for help]\r\n[MSG:boot ");
    put_dec(boot_count);
    puts_("]\r\n");
}

static uint8_t starts_with(const char* line, const char* word) {
    while (*word)
        if (*line++ != *word++) return 0;
    return 1;
}

static void execute(const char* line) {
    if (line[0] == 'E' && line[1] >= '0' && line[1] <= '9') {
        puts_("error:");
        puts_(line + 1);
        puts_("\r\n");
        return;
    }
    if (starts_with(line, "PIN")) {
        puts_("[PINB:");
        put_hex(PINB);
        puts_("]\r\n");
    } else if (starts_with(line, "BOOT")) {
        puts_("[BOOT:");
        put_dec(boot_count);
        puts_("]\r\n");
    } else if (starts_with(line, "STAT")) {
        puts_("[RXOVF:");
        put_dec(rx_overflows);
        puts_("]\r\n");
    } else if (starts_with(line, "SLOW")) {
        _delay_ms(20);
    } else if (line[0]) {
        _delay_ms(2);
    }
    puts_("ok\r\n");
}

int main(void) {
    DDRD = STEP_X | STEP_Y | STEP_Z | DIR_X | DIR_Y | DIR_Z;
    DDRB = ENABLE | STEP_A | DIR_A;
    PORTB = (1 << PB1) | (1 << PB2) | (1 << PB3); /* limit inputs with pull-ups, as GRBL */
    uint8_t stored = eeprom_read_byte((uint8_t*)0);
    boot_count = (uint8_t)((stored == 0xFF ? 0 : stored) + 1);
    eeprom_write_byte((uint8_t*)0, boot_count);

    UCSR0A = 1 << U2X0;
    UBRR0H = 0;
    UBRR0L = 16;
    UCSR0B = (1 << RXEN0) | (1 << TXEN0) | (1 << RXCIE0);
    sei();
    banner();

    char line[LINE_MAX + 1];
    uint8_t len = 0;
    for (;;) {
        if (rt_flags) {
            cli();
            const uint8_t rt = rt_flags;
            rt_flags = 0;
            sei();
            if (rt & RT_STATUS) puts_("<Idle|MPos:0.000,0.000,0.000|FS:0,0>\r\n");
            if (rt & RT_RESET) {
                len = 0;
                banner();
            }
        }
        if (rx_tail == rx_head) continue;
        const char c = (char)rx_buf[rx_tail];
        rx_tail = (uint8_t)((rx_tail + 1) & (RX_SIZE - 1));
        if (c == '\n') {
            line[len] = 0;
            execute(line);
            len = 0;
        } else if (c != '\r' && len < LINE_MAX) {
            line[len++] = c;
        }
    }
}
