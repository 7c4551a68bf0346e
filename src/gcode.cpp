// G-code parser and executor. See gcode.h; the stages follow GRBL's gc_execute_line.
#include "lowlevel/gcode.h"

#include <stddef.h>
#include <string.h>

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

// Modal groups (NIST RS274NGC table 4; GRBL's numbering in the comments). A block keeps the
// value each command gives its group in Block::g[group]: 0 is the program flow, 1 to 7 are the
// bytes of Modal in order, then T and L (not groups: the bytes after Modal, as State::tool
// follows State::modal, so that Modal and the tool are copied as two words), 10 the non-modal
// command. The groups from kGroupArcDistance on have one command each that changes nothing:
// they only count for error:21.
enum Group : uint8_t {
    kGroupFlow,        // M0 M1 M2 M30 (M4)
    kGroupMotion,      // G0 G1 G80, later G2 G3 G2.1 G3.1 G5 (G1)
    kGroupPlane,       // G17 G18 G19 (G2)
    kGroupUnits,       // G20 G21 (G6)
    kGroupDistance,    // G90 G91 (G3)
    kGroupCoord,       // G54..G59 (G12)
    kGroupSpindle,     // M3 M4 M5 (M7)
    kGroupCoolant,     // M8 M9 (M8)
    kBlockTool,        // (T, Block::g's byte after Modal's)
    kBlockL,           // (L, 0xFF when not an integer 0..254)
    kGroupNonModal,    // G4 G10 G53 G92 G92.1 (G0)
    kGroupArcDistance, // G91.1 (G4)
    kGroupFeedMode,    // G94 (G5)
    kGroupCutter,      // G40 (G7)
    kGroupToolLength,  // G49 (G8)
    kGroupPath,        // G61 (G13)
};
static_assert(offsetof(Modal, motion) == kGroupMotion - 1 &&
                  offsetof(Modal, plane) == kGroupPlane - 1 &&
                  offsetof(Modal, inches) == kGroupUnits - 1 &&
                  offsetof(Modal, incremental) == kGroupDistance - 1 &&
                  offsetof(Modal, coord) == kGroupCoord - 1 &&
                  offsetof(Modal, spindle) == kGroupSpindle - 1 &&
                  offsetof(Modal, coolant) == kGroupCoolant - 1 && sizeof(Modal) == 7,
              "Modal holds the groups 1..7 as bytes, in group order");

enum NonModal : uint8_t {
    kNoNonModal,
    kDwellCmd,
    kSetCoordData,
    kAbsoluteOverride,
    kSetOffset,
    kResetOffset
};

// Which command uses the axis words of the block (GRBL's AXIS_COMMAND_*).
enum AxisCommand : uint8_t {
    kAxisNone,
    kAxisMotion = kGroupMotion + 1,
    kAxisNonModal = kGroupNonModal + 1,
};

enum Flow : uint8_t { kFlowRunning, kFlowPause, kFlowEnd };

// G and M commands: one 3-byte row each, searched in order.
//   key:   the G number, or 0x80 + the M number
//   group: the modal group, and the decimal of the command (G92.1 -> 1) in the high nibble
//   value: what the command sets its group to, and flags
enum : uint8_t {
    kUsesAxes = 0x40, // uses the axis words: two of these in a block is error:24
    kStrict = 0x80,   // another decimal of this number is unsupported (20), not fractional (23)
};
constexpr uint8_t kM = 0x80;
struct Command {
    uint8_t key, group, value;
};
constexpr uint8_t dec1 = 1 << 4; // group byte of a command with decimal 1

// In the order of their frequency in CAM output: the search stops at the first match.
const Command kCommands[] LL_PROGMEM = {
    {1, kGroupMotion, uint8_t(Motion::Linear) | kUsesAxes},
    {0, kGroupMotion, uint8_t(Motion::Seek) | kUsesAxes},
    {90, kGroupDistance, 0 | kStrict}, // G90.1: 20
    {91, kGroupDistance, 1 | kStrict},
    {21, kGroupUnits, 0},
    {20, kGroupUnits, 1},
    {17, kGroupPlane, 0},
    {94, kGroupFeedMode, 0},
    {54, kGroupCoord, 0},
    {kM | 3, kGroupSpindle, 3},
    {kM | 5, kGroupSpindle, 5},
    {kM | 8, kGroupCoolant, 8},
    {kM | 9, kGroupCoolant, 9},
    {kM | 30, kGroupFlow, kFlowEnd},
    {kM | 2, kGroupFlow, kFlowEnd},
    {4, kGroupNonModal, kDwellCmd},
    {92, kGroupNonModal, kSetOffset | kUsesAxes | kStrict},
    {53, kGroupNonModal, kAbsoluteOverride},
    {80, kGroupMotion, uint8_t(Motion::None)},
    {18, kGroupPlane, 1},
    {19, kGroupPlane, 2},
    {40, kGroupCutter, 0},     // cutter compensation off: always off
    {49, kGroupToolLength, 0}, // tool length offset off: always off
    {61, kGroupPath, kStrict}, // G61.1: 20
    {kM | 0, kGroupFlow, kFlowPause},
    {kM | 1, kGroupFlow, kFlowRunning}, // M1 (optional stop): accepted and ignored, as GRBL
    {kM | 4, kGroupSpindle, 4},
    {10, kGroupNonModal, kSetCoordData | kUsesAxes},
    {92, kGroupNonModal | dec1, kResetOffset | kStrict},
    {91, kGroupArcDistance | dec1, kStrict}, // G91.1: arc centres incremental, the default
    {55, kGroupCoord, 1},
    {56, kGroupCoord, 2},
    {57, kGroupCoord, 3},
    {58, kGroupCoord, 4},
    {59, kGroupCoord, 5},
    // Curves stepped in the low level (seed part IV, docs/curves.md).
    {2, kGroupMotion, uint8_t(Motion::ArcCw) | kUsesAxes | kStrict},
    {3, kGroupMotion, uint8_t(Motion::ArcCcw) | kUsesAxes | kStrict},
    {2, kGroupMotion | dec1, uint8_t(Motion::EllipseCw) | kUsesAxes | kStrict},
    {3, kGroupMotion | dec1, uint8_t(Motion::EllipseCcw) | kUsesAxes | kStrict},
    {5, kGroupMotion, uint8_t(Motion::Bezier) | kUsesAxes | kStrict},
};
constexpr uint8_t kCommandCount = sizeof(kCommands) / sizeof(kCommands[0]);

