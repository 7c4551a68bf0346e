// UART0: 115200 baud 8N1 (U2X0 = 1, UBRR0 = 16, as GRBL), interrupt-driven in both directions.
//
// Neither handler may delay the step interrupt by more than a few cycles, so both re-enable
// interrupts as soon as their source is cleared:
//   - receive: a naked stub disables the receive interrupt (one constant store: nothing else
//     ever changes UCSR0B) and re-enables interrupts, 6 cycles after the vector; the rest runs
//     interruptible in rx_drain(), which takes the oldest byte of the 2-byte hardware FIFO and
//     then re-enables the receive interrupt (which comes again at once for a second byte). Order
//     can never be swapped by a nested receive.
//   - transmit: the "transmit complete" interrupt (its flag clears itself when the vector
//     runs), so the handler starts with sei (its first instruction). It refills UDR0 with up to two
//     bytes (shift register + buffer). The "data register empty" interrupt would need UDRIE
//     toggled, i.e. a read-modify-write of UCSR0B shared with the receive stub.
#include <avr/interrupt.h>
#include <avr/io.h>

#include "fw.h"
#include "lowlevel/hal.h"
#include "lowlevel/realtime.h"

namespace ll {
namespace {

using fw::kUcsr0bRun;
constexpr uint8_t kUcsr0bRxMasked = _BV(TXCIE0) | _BV(RXEN0) | _BV(TXEN0);

// Receive ring: 128 bytes, all usable (senders' character counting sends 128 bytes
// unacknowledged). Indices run freely over 0..255; the slot is index & 127.
constexpr uint16_t kRxSize = 128;
// Transmit ring: 64 bytes. A status report (~90 bytes) waits for about 26 bytes to leave
// (2.3 ms); longer waits only happen while printing $$ or $# when idle.
constexpr uint16_t kTxSize = 64;
static_assert(kRxSize <= 128 && (kRxSize & (kRxSize - 1)) == 0, "free-running 8-bit indices");
static_assert(kTxSize <= 128 && (kTxSize & (kTxSize - 1)) == 0, "free-running 8-bit indices");

uint8_t s_rx_buf[kRxSize];
volatile uint8_t s_rx_head;     // consumer: main loop
volatile uint8_t s_rx_tail;     // producer: receive handler
volatile uint8_t s_rx_overflow; // a byte was lost (buffer full or hardware overrun)

uint8_t s_tx_buf[kTxSize];
volatile uint8_t s_tx_head;   // consumer: transmit handler (or serial_put when idle)
volatile uint8_t s_tx_tail;   // producer: main loop
volatile uint8_t s_tx_active; // a "transmit complete" interrupt is still to come

} // namespace
} // namespace ll

