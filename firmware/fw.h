// Firmware-internal helpers shared by the AVR drivers.
#pragma once

#include <avr/io.h>
#include <stdint.h>

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

// Initialisation of each driver, called once by main() with interrupts off.
void board_init();
void clock_init();
void serial_init();
void stepper_init();

} // namespace fw
} // namespace ll