// Value words, numbered so that their bit in Block::words is their number: the axes first, then
// F, P and the curves' I J K Q R (kept as decimals until the units of the block are known), the
// other words. I J K are the offsets along X Y Z (so kWordI + axis for X, Y, Z).
enum Word : uint8_t {
    kWordF = kAxes,
    kWordP,
    kWordI,
    kWordJ,
    kWordK,
    kWordQ,
    kWordR,
    kWordS,
    kWordN,
    kWordL,
    kWordT,
    kWordCount
};
static_assert(kWordS < kWordN && kWordT == kWordL + 1 && kWordT == kWordCount - 1, "S, N L T last");
constexpr uint8_t kDecimalSlots = kWordR + 1;
constexpr uint8_t kLetterG = 0xFD, kLetterM = 0xFE, kLetterNone = 0xFF;

template <bool Small>
struct MaskOf {
    using type = uint16_t;
};
template <>
struct MaskOf<false> {
    using type = uint32_t;
};
using WordMask = MaskOf<kWordCount <= 16>::type;

constexpr WordMask bit(uint8_t w) {
    return static_cast<WordMask>(WordMask(1) << w);
}
constexpr WordMask kAxisWords = static_cast<WordMask>(bit(kAxes) - 1);
// (P may be negative in a G5 only: checked in stage 3.)
constexpr WordMask kNotNegative = bit(kWordF) | bit(kWordN) | bit(kWordS) | bit(kWordT);
// Words that a command must consume.
constexpr WordMask kMustBeUsed =
    bit(kWordP) | bit(kWordL) | bit(kWordI) | bit(kWordJ) | bit(kWordK) | bit(kWordQ) | bit(kWordR);

constexpr uint8_t axis_letter(uint8_t a) {
    return a < kAxes ? a : kLetterNone;
}
// What each letter A..Z is.
const uint8_t kLetterInfo[26] LL_PROGMEM = {
    axis_letter(3), axis_letter(4), axis_letter(5), // A B C
    kLetterNone,    kLetterNone,    kWordF,         // D E F
    kLetterG,       kLetterNone,    kWordI,         // G H I
    kWordJ,         kWordK,         kWordL,         // J K L
    kLetterM,       kWordN,         kLetterNone,    // M N O
    kWordP,         kWordQ,         kWordR,         // P Q R
    kWordS,         kWordT,         kLetterNone,    // S T U
    kLetterNone,    kLetterNone,    axis_letter(0), // V W X
    axis_letter(1), axis_letter(2),                 // Y Z
};

constexpr uint32_t kNoLineNumber = 0xFFFFFFFFu;

// An axis, F, P, I J K Q R word: the number as read, then (axes) its value in um once the units
// are known.
union Slot {
    num::Decimal d;
    int32_t um;
};

struct Block {
    uint8_t g[kGroupNonModal + 1]; // the value of each group with a value, T and L (see Group)
    uint8_t axis_command;
    uint8_t overflow; // an offset or target does not fit an int32 (see add())
    uint16_t groups;  // modal groups commanded in this block
    WordMask words;   // value words present, bit(Word)
    // As State::feed, spindle_speed and line_number (copied as one).
    uint32_t feed;
    uint32_t s;
    uint32_t n;
    union {
        Slot v[kDecimalSlots]; // the axes, F, P, I J K Q R
        // Stage 3 and 4 of a curve, handed to the planner with the move: written once the axes
        // and F are in um (stage 3 [19]) and check_curve() has read P I J K Q R, so that it
        // only overlays the slots of the axes and F (40 bytes of RAM less).
        CurveParams curve;
    };
};
static_assert(sizeof(CurveParams) <= kWordP * sizeof(Slot),
              "the curve overlays the axis and F slots only");
static_assert(offsetof(Block, n) - offsetof(Block, feed) ==
                  offsetof(State, line_number) - offsetof(State, feed),
              "feed, S and N are laid out as in State");

// The block being checked and what it computes, kept static: a stack frame this large costs
// the AVR an address computation on every access (displacements stop at 63 bytes), and the
// static size is visible to the RAM budget.
struct Work {
    Block b;
    union {
        num::Decimal other; // stage 2: a G, M, N, L, S, T, I, J, K, Q or R number
        // Stage 3 and 4: the move; for G10 / G92, target_um holds the new offsets (such a
        // block never moves).
        motion::LineRequest req;
    };
};
static_assert(offsetof(Work, other) == offsetof(Work, b) + offsetof(Block, v) + sizeof(Block::v),
              "Work::other is the slot past the block's last one");
// In the motion side's scratch RAM (motion.h: it is ours from execute() until push_line()).
static_assert(sizeof(void*) != 2 || sizeof(Work) == motion::kScratchBytes,
              "motion::kScratchBytes is the size of the work block on the AVR");
// Under push_line(), curve_shape() keeps its track in the slots past the curve (P I J K Q R,
// read by check_curve() before the curve was written): only the curve and req are live then.
static_assert(offsetof(Work, b) + offsetof(Block, v) + sizeof(CurveParams) <= kCurveTrackAt &&
                  kCurveTrackAt + kCurveTrackBytes <= offsetof(Block, v) + sizeof(Block::v) &&
                  offsetof(Block, v) + sizeof(Block::v) <= offsetof(Work, req),
              "the curve track (scratch.h) overlays dead slots of the work block only");
// And probe()'s derivatives its header, which execute() writes afresh from stage 1 on.
static_assert(kCurveProbeAt + kCurveProbeBytes <= offsetof(Work, b) + offsetof(Block, v) &&
                  kCurveProbeAt + kCurveProbeBytes <= kCurveTrackAt,
              "the curve's derivatives (scratch.h) overlay the work block's header only");
inline Work& work() {
    return motion::scratch<Work>();
}

// x through a pointer the compiler cannot see through: its fields are then read and written with
// a displacement from a pointer register (2 bytes an instruction), not at absolute addresses
// (lds/sts, 4 bytes).
template <typename T>
T& opaque(T& x) {
    T* p = &x;
    asm("" : "+r"(p));
    return *p;
}

// The first decimal of a command number (G92.1 -> 1) in the high nibble, as in Command::group,
// or 0xFF with a finer fraction (G1.05).
uint8_t tenths(const num::Decimal& d) {
    if (d.sub != 0 || (d.frac != 0 && (d.flags & num::Decimal::kInexact) != 0)) return 0xFF;
    uint8_t t = 0;
    for (uint16_t f = d.frac; f != 0; f = static_cast<uint16_t>(f - 100u)) {
        if (f < 100) return 0xFF;
        t = static_cast<uint8_t>(t + 0x10);
    }
    return t;
}

