// G-code parser and executor. See gcode.h; the stages follow GRBL's gc_execute_line.
#include "lowlevel/gcode.h"

#include "lowlevel/fixmath.h"
#include "lowlevel/line.h"

#include "lowlevel/motion.h"
#include "lowlevel/numparse.h"
#include "lowlevel/pgm.h"
#include "lowlevel/print.h"
#include "lowlevel/settings.h"
#include "lowlevel/status.h"

namespace ll {
namespace gcode {

State g_state;

namespace {

using namespace status;

// Modal groups (NIST RS274NGC table 4, GRBL's numbering in the comments), as bits.
enum Group : uint8_t {
    kGroupNonModal,    // G4 G10 G28 G30 G53 G92 G92.1 (G0)
    kGroupMotion,      // G0 G1 G2 G3 G2.1 G3.1 G5 G80 (G1)
    kGroupPlane,       // G17 G18 G19 (G2)
    kGroupDistance,    // G90 G91 (G3)
    kGroupArcDistance, // G91.1 (G4)
    kGroupFeedMode,    // G94 (G5)
    kGroupUnits,       // G20 G21 (G6)
    kGroupCutter,      // G40 (G7)
    kGroupToolLength,  // G49 (G8)
    kGroupCoord,       // G54..G59 (G12)
    kGroupPath,        // G61 (G13)
    kGroupFlow,        // M0 M1 M2 M30 (M4)
    kGroupSpindle,     // M3 M4 M5 (M7)
    kGroupCoolant,     // M8 M9 (M8)
};

enum NonModal : uint8_t {
    kNoNonModal,
    kDwellCmd,
    kSetCoordData,
    kAbsoluteOverride,
    kSetOffset,
    kResetOffset
};

// Which command uses the axis words of the block (GRBL's AXIS_COMMAND_*).
enum AxisCommand : uint8_t { kAxisNone, kAxisNonModal, kAxisMotion };

enum Flow : uint8_t { kFlowRunning, kFlowPause, kFlowEnd };

// Value letters other than the axes, numbered so that their bit in Block::words is their number.
// F I J K P Q R keep their Decimal until the units of the block are known (the curves to come
// use I J K R and P Q: G2/G3 I J K R P, G2.1/G3.1 and G5 I J P Q).
enum Word : uint8_t {
    kWordF,
    kWordI,
    kWordJ,
    kWordK,
    kWordP,
    kWordQ,
    kWordR,
    kWordN,
    kWordL,
    kWordS,
    kWordT
};
constexpr uint8_t kDecimalWords = kWordR + 1; // Block::v[0..6]; the axes follow
constexpr uint8_t kWordAxis = 16;             // kLetterInfo of axis a: kWordAxis + a
constexpr uint8_t kLetterNone = 0xFF;
constexpr uint16_t bit(Word w) {
    return static_cast<uint16_t>(1u << w);
}

constexpr uint8_t axis_letter(uint8_t a) {
    return a < kAxes ? static_cast<uint8_t>(kWordAxis + a) : kLetterNone;
}
// What each letter A..Z is, besides G and M.
const uint8_t kLetterInfo[26] LL_PROGMEM = {
    axis_letter(3), axis_letter(4), axis_letter(5), // A B C
    kLetterNone,    kLetterNone,    kWordF,         // D E F
    kLetterNone,    kLetterNone,    kWordI,         // G H I
    kWordJ,         kWordK,         kWordL,         // J K L
    kLetterNone,    kWordN,         kLetterNone,    // M N O
    kWordP,         kWordQ,         kWordR,         // P Q R
    kWordS,         kWordT,         kLetterNone,    // S T U
    kLetterNone,    kLetterNone,    axis_letter(0), // V W X
    axis_letter(1), axis_letter(2),                 // Y Z
};

constexpr uint32_t kNoLineNumber = 0xFFFFFFFFu;

struct Block {
    Modal modal;
    uint8_t non_modal;
    uint8_t axis_command;
    uint8_t flow;
    uint8_t axis_words; // bit a: axis a has a word
    uint8_t l;          // L, 0xFF when not an integer 0..254
    uint8_t tool;
    uint16_t groups; // modal groups commanded in this block
    uint16_t words;  // value letters present, bit(Word)
    uint32_t n;
    uint32_t s;
    num::Decimal v[kDecimalWords + kAxes]; // F I J K P Q R, then the axes
};

// The block being checked and what it computes, kept static: a stack frame this large costs
// the AVR an address computation on every access (displacements stop at 63 bytes), and the
// static size is visible to the RAM budget.
struct Work {
    Block b;
    int32_t values[kAxes];  // axis words of the block, um
    int32_t offsets[kAxes]; // new G54 (G10) or G92 offsets, um
    motion::LineRequest req;
};
Work w;

// Steps per um of each axis as whole + k / 2^32 (see um_to_steps).
struct Scale {
    uint32_t k;     // floor(frac * 2^32 / 10^6), frac = steps_per_unit mod 10^6
    uint16_t whole; // steps_per_unit / 10^6
};
Scale g_scale[kAxes];

// The first decimal of a command number (G92.1 -> 1), or 0xFF with a finer fraction (G1.05).
uint8_t tenths(const num::Decimal& d) {
    if (d.frac == 0 && d.sub == 0) return 0; // the usual case: G1, G90
    if (d.sub != 0 || (d.flags & num::Decimal::kInexact) != 0) return 0xFF;
    for (uint8_t t = 0; t < 10; ++t) {
        if (d.frac == t * 100u) return t;
    }
    return 0xFF;
}

// Stage 2 helpers: one word each. G and M commands are recognised here (unsupported: 20,
// two from one modal group: 21, two that use axis words: 24).
uint8_t import_g(Block& b, const num::Decimal& d) {
    if (d.negative() || d.ipart > 255) return kUnsupportedCommand;
    uint8_t code = static_cast<uint8_t>(d.ipart);
    uint8_t mant = tenths(d);
    bool mant_used = false;
    Group group;
    switch (code) {
        case 0:
        case 1:
        case 80:
            if (code != 80) {
                if (b.axis_command != kAxisNone) return kAxisCommandConflict;
                b.axis_command = kAxisMotion;
            }
            group = kGroupMotion;
            b.modal.motion = code == 0 ? Motion::Seek : code == 1 ? Motion::Linear : Motion::None;
            break;
        case 2:
        case 3:
        case 5:
            // G2/G3 (arcs), G2.1/G3.1 (ellipses) and G5 (cubic Bezier) take their place here as
            // motion-group commands that use axis words, once their generators exist.
            return kUnsupportedCommand;
        case 4:
        case 10:
        case 53:
        case 92:
            if (code == 10 || (code == 92 && mant == 0)) {
                if (b.axis_command != kAxisNone) return kAxisCommandConflict;
                b.axis_command = kAxisNonModal;
            }
            group = kGroupNonModal;
            if (code == 4) b.non_modal = kDwellCmd;
            if (code == 10) b.non_modal = kSetCoordData;
            if (code == 53) b.non_modal = kAbsoluteOverride;
            if (code == 92) {
                if (mant > 1) return kUnsupportedCommand; // G92.2, G92.3
                b.non_modal = mant == 0 ? kSetOffset : kResetOffset;
                mant_used = true;
            }
            break;
        case 17:
        case 18:
        case 19:
            group = kGroupPlane;
            b.modal.plane = static_cast<uint8_t>(code - 17);
            break;
        case 20:
        case 21:
            group = kGroupUnits;
            b.modal.inches = code == 20 ? 1 : 0;
            break;
        case 40:
            group = kGroupCutter;
            break; // cutter compensation off: always off
        case 49:
            group = kGroupToolLength;
            break; // tool length offset off: always off
        case 54:
        case 55:
        case 56:
        case 57:
        case 58:
        case 59:
            group = kGroupCoord;
            b.modal.coord = static_cast<uint8_t>(code - 54);
            break;
        case 61:
            if (mant != 0) return kUnsupportedCommand; // G61.1
            group = kGroupPath;
            break;
        case 90:
        case 91:
            if (mant == 0) {
                group = kGroupDistance;
                b.modal.incremental = code == 91 ? 1 : 0;
            } else {
                if (code == 90 || mant != 1) return kUnsupportedCommand; // G90.1
                group = kGroupArcDistance; // G91.1: arc centres are incremental, the default
                mant_used = true;
            }
            break;
        case 94:
            group = kGroupFeedMode;
            break;
        default:
            return kUnsupportedCommand; // G28 G30 G38.x G43.1 G64 G93 ...
    }
    if (mant != 0 && !mant_used) return kCommandValueNotInteger;
    uint16_t bit = static_cast<uint16_t>(1u << group);
    if (b.groups & bit) return kModalGroupViolation;
    b.groups |= bit;
    return kOk;
}

uint8_t import_m(Block& b, const num::Decimal& d) {
    if (!d.integral()) return kCommandValueNotInteger;
    if (d.negative() || d.ipart > 255) return kUnsupportedCommand;
    uint8_t code = static_cast<uint8_t>(d.ipart);
    Group group;
    switch (code) {
        case 0:
        case 1:
        case 2:
        case 30:
            group = kGroupFlow;
            if (code == 0) b.flow = kFlowPause;
            if (code == 2 || code == 30) b.flow = kFlowEnd;
            break; // M1 (optional stop) is accepted and ignored, as GRBL does
        case 3:
        case 4:
        case 5:
            group = kGroupSpindle;
            b.modal.spindle = code;
            break;
        case 8:
        case 9:
            group = kGroupCoolant;
            b.modal.coolant = code;
            break;
        default:
            return kUnsupportedCommand; // M6, M7 (no mist output), ...
    }
    uint16_t bit = static_cast<uint16_t>(1u << group);
    if (b.groups & bit) return kModalGroupViolation;
    b.groups |= bit;
    return kOk;
}

uint8_t import_value(Block& b, char letter, const num::Decimal& d) {
    uint8_t info = flash_read_byte(&kLetterInfo[letter - 'A']);
    if (info == kLetterNone) return kUnsupportedCommand;
    if (info >= kWordAxis) {
        uint8_t a = static_cast<uint8_t>(info - kWordAxis);
        uint8_t abit = static_cast<uint8_t>(1u << a);
        if (b.axis_words & abit) return kWordRepeated;
        b.axis_words |= abit;
        b.v[kDecimalWords + a] = d;
        return kOk;
    }
    Word word = static_cast<Word>(info);
    if (b.words & bit(word)) return kWordRepeated;
    constexpr uint16_t kNotNegative =
        bit(kWordF) | bit(kWordP) | bit(kWordN) | bit(kWordS) | bit(kWordT);
    if (d.negative() && (bit(word) & kNotNegative)) return kNegativeValue;
    b.words |= bit(word);
    uint32_t v;
    switch (word) {
        case kWordN:
            b.n = num::to_uint(d, 10000000u, v) ? v : kNoLineNumber;
            break;
        case kWordL:
            b.l = num::to_uint(d, 254u, v) ? static_cast<uint8_t>(v) : 0xFF;
            break;
        case kWordT:
            if (!d.integral()) return kCommandValueNotInteger;
            if (d.ipart > 255) return kMaxValueExceeded;
            b.tool = static_cast<uint8_t>(d.ipart);
            break;
        case kWordS:
            b.s = d.ipart + (d.frac >= 500 ? 1u : 0u);
            break;
        default:
            b.v[word] = d;
            break;
    }
    return kOk;
}

// A length word in the units of the block, to um (or a feed to mm/min x1000).
bool length(const Block& b, uint8_t slot, int32_t& out) {
    return b.modal.inches ? num::inch_to_milli(b.v[slot], out) : num::to_milli(b.v[slot], out);
}

bool has_axis(uint8_t axis_words, uint8_t a) {
    return ((axis_words >> a) & 1) != 0;
}

bool add(int32_t a, int32_t b, int32_t& out) {
    return !__builtin_add_overflow(a, b, &out);
}
bool sub(int32_t a, int32_t b, int32_t& out) {
    return !__builtin_sub_overflow(a, b, &out);
}

} // namespace

// round(|um| * s / 10^6) without a division: q = floor(|um| * k / 2^32) is the floor of
// |um| * frac / 10^6 or one less (k is short of the exact ratio by less than 1 and |um| < 2^31);
// the remainder |um| * frac - q * 10^6 is then exact in 32-bit wrap-around arithmetic (it is
// below 2 * 10^6) and settles both the missing unit and the rounding. The whole part of the
// ratio (1000 steps/mm and more) is one multiplication.
bool um_to_steps(uint8_t axis, int32_t um, int32_t& steps) {
    const Scale& sc = g_scale[axis];
    bool negative = um < 0;
    uint32_t m = negative ? 0u - static_cast<uint32_t>(um) : static_cast<uint32_t>(um);
    uint32_t frac = g_settings.axis[axis].steps_per_unit;
    if (sc.whole != 0) frac -= sc.whole * 1000000u;
    uint32_t q, lo;
    num::mul64(m, sc.k, q, lo);
    uint32_t r = m * frac - q * 1000000u;
    if (r >= 1000000u) {
        r -= 1000000u;
        ++q;
    }
    if (r >= 500000u) ++q; // half away from zero, on the magnitude
    if (sc.whole != 0) {
        uint32_t hi, whole;
        num::mul64(m, sc.whole, hi, whole);
        if (hi != 0 || __builtin_add_overflow(q, whole, &q)) return false;
    }
    if (q > 0x7FFFFFFFu) return false;
    steps = negative ? -static_cast<int32_t>(q) : static_cast<int32_t>(q);
    return true;
}

uint8_t execute(const char* line, uint8_t flags, Outcome& outcome) {
    State& st = g_state;
    outcome.then = Then::Nothing;
    outcome.dwell_ms = 0;

    // ---- Stage 1: a block that starts from the current modes.
    Block& b = w.b;
    b.modal = st.modal;
    b.non_modal = kNoNonModal;
    b.axis_command = kAxisNone;
    b.flow = kFlowRunning;
    b.axis_words = 0;
    b.l = 0xFF;
    b.tool = st.tool;
    b.groups = 0;
    b.words = 0;
    b.n = 0;
    b.s = st.spindle_speed;

    // ---- Stage 2: import every word (letter + number), checking repeats, modal groups and
    // negative F N P S T.
    uint8_t i = 0;
    while (line[i] != 0) {
        char letter = line[i++];
        if (letter < 'A' || letter > 'Z') return kExpectedCommandLetter;
        num::Decimal d;
        if (!num::parse(line, i, d)) return kBadNumberFormat;
        uint8_t r = letter == 'G'   ? import_g(b, d)
                    : letter == 'M' ? import_m(b, d)
                                    : import_value(b, letter, d);
        if (r != kOk) return r;
    }

    // ---- Stage 3: check the block as a whole and compute everything it will change.
    // [0] Axis words without a command that uses them: the current motion mode does.
    if (b.axis_words != 0 && b.axis_command == kAxisNone) b.axis_command = kAxisMotion;
    if ((b.words & bit(kWordN)) && b.n == kNoLineNumber) return kInvalidLineNumber;

    // [3] Feed rate (G94 only): a new F in the units of the block, or the last one.
    uint32_t feed = st.feed;
    if (b.words & bit(kWordF)) {
        int32_t f;
        if (!length(b, kWordF, f)) return kBadNumberFormat;
        feed = static_cast<uint32_t>(f);
    }

    // [10] Dwell: P seconds.
    int32_t dwell_ms = 0;
    if (b.non_modal == kDwellCmd) {
        if (!(b.words & bit(kWordP))) return kValueWordMissing;
        if (!num::to_milli(b.v[kWordP], dwell_ms)) return kBadNumberFormat;
        b.words &= static_cast<uint16_t>(~bit(kWordP));
    }

    // [15] Coordinate system: G54 only.
    if (b.modal.coord != 0) return kUnsupportedCoordSys;

    // [19] Non-modal commands that use axis words, and the motion target.
    int32_t* values = w.values;
    for (uint8_t a = 0; a < kAxes; ++a) {
        values[a] = 0;
        if (has_axis(b.axis_words, a)) {
            if (!length(b, static_cast<uint8_t>(kDecimalWords + a), values[a])) {
                return kBadNumberFormat;
            }
        }
    }
    int32_t* offsets = w.offsets;
    motion::LineRequest& req = w.req;
    switch (b.non_modal) {
        case kSetCoordData: { // G10 L2 / L20 P0|P1: G54
            if (b.axis_words == 0) return kNoAxisWords;
            if (!(b.words & bit(kWordP)) || !(b.words & bit(kWordL))) {
                return kValueWordMissing;
            }
            uint32_t p;
            if (!num::to_uint(b.v[kWordP], 255u, p) || p > 1) return kUnsupportedCoordSys;
            if (b.l != 2 && b.l != 20) return kUnsupportedCommand;
            if (b.l == 2 && (b.words & bit(kWordR))) return kUnsupportedCommand;
            b.words &= static_cast<uint16_t>(~(bit(kWordL) | bit(kWordP)));
            for (uint8_t a = 0; a < kAxes; ++a) {
                offsets[a] = st.g54[a];
                if (!(has_axis(b.axis_words, a))) continue;
                if (b.l == 2) {
                    offsets[a] = values[a];
                } else if (!sub(st.position[a], st.g92[a], offsets[a]) ||
                           !sub(offsets[a], values[a], offsets[a])) {
                    return kInvalidTarget;
                }
            }
            break;
        }
        case kSetOffset: // G92: the current position becomes the given work position
            if (b.axis_words == 0) return kNoAxisWords;
            for (uint8_t a = 0; a < kAxes; ++a) {
                offsets[a] = st.g92[a];
                if (!(has_axis(b.axis_words, a))) continue;
                if (!sub(st.position[a], st.g54[a], offsets[a]) ||
                    !sub(offsets[a], values[a], offsets[a])) {
                    return kInvalidTarget;
                }
            }
            break;
        default:
            if (b.non_modal == kAbsoluteOverride && b.modal.motion != Motion::Seek &&
                b.modal.motion != Motion::Linear) {
                return kG53InvalidMotionMode;
            }
            if (b.axis_command != kAxisMotion) break;
            for (uint8_t a = 0; a < kAxes; ++a) {
                int32_t t = st.position[a];
                int32_t steps = st.position_steps[a];
                if (has_axis(b.axis_words, a)) {
                    t = values[a];
                    bool ok = true;
                    if (b.non_modal == kAbsoluteOverride) {
                        // G53: machine coordinates, whatever the distance mode
                    } else if (b.modal.incremental) {
                        ok = add(st.position[a], t, t);
                    } else {
                        ok = add(t, st.g54[a], t) && add(t, st.g92[a], t);
                    }
                    // Always from the absolute target: no rounding error accumulates.
                    if (!ok || !um_to_steps(a, t, steps)) return kInvalidTarget;
                    // One move travels at most kMaxLineTicks steps per axis (line.h).
                    if (abs32(steps - st.position_steps[a]) > kMaxLineTicks) return kInvalidTarget;
                }
                req.target_um[a] = t;
                req.target_steps[a] = steps;
            }
            break;
    }

    // [20] Motion modes.
    if (b.modal.motion == Motion::None) {
        if (b.axis_words != 0) return kAxisWordsExist;
    } else if (b.axis_command == kAxisMotion) {
        if (b.modal.motion != Motion::Seek && feed == 0) return kUndefinedFeedRate;
        if (b.axis_words == 0) b.axis_command = kAxisNone; // G0/G1 alone: a mode change only
    }

    // [0] Every word must have been used.
    // (Axis words always have a user by now: the motion mode takes them, or G80 refused them.)
    uint16_t unused =
        b.words & static_cast<uint16_t>(~(bit(kWordN) | bit(kWordF) | bit(kWordS) | bit(kWordT)));
    if (unused != 0) return kUnusedWords;

    // ---- The block is valid. Conditions to wait for, still without any side effect.
    bool check = (flags & kCheckMode) != 0;
    bool moves = b.axis_command == kAxisMotion;
    if (!check) {
        if (b.non_modal == kDwellCmd && !(flags & kDwellDone)) {
            outcome.dwell_ms = static_cast<uint32_t>(dwell_ms);
            return kDwell;
        }
        if ((b.non_modal == kSetCoordData || b.non_modal == kSetOffset ||
             b.non_modal == kResetOffset) &&
            motion::state() != motion::State::Idle) {
            return kRetryWhenIdle;
        }
        if (moves && !motion::can_accept()) return kRetryWhenAccepting;
    }

    // ---- Stage 4: execute, in GRBL's order.
    st.line_number = b.n;
    st.feed = feed;
    st.spindle_speed = b.s;
    st.tool = b.tool;
    st.modal.spindle = b.modal.spindle;
    st.modal.coolant = b.modal.coolant;
    st.modal.plane = b.modal.plane;
    st.modal.inches = b.modal.inches;
    st.modal.incremental = b.modal.incremental;
    if (b.non_modal == kSetCoordData) {
        for (uint8_t a = 0; a < kAxes; ++a) st.g54[a] = offsets[a];
        if (!check) settings::save_coord(st.g54);
        st.wco_changed = 1;
    } else if (b.non_modal == kSetOffset || b.non_modal == kResetOffset) {
        for (uint8_t a = 0; a < kAxes; ++a) {
            st.g92[a] = b.non_modal == kSetOffset ? offsets[a] : 0;
        }
        st.wco_changed = 1;
    }
    st.modal.motion = b.modal.motion;
    if (moves) {
        req.feed = feed;
        req.rapid = b.modal.motion == Motion::Seek;
        if (!check) motion::push_line(req); // cannot refuse: the length was checked above
        for (uint8_t a = 0; a < kAxes; ++a) {
            st.position[a] = req.target_um[a];
            st.position_steps[a] = req.target_steps[a];
        }
    }
    if (b.flow == kFlowPause) {
        if (!check) outcome.then = Then::Pause;
    } else if (b.flow == kFlowEnd) {
        // Program end resets groups 1 2 3 5 7 12 and M7 M8 M9, as GRBL (after LinuxCNC) does.
        st.modal.motion = Motion::Linear;
        st.modal.plane = 0;
        st.modal.incremental = 0;
        st.modal.coord = 0;
        st.modal.spindle = 5;
        st.modal.coolant = 9;
        outcome.then = Then::ProgramEnd;
    }
    return kOk;
}

bool reset() {
    State& st = g_state;
    st.modal.motion = Motion::Seek;
    st.modal.plane = 0;
    st.modal.inches = 0;
    st.modal.incremental = 0;
    st.modal.coord = 0;
    st.modal.spindle = 5;
    st.modal.coolant = 9;
    st.feed = 0;
    st.spindle_speed = 0;
    st.tool = 0;
    st.line_number = 0;
    for (uint8_t a = 0; a < kAxes; ++a) st.g92[a] = 0;
    bool ok = settings::load_coord(st.g54);
    settings_changed(); // the step scales
    sync_position();
    st.wco_changed = 1;
    return ok;
}

void sync_position() {
    int32_t steps[kAxes];
    motion::position(steps);
    for (uint8_t a = 0; a < kAxes; ++a) {
        g_state.position_steps[a] = steps[a];
        num::mul_div_round(steps[a], 1000000u, g_settings.axis[a].steps_per_unit,
                           g_state.position[a]);
    }
}

void settings_changed() {
    for (uint8_t a = 0; a < kAxes; ++a) {
        uint32_t s = g_settings.axis[a].steps_per_unit;
        uint16_t whole = static_cast<uint16_t>(s / 1000000u);
        uint32_t rem;
        g_scale[a].whole = whole;
        g_scale[a].k = num::div64(s - whole * 1000000u, 0, 1000000u, rem);
        um_to_steps(a, g_state.position[a], g_state.position_steps[a]);
    }
}

void work_offset(int32_t (&um)[kAxes]) {
    for (uint8_t a = 0; a < kAxes; ++a) {
        um[a] = static_cast<int32_t>(static_cast<uint32_t>(g_state.g54[a]) +
                                     static_cast<uint32_t>(g_state.g92[a]));
    }
}

void report_modes() {
    const Modal& m = g_state.modal;
    static const uint8_t kMotionCode[8] LL_PROGMEM = {0, 1, 2, 3, 2, 3, 5, 80};
    uint8_t motion = static_cast<uint8_t>(m.motion);
    out::str(LL_PSTR("[GC:G"));
    out::u32(flash_read_byte(&kMotionCode[motion]));
    if (m.motion == Motion::EllipseCw || m.motion == Motion::EllipseCcw) out::str(LL_PSTR(".1"));
    out::str(LL_PSTR(" G"));
    out::u32(54u + m.coord);
    out::str(LL_PSTR(" G"));
    out::u32(17u + m.plane);
    out::str(m.inches ? LL_PSTR(" G20 G") : LL_PSTR(" G21 G"));
    out::u32(90u + m.incremental);
    out::str(LL_PSTR(" G94 M"));
    out::u32(m.spindle);
    out::str(LL_PSTR(" M"));
    out::u32(m.coolant);
    out::str(LL_PSTR(" T"));
    out::u32(g_state.tool);
    out::str(LL_PSTR(" F"));
    out::rate(g_state.feed);
    out::str(LL_PSTR(" S"));
    out::u32(g_state.spindle_speed);
    out::ch(']');
    out::eol();
}

void report_offsets() {
    static const int32_t kZero[kAxes] = {};
    for (uint8_t g = 54; g <= 59; ++g) {
        out::str(LL_PSTR("[G"));
        out::u32(g);
        out::ch(':');
        out::coords(g == 54 ? g_state.g54 : kZero);
        out::ch(']');
        out::eol();
    }
    out::str(LL_PSTR("[G28:"));
    out::coords(kZero);
    out::str(LL_PSTR("]\r\n[G30:"));
    out::coords(kZero);
    out::str(LL_PSTR("]\r\n[G92:"));
    out::coords(g_state.g92);
    out::str(LL_PSTR("]\r\n[TLO:"));
    out::fixed(0, g_settings.report_inches ? 4 : 3);
    out::str(LL_PSTR("]\r\n[PRB:"));
    out::coords(kZero);
    out::str(LL_PSTR(":0]\r\n"));
}

} // namespace gcode
} // namespace ll
