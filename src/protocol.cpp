// GRBL 1.1 line protocol: line assembly, `$` commands, real-time commands, reports, and the
// non-blocking waits (planner full, G4, M0, M2/M30). Implements app.h. See docs/protocol.md.
#include "lowlevel/protocol.h"

#include <stddef.h>
#include <string.h>

#include "lowlevel/app.h"
#include "lowlevel/gcode.h"
#include "lowlevel/hal.h"
#include "lowlevel/motion.h"
#include "lowlevel/numparse.h"
#include "lowlevel/print.h"
#include "lowlevel/realtime.h"
#include "lowlevel/settings.h"
#include "lowlevel/status.h"

#ifndef LL_BUILD_DATE
#define LL_BUILD_DATE "20250101" // GRBL's build-date field of `$I`, YYYYMMDD
#endif

namespace ll {
namespace {

using namespace status;

// Flags of the line being assembled.
enum : uint8_t {
    kInParen = 1,     // inside a ( ) comment
    kInSemicolon = 2, // after ';': the rest is a comment
    kTooLong = 4,     // more than kLineMax characters kept: error:11
    kBadByte = 8,     // a byte that is neither printable ASCII nor tab: error:20
    kLost = 16,       // the receive buffer overflowed inside this line: error:11
};

// What the protocol waits for before it reads the next line. Every wait keeps serving
// real-time commands and motion::poll(); the line's `ok` comes when the wait ends. The first
// three follow gcode::execute()'s retry codes, in their order; the next two gcode::Then's.
enum class Wait : uint8_t {
    None,          // assembling a line
    WhenAccepting, // the planner is full: execute again when it has room
    WhenIdle,      // G10/G92: execute again when motion is idle
    DwellWhenIdle, // G4: start the dwell when motion is idle
    Dwell,         // G4: until `o.dwell_ms` (then a hal::millis() time)
    PauseWhenIdle, // M0: hold when motion is idle
    EndWhenIdle,   // M2/M30: [MSG:Pgm End] when motion is idle
    Paused,        // M0: until cycle start ('~')
};
static_assert(gcode::kRetryWhenIdle == gcode::kRetryWhenAccepting + 1 &&
                  gcode::kDwell == gcode::kRetryWhenAccepting + 2,
              "retry codes map to waits");
static_assert(uint8_t(Wait::PauseWhenIdle) == uint8_t(gcode::Then::Pause) + 4 &&
                  uint8_t(Wait::EndWhenIdle) == uint8_t(gcode::Then::ProgramEnd) + 4,
              "M0 and M2/M30 map to waits");

// Special result of a `$` command: answer ok, then soft-reset ($C off, $RST).
constexpr uint8_t kOkThenReset = 0xFF;

struct Protocol {
    char line[protocol::kLineMax + 1];
    uint8_t len;
    uint8_t flags;
    uint8_t last;       // the previous byte: a '\n' right after a '\r' ends nothing
    uint8_t lost_after; // the line of the lost_after-th byte from now lost bytes (0: none)
    uint8_t gflags;     // gcode::execute() flags for the pending line
    Wait wait;
    uint8_t check;         // `$C` check mode: 0 or 1 (= gcode::kCheckMode)
    uint8_t wco_countdown; // status reports until WCO: is shown again
    // What gcode::execute() asked for (static: not a frame under which the move is planned);
    // o.dwell_ms: G4 ms, then (Wait::Dwell) hal::millis() at its end.
    gcode::Outcome o;
    // Kept by a soft reset:
    uint8_t alarm;
    uint8_t rx_capacity; // receive buffer size, for `$I`
};
Protocol p;

// &p.o.dwell_ms through a pointer register (taken after the hal::millis() call that clobbers
// it): ld/st instead of lds/sts for its four bytes (16 B less for the two uses).
uint32_t& dwell_ms() {
    uint32_t* d = &p.o.dwell_ms;
#if defined(__AVR__)
    asm("" : "+e"(d)); // X, Y or Z: the compiler no longer sees the constant address
#endif
    return *d;
}

bool motion_idle() {
    return motion::state() == motion::State::Idle;
}

void finish(uint8_t code) {
    out::status(code);
    p.wait = Wait::None;
    p.gflags = 0;
}

// After power-up or a soft reset (p cleared): the parser, the GRBL messages, the banner.
void start(bool lost) {
    bool coord_ok = gcode::reset();
    // GRBL 1.1h order: the alarm of the abort, then (re-initialisation) the banner, then the
    // reminder that the alarm locks G-code.
    if (lost) {
        p.alarm = 1;
        out::line(LL_PSTR("ALARM:3"));
    }
    if (!coord_ok) out::status(kSettingReadFail);
    out::line(LL_PSTR("\r\nGrbl 1.1h ['$' for help]"));
    if (p.alarm) out::msg(LL_PSTR("'$H'|'$X' to unlock"));
}

void soft_reset() {
    bool lost = motion::abort();
    hal::serial_rx_clear();
    hal::serial_rx_overflowed(); // clears the flag: nothing is pending any more
    memset(&p, 0, offsetof(Protocol, alarm));
    start(lost);
}

__attribute__((noinline)) void report_status() {
    motion::State ms = motion::state();
    // The state names, indexed below: motion::State, then M0 (as held), check mode, alarm.
    static_assert(uint8_t(motion::State::Idle) == 0 && uint8_t(motion::State::Cycle) == 1 &&
                      uint8_t(motion::State::Holding) == 2 && uint8_t(motion::State::Held) == 3,
                  "state names follow motion::State");
    // In rising priority, each overriding the one before (straight-line code, no branch tree).
    uint8_t name = uint8_t(ms);
    if (p.wait == Wait::Paused) name = 3;
    if (p.check) name = 4;
    if (p.alarm) name = 5;
    const char* s =
        reinterpret_cast<const char*>(LL_PSTR("<Idle\0<Run\0<Hold:1\0<Hold:0\0<Check\0<Alarm"));
    while (name != 0) {
        if (flash_read_byte(s++) == 0) --name;
    }
    out::str(reinterpret_cast<const FlashChar*>(s));
    // In the motion side's scratch RAM (motion.h): no frame to build, 32 B less stack.
    struct Coords {
        int32_t pos[kAxes], wco[kAxes];
    };
    Coords& c = motion::scratch<Coords>();
    int32_t* pos = c.pos;
    int32_t(&wco)[kAxes] = c.wco;
    motion::position(pos);
    gcode::steps_to_um(pos, pos);
    gcode::work_offset(wco);
    bool mpos = (g_settings.status_mask & 1u) != 0;
    if (!mpos) {
        // Wrapping subtraction: a display value, never UB even for absurd offsets.
        for (uint8_t a = 0; a < kAxes; ++a) {
            pos[a] =
                static_cast<int32_t>(static_cast<uint32_t>(pos[a]) - static_cast<uint32_t>(wco[a]));
        }
    }
    out::str(mpos ? LL_PSTR("|MPos:") : LL_PSTR("|WPos:"));
    out::coords(pos);
    if (g_settings.status_mask & 2u) {
        out::str(LL_PSTR("|Bf:"));
        out::u8(motion::blocks_free());
        out::ch(',');
        out::u8(hal::serial_rx_free());
    }
    out::str(LL_PSTR("|FS:"));
    out::rate(motion::current_feed() * 1000u);
    out::ch(','); // (two characters: 1 B less than a string and its call)
    out::ch('0');
    // WCO: in the first report after a reset, right after an offset changed, then every 10th
    // report (every 30th while moving), as GRBL 1.1h.
    if (gcode::g_state.wco_changed || p.wco_countdown == 0) {
        gcode::g_state.wco_changed = 0;
        out::str(LL_PSTR("|WCO:"));
        out::coords(wco);
        p.wco_countdown = ms == motion::State::Idle ? 9 : 29;
    } else {
        --p.wco_countdown;
    }
    out::ch('>');
    out::eol();
}

// `$N=value`.
uint8_t store_setting() {
    // In the motion side's scratch RAM (motion.h), as the status report's coordinates: no frame.
    struct Words {
        num::Decimal n, v;
        uint32_t number;
    };
    Words& w = motion::scratch<Words>();
    const char* s = num::parse(p.line + 1, w.n);
    if (s == nullptr) return kBadNumberFormat;
    if (*s++ != '=') return kInvalidStatement;
    if (!num::to_uint(w.n, 255u, w.number)) return kInvalidStatement;
    s = num::parse(s, w.v);
    if (s == nullptr) return kBadNumberFormat;
    if (*s != 0) return kInvalidStatement;
    uint8_t r = settings::store(static_cast<uint8_t>(w.number), w.v);
    if (r == kOk) {
        motion::settings_changed();
        gcode::settings_changed();
        gcode::g_state.wco_changed = 1; // $13 may have changed the units of WCO
    }
    return r;
}

__attribute__((noinline)) uint8_t system_command() {
    const char* s = p.line + 1;
    char c = s[0];
    if (c == 0) {
        out::line(LL_PSTR("[HLP:$$ $# $G $I $x=val $C $X $RST=$ ~ ! ? ctrl-x]"));
        return kOk;
    }
    char c1 = s[1];
    bool one_letter = c1 == 0;
    bool busy = !motion_idle(); // asked once for the three commands that need idle
    if (c == '$' || c == 'G' || c == 'C' || c == 'X') {
        if (!one_letter) return kInvalidStatement;
        if (c == '$') {
            if (busy) return kIdleError; // too long to print while moving
            settings::report();
        } else if (c == 'G') {
            gcode::report_modes();
        } else if (c == 'C') {
            if (p.check) {
                out::msg(LL_PSTR("Disabled"));
                return kOkThenReset; // restores the parser state check mode changed
            }
            if (p.alarm || busy) return kIdleError;
            p.check = 1;
            out::msg(LL_PSTR("Enabled"));
        } else if (p.alarm) {
            out::msg(LL_PSTR("Caution: Unlocked"));
            p.alarm = 0;
        }
        return kOk;
    }
    // The rest needs the machine idle (or in alarm), as in GRBL.
    if (p.check || busy) return kIdleError;
    if (c == '#' || c == 'I') {
        if (!one_letter) return kInvalidStatement;
        if (c == '#') {
            gcode::report_offsets();
        } else {
            // The ring holds kPlannerSize moves (written out: one call less).
            static_assert(kPlannerSize == 16, "[OPT:I,16, follows kPlannerSize");
            out::str(LL_PSTR("[VER:1.1h." LL_BUILD_DATE ":Low Level " LL_VERSION_STRING
                             "]\r\n[OPT:I,16,"));
            out::u8(p.rx_capacity);
            // The curve extensions (docs/curves.md), as a message senders show as it is.
            out::bracket_eol();
            out::msg(LL_PSTR("G2.1/G3.1 ellipse IJ=centre PQ=semi-axes, G5 Bezier"));
        }
        return kOk;
    }
    if (c == 'R') { // $RST=$ settings, $RST=# G54, $RST=* both
        char what = s[4];
        if (c1 != 'S' || s[2] != 'T' || s[3] != '=' || s[5] != 0 ||
            (what != '$' && what != '#' && what != '*')) {
            return kInvalidStatement;
        }
        if (what != '#') {
            settings::restore_defaults(); // also zeroes G54
            motion::settings_changed();
        } else {
            settings::clear_coord();
        }
        out::msg(LL_PSTR("Restoring defaults"));
        return kOkThenReset;
    }
    if (c >= '0' && c <= '9') return store_setting();
    return kInvalidStatement;
}

void run_gcode() {
    gcode::Outcome& o = p.o;
    static_assert(gcode::kCheckMode == 1, "p.check (0 or 1) is the flag");
    uint8_t r = gcode::execute(p.line, static_cast<uint8_t>(p.gflags | p.check), o);
    if (r >= gcode::kRetryWhenAccepting) {
        p.wait = static_cast<Wait>(r - gcode::kRetryWhenAccepting + uint8_t(Wait::WhenAccepting));
    } else if (r == kOk && o.then != gcode::Then::Nothing) {
        p.wait = static_cast<Wait>(uint8_t(o.then) + 4);
    } else {
        finish(r);
    }
    // Planned here, not under execute()'s frame, and after its `ok` is queued: the answer does
    // not depend on the planning (push_line() prints nothing), and the sender's next line is
    // then on its way while the planner works. (A wait set above is only looked at in a later
    // run_once(), after this move is queued.)
    if (o.move) motion::push_line(*o.move);
}

// A complete line: answer it, or start executing it.
void dispatch() {
    uint8_t f = p.flags; // p.line is terminated (read_line())
    if (f & (kLost | kBadByte | kTooLong)) {
        finish((f & (kBadByte | kLost)) == kBadByte ? kUnsupportedCommand : kOverflow);
    } else if (p.len == 0) {
        finish(kOk); // empty or comment-only line: ok, for the sender's counting
    } else if (p.line[0] == '$') {
        uint8_t r = system_command();
        bool reset = r == kOkThenReset;
        if (reset) r = kOk;
        finish(r);
        if (reset) soft_reset();
    } else if (p.alarm) {
        finish(kGcodeLock);
    } else {
        // Parsed by advance_wait() once the planner has room (right after this, in the same
        // run_once(), when it has some now): when it is full, parsing now and again then would
        // double the parse, a third of a short line's cost, and a streaming sender keeps the
        // planner full. A line that would not move waits for that room too.
        p.wait = Wait::WhenAccepting;
    }
    p.len = 0;
    p.flags = 0;
}

// Takes received bytes until a line is complete (then dispatches it) or none is left.
void read_line() {
    for (;;) {
        if (hal::serial_rx_overflowed()) {
            // Bytes were dropped after everything now in the buffer (nothing was read since the
            // buffer filled up): the line of the byte that follows those lost some. Marked as
            // that byte is taken (the line in progress when the buffer is empty).
            uint8_t free = hal::serial_rx_free();
            uint8_t capacity = p.rx_capacity;
            if (free > capacity) p.rx_capacity = capacity = free;
            p.lost_after = static_cast<uint8_t>(capacity - free + 1);
        }
        uint8_t prev = p.last;
        if (!hal::serial_get(p.last)) return; // straight into p.last: no frame for it
        if (p.lost_after != 0 && --p.lost_after == 0) p.flags |= kLost;
        uint8_t c = p.last;
        uint8_t f = p.flags;
        // The common case first: in a line without flags (none in a comment), '-' to 'Z' but
        // '/' and ';' (digits, '.', capitals) is kept as it is, without the tests below (about
        // 20 cycles a byte).
        if (f == 0 && static_cast<uint8_t>(c - '-') <= 'Z' - '-' && c != '/' && c != ';') {
            goto keep;
        }
        if (c == '\n' || c == '\r') {
            if (c == '\n' && prev == '\r') continue; // CR LF is one line end
            dispatch();
            return; // one line per run_once()
        }
        if (c == ' ' || c == '\t' || c == '/') {
            // spaces and tabs, and block delete (ignored, as GRBL does), in comments too
        } else if (c < 0x20 || c >= 0x7F) {
            f |= kBadByte; // GRBL drops such bytes and runs the rest; we refuse the line
        } else if (f & kInSemicolon) {
        } else if (f & kInParen) {
            if (c == ')') f &= static_cast<uint8_t>(~kInParen);
        } else if (c == '(') {
            f |= kInParen;
        } else if (c == ';') {
            f |= kInSemicolon;
        } else {
            if (c >= 'a' && c <= 'z') c = static_cast<uint8_t>(c - ('a' - 'A'));
        keep:
            if (p.len >= protocol::kLineMax) {
                f |= kTooLong;
            } else {
                // Kept terminated: the pointer is at hand here (dispatch() would compute it).
                char* at = p.line + p.len++;
                at[0] = static_cast<char>(c);
                at[1] = 0;
            }
        }
        p.flags = f;
    }
}

void advance_wait() {
    Wait w = p.wait;
    if (w == Wait::WhenAccepting) {
        if (motion::can_accept()) run_gcode();
        return;
    }
    if (w == Wait::Dwell) {
        uint32_t now = hal::millis();
        if (static_cast<int32_t>(now - dwell_ms()) >= 0) {
            p.gflags = gcode::kDwellDone;
            run_gcode();
        }
        return;
    }
    if (w == Wait::Paused || !motion_idle()) return;
    // The waits that end once motion is idle.
    if (w == Wait::WhenIdle) {
        run_gcode();
    } else if (w == Wait::DwellWhenIdle) {
        uint32_t now = hal::millis();
        dwell_ms() += now;
        p.wait = Wait::Dwell;
    } else if (w == Wait::PauseWhenIdle) {
        p.wait = Wait::Paused;
    } else {
        out::msg(LL_PSTR("Pgm End"));
        finish(kOk);
    }
}

} // namespace

namespace protocol {

void raise_alarm(uint8_t code) {
    p.alarm = 1;
    out::str(LL_PSTR("ALARM:"));
    out::u8(code);
    out::eol();
    if (p.wait != Wait::None) finish(kGcodeLock);
}

bool alarmed() {
    return p.alarm != 0;
}

bool idle() {
    return p.wait == Wait::None && p.len == 0 && p.flags == 0;
}

} // namespace protocol

namespace app {

void init() {
#if !defined(__AVR__)
    // On the chip p is in .bss, which the start-up code has cleared: main() calls init() once,
    // right after it. The host tests boot again and again.
    memset(&p, 0, sizeof(p));
#endif
    p.rx_capacity = hal::serial_rx_free(); // the buffer is empty at power-up
    if (!settings::load()) {
        // GRBL 1.1h: error:7 ("EEPROM read fail. Using defaults"), then the restored settings.
        out::status(kSettingReadFail);
        settings::report();
    }
    motion::init();
    motion::settings_changed();
    start(false);
}

void run_once() {
    uint8_t rt = rt::take();
    if (rt & rt::kReset) {
        soft_reset();
        return;
    }
    if (rt & rt::kStatusReport) report_status();
    if ((rt & rt::kFeedHold) && !p.alarm && !p.check) motion::feed_hold();
    if (rt & rt::kCycleStart) {
        if (p.wait == Wait::Paused) {
            finish(kOk); // M0 resumed
        } else {
            motion::cycle_start();
        }
    }
    motion::poll();
    // A line just read is executed at once when the planner has room, not one poll later: its
    // `ok`, and so the sender's next line, come that much sooner.
    if (p.wait == Wait::None) read_line();
    if (p.wait != Wait::None) advance_wait();
}

} // namespace app
} // namespace ll