// Stage 2 for a G or M word (unsupported: 20, two from one modal group: 21, two that use axis
// words: 24, a decimal where none is defined: 23).
uint8_t import_command(Block& b, uint8_t m, const num::Decimal& d) {
    if (m != 0 && !d.integral()) return kCommandValueNotInteger;
    if (d.negative() || d.ipart > 127) return kUnsupportedCommand;
    uint8_t key = static_cast<uint8_t>(d.ipart | m);
    uint8_t dec = tenths(d);
    const Command* c = nullptr;
    bool found = false;
    const Command* e = kCommands;
    for (uint8_t n = kCommandCount; n != 0; --n, ++e) {
        if (flash_read_byte(&e->key) != key) continue;
        c = e;
        if ((flash_read_byte(&e->group) & 0xF0) == dec) {
            found = true;
            break;
        }
    }
    if (c == nullptr) return kUnsupportedCommand; // G28 G30 G38.x G43.1 G64 G93 M6 M7 ...
    uint8_t group = flash_read_byte(&c->group) & 0x0F;
    uint8_t value = flash_read_byte(&c->value);
    if (!found && (value & kStrict)) return kUnsupportedCommand; // G61.1 G90.1 G92.2 ...
    // As GRBL: the axis-word conflict is checked before the decimal and the modal group.
    if (value & kUsesAxes) {
        if (b.axis_command != kAxisNone) return kAxisCommandConflict;
        // (Only the motion and the non-modal group's commands use axes.)
        static_assert(kGroupNonModal + 1 == kAxisNonModal && kGroupMotion + 1 == kAxisMotion,
                      "the axis command of a group is its number + 1");
        b.axis_command = static_cast<uint8_t>(group + 1);
    }
    if (!found) return kCommandValueNotInteger;
    uint16_t gbit = static_cast<uint16_t>(1u << group);
    if (b.groups & gbit) return kModalGroupViolation;
    b.groups |= gbit;
    if (group <= kGroupNonModal) b.g[group] = value & 0x0F; // (never kBlockTool, kBlockL)
    return kOk;
}

// Stage 2 for any other word, already read into its slot or into Work::other.
uint8_t import_value(Block& b, uint8_t word, const num::Decimal& d) {
    WordMask wbit = bit(word);
    if (b.words & wbit) return kWordRepeated;
    if (d.negative() && (wbit & kNotNegative)) return kNegativeValue;
    b.words |= wbit;
    if (word == kWordS) {
        uint32_t v = d.ipart;
        if (d.frac >= 500) ++v; // rounded half up
        b.s = v;
    } else if (word >= kWordN) { // N L T (the last words)
        // N 0..10000000 and L 0..254 (else checked in stage 3), T 0..255.
        uint32_t v;
        if (!num::to_uint(d, word == kWordN ? 10000000u : 254u + word - kWordL, v)) {
            if (word == kWordT) return d.integral() ? kMaxValueExceeded : kCommandValueNotInteger;
            v = kNoLineNumber; // for L: 0xFF
        }
        if (word == kWordN) {
            b.n = v;
        } else {
            b.g[kBlockL + kWordL - word] = static_cast<uint8_t>(v); // L, T
        }
    }
    return kOk;
}

// The length word `word` of the block (its slot), in the units of the block, to um (or a feed to
// mm/min x1000).
__attribute__((noinline)) bool length(uint8_t word, int32_t& out) {
    static_assert(sizeof(bool) == 1, "a bool is a byte");
    bool inches; // (the byte is 0 or 1 already: copied, not tested)
    memcpy(&inches, &work().b.g[kGroupUnits], 1);
    return num::length_to_milli(work().b.v[word].d, inches, out);
}

// um along axis a to steps, rounded (false when out of the int32 range).
__attribute__((noinline)) bool to_steps(int32_t um, uint8_t a, int32_t& steps) {
    return num::mul_div_round(um, g_settings.axis[a].steps_per_unit, 1000000u, steps);
}

// a + b, a - b with kSub (or any other value but 0 and kKeep: combine2()'s ops), or a alone with
// kKeep; an overflow sets Block::overflow (checked once
// per line: error:33).
enum AddOp : uint8_t { kAdd, kSub, kKeep = 4 };
__attribute__((noinline)) int32_t add(int32_t a, int32_t b, uint8_t subtract = kAdd) {
#if defined(__AVR__)
    // The chip's add/adc or sub/sbc chain, whose V flag is the signed overflow: the function
    // takes 48 bytes and about 25 cycles, the portable test below 100 bytes and about 50. (The
    // simavr checks run it: fw_test_*.)
    uint8_t v = 0;
    asm("sbrc %[s], 2\n\t"
        "rjmp 3f\n\t"
        "cpse %[s], __zero_reg__\n\t"
        "rjmp 1f\n\t"
        "add %A[a], %A[b]\n\t"
        "adc %B[a], %B[b]\n\t"
        "adc %C[a], %C[b]\n\t"
        "adc %D[a], %D[b]\n\t"
        "rjmp 2f\n"
        "1:\n\t"
        "sub %A[a], %A[b]\n\t"
        "sbc %B[a], %B[b]\n\t"
        "sbc %C[a], %C[b]\n\t"
        "sbc %D[a], %D[b]\n"
        "2:\n\t"
        "brvc 3f\n\t"
        "inc %[v]\n"
        "3:"
        : [a] "+r"(a), [v] "+r"(v)
        : [b] "r"(b), [s] "r"(subtract));
    if (v) work().b.overflow = 1;
    return a;
#else
    // Bit 31 of (a ^ r) & (b' ^ r) is the signed overflow of r = a + b'.
    if (subtract == kKeep) return a;
    uint32_t ua = static_cast<uint32_t>(a), ub = static_cast<uint32_t>(b);
    if (subtract) ub = ~ub; // a - b = a + ~b + 1, and overflows as a + ~b would
    uint32_t r = ua + ub + (subtract != kAdd);
    if (((ua ^ r) & (ub ^ r)) >> 31) work().b.overflow = 1;
    return static_cast<int32_t>(r);
#endif
}

