// GRBL 1.1 real-time commands, picked out of the byte stream by the receive interrupt.
#pragma once

#include <stdint.h>

namespace ll {
namespace rt {

/// Pending real-time requests, as bits. Set by the receive interrupt, taken by the main loop.
enum : uint8_t {
    kStatusReport = 1 << 0, ///< '?'
    kFeedHold = 1 << 1,     ///< '!'
    kCycleStart = 1 << 2,   ///< '~'
    kReset = 1 << 3,        ///< 0x18 (ctrl-X)
};

extern volatile uint8_t g_pending;

/// Called for every received byte (the chip's receive interrupt has the same tests in assembly,
/// firmware/serial.cpp: keep both in step). Returns true when the byte is a real-time
/// command (it is then consumed here and never enters the receive buffer). Besides the four
/// commands above, GRBL 1.1's extended real-time bytes (0x84 safety door, 0x85 jog cancel,
/// 0x87 debug, 0x90-0x9D overrides, 0xA0-0xA1 accessories) are consumed and ignored: a sender
/// may send them at any time and they must not corrupt a line.
inline bool filter(uint8_t byte) {
    // One read-modify-write of g_pending for the four commands (not one per case).
    uint8_t bit = 0;
    if (byte == '?') bit = kStatusReport;
    if (byte == '!') bit = kFeedHold;
    if (byte == '~') bit = kCycleStart;
    if (byte == 0x18) bit = kReset;
    if (bit != 0) {
        g_pending |= bit;
        return true;
    }
    if (byte < 0x84) return false;
    return byte <= 0x87 || (byte >= 0x90 && byte <= 0x9D) || byte == 0xA0 || byte == 0xA1;
}

/// Takes and clears the pending bits (interrupts off for the read-modify-write).
uint8_t take();

} // namespace rt
} // namespace ll
