// What the G-code layer asks of the motion side (planner + step generator). The protocol and
// the G-code executor use only this header; tests can replace it with a recording fake.
#pragma once

#include "lowlevel/config.h"
#include "lowlevel/curve.h"
#include "lowlevel/scratch.h"

namespace ll {
namespace motion {

/// One move in machine coordinates: straight, or along a curve (seed part IV).
struct LineRequest {
    int32_t target_steps[kAxes]; ///< absolute target, steps: round_half_away(mm * steps/mm)
    int32_t target_um[kAxes];    ///< absolute target, mm x1000 (deg x1000 on a rotary axis)
    uint32_t feed;               ///< F in units/min x1000; ignored when `rapid`
    bool rapid;                  ///< G0: as fast as every axis allows
    /// The curve from the current position to the target, or nullptr for a straight move.
    /// Copied by push_line().
    const CurveParams* curve;
};

/// Scratch RAM that the motion side uses only inside poll(), to hand the next move to the step
/// generator. Outside poll() it is lent to the G-code layer, which keeps there its work block
/// (gcode.cpp), live from gcode::execute() until push_line() has queued the move: neither
/// push_line() nor execute() polls. Sharing it saves RAM
/// on the deepest stack (the move handed over was a local of poll()). The status report
/// (protocol.cpp) and the `$` commands, which run neither inside poll() nor inside execute() and
/// poll nothing, keep their coordinates and numbers there too, as do init(), abort() and
/// settings_changed(). While push_line() shapes a curve, curve_shape() keeps its track in bytes
/// of the work block that are dead by then (scratch.h).
// (In scratch.h, as the curve track's share of it.)
using ll::g_scratch;
using ll::kScratchBytes;
using ll::scratch;

/// Power-up state: position zero, nothing queued, step timer stopped. Call once before
/// settings_changed().
void init();

/// True when the planner has room for one more move.
bool can_accept();
/// True when the planner has room for one more curve (curves also need one of a few slots).
bool can_accept_curve();
/// Queues a move. Precondition: can_accept(). A move of zero length is dropped silently (as
/// GRBL does) but still counts as accepted. Returns false, queueing nothing, when one axis
/// would travel more than kMaxLineTicks steps (2^23 - 1) in one move: the G-code layer reports it
/// as an invalid target (error:33) rather than running part of it. It does not poll(): the
/// line's `ok` goes out as soon as the move is planned, and the next poll() (the main loop's,
/// right after) starts producing its steps; in send-and-wait streaming that shortens every
/// line's round trip by the step generation (about 1 ms a 0.1 mm line on the chip).
bool push_line(const LineRequest& req);
/// Free planner blocks (first field of `Bf:`).
uint8_t blocks_free();

/// Background work: plans, produces runs, starts the step timer, handles the idle delay ($1).
/// Call it from every wait loop; it never blocks.
void poll();

enum class State : uint8_t {
    Idle,    ///< nothing queued, nothing moving
    Cycle,   ///< moving or about to move
    Holding, ///< feed hold requested, decelerating (GRBL "Hold:1")
    Held,    ///< feed hold complete, motion stopped and resumable (GRBL "Hold:0")
};
State state();

/// Feed hold: decelerate along the path to a stop, losing no step.
void feed_hold();
/// Resumes after a feed hold (no effect otherwise).
void cycle_start();
/// Stops at once and forgets everything queued (soft reset). Returns true when steps were
/// being emitted, i.e. the position may be lost (GRBL raises ALARM:3 then).
bool abort();

/// Current machine position, steps, as executed by the step interrupt so far.
void position(int32_t steps[kAxes]);
/// Current feed along the regulated path, units/min (for `FS:`).
uint32_t current_feed();

/// The settings changed: recompute derived tables. Only called while state() == Idle.
void settings_changed();

} // namespace motion
} // namespace ll

namespace ll {
namespace motion {
/// Times the step queue ran dry in the middle of a move since power-up (benchmarks).
uint32_t starvations();
} // namespace motion
} // namespace ll
