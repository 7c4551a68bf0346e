// Board pin map: Arduino Uno + CNC shield, wired as GRBL 1.1 uses it. Pins are types (modm
// style): every mask below is a compile-time constant, so the step interrupt never looks a pin
// up at run time.
#pragma once

#include <avr/io.h>
#include <stdint.h>

#include "lowlevel/config.h"

namespace ll {
namespace board {

enum class Port : uint8_t { B, C, D };

template <Port P, uint8_t Bit>
struct Pin {
    static_assert(Bit < 8, "an AVR port has 8 pins");
    static constexpr Port kPort = P;
    static constexpr uint8_t kBit = Bit;
    static constexpr uint8_t kMask = static_cast<uint8_t>(1u << Bit);
};

// Step and direction outputs (GRBL's default map for the CNC shield; A = the shield's 4th
// driver, cloned-axis jumpers set to D12/D13).
using StepX = Pin<Port::D, 2>;
using StepY = Pin<Port::D, 3>;
using StepZ = Pin<Port::D, 4>;
using StepA = Pin<Port::B, 4>; // D12
using DirX = Pin<Port::D, 5>;
using DirY = Pin<Port::D, 6>;
using DirZ = Pin<Port::D, 7>;
using DirA = Pin<Port::B, 5>; // D13 (also the Uno's LED)
/// Stepper drivers' enable input, shared by all axes: active low unless $4 = 1.
using Enable = Pin<Port::B, 0>; // D8
// Limit switch inputs with pull-ups; a switch closing to ground triggers ($5 = 0).
using LimitX = Pin<Port::B, 1>; // D9
using LimitY = Pin<Port::B, 2>; // D10
using LimitZ = Pin<Port::B, 3>; // D11

/// The CNC shield carries four drivers; more axes need another board file.
constexpr uint8_t kBoardAxes = 4;
static_assert(kAxes <= kBoardAxes, "the CNC shield map has X, Y, Z and A only");

/// One axis' pin, described by value so that constexpr loops can walk the axes.
struct PinDesc {
    Port port;
    uint8_t mask;
};
template <typename P>
constexpr PinDesc desc() {
    return PinDesc{P::kPort, P::kMask};
}

constexpr PinDesc kStepPins[kBoardAxes] = {desc<StepX>(), desc<StepY>(), desc<StepZ>(),
                                           desc<StepA>()};
constexpr PinDesc kDirPins[kBoardAxes] = {desc<DirX>(), desc<DirY>(), desc<DirZ>(), desc<DirA>()};
constexpr PinDesc kLimitPins[3] = {desc<LimitX>(), desc<LimitY>(), desc<LimitZ>()};

/// Port bits of the pins in `pins` selected by the axis bits `axes` that sit on `port`.
/// Evaluated at compile time (the interrupt uses it only through constant operands) and by the
/// main loop while the step timer is stopped.
constexpr uint8_t port_mask(const PinDesc* pins, uint8_t count, Port port, uint8_t axes) {
    uint8_t m = 0;
    for (uint8_t a = 0; a < count; ++a) {
        if (axes & (1u << a)) {
            if (pins[a].port == port) m = static_cast<uint8_t>(m | pins[a].mask);
        }
    }
    return m;
}

constexpr uint8_t kAllAxes = static_cast<uint8_t>((1u << kAxes) - 1u);

/// The port bit of axis `a`'s step (or direction) pin on `port`, 0 when it sits elsewhere.
constexpr uint8_t step_bit(uint8_t a, Port port) {
    return a < kAxes ? port_mask(kStepPins, kAxes, port, static_cast<uint8_t>(1u << a)) : 0;
}
constexpr uint8_t dir_bit(uint8_t a, Port port) {
    return a < kAxes ? port_mask(kDirPins, kAxes, port, static_cast<uint8_t>(1u << a)) : 0;
}

/// The axes (bits) whose pin in `pins` sits on `port`.
constexpr uint8_t axes_on(const PinDesc* pins, Port port) {
    uint8_t m = 0;
    for (uint8_t a = 0; a < kAxes; ++a) {
        if (pins[a].port == port) m = static_cast<uint8_t>(m | (1u << a));
    }
    return m;
}
/// The s such that the pin of every axis a on `port` is port bit a + s (the port bits are then
/// the axis bits shifted, a few instructions); -1 when there is none.
constexpr int shift_on(const PinDesc* pins, Port port) {
    int s = -1;
    for (uint8_t a = 0; a < kAxes; ++a) {
        if (pins[a].port != port) continue;
        int b = 0;
        while (b < 8 && pins[a].mask != (1u << b)) ++b;
        int d = b - a;
        if (d < 0 || (s >= 0 && s != d)) return -1;
        s = d;
    }
    return s < 0 ? 0 : s;
}

/// Port bits on P of the axes in `axes`, for the pins `pins`: a shift when the pins are in axis
/// order on consecutive bits, else one test per axis, from constant masks only (template
/// arguments: the pin tables never reach RAM or the interrupt).
template <Port P, uint8_t B0, uint8_t B1, uint8_t B2, uint8_t B3, uint8_t Axes, int Shift>
inline uint8_t port_bits(uint8_t axes) {
    if (Shift >= 0) return static_cast<uint8_t>((axes & Axes) << (Shift < 0 ? 0 : Shift));
    uint8_t m = 0;
    if (axes & 1u) m = static_cast<uint8_t>(m | B0);
    if (axes & 2u) m = static_cast<uint8_t>(m | B1);
    if (axes & 4u) m = static_cast<uint8_t>(m | B2);
    if (axes & 8u) m = static_cast<uint8_t>(m | B3);
    return m;
}

/// Port bits of the step (or direction) pins of the axes in `axes`, at run time.
template <Port P>
inline uint8_t step_port_bits(uint8_t axes) {
    return port_bits<P, step_bit(0, P), step_bit(1, P), step_bit(2, P), step_bit(3, P),
                     axes_on(kStepPins, P), shift_on(kStepPins, P)>(axes);
}
template <Port P>
inline uint8_t dir_port_bits(uint8_t axes) {
    return port_bits<P, dir_bit(0, P), dir_bit(1, P), dir_bit(2, P), dir_bit(3, P),
                     axes_on(kDirPins, P), shift_on(kDirPins, P)>(axes);
}
static_assert(kBoardAxes == 4, "step_port_bits/dir_port_bits and the interrupt cover 4 axes");

constexpr uint8_t kStepMaskD = port_mask(kStepPins, kAxes, Port::D, kAllAxes);
constexpr uint8_t kStepMaskB = port_mask(kStepPins, kAxes, Port::B, kAllAxes);
constexpr uint8_t kDirMaskD = port_mask(kDirPins, kAxes, Port::D, kAllAxes);
constexpr uint8_t kDirMaskB = port_mask(kDirPins, kAxes, Port::B, kAllAxes);
constexpr uint8_t kLimitMaskB = port_mask(kLimitPins, 3, Port::B, 0x7);

// The step interrupt toggles pins by writing PIND / PINB. It must never touch PD0/PD1 (UART: a
// toggle of PORTD0 would switch the RX pull-up) nor the enable and limit pins on port B.
static_assert((kStepMaskD & 0x03) == 0 && (kDirMaskD & 0x03) == 0, "PD0/PD1 belong to UART0");
static_assert(((kStepMaskB | kDirMaskB) & (Enable::kMask | kLimitMaskB)) == 0,
              "port B step/direction pins overlap the enable or limit pins");
static_assert((kStepMaskD & kDirMaskD) == 0 && (kStepMaskB & kDirMaskB) == 0,
              "a pin cannot be both step and direction");
static_assert(Enable::kPort == Port::B, "stepper_enable() drives PORTB");
static_assert(LimitX::kPort == Port::B && LimitY::kPort == Port::B && LimitZ::kPort == Port::B,
              "limits() reads PINB");
static_assert(LimitY::kBit == LimitX::kBit + 1 && LimitZ::kBit == LimitX::kBit + 2,
              "limits() shifts PINB: X, Y, Z limits must be adjacent and in order");

} // namespace board
} // namespace ll
