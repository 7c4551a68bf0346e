// The hardware boundary (DESIGN.md "Layout"): everything the portable core needs from a board.
// Implemented twice, and only twice: firmware/ (ATmega328P registers) and tools/host/ (a fake
// that records every pin edge with its CPU-cycle time). The core never includes a chip header.
#pragma once

#include <stdint.h>

namespace ll {
namespace hal {

// ---- serial: UART0, 115200 baud 8N1 ------------------------------------------------------
// The receive interrupt hands each byte to rt::filter() (realtime.h) first; real-time commands
// never reach the receive buffer. Everything else is queued in arrival order.

/// Takes the next received byte. Returns false when none is waiting.
bool serial_get(uint8_t& byte);
/// Bytes that can still be received without loss (the second field of `Bf:`).
uint8_t serial_rx_free();
/// True once the receive buffer overflowed since the last call (the call clears it). A sender
/// that respects character counting never causes this; when it happens the protocol rejects the
/// affected line instead of running a line with missing bytes.
bool serial_rx_overflowed();
/// Drops every byte waiting in the receive buffer (soft reset).
void serial_rx_clear();
/// Queues one byte for transmission; waits while the transmit buffer is full.
void serial_put(uint8_t byte);
/// Waits until every queued byte has left the UART.
void serial_flush();

// ---- step generation ----------------------------------------------------------------------

struct StepperConfig {
    uint16_t pulse_cycles; ///< step pulse width in CPU cycles ($0 x 16); never shortened
    uint8_t step_invert;   ///< $2: axis bits whose step pin idles high
    uint8_t dir_invert;    ///< $3: axis bits whose direction pin is inverted
    uint8_t enable_invert; ///< $4: 1 = enable pin active high
};

/// Applies pin polarities and pulse width. Only called while the step timer is stopped.
void stepper_configure(const StepperConfig& cfg);
/// Starts the step timer on g_runs' first run: sets the direction pins for that run, loads its
/// period and starts counting. Precondition: timer stopped, queue not empty.
void stepper_start();
/// Stops the step timer at once, ends any pulse in progress, clears g_exec (soft reset, alarm).
void stepper_stop();
/// Stepper driver enable pin ($4 polarity).
void stepper_enable(bool on);

// ---- time ---------------------------------------------------------------------------------

/// Milliseconds since power-up (wraps after 49 days). For $1 idle delay and G4 dwell only.
uint32_t millis();

// ---- non-volatile storage -----------------------------------------------------------------

uint8_t eeprom_read(uint16_t addr);
/// Writes one byte (skips the write when the byte already holds `value`). Returns `value`.
uint8_t eeprom_write(uint16_t addr, uint8_t value);
constexpr uint16_t kEepromSize = 1024;

// ---- inputs -------------------------------------------------------------------------------

/// Limit switch inputs as axis bits (1 = triggered, after $5 inversion).
uint8_t limits();

// ---- critical sections ---------------------------------------------------------------------

/// Saves the interrupt state and disables interrupts; restore with irq_restore().
/// On the AVR both are inline (`in r, SREG; cli` ... `out SREG, r`): an out-of-line pair kept
/// interrupts off for the `ret` of irq_save(), the `call` and the body of irq_restore() as
/// well, up to 21 cycles in motion::position() (docs/verification.md), longer than
/// step_timing::kPulseGuard. Inline, a section costs its body + 2 cycles. Plain inline asm, so
/// the core still needs no chip header. The host fake (tools/host) defines them out of line.
#if defined(__AVR__)
inline uint8_t irq_save() {
    uint8_t s;
    asm volatile("in %0, __SREG__\n\tcli" : "=r"(s)::"memory");
    return s;
}
inline void irq_restore(uint8_t state) {
    asm volatile("out __SREG__, %0" ::"r"(state) : "memory");
}
#else
uint8_t irq_save();
void irq_restore(uint8_t state);
#endif

/// RAII critical section for short sections only (a few dozen cycles: every cycle spent here
/// delays the step interrupt).
struct Critical {
    uint8_t state;
    Critical() : state(irq_save()) {}
    ~Critical() { irq_restore(state); }
    Critical(const Critical&) = delete;
    Critical& operator=(const Critical&) = delete;
};

} // namespace hal
} // namespace ll
