// GRBL 1.1 line protocol: line assembly, `$` commands, real-time commands, reports, and the
// non-blocking waits (planner full, G4, M0, M2/M30). Implements app.h. See docs/protocol.md.
#include "lowlevel/protocol.h"

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
// real-time commands and motion::poll(); the line's `ok` comes when the wait ends.
enum class Wait : uint8_t {
    None,          // assembling a line
    WhenAccepting, // the planner is full: execute again when it has room
    WhenIdle,      // G10/G92: execute again when motion is idle
    DwellWhenIdle, // G4: start the dwell when motion is idle
    Dwell,         // G4: until `deadline`
    PauseWhenIdle, // M0: hold when motion is idle
    Paused,        // M0: until cycle start ('~')
    EndWhenIdle,   // M2/M30: [MSG:Pgm End] when motion is idle
};

// Special result of a `$` command: answer ok, then soft-reset ($C off, $RST).
constexpr uint8_t kOkThenReset = 0xFF;

struct Protocol {
    char line[protocol::kLineMax + 1];
    uint8_t len;
    uint8_t flags;
    uint8_t last_cr;     // the previous byte was '\r': a '\n' right after it ends nothing
    uint8_t lost_after;  // after this many more bytes, the line in progress lost bytes
    uint8_t rx_capacity; // receive buffer size, for `$I`
    uint8_t gflags;      // gcode::execute() flags for the pending line
    Wait wait;
    uint8_t alarm;
    uint8_t check;
    uint8_t wco_countdown; // status reports until WCO: is shown again
    uint32_t dwell_ms;
    uint32_t deadline; // hal::millis() at the end of the dwell
};
Protocol p;

bool motion_idle() {
    return motion::state() == motion::State::Idle;
}

void banner() {
    out::str(LL_PSTR("\r\nGrbl 1.1h ['$' for help]\r\n"));
}

void new_line() {
    p.len = 0;
    p.flags = 0;
}

void finish(uint8_t code) {
    out::status(code);
    p.wait = Wait::None;
    p.gflags = 0;
}

void soft_reset() {
    bool lost = motion::abort();
    hal::serial_rx_clear();
    hal::serial_rx_overflowed(); // clears the flag: nothing is pending any more
    new_line();
    p.last_cr = 0;
    p.lost_after = 0;
    p.wait = Wait::None;
    p.gflags = 0;
    p.check = 0;
    p.wco_countdown = 0;
    bool coord_ok = gcode::reset();
    // GRBL 1.1h order: the alarm of the abort, then (re-initialisation) the banner, then the
    // reminder that the alarm locks G-code.
    if (lost) {
        p.alarm = 1;
        out::str(LL_PSTR("ALARM:3\r\n"));
    }
    if (!coord_ok) out::status(kSettingReadFail);
    banner();
    if (p.alarm) out::msg(LL_PSTR("'$H'|'$X' to unlock"));
}

void report_status() {
    out::ch('<');
    motion::State ms = motion::state();
    if (p.alarm) {
        out::str(LL_PSTR("Alarm"));
    } else if (p.check) {
        out::str(LL_PSTR("Check"));
    } else if (p.wait == Wait::Paused || ms == motion::State::Held) {
        out::str(LL_PSTR("Hold:0"));
    } else if (ms == motion::State::Holding) {
        out::str(LL_PSTR("Hold:1"));
    } else if (ms == motion::State::Cycle) {
        out::str(LL_PSTR("Run"));
    } else {
        out::str(LL_PSTR("Idle"));
    }
    int32_t steps[kAxes], pos[kAxes], wco[kAxes];
    motion::position(steps);
    gcode::work_offset(wco);
    bool mpos = (g_settings.status_mask & 1u) != 0;
    for (uint8_t a = 0; a < kAxes; ++a) {
        num::mul_div_round(steps[a], 1000000u, g_settings.axis[a].steps_per_unit, pos[a]);
        // Wrapping subtraction: a display value, never UB even for absurd offsets.
        if (!mpos)
            pos[a] =
                static_cast<int32_t>(static_cast<uint32_t>(pos[a]) - static_cast<uint32_t>(wco[a]));
    }
    out::str(mpos ? LL_PSTR("|MPos:") : LL_PSTR("|WPos:"));
    out::coords(pos);
    if (g_settings.status_mask & 2u) {
        out::str(LL_PSTR("|Bf:"));
        out::u32(motion::blocks_free());
        out::ch(',');
        out::u32(hal::serial_rx_free());
    }
    out::str(LL_PSTR("|FS:"));
    out::rate(motion::current_feed() * 1000u);
    out::str(LL_PSTR(",0"));
    // WCO: in the first report after a reset, right after an offset changed, then every 10th
    // report (every 30th while moving), as GRBL 1.1h.
    if (gcode::g_state.wco_changed) {
        gcode::g_state.wco_changed = 0;
        p.wco_countdown = 0;
    }
    if (p.wco_countdown == 0) {
        out::str(LL_PSTR("|WCO:"));
        out::coords(wco);
        p.wco_countdown = ms == motion::State::Idle ? 9 : 29;
    } else {
        --p.wco_countdown;
    }
    out::str(LL_PSTR(">\r\n"));
}