// Copies `words` 32-bit words: 4 cycles a byte on the AVR, against 7 for memcpy's byte loop.
__attribute__((noinline)) void copy_words(void* dst, const void* src, uint8_t words) {
    uint8_t* d = static_cast<uint8_t*>(dst);
    const uint8_t* s = static_cast<const uint8_t*>(src);
#if defined(__AVR__)
    // X and Z post-increment through the scratch register: the compiler's version kept a word in
    // saved registers (or its pointer in Y), for 10 B and 10 cycles a call more.
    asm volatile("1:\n\t"
                 "ld  __tmp_reg__, Z+\n\t"
                 "st  X+, __tmp_reg__\n\t"
                 "ld  __tmp_reg__, Z+\n\t"
                 "st  X+, __tmp_reg__\n\t"
                 "ld  __tmp_reg__, Z+\n\t"
                 "st  X+, __tmp_reg__\n\t"
                 "ld  __tmp_reg__, Z+\n\t"
                 "st  X+, __tmp_reg__\n\t"
                 "dec %[n]\n\t"
                 "brne 1b"
                 : "+x"(d), "+z"(s), [n] "+r"(words)
                 :
                 : "memory");
#else
    do {
        uint32_t v;
        memcpy(&v, s, sizeof(v));
        memcpy(d, &v, sizeof(v));
        d += sizeof(v);
        s += sizeof(v);
    } while (--words != 0);
#endif
}

void set_end_modes(Modal& m) {
    // Program end resets groups 1 2 3 5 7 12 and M7 M8 M9, as GRBL (after LinuxCNC) does.
    m.motion = Motion::Linear;
    m.plane = 0;
    m.incremental = 0;
    m.coord = 0;
    m.spindle = 5;
    m.coolant = 9;
}

// Two points of the plane combined per coordinate: p - q, |p - q| (kMagnitudes, as uint32_t: 2^31
// for INT32_MIN) or p + q (kSum). An overflow flags the block, as add() does. (add() takes the op:
// kSum adds, the others subtract.)
enum Op2 : uint8_t { kSum = kAdd, kDifference = kSub, kMagnitudes = 2 };
__attribute__((noinline)) void combine2(int32_t out[2], const int32_t p[2], const int32_t q[2],
                                        uint8_t op = kDifference) {
    for (uint8_t k = 0; k < 2; ++k) {
        int32_t v = add(p[k], q[k], op);
        out[k] = op == kMagnitudes ? static_cast<int32_t>(abs32(v)) : v;
    }
}

// |p - q| for two points of the plane, um.
// (Into the caller's Num: returned, it would be copied through registers twice.) Returns its
// floor.
__attribute__((noinline)) uint32_t dist_um(const int32_t p[2], const int32_t q[2], Num& out) {
    uint32_t v[2];
    combine2(reinterpret_cast<int32_t*>(v), p, q, kMagnitudes);
    out = sum_squares(v, 2);
    return out.sqrt().u32();
}

// plane_axes() as a rotation: (u, v, w) = axes (k - plane) mod 3.
__attribute__((noinline)) void axes_of(uint8_t plane, uint8_t ax[3]) {
    uint8_t a = static_cast<uint8_t>(3 - plane); // 3 for G17: wraps to 0 at once
    for (uint8_t k = 3; k != 0; --k) {
        asm("" : "+r"(k)); // (counted in k: the compiler would compare the pointer instead)
        if (a == 3) a = 0;
        *ax++ = a++;
    }
}

// out = the coordinates of `from` along the plane's axes ax[0], ax[1].
__attribute__((noinline)) void pick2(int32_t out[2], const int32_t* from, const uint8_t ax[2]) {
    for (uint8_t k = 2; k != 0; --k) {
        asm("" : "+r"(k)); // a loop: unrolled, the two copies take 78 B
        *out++ = from[*ax++];
    }
}

// The step generator's fixed-point range (docs/curves.md): the ends, the control points or the
// centre, and the semi-axes, within 2^22 steps; the length within 2^23 um (an arc's is at most
// its larger semi-axis times its sweep; a Bezier's at most its control polygon's), and the
// normal axis' travel too. An ellipse's ends must also be on it within the larger step + 2 um:
// each coordinate that close to the ellipse's point that has the same direction in the
// ellipse's own scale (ellipse_direction). (A function of its own, called by execute() after
// check_curve(): a small stack frame, not on top of check_curve()'s.)
__attribute__((noinline)) bool curve_in_range(const CurveParams& c, bool ellipse) {
    uint8_t ax[3];
    axes_of(c.plane, ax);
    static_assert(offsetof(CurveParams, end_um) == offsetof(CurveParams, start_um) + 8 &&
                      offsetof(CurveParams, a_um) == offsetof(CurveParams, start_um) + 16 &&
                      offsetof(CurveParams, b_um) == offsetof(CurveParams, start_um) + 24,
                  "start, end, a, b: four points in a row");
    const int32_t* const row = c.start_um; // (a pointer: indexing the array past 2 is undefined)
    uint32_t spu_min = 0xFFFFFFFFu;
    for (uint8_t i = 0; i < 8; ++i) {
        int32_t steps;
        uint8_t a = ax[0]; // ax[i & 1], without the computed index (12 B)
        if (i & 1) a = ax[1];
        uint32_t spu = g_settings.axis[a].steps_per_unit;
        if (spu < spu_min) spu_min = spu;
        // (|steps| > 2^22 as one unsigned comparison: steps + 2^22 wraps above 2^23. A result
        // out of the int32 range is saturated to +-(2^31 - 1): out of this one too.)
        to_steps(row[i], a, steps);
        if (static_cast<uint32_t>(static_cast<uint32_t>(steps) + (uint32_t(1) << 22)) >
            (uint32_t(1) << 23)) {
            return false;
        }
    }
    // A circle's ends are checked in check_curve().
    uint32_t gap_um = 1000000ul / spu_min + 2; // (an ellipse's; spu > 0: $100.. refuse 0)
    Num reach{};                               // length bound, um
    if (c.kind == kCurveBezier) {
        // The control polygon start, a, b, end: points 0 2 3 1 of the row, 2 bits each.
        // (The loop runs on seq, not on a 16-bit trip count the compiler would add: the asm.)
        const int32_t* prev = row;
        for (uint8_t seq = 0x1E; seq != 0; seq = static_cast<uint8_t>(seq >> 2)) {
            asm("" : "+r"(seq));
            const int32_t* point = row + 2 * (seq & 3);
            uint32_t d[2];
            combine2(reinterpret_cast<int32_t*>(d), point, prev, kMagnitudes);
            reach.add(Num(d[0])).add(Num(d[1]));
            prev = point;
        }
    } else {
        const uint32_t* radii = reinterpret_cast<const uint32_t*>(c.b_um);
        // The ends' directions, the end first for a clockwise arc: its sweep is then the
        // counter-clockwise one from the end to the start (sweep_q29 swaps them so), >= 0.
        int32_t cs[4];
        for (uint8_t e = 0; e < 2; ++e) {
            int32_t p[2];
            combine2(p, row + 2 * e, c.a_um);
            int32_t* cse = &cs[2 * (e ^ c.clockwise)];
            ellipse_direction(p[0], p[1], radii, cse[0], cse[1]);
            for (uint8_t k = 0; k < 2; ++k) {
                uint32_t on = Num(abs32(cse[k]), -30).mul(radii[k]).u32(); // r |cs| (Q30)
                // p - sign(cs) on, as |p| - on: the same magnitude (cs has the sign of p, or is
                // 0: ellipse_direction() scales |p| and then gives it p's sign).
                uint32_t d = abs32(p[k]) - on;
                if (ellipse && abs32(static_cast<int32_t>(d)) > gap_um) return false;
            }
        }
        int64_t sweep = arc_sweep_q29(cs[0], cs[1], cs[2], cs[3], false, c.turns);
        // 0 <= sweep < 2^40 (Q29, 256 turns): radians in Q21 fit 32 bits. r sweep.
        uint32_t q21;
#if defined(__AVR__)
        // Bytes 1 to 4 by moves: avr-gcc would call its 64-bit shift, which nothing else in the
        // image needs (__ashrdi3 and __lshrdi3: 60 B).
        asm("mov %A0, %B1\n\t"
            "mov %B0, %C1\n\t"
            "mov %C0, %D1\n\t"
            "mov %D0, %r1+4"
            : "=&r"(q21)
            : "r"(sweep));
#else
        q21 = static_cast<uint32_t>(sweep >> 8);
#endif
        reach.set(q21, -21).mul(radii[0] > radii[1] ? radii[0] : radii[1]);
    }
    // The normal axis' travel: |target - position| as the first of a pair (the second, the next
    // axis' or the words after the arrays, is not used).
    static_assert(offsetof(State, position) + 4 * 4 <= sizeof(State) &&
                      offsetof(motion::LineRequest, target_um) + 4 * 4 <=
                          sizeof(motion::LineRequest),
                  "the pair of the normal axis (2 at most) lies within the state and the request");
    uint32_t w[2];
    combine2(reinterpret_cast<int32_t*>(w), work().req.target_um + ax[2], g_state.position + ax[2],
             kMagnitudes);
    reach.add(Num(w[0]));
    return reach.u32() < (1ul << 23); // (floor(x) < 2^23 exactly when x < 2^23)
}

