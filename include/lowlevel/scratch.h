// Scratch RAM shared by modules whose uses never overlap in time (see motion.h for who owns it
// when). A lower-level header than motion.h, so that the curve and step generators, which must
// not include motion.h, can reach it too.
#pragma once

#include "lowlevel/config.h"

#include <stdint.h>

namespace ll {

// The size of the G-code work block on the AVR (gcode.cpp checks it), generous on the host.
constexpr uint16_t kScratchBytes =
    sizeof(void*) == 2 ? 92 + 16 * kAxes + (kAxes > 5 ? 2 : 0) : 128 + 32 * kAxes;
extern uint8_t g_scratch[kScratchBytes];

/// Bytes [kCurveTrackAt, kCurveTrackAt + kCurveTrackBytes) of the scratch RAM are dead while
/// the planner shapes a curve (motion::push_line() -> curve_shape()): there the G-code work
/// block holds the slots of the block's P I J K Q R numbers, read before the curve was written
/// over the axis and F slots. curve_shape() keeps its track there rather than in a 46-byte
/// frame on the deepest stack of the firmware. gcode.cpp pins the layout.
constexpr uint16_t kCurveTrackAt = sizeof(void*) == 2 ? 65 : 68;
constexpr uint16_t kCurveTrackBytes = 52;
/// Bytes [kCurveProbeAt, kCurveProbeAt + kCurveProbeBytes) are dead there too: the work block's
/// header, which execute() writes afresh at its start and no one reads once it has returned.
/// The curve's probe() keeps its derivatives there.
constexpr uint16_t kCurveProbeAt = 0;
constexpr uint16_t kCurveProbeBytes = 16;

/// The scratch RAM from byte `at` as a T. Each user only ever accesses it as its own type, in
/// its own translation unit, and the other users' accesses are behind a call: no access through
/// one type can be reordered across an access through the other (the -Wstrict-aliasing
/// concern).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wstrict-aliasing"
template <typename T, uint16_t At = 0>
inline T& scratch() {
    static_assert(At + sizeof(T) <= kScratchBytes, "fits the scratch RAM");
    return *reinterpret_cast<T*>(g_scratch + At);
}
#pragma GCC diagnostic pop

} // namespace ll