// `$N=value`.
uint8_t store_setting() {
    uint8_t i = 1;
    num::Decimal n, v;
    if (!num::parse(p.line, i, n)) return kBadNumberFormat;
    if (p.line[i++] != '=') return kInvalidStatement;
    uint32_t number;
    if (!num::to_uint(n, 255u, number)) return kInvalidStatement;
    if (!num::parse(p.line, i, v)) return kBadNumberFormat;
    if (p.line[i] != 0) return kInvalidStatement;
    uint8_t r = settings::store(static_cast<uint8_t>(number), v);
    if (r == kOk) {
        motion::settings_changed();
        gcode::settings_changed();
        gcode::g_state.wco_changed = 1; // $13 may have changed the units of WCO
    }
    return r;
}

uint8_t system_command() {
    const char* s = p.line + 1;
    char c = s[0];
    if (c == 0) {
        out::str(LL_PSTR("[HLP:$$ $# $G $I $x=val $C $X $RST=$ ~ ! ? ctrl-x]\r\n"));
        return kOk;
    }
    bool one_letter = s[1] == 0;
    switch (c) {
        case '$':
            if (!one_letter) return kInvalidStatement;
            if (!motion_idle()) return kIdleError; // too long to print while moving
            settings::report();
            return kOk;
        case 'G':
            if (!one_letter) return kInvalidStatement;
            gcode::report_modes();
            return kOk;
        case 'C':
            if (!one_letter) return kInvalidStatement;
            if (p.check) {
                out::msg(LL_PSTR("Disabled"));
                return kOkThenReset; // restores the parser state check mode changed
            }
            if (p.alarm || !motion_idle()) return kIdleError;
            p.check = 1;
            out::msg(LL_PSTR("Enabled"));
            return kOk;
        case 'X':
            if (!one_letter) return kInvalidStatement;
            if (p.alarm) {
                out::msg(LL_PSTR("Caution: Unlocked"));
                p.alarm = 0;
            }
            return kOk;
        default:
            break;
    }
    // The rest needs the machine idle (or in alarm), as in GRBL.
    if (p.check || !motion_idle()) return kIdleError;
    if (c == '#') {
        if (!one_letter) return kInvalidStatement;
        gcode::report_offsets();
        return kOk;
    }
    if (c == 'I') {
        if (!one_letter) return kInvalidStatement;
        out::str(
            LL_PSTR("[VER:1.1h." LL_BUILD_DATE ":Low Level " LL_VERSION_STRING "]\r\n[OPT:I,"));
        out::u32(kPlannerSize); // the ring holds kPlannerSize moves
        out::ch(',');
        out::u32(p.rx_capacity);
        out::str(LL_PSTR("]\r\n"));
        return kOk;
    }
    if (c == 'R') { // $RST=$ settings, $RST=# G54, $RST=* both
        if (s[1] != 'S' || s[2] != 'T' || s[3] != '=' || s[4] == 0 || s[5] != 0) {
            return kInvalidStatement;
        }
        char what = s[4];
        if (what != '$' && what != '#' && what != '*') return kInvalidStatement;
        if (what != '#') {
            settings::restore_defaults(); // also zeroes G54
            motion::settings_changed();
        } else {
            int32_t zero[kAxes] = {};
            settings::save_coord(zero);
        }
        out::msg(LL_PSTR("Restoring defaults"));
        return kOkThenReset;
    }
    if (c >= '0' && c <= '9') return store_setting();
    return kInvalidStatement;
}

void run_gcode() {
    gcode::Outcome o;
    uint8_t r = gcode::execute(
        p.line, static_cast<uint8_t>(p.gflags | (p.check ? gcode::kCheckMode : 0)), o);
    switch (r) {
        case gcode::kRetryWhenAccepting:
            p.wait = Wait::WhenAccepting;
            return;
        case gcode::kRetryWhenIdle:
            p.wait = Wait::WhenIdle;
            return;
        case gcode::kDwell:
            p.dwell_ms = o.dwell_ms;
            p.wait = Wait::DwellWhenIdle;
            return;
        default:
            break;
    }
    if (r == kOk && o.then == gcode::Then::Pause) {
        p.wait = Wait::PauseWhenIdle;
    } else if (r == kOk && o.then == gcode::Then::ProgramEnd) {
        p.wait = Wait::EndWhenIdle;
    } else {
        finish(r);
    }
}