// Stage 3 of a curve (docs/curves.md): the checks and errors of GRBL's arcs (26 32 33 34 35), our
// extensions' (ellipses, G5), and the geometry handed to the planner. Consumes its words.
__attribute__((noinline)) uint8_t check_curve(Block& b, Motion motion, uint8_t axes,
                                              const State& st, CurveParams& c) {
    // The plane's axes, then (in place of the normal axis, which this function does not use)
    // P's and Q's distances from I: the four words of the loop below as kWordI + ax[k].
    uint8_t ax[4];
    const uint8_t plane = c.plane = b.g[kGroupPlane];
    axes_of(plane, ax);
    ax[2] = static_cast<uint8_t>(kWordP - kWordI); // (wraps: kWordI + it is kWordP)
    ax[3] = kWordQ - kWordI;
    // The normal of plane p is axis 2 - p (plane_axes), so the plane's axes are X Y Z but it.
    // (7 ^ (4 >> plane): 3, 5, 6, computed without a shift loop)
    const uint8_t in_plane = static_cast<uint8_t>(3 + 2 * plane - (plane >> 1));
    // A curve moves the plane's axes and, along a helix, the normal one: not the others.
    if (axes & ~7u) return kAxisWordsExist;
    bool ellipse = motion == Motion::EllipseCw || motion == Motion::EllipseCcw;
    bool bezier = motion == Motion::Bezier;
    if (!ellipse && axes == 0) return kNoAxisWords;
    if (!ellipse && !bezier && !(axes & in_plane)) return kNoAxisWordsInPlane;
    c.kind = bezier ? kCurveBezier : kCurveArc;
    c.clockwise = motion == Motion::ArcCw || motion == Motion::EllipseCw;
    c.turns = 0;
    // o: the plane's offsets (I J, I K or J K), then P and Q, in um; kept in c.a_um and c.b_um
    // (a row of 4: checked in curve_in_range) until they become the points.
    int32_t* const o = c.a_um;
    bool pq_not_positive = false; // an ellipse's semi-axes must be above 0
    for (uint8_t k = 0; k < 4; ++k) {
        uint8_t word = static_cast<uint8_t>(kWordI + ax[k]);
        o[k] = 0;
        if ((b.words & bit(word)) && !length(word, o[k])) return kBadNumberFormat;
        if (k >= 2 && o[k] <= 0) pq_not_positive = true;
    }
    pick2(c.start_um, st.position, ax);
    pick2(c.end_um, work().req.target_um, ax);
    int32_t d[2]; // end - start
    combine2(d, c.end_um, c.start_um);
    bool has_offsets = (b.words & (WordMask(in_plane) << kWordI)) != 0; // I J K: X Y Z's
    bool has_pq = (~b.words & (bit(kWordP) | bit(kWordQ))) == 0;
    const WordMask ijk = bit(kWordI) | bit(kWordJ) | bit(kWordK);
    WordMask used = static_cast<WordMask>(ijk | bit(kWordP) | bit(kWordQ)); // G2.1, G3.1, G5
    uint32_t r = 0;
    if (bezier) {
        // G5 (Marlin): I J the first control point from the start (or, after a G5, the
        // reflection of its second one), P Q the second control point from the end.
        if (!has_pq) return kValueWordMissing;
        if (!has_offsets) {
            if (!st.g5_continues) return kValueWordMissing;
            copy_words(o, st.g5_reflect, 2);
        }
    } else if (ellipse) {
        // G2.1 / G3.1: I J the centre from the start, P Q the semi-axes along the plane's
        // axes; both ends on the ellipse within one tick + 0.002 mm (in curve_in_range()).
        if (!has_offsets) return kNoOffsetsInPlane;
        if (!has_pq) return kValueWordMissing;
        if (pq_not_positive) return kNegativeValue;
    } else {
        // G2 / G3, as GRBL: radius mode (R) or centre mode (the plane's offsets).
        used = bit(kWordP);
        if (b.words & bit(kWordR)) {
            used = static_cast<WordMask>(used | bit(kWordR)); // I J K stay unused (GRBL: 36)
            int32_t rw;
            if (!length(kWordR, rw)) return kBadNumberFormat;
            Num dn;
            dist_um(c.end_um, c.start_um, dn);    // |d|
            if (dn.m == 0) return kInvalidTarget; // start = end
            // Centre on the perpendicular bisector: h = -sqrt(4 r^2 - d^2) / d, negated for
            // G3 and for a negative R (the longer arc).
            r = abs32(rw);
            Num r2(r);
            r2.mul(r2).shift(2); // 4 r^2
            Num d2 = dn;
            d2.mul(dn);
            if (r2.cmp(d2) < 0) return kArcRadiusError;
            uint32_t rr = r2.shift(-16).u32(), dd = d2.shift(-16).u32(); // both below 2^32
            Num h(rr - dd, 16);
            h.sqrt().div(dn); // |h|
            // -sqrt(..), flipped for G3 and R < 0, and for u: x - y h = x + y (-h).
            // (R's sign: rw != 0 here, else r2 < d2 above.)
            bool neg = (motion == Motion::ArcCcw) != b.v[kWordR].d.negative();
            // o = (d - h (d1, -d0)) / 2: (x - y h) / 2, (y + x h) / 2.
            for (uint8_t k = 0; k < 2; ++k) {
                int32_t t = static_cast<int32_t>(h.of(abs32(d[1 - k])));
                if ((d[1 - k] < 0) != neg) t = -t;
                // (d[k] + t) / 2, rounded toward zero as the division would be (without the
                // library's 32-bit division: the sign bit added, then an arithmetic shift).
                uint32_t sum = static_cast<uint32_t>(d[k]) + static_cast<uint32_t>(t);
                o[k] = static_cast<int32_t>(sum + (sum >> 31)) >> 1;
                neg = !neg;
            }
        } else if (!has_offsets) {
            return kNoOffsetsInPlane;
        } else {
            used = static_cast<WordMask>(used | ijk);
        }
    }
    // a = start + the offsets; a G5's b = end + P Q (start, end: a row of 4 too).
    combine2(o, c.start_um, o, kSum);
    if (bezier) combine2(o + 2, c.end_um, o + 2, kSum);
    // (An ellipse's ends are checked in curve_in_range().)
    if (!ellipse && !bezier) {
        if (!(b.words & bit(kWordR))) {
            // The end must be on the circle: within 0.005 mm, or else within 0.5 mm and 0.1 %.
            Num t;
            r = dist_um(c.start_um, c.a_um, t);
            uint32_t x = dist_um(c.end_um, c.a_um, t), delta = x > r ? x - r : r - x;
            // (delta > r / 1000 as delta * 1000 > r: the same for integers, delta <= 500.)
            if (delta > 5 && (delta > 500 || delta * 1000u > r)) return kInvalidTarget;
        }
        if (r == 0) return kInvalidTarget;
        int32_t* radii = opaque(c.b_um); // (through a pointer: no absolute stores)
        radii[0] = radii[1] = static_cast<int32_t>(r);
        if (b.words & bit(kWordP)) { // LinuxCNC: P turns, P1 the plain arc
            uint32_t turns;
            if (!num::to_uint(b.v[kWordP].d, 256u, turns)) return kCommandValueNotInteger;
            // (turns <= 256: its low 16 bits are zero only when it is)
            if (static_cast<uint16_t>(turns) == 0) return kInvalidTarget;
            c.turns = static_cast<uint8_t>(turns - 1);
        }
    }
    if (b.overflow) return kInvalidTarget; // (curve_in_range() follows, in execute())
    b.words = static_cast<WordMask>(b.words & ~used);
    return kOk;
}

} // namespace

