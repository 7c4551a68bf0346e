// G-code parser and executor, GRBL 1.1 subset (docs/protocol.md lists what is supported).
// execute() works like GRBL's gc_execute_line: numbered stages with early returns, and no side
// effect until the whole line is validated. A rejected line changes nothing: the next valid line
// runs as if the bad one had never come.
#pragma once

#include "lowlevel/config.h"
#include "lowlevel/motion.h"
#include "lowlevel/numparse.h"
#include "lowlevel/settings.h"

namespace ll {
namespace gcode {

/// Motion modes (modal group 1). Arcs, ellipses and Bezier curves have their codes here and in
/// the word tables already; until their generators exist, execute() answers error:20 for them.
enum class Motion : uint8_t {
    Seek,       ///< G0
    Linear,     ///< G1
    ArcCw,      ///< G2 (I J K R, P turns)
    ArcCcw,     ///< G3
    EllipseCw,  ///< G2.1 (I J P Q X Y)
    EllipseCcw, ///< G3.1
    Bezier,     ///< G5 (I J P Q X Y)
    None,       ///< G80
};

/// One byte per modal group, in the order of gcode.cpp's group numbers (it copies them as bytes).
struct Modal {
    Motion motion;
    uint8_t plane;       ///< 0 = G17 (XY), 1 = G18 (ZX), 2 = G19 (YZ)
    uint8_t inches;      ///< 1 = G20, 0 = G21
    uint8_t incremental; ///< 1 = G91, 0 = G90
    uint8_t coord;       ///< 0 = G54, the only work coordinate system
    uint8_t spindle;     ///< 3, 4 or 5 (M3/M4/M5): tracked and reported, no output yet
    uint8_t coolant;     ///< 8 or 9 (M8/M9): tracked and reported, no output yet
};

/// execute() copies modal + tool (8 bytes) and feed, spindle_speed, line_number as 32-bit words:
/// keep them in this order (static_asserts in gcode.cpp).
struct State {
    Modal modal;
    uint8_t tool;                  ///< T
    uint32_t feed;                 ///< F, mm/min x1000 (deg/min x1000); 0 = undefined
    uint32_t spindle_speed;        ///< S, rpm
    uint32_t line_number;          ///< N of the last executed line (0 without N)
    int32_t position[kAxes];       ///< machine position of the last target, um
    int32_t position_steps[kAxes]; ///< the same in steps, exactly as sent to the planner
    int32_t g54[kAxes];            ///< G54 work offset, um (kept in EEPROM)
    int32_t g92[kAxes];            ///< G92 offset, um (RAM only; reset clears it)
    uint8_t wco_changed;           ///< set when G54/G92 change (the next status report shows WCO)
    uint8_t g5_continues;          ///< the last move was a G5: a G5 without I J continues it
    int32_t g5_reflect[2];         ///< last G5: end minus second control point (plane u, v), um
};

extern State g_state;

/// Flags for execute().
enum : uint8_t {
    kCheckMode = 1, ///< `$C`: validate and update the parser state, queue no motion, no EEPROM
    kDwellDone = 2, ///< the dwell of this line has been waited for already
};

/// Results of execute() besides the GRBL status codes. Nothing has changed; call again with the
/// same line when the condition holds.
enum : uint8_t {
    kRetryWhenAccepting = 0xF0, ///< the planner is full
    kRetryWhenIdle = 0xF1,      ///< G10/G92/G92.1: offsets change only once motion is idle
    kDwell = 0xF2,              ///< G4: wait for idle, then Outcome::dwell_ms, then kDwellDone
};

/// What the protocol does after a successful line, before it answers `ok`.
enum class Then : uint8_t {
    Nothing,
    Pause,      ///< M0: once motion is idle, hold (Hold:0) until cycle start
    ProgramEnd, ///< M2/M30: once motion is idle, print [MSG:Pgm End]
};

struct Outcome {
    Then then;
    uint32_t dwell_ms; ///< with kDwell
    /// A move to queue, or nullptr. The caller hands it to motion::push_line() once execute()
    /// has returned, so that planning the move does not stack on top of parsing the line.
    const motion::LineRequest* move;
};

/// Parses and executes one line: upper case, no spaces, no comments, NUL-terminated (the
/// protocol's line assembler does that). Returns status::kOk, a GRBL error code, or one of the
/// retry codes above.
uint8_t execute(const char* line, uint8_t flags, Outcome& outcome);

/// Power-up and soft-reset state: G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0, G92 cleared, G54 read
/// from EEPROM, position taken from motion::position(). Returns false when the G54 record was
/// corrupt (it is then zero and rewritten; GRBL reports error:7).
bool reset();
/// Takes the parser position from motion::position() (after an abort).
void sync_position();
/// Machine steps to um, per axis (`steps` and `um` may be the same array): exact, rounded half
/// away from zero, saturated on overflow.
void steps_to_um(const int32_t* steps, int32_t* um);
/// Steps per unit changed: recomputes position_steps from the um position (GRBL keeps the mm).
void settings_changed();

/// `$G`: [GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]
void report_modes();
/// `$#`: [G54:..] to [G59:..], [G28:..], [G30:..], [G92:..], [TLO:..], [PRB:..:0]
void report_offsets();
/// Work coordinate offset (G54 + G92), um.
void work_offset(int32_t (&um)[kAxes]);

/// round_half_away_from_zero(um * steps_per_unit_milli / 10^6), exact. False (and `steps`
/// unchanged) when the result does not fit an int32.
inline bool um_to_steps(uint8_t axis, int32_t um, int32_t& steps) {
    int32_t s;
    if (!num::mul_div_round(um, g_settings.axis[axis].steps_per_unit, 1000000u, s)) return false;
    steps = s;
    return true;
}

} // namespace gcode
} // namespace ll