// Interruptible tail of the receive interrupt: rt::filter() (realtime.h), then the ring. In
// assembly: C's version saved r0, r1 and three more registers, and SREG through r0 (32 B and
// about 25 cycles a byte more); the hardware's DOR0 (a byte lost before this one) waits in T. Named
// __vector_* to keep its place in cmake/text_order.ld.
extern "C" void __vector_rx_drain() __attribute__((naked, used, externally_visible));
// Its full test is bit 7 of tail - head (128 queued): the ring must hold exactly 128 bytes.
static_assert(ll::kRxSize == 128, "__vector_rx_drain tests a full ring as tail - head >= 128");
void __vector_rx_drain() {
    asm volatile(
        "push r24\n\t"
        "in   r24, __SREG__\n\t"
        "push r24\n\t"
        "push r25\n\t"
        "push r30\n\t"
        "push r31\n\t"
        "lds  r24, %[ucsr0a]\n\t"
        "bst  r24, %[dor0]\n\t"
        "lds  r24, %[udr0]\n\t"
        // The four real-time commands (a bit of rt::g_pending each) and GRBL's extended bytes
        // (0x84-0x87, 0x90-0x9D, 0xA0-0xA1), consumed; split at '?' so that a digit takes 8
        // cycles of tests and a capital 9.
        "cpi  r24, '?'\n\t"
        "breq 7f\n\t"
        "brsh 2f\n\t"
        "cpi  r24, '!'\n\t"
        "breq 8f\n\t"
        "cpi  r24, 0x18\n\t"
        "brne 1f\n\t"
        "ldi  r25, %[reset]\n\t"
        "rjmp 5f\n"
        "2:\n\t"
        "cpi  r24, '~'\n\t"
        "breq 9f\n\t"
        "cpi  r24, 0x84\n\t"
        "brlo 1f\n\t"
        "cpi  r24, 0x88\n\t"
        "brlo 3f\n\t"
        "mov  r25, r24\n\t"
        "subi r25, 0x90\n\t"
        "cpi  r25, 0x0E\n\t"
        "brlo 3f\n\t"
        "subi r25, 0x10\n\t"
        "cpi  r25, 2\n\t"
        "brlo 3f\n"
        "1:\n\t" // into the ring, unless 128 bytes are queued (then it is lost)
        "lds  r25, %[tail]\n\t"
        "lds  r30, %[head]\n\t"
        "mov  r31, r25\n\t"
        "sub  r31, r30\n\t"
        "sbrc r31, 7\n\t"
        "rjmp 4f\n\t"
        "mov  r30, r25\n\t"
        "andi r30, %[mask]\n\t"
        "ldi  r31, 0\n\t"
        "subi r30, lo8(-(%[buf]))\n\t"
        "sbci r31, hi8(-(%[buf]))\n\t"
        "st   Z, r24\n\t"
        "inc  r25\n\t"
        "sts  %[tail], r25\n"
        "3:\n\t"
        "brtc 6f\n"
        "4:\n\t"
        "ldi  r24, 1\n\t"
        "sts  %[overflow], r24\n"
        "6:\n\t"
        // A second byte in the FIFO (or one that arrived meanwhile) raises the
        // interrupt again at once: one byte per entry.
        "ldi  r24, %[run]\n\t"
        "sts  %[ucsr0b], r24\n\t"
        "pop  r31\n\t"
        "pop  r30\n\t"
        "pop  r25\n\t"
        "pop  r24\n\t"
        "out  __SREG__, r24\n\t"
        "pop  r24\n\t"
        "reti\n"
        "7:\n\t"
        "ldi  r25, %[status]\n\t"
        "rjmp 5f\n"
        "8:\n\t"
        "ldi  r25, %[hold]\n\t"
        "rjmp 5f\n"
        "9:\n\t"
        "ldi  r25, %[start]\n"
        "5:\n\t"
        "lds  r24, _ZN2ll2rt9g_pendingE\n\t" // rt::g_pending
        "or   r24, r25\n\t"
        "sts  _ZN2ll2rt9g_pendingE, r24\n\t"
        "rjmp 3b\n\t"
        :
        : [ucsr0a] "n"(_SFR_MEM_ADDR(UCSR0A)), [udr0] "n"(_SFR_MEM_ADDR(UDR0)),
          [ucsr0b] "n"(_SFR_MEM_ADDR(UCSR0B)), [dor0] "I"(DOR0),
          [status] "M"(ll::rt::kStatusReport), [hold] "M"(ll::rt::kFeedHold),
          [start] "M"(ll::rt::kCycleStart), [reset] "M"(ll::rt::kReset), [tail] "i"(&ll::s_rx_tail),
          [head] "i"(&ll::s_rx_head), [buf] "i"(&ll::s_rx_buf[0]), [mask] "M"(ll::kRxSize - 1),
          [overflow] "i"(&ll::s_rx_overflow), [run] "n"(ll::kUcsr0bRun));
}

// r24 is kept in OCR0B, not on the stack: out/in take 1 cycle each where push/pop take 2, so
// interrupts stay off 13 cycles from acceptance instead of 15 (4 response, 3 jmp, out, ldi,
// sts, sei, in: the instruction after sei runs before any interrupt). Timer0 counts
// milliseconds in CTC mode up to OCR0A (clock.cpp), so OCR0B only sets a flag nobody enables
// (OCIE0B and COM0B stay 0): free scratch; any other user must also hold it with interrupts
// off only, as here.
ISR(USART_RX_vect, ISR_NAKED) {
    asm volatile("out  %[scratch], r24\n\t"
                 "ldi  r24, %[masked]\n\t"
                 "sts  %[ucsr0b], r24\n\t"
                 "sei\n\t"
                 "in   r24, %[scratch]\n\t"
                 "rjmp __vector_rx_drain\n\t"
                 :
                 : [masked] "M"(ll::kUcsr0bRxMasked), [ucsr0b] "n"(_SFR_MEM_ADDR(UCSR0B)),
                   [scratch] "I"(_SFR_IO_ADDR(OCR0B)));
}