uint8_t execute(const char* line, uint8_t flags, Outcome& outcome) {
    State& st = g_state;
    static_assert(uint8_t(Then::Nothing) == 0, "an Outcome of zeros: nothing to do");
    memset(&outcome, 0, sizeof(outcome));

    // ---- Stage 1: a block that starts from the current modes.
    Block& b = opaque(work().b);
    static_assert(offsetof(State, tool) == sizeof(Modal) && sizeof(Modal) + 1 == 8 &&
                      kBlockTool == kGroupMotion + sizeof(Modal),
                  "modal and tool are two words, in the state and in the block");
    static_assert(kNoNonModal == 0 && kFlowRunning == 0 && kAxisNone == 0, "a header of zeros");
    // The bytes that the copies below do not write, one store each (a memset of the whole
    // header took 116 cycles).
    b.g[kGroupFlow] = 0;
    b.g[kGroupNonModal] = 0;
    b.axis_command = 0;
    b.overflow = 0;
    b.groups = 0;
    b.words = 0;
    b.n = 0;
    copy_words(&b.g[kGroupMotion], &st.modal, 2); // and the tool
    b.g[kBlockL] = 0xFF;
    copy_words(&b.feed, &st.feed, 2); // and S

    // ---- Stage 2: import every word (letter + number), checking repeats, modal groups and
    // negative F N P S T.
    while (*line != 0) {
        // (Unsigned: no sign extension of the index.)
        uint8_t letter = static_cast<uint8_t>(static_cast<uint8_t>(*line++) - 'A');
        if (letter > 'Z' - 'A') return kExpectedCommandLetter;
        uint8_t word = flash_read_byte(&kLetterInfo[letter]);
        // Its slot, or Work::other for the other letters: the slot past the last one.
        Slot* const slots = b.v; // (a pointer: indexing the array past its end is undefined)
        num::Decimal& d = slots[word < kDecimalSlots ? word : kDecimalSlots].d;
        line = num::parse(line, d);
        if (line == nullptr) return kBadNumberFormat;
        uint8_t r = kUnsupportedCommand;
        if (word < kWordCount) {
            r = import_value(b, word, d);
        } else if (word != kLetterNone) {
            r = import_command(b, word == kLetterM ? kM : 0, d);
        }
        if (r != kOk) return r;
    }

    // ---- Stage 3: check the block as a whole and compute everything it will change.
    uint8_t non_modal = b.g[kGroupNonModal];
    Motion motion = static_cast<Motion>(b.g[kGroupMotion]);
    uint8_t axes = static_cast<uint8_t>(b.words & kAxisWords);
    // [0] Axis words without a command that uses them: the current motion mode does; so do the
    // words of an ellipse without an end point (a full ellipse, docs/curves.md).
    bool ellipse = motion == Motion::EllipseCw || motion == Motion::EllipseCcw;
    if (b.axis_command == kAxisNone &&
        (axes != 0 || (ellipse && (b.words & (bit(kWordI) | bit(kWordJ) | bit(kWordK) |
                                              bit(kWordP) | bit(kWordQ)))))) {
        b.axis_command = kAxisMotion;
    }
    // P: negative only as a G5 control point offset (GRBL refuses a negative P as error:4).
    if ((b.words & bit(kWordP)) && b.v[kWordP].d.negative() &&
        !(motion == Motion::Bezier && b.axis_command == kAxisMotion)) {
        return kNegativeValue;
    }
    // (N is 0 without the word, at most 10000000 when valid, else kNoLineNumber: its top bit.)
    // (Its top byte: both the chip and the host are little-endian.)
    static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "N's top byte is its last");
    if (reinterpret_cast<const uint8_t*>(&b.n)[3] & 0x80) return kInvalidLineNumber;

    // [3] Feed rate (G94 only): a new F in the units of the block, or the last one.
    if (b.words & bit(kWordF)) {
        // (Straight into the block: a line rejected here never reaches stage 4.)
        if (!length(kWordF, *reinterpret_cast<int32_t*>(&b.feed))) return kBadNumberFormat;
    }

    // [10] Dwell: P seconds (the outcome's dwell_ms only counts with kDwell).
    if (non_modal == kDwellCmd) {
        if (!(b.words & bit(kWordP))) return kValueWordMissing;
        if (!num::to_milli(b.v[kWordP].d, *reinterpret_cast<int32_t*>(&outcome.dwell_ms))) {
            return kBadNumberFormat;
        }
        b.words = static_cast<WordMask>(b.words & ~bit(kWordP));
    }

    // [15] Coordinate system: G54 only.
    if (b.g[kGroupCoord] != 0) return kUnsupportedCoordSys;

    // [19] The axis words in um, then the non-modal commands that use them, or the target.
    // One pass over the axes converts each word and computes either the new offsets (G10, G92)
    // or the target of a move: an axis without a word keeps `keep`, an axis with a word gets its
    // value v, turned into a machine position as (x op1 st[o1]) op2 y, st[o1] an array of State
    // o1 bytes from the position (+ 4 kAxes: position_steps, + 8 kAxes: g54, + 12 kAxes: g92):
    //   G53, G10 L2 (the value is the new G54): v
    //   G91: v + position
    //   G90: v + G54 + G92 (the work position)
    //   G92, G10 L20: position - the other offset - v (x = position, y = v)
    // The commands' own checks follow the pass, and its overflow them, in GRBL's order: a bad
    // number first, then the command, then the target.
    bool offsets = non_modal == kSetCoordData || non_modal == kSetOffset;
    const int32_t* keep = st.position;
    uint8_t op1 = kKeep, op2 = kKeep, o1 = 0;
    if (offsets) {
        // G92: the current position becomes the given work position. G10 L20 P0|P1: the same
        // for G54; G10 L2: the given values are the new G54.
        keep = st.g92;
        op1 = op2 = kSub;
        o1 = 2 * kAxes * 4; // G92: the other offset is G54
        if (non_modal == kSetCoordData) {
            if (b.g[kBlockL] == 2) op1 = op2 = kKeep;
            keep = st.g54;
            o1 = 3 * kAxes * 4; // and G92 for G10 L20
        }
    } else if (non_modal != kAbsoluteOverride) {
        op1 = kAdd;
        if (!b.g[kGroupDistance]) {
            op2 = kAdd;
            o1 = 2 * kAxes * 4;
        }
    }
    motion::LineRequest& req = work().req;
    static_assert(offsetof(State, position_steps) == offsetof(State, position) + 4 * kAxes &&
                      offsetof(State, g54) == offsetof(State, position) + 8 * kAxes &&
                      offsetof(State, g92) == offsetof(State, position) + 12 * kAxes &&
                      offsetof(motion::LineRequest, target_um) ==
                          offsetof(motion::LineRequest, target_steps) + 4 * kAxes,
                  "the arrays of axes in a row");
    // (Axis words always have a user here: [0] gave them to the motion mode, or G10 / G92 took
    // them.)
    if (offsets || b.axis_command == kAxisMotion) {
        copy_words(req.target_um, keep, kAxes); // for G10 / G92: the new offsets
        copy_words(req.target_steps, st.position_steps, kAxes);
        for (uint8_t a = 0, m = axes; m != 0; ++a, m >>= 1) {
            if (!(m & 1)) continue;
            // In place: length_to_milli() has read the number when it writes the um.
            if (!length(a, b.v[a].um)) return kBadNumberFormat;
            // Axis a of the arrays in a row: st's position (+ kAxes: position_steps, + 2 kAxes:
            // g54, + 3 kAxes: g92) and req's target_steps (+ kAxes: target_um).
            const int32_t* const sa = st.position + a;
            int32_t* const ra = req.target_steps + a;
            const int32_t *x = &b.v[a].um, *y = sa + 3 * kAxes;
            if (op1 == kSub) { // G92, G10 L20
                y = x;
                x = sa;
            }
            // (o1 in bytes: no shift an axis)
            int32_t t = add(
                add(*x,
                    *reinterpret_cast<const int32_t*>(reinterpret_cast<const uint8_t*>(sa) + o1),
                    op1),
                *y, op2);
            ra[kAxes] = t;
            // Always from the absolute target: no rounding error accumulates. One move travels
            // at most kMaxLineTicks steps per axis (line.h).
            if (!offsets &&
                // (|d| > max as one unsigned comparison: d + max wraps above 2 max.)
                (!to_steps(t, a, ra[0]) ||
                 static_cast<uint32_t>(ra[0]) - static_cast<uint32_t>(sa[kAxes]) + kMaxLineTicks >
                     2u * kMaxLineTicks)) {
                b.overflow = 1;
            }
        }
    }
    if (offsets) {
        if (axes == 0) return kNoAxisWords;
        if (non_modal == kSetCoordData) {
            if (!(b.words & bit(kWordP)) || !(b.words & bit(kWordL))) return kValueWordMissing;
            // (The value over the number's integer part, which it is when valid: no local.)
            num::Decimal& p = b.v[kWordP].d;
            if (!num::to_uint(p, 1u, p.ipart)) return kUnsupportedCoordSys;
            uint8_t l = b.g[kBlockL];
            if (l != 2 && l != 20) return kUnsupportedCommand;
            if (l == 2 && (b.words & bit(kWordR))) return kUnsupportedCommand;
            b.words = static_cast<WordMask>(b.words & ~(bit(kWordL) | bit(kWordP)));
        }
    } else if (non_modal == kAbsoluteOverride && motion > Motion::Linear) {
        return kG53InvalidMotionMode;
    }
    if (b.overflow) return kInvalidTarget;

    // [20] Motion modes.
    bool curve = false;
    if (motion == Motion::None) {
        if (axes != 0) return kAxisWordsExist;
    } else if (b.axis_command == kAxisMotion) {
        if (motion != Motion::Seek && b.feed == 0) return kUndefinedFeedRate;
        if (motion >= Motion::ArcCw && motion <= Motion::Bezier) {
            uint8_t r =
                check_curve(work().b, motion, axes, st, work().b.curve); // (at fixed addresses)
            if (r != kOk) return r;
            // Called here rather than under check_curve()'s frame: it reaches
            // ellipse_direction(), the deepest stack of a G-code line.
            if (!curve_in_range(b.curve, ellipse)) return kInvalidTarget;
            curve = true;
        } else if (axes == 0) {
            b.axis_command = kAxisNone; // G0/G1 alone: a mode change only
        }
    }

    // [0] Every word must have been used.
    // (Axis words always have a user by now: the motion mode takes them, or G80 refused them.)
    if (b.words & kMustBeUsed) return kUnusedWords;

    // ---- The block is valid. Conditions to wait for, still without any side effect.
    bool check = (flags & kCheckMode) != 0;
    bool moves = b.axis_command == kAxisMotion;
    if (!check) {
        if (non_modal == kDwellCmd && !(flags & kDwellDone)) return kDwell;
        if ((offsets || non_modal == kResetOffset) && motion::state() != motion::State::Idle) {
            return kRetryWhenIdle;
        }
        if (moves && !(curve ? motion::can_accept_curve() : motion::can_accept())) {
            return kRetryWhenAccepting;
        }
    }

    // ---- Stage 4: execute, in GRBL's order.
    copy_words(&st.modal, &b.g[kGroupMotion], 2); // coord: 0, checked above; and the tool
    copy_words(&st.feed, &b.feed, 3);             // and S, N
    if (offsets) {
        bool g10 = non_modal == kSetCoordData;
        copy_words(g10 ? st.g54 : st.g92, req.target_um, kAxes);
        if (g10 && !check) settings::save_coord(st.g54);
        st.wco_changed = 1;
    } else if (non_modal == kResetOffset) {
        memset(st.g92, 0, sizeof(st.g92));
        st.wco_changed = 1;
    }
    if (moves) {
        copy_words(&req.feed, &b.feed, 1); // (a call: 10 B less than the bytes' loads and stores)
        req.rapid = motion == Motion::Seek;
        req.curve = curve ? &b.curve : nullptr;
        if (!check) outcome.move = &req; // queued by the caller; the length was checked above
        // A G5 without I J continues the last G5 smoothly: remember its second arm.
        st.g5_continues = motion == Motion::Bezier;
        if (st.g5_continues) {
            combine2(st.g5_reflect, b.curve.end_um, b.curve.b_um);
        }
        copy_words(st.position, req.target_um, kAxes);
        copy_words(st.position_steps, req.target_steps, kAxes);
    }
    uint8_t flow = b.g[kGroupFlow];
    if (flow == kFlowPause) {
        if (!check) outcome.then = Then::Pause;
    } else if (flow == kFlowEnd) {
        set_end_modes(st.modal);
        outcome.then = Then::ProgramEnd;
    }
    return kOk;
}

