// Firmware-internal helpers shared by the AVR drivers.
#pragma once

#include <avr/io.h>
#include <stdint.h>

#include "board.h"

namespace ll {
namespace fw {

/// Interrupts off for the life of the object, restored (not forced on) at the end. Inline, so
/// the window is the body plus 2 cycles; hal::Critical costs two calls more. Bodies must stay
/// a few cycles long: every cycle here can delay a step edge (step_timing::kPulseGuard).
class IrqGuard {
  public:
    IrqGuard() : sreg_(SREG) { asm volatile("cli" ::: "memory"); }
    ~IrqGuard() {
        asm volatile("" ::: "memory");
        SREG = sreg_;
    }
    IrqGuard(const IrqGuard&) = delete;
    IrqGuard& operator=(const IrqGuard&) = delete;

  private:
    uint8_t sreg_;
};

// Initialisation of each driver, called once by main() with interrupts off. Inline (main() is
// their only caller): no call and return each.

inline void board_init() {
    // Step and direction outputs start low; stepper_configure() applies $2. Enable starts at
    // "disabled" for $4 = 0 (high) until stepper_configure() and motion set it properly; limit
    // inputs get their pull-ups. Plain writes: the ports hold their reset value 0 (main.cpp).
    DDRD = static_cast<uint8_t>(board::kStepMaskD | board::kDirMaskD);
    PORTB = static_cast<uint8_t>(board::Enable::kMask | board::kLimitMaskB);
    DDRB = static_cast<uint8_t>(board::kStepMaskB | board::kDirMaskB | board::Enable::kMask);
}

inline void clock_init() {
    // TCNT0 and the flags keep their reset value 0 (main.cpp).
    TCCR0A = _BV(WGM01); // CTC
    OCR0A = 249;         // 250 ticks of 4 µs
    TIMSK0 = _BV(OCIE0A);
    TCCR0B = _BV(CS01) | _BV(CS00); // clk/64
}

// UART0 (serial.cpp).
constexpr uint8_t kUbrr = 16; // 16 MHz / (8 * (16 + 1)) = 117647 baud, +2.1 % (as GRBL)
constexpr uint8_t kUcsr0bRun = _BV(RXCIE0) | _BV(TXCIE0) | _BV(RXEN0) | _BV(TXEN0);

inline void serial_init() {
    // UBRR0H (0) and UCSR0C (8N1) keep their reset values (main.cpp).
    UBRR0L = kUbrr;
    UCSR0A = _BV(U2X0);
    UCSR0B = kUcsr0bRun;
}

inline void stepper_init() {
    // TCCR1A, TCCR1B (no clock: stopped) and GPIOR0 keep their reset value 0 (main.cpp).
    TIMSK1 = _BV(OCIE1A) | _BV(OCIE1B); // the timer only runs while there are runs
    // The pulse width, the guard period and the pin polarities come from stepper_configure(),
    // which app::init() calls (motion::settings_changed()) before any run can start (llbench
    // sends the bench app a `C` first). stepper_enable(false) here would repeat board_init()'s
    // level (s_enable_invert is still 0).
}

} // namespace fw
} // namespace ll