// The shift register is empty: the first byte goes straight into it, the second waits in UDR0,
// so the line stays busy for two frames per interrupt. In assembly: C's version saved r0, r1
// and SREG through r0, for 10 B more.
ISR(USART_TX_vect, ISR_NAKED) {
    asm volatile(
        "sei\n\t"
        "nop\n\t" // the instruction after sei runs before any interrupt: 1 cycle, not push's 2
        "push r24\n\t"
        "in   r24, __SREG__\n\t"
        "push r24\n\t"
        "push r25\n\t"
        "push r30\n\t"
        "push r31\n\t"
        "lds  r24, %[head]\n\t"
        "lds  r25, %[tail]\n\t"
        "cp   r24, r25\n\t"
        "brne 2f\n\t"
        "clr  r30\n\t"
        "sts  %[active], r30\n\t" // nothing left: no completion to come
        "rjmp 4f\n\t"
        "1:\n\t"
        "lds  r30, %[ucsr0a]\n\t"
        "sbrs r30, %[udre0]\n\t"
        "rjmp 3f\n\t"
        "2:\n\t"
        "mov  r30, r24\n\t"
        "andi r30, %[mask]\n\t"
        "ldi  r31, 0\n\t"
        "subi r30, lo8(-(%[buf]))\n\t"
        "sbci r31, hi8(-(%[buf]))\n\t"
        "ld   r30, Z\n\t"
        "sts  %[udr0], r30\n\t"
        "inc  r24\n\t"
        "cpse r24, r25\n\t"
        "rjmp 1b\n\t"
        "3:\n\t"
        "sts  %[head], r24\n\t"
        "4:\n\t"
        "pop  r31\n\t"
        "pop  r30\n\t"
        "pop  r25\n\t"
        "pop  r24\n\t"
        "out  __SREG__, r24\n\t"
        "pop  r24\n\t"
        "reti\n\t"
        :
        : [head] "i"(&ll::s_tx_head), [tail] "i"(&ll::s_tx_tail), [active] "i"(&ll::s_tx_active),
          [buf] "i"(&ll::s_tx_buf[0]), [mask] "M"(ll::kTxSize - 1),
          [ucsr0a] "n"(_SFR_MEM_ADDR(UCSR0A)), [udr0] "n"(_SFR_MEM_ADDR(UDR0)), [udre0] "I"(UDRE0));
}

namespace ll {
namespace hal {

bool serial_get(uint8_t& byte) {
    uint8_t h = s_rx_head;
    if (h == s_rx_tail) return false;
    byte = s_rx_buf[h & (kRxSize - 1)];
    s_rx_head = static_cast<uint8_t>(h + 1);
    return true;
}

uint8_t serial_rx_free() {
    return static_cast<uint8_t>(kRxSize - static_cast<uint8_t>(s_rx_tail - s_rx_head));
}

bool serial_rx_overflowed() {
    // Called at every main-loop iteration: a byte read is atomic, so only a set flag needs the
    // critical section (6 cycles with interrupts off, which delayed step edges by as much).
    if (s_rx_overflow == 0) return false;
    fw::IrqGuard g;
    uint8_t o = s_rx_overflow;
    s_rx_overflow = 0;
    return o != 0;
}

void serial_rx_clear() {
    s_rx_head = s_rx_tail;
}

void serial_put(uint8_t byte) {
    uint8_t t = s_tx_tail;
    while (static_cast<uint8_t>(t - s_tx_head) >= kTxSize) {
        // Full, so a transmission is under way: the interrupt frees a slot within two frames.
    }
    s_tx_buf[t & (kTxSize - 1)] = byte;
    t = static_cast<uint8_t>(t + 1);
    s_tx_tail = t;
    // No critical section (it kept interrupts off 7 cycles per byte): the tail is published
    // before s_tx_active is read, and the handler clears s_tx_active only when it finds the
    // ring empty. So if the handler runs after the tail store, it sends this byte and leaves
    // s_tx_active set; if it cleared s_tx_active before, we read 0 here, and then no
    // completion is pending and the handler cannot run again before our own UDR0 write below:
    // the read and the store cannot be separated by it.
    if (!s_tx_active) {
        s_tx_active = 1;
        // The transmitter was idle, so the interrupt cannot run before this byte has left:
        // take it from the ring here. The ring was empty (the interrupt found it so before it
        // cleared s_tx_active), so it is this byte.
        UDR0 = byte;
        s_tx_head = t;
    }
}

void serial_flush() {
    while (s_tx_active) {
    }
}

} // namespace hal
} // namespace ll