bool reset() {
    State& st = g_state;
    memset(&st, 0, sizeof(st));
    set_end_modes(st.modal);
    st.modal.motion = Motion::Seek;
    bool ok = settings::load_coord(st.g54);
    sync_position();
    st.wco_changed = 1;
    return ok;
}

namespace {
// Every axis between steps and um, in one loop for both ways: to um, um = steps x 10^6 / spu
// (saturated on overflow); to steps, steps = um x spu / 10^6, written only when it fits.
__attribute__((noinline)) void convert_axes(const int32_t* from, int32_t* to, bool to_um) {
    const AxisSettings* s = g_settings.axis;
    for (uint8_t a = kAxes; a != 0; --a, ++to) {
        uint32_t mul = (s++)->steps_per_unit, div = 1000000u;
        if (to_um) {
            div = mul;
            mul = 1000000u;
        }
        // Written in place (no frame for the result), the old value put back when it is kept.
        int32_t old = *to;
        if (!num::mul_div_round(*from++, mul, div, *to) && !to_um) *to = old;
    }
}
} // namespace

void steps_to_um(const int32_t* steps, int32_t* um) {
    convert_axes(steps, um, true);
}

void sync_position() {
    motion::position(g_state.position_steps);
    steps_to_um(g_state.position_steps, g_state.position);
}