// A complete line: answer it, or start executing it.
void dispatch() {
    uint8_t f = p.flags;
    p.line[p.len] = 0;
    if (f & kLost) {
        finish(kOverflow);
    } else if (f & kBadByte) {
        finish(kUnsupportedCommand);
    } else if (f & kTooLong) {
        finish(kOverflow);
    } else if (p.len == 0) {
        finish(kOk); // empty or comment-only line: ok, for the sender's counting
    } else if (p.line[0] == '$') {
        uint8_t r = system_command();
        if (r == kOkThenReset) {
            finish(kOk);
            soft_reset();
        } else {
            finish(r);
        }
    } else if (p.alarm) {
        finish(kGcodeLock);
    } else {
        run_gcode();
    }
    new_line();
}

// Takes received bytes until a line is complete (then dispatches it) or none is left.
void read_line() {
    for (;;) {
        if (hal::serial_rx_overflowed()) {
            // Bytes were dropped after everything now in the buffer (nothing was read since the
            // buffer filled up): the line in progress once those bytes are read lost some.
            uint8_t free = hal::serial_rx_free();
            if (free > p.rx_capacity) p.rx_capacity = free;
            p.lost_after = static_cast<uint8_t>(p.rx_capacity - free);
            if (p.lost_after == 0) p.flags |= kLost;
        }
        uint8_t c;
        if (!hal::serial_get(c)) return;
        bool end = false;
        if (c == '\n' || c == '\r') {
            end = !(c == '\n' && p.last_cr); // CR LF is one line end
            p.last_cr = c == '\r';
        } else {
            p.last_cr = 0;
            if ((c < 0x20 && c != '\t') || c >= 0x7F) {
                p.flags |= kBadByte; // GRBL drops such bytes and runs the rest; we refuse the line
            } else if (p.flags & kInSemicolon) {
            } else if (p.flags & kInParen) {
                if (c == ')') p.flags &= static_cast<uint8_t>(~kInParen);
            } else if (c == ' ' || c == '\t' || c == '/') {
                // spaces, and block delete (ignored, as GRBL does)
            } else if (c == '(') {
                p.flags |= kInParen;
            } else if (c == ';') {
                p.flags |= kInSemicolon;
            } else if (p.len >= protocol::kLineMax) {
                p.flags |= kTooLong;
            } else {
                if (c >= 'a' && c <= 'z') c = static_cast<uint8_t>(c - ('a' - 'A'));
                p.line[p.len++] = static_cast<char>(c);
            }
        }
        if (end) dispatch();
        if (p.lost_after != 0 && --p.lost_after == 0) p.flags |= kLost;
        if (end) return; // one line per run_once()
    }
}

void advance_wait() {
    switch (p.wait) {
        case Wait::WhenAccepting:
            if (motion::can_accept()) run_gcode();
            break;
        case Wait::WhenIdle:
            if (motion_idle()) run_gcode();
            break;
        case Wait::DwellWhenIdle:
            if (motion_idle()) {
                p.deadline = hal::millis() + p.dwell_ms;
                p.wait = Wait::Dwell;
            }
            break;
        case Wait::Dwell:
            if (static_cast<int32_t>(hal::millis() - p.deadline) >= 0) {
                p.gflags = gcode::kDwellDone;
                run_gcode();
            }
            break;
        case Wait::PauseWhenIdle:
            if (motion_idle()) p.wait = Wait::Paused;
            break;
        case Wait::EndWhenIdle:
            if (motion_idle()) {
                out::msg(LL_PSTR("Pgm End"));
                finish(kOk);
            }
            break;
        default:
            break;
    }
}

} // namespace

namespace protocol {

void raise_alarm(uint8_t code) {
    p.alarm = 1;
    out::str(LL_PSTR("ALARM:"));
    out::u32(code);
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
    new_line();
    p.last_cr = 0;
    p.lost_after = 0;
    p.gflags = 0;
    p.wait = Wait::None;
    p.alarm = 0;
    p.check = 0;
    p.wco_countdown = 0;
    p.rx_capacity = hal::serial_rx_free(); // the buffer is empty at power-up
    if (!settings::load()) {
        // GRBL 1.1h: error:7 ("EEPROM read fail. Using defaults"), then the restored settings.
        out::status(kSettingReadFail);
        settings::report();
    }
    motion::init();
    motion::settings_changed();
    if (!gcode::reset()) out::status(kSettingReadFail);
    banner();
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
    if (p.wait != Wait::None) advance_wait();
    if (p.wait == Wait::None) read_line();
}

} // namespace app
} // namespace ll