void settings_changed() {
    convert_axes(g_state.position, g_state.position_steps, false);
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
    out::str(LL_PSTR("[GC:G"));
    out::u8(flash_read_byte(&kMotionCode[static_cast<uint8_t>(m.motion)]));
    out::word('G', static_cast<uint8_t>(54u + m.coord));
    out::word('G', static_cast<uint8_t>(17u + m.plane));
    out::word('G', static_cast<uint8_t>(21u - m.inches));
    out::word('G', static_cast<uint8_t>(90u + m.incremental));
    out::word('G', 94);
    out::word('M', m.spindle);
    out::word('M', m.coolant);
    out::word('T', g_state.tool);
    out::ch(' '); // (two characters: 1 B less than a string and its call)
    out::ch('F');
    out::rate(g_state.feed);
    out::ch(' ');
    out::ch('S');
    out::u32(g_state.spindle_speed);
    out::bracket_eol();
}

void report_offsets() {
    // G54 is real, G55..G59, G28 and G30 are zeros (not supported), then G92.
    static const uint8_t kCodes[9] LL_PROGMEM = {54, 55, 56, 57, 58, 59, 28, 30, 92};
    for (uint8_t i = 0; i < sizeof(kCodes); ++i) {
        asm("" : "+r"(i)); // (counted in i, not by a 16-bit address compare)
        uint8_t code = flash_read_byte(&kCodes[i]);
        out::str(LL_PSTR("[G"));
        out::u8(code);
        out::ch(':');
        out::coords(code == 54 ? g_state.g54 : code == 92 ? g_state.g92 : nullptr);
        out::bracket_eol();
    }
    out::str(LL_PSTR("[TLO:"));
    out::coord(0);
    out::str(LL_PSTR("]\r\n[PRB:"));
    out::coords(nullptr);
    out::line(LL_PSTR(":0]"));
}

} // namespace gcode
} // namespace ll
