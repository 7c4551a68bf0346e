// Settings: defaults, EEPROM storage, `$N=value` and `$$`. See settings.h.
#include "lowlevel/settings.h"

#include <stddef.h>
#include <string.h>

#include "lowlevel/hal.h"
#include "lowlevel/print.h"
#include "lowlevel/scratch.h"
#include "lowlevel/status.h"

namespace ll {
namespace settings {

namespace {

static_assert(kEepromSettingsAddr + sizeof(Settings) + 2 <= kEepromCoordAddr,
              "settings record overlaps the G54 record");
static_assert(kEepromCoordAddr + 4 * kAxes + 2 <= hal::kEepromSize, "EEPROM too small");
static_assert(sizeof(Settings) < 256, "records are counted in bytes");

// How a `$` number is stored, checked and printed.
enum Kind : uint8_t {
    kByte,     // integer 0..255
    kBool,     // 0 or 1
    kPulse,    // integer 3..255 (below 3: error:6, GRBL's minimum)
    kGroup,    // integer 0..kAxes-1
    kMilli,    // uint32 thousandths, printed with 3 decimals
    kMilliPos, // the same, but zero is refused like a negative (a division follows)
};

// One row per `$` number, in `$$` order; from 100 on, a row is kAxes numbers (one per axis).
struct Row {
    uint8_t number;
    uint8_t kind;
    uint8_t offset; // offsetof(Settings, field) of the field (of axis 0)
};
constexpr uint8_t kFirstAxisNumber = 100;

#define LL_ROW(n, kind, field)                                                                     \
    { n, kind, static_cast<uint8_t>(offsetof(Settings, field)) }
const Row kRows[] LL_PROGMEM = {
    LL_ROW(0, kPulse, pulse_us),
    LL_ROW(1, kByte, idle_delay_ms),
    LL_ROW(2, kByte, step_invert),
    LL_ROW(3, kByte, dir_invert),
    LL_ROW(4, kBool, enable_invert),
    LL_ROW(5, kBool, limit_invert),
    LL_ROW(6, kBool, probe_invert),
    LL_ROW(10, kByte, status_mask),
    LL_ROW(11, kMilli, junction_dev),
    LL_ROW(12, kMilliPos, arc_tolerance), // arcs divide by it
    LL_ROW(13, kBool, report_inches),
    LL_ROW(100, kMilliPos, axis[0].steps_per_unit),
    LL_ROW(110, kMilliPos, axis[0].max_rate),
    LL_ROW(120, kMilliPos, axis[0].accel),
    LL_ROW(130, kMilli, axis[0].max_travel),
    LL_ROW(140, kGroup, axis_group[0]),
};
#undef LL_ROW
constexpr uint8_t kRowCount = sizeof(kRows) / sizeof(kRows[0]);

// The field that holds `$n` and its kind; field nullptr when no row has that number. Returned in
// registers (r22..r24), not through a pointer: the callers then keep no frame for the kind.
struct Found {
    uint8_t* field;
    uint8_t kind;
};
Found find(uint8_t n) {
    const Row* row = kRows;
    do {
        // The row's three bytes in turn, the pointer left on the next row (on the chip: lpm Z+,
        // 10 B less than three addressed reads).
        uint8_t first, kind, offset;
#if defined(__AVR__)
        asm("lpm %0, Z+\n\tlpm %1, Z+\n\tlpm %2, Z+"
            : "=r"(first), "=r"(kind), "=r"(offset), "+z"(row));
#else
        first = row->number;
        kind = row->kind;
        offset = row->offset;
        ++row;
#endif
        uint8_t a = static_cast<uint8_t>(n - first);
        uint8_t count = first >= kFirstAxisNumber ? kAxes : 1; // compared in 8 bits
        if (a >= count) continue;
        uint8_t stride = kind == kGroup ? 1 : sizeof(AxisSettings);
        return {reinterpret_cast<uint8_t*>(&g_settings) + offset + static_cast<uint8_t>(a * stride),
                kind};
    } while (row != kRows + kRowCount);
    return {nullptr, 0};
}

// Fletcher-style 16-bit check over the record (two running 8-bit sums), computed while it is
// read or written: catches changed, swapped and zeroed bytes, and a blank (all 0xFF) record
// never matches its own check. Returns true when a read record matches its check.
// Writes v at addr and returns it, or (write false) returns the byte at addr.
__attribute__((noinline)) uint8_t transfer(uint16_t addr, uint8_t v, bool write) {
    if (!write) return hal::eeprom_read(addr);
    return hal::eeprom_write(addr, v);
}

bool record(uint16_t addr, void* data, uint8_t n, bool write) {
    uint8_t* p = static_cast<uint8_t*>(data);
    uint8_t a = 0x5A, b = 0xA5;
    for (; n != 0; --n, ++addr, ++p) {
        // addr counted on its own (the compiler would derive it from p: 8 B a byte more).
        asm("" : "+r"(addr));
        uint8_t v = transfer(addr, *p, write);
        *p = v; // unchanged when writing
        a = static_cast<uint8_t>(a + v);
        b = static_cast<uint8_t>(b + a);
    }
    // Writing, both compare equal (and both bytes are written: no short cut).
    return transfer(addr, a, write) == a &&
           transfer(static_cast<uint16_t>(addr + 1), b, write) == b;
}

// GRBL 1.1h's generic machine, $10=3 and the speed groups X Y Z -> 0, A B C -> 1. Every axis has
// the same defaults, so flash keeps the first one only (SettingsFor<1>: the same layout up to
// it) and restore_defaults() repeats it (kAxes copies took 48 B more).
constexpr SettingsFor<1> make_defaults() {
    SettingsFor<1> s{};
    s.pulse_us = 10;
    s.idle_delay_ms = 25;
    s.status_mask = 3; // MPos and Bf: (GRBL 1.1h: 1, MPos only; see docs/protocol.md)
    s.junction_dev = 10;
    s.arc_tolerance = 2;
    for (uint8_t a = 0; a < kAxes; ++a) s.axis_group[a] = a < 3 ? 0 : 1;
    s.axis[0].steps_per_unit = 250000;
    s.axis[0].max_rate = 500000;
    s.axis[0].accel = 10000;
    s.axis[0].max_travel = 200000;
    return s;
}
const SettingsFor<1> kDefaults LL_PROGMEM = make_defaults();
static_assert(offsetof(SettingsFor<1>, axis) == offsetof(Settings, axis) &&
                  sizeof(SettingsFor<1>) + (kAxes - 1) * sizeof(AxisSettings) == sizeof(Settings),
              "the defaults are Settings up to the first axis");

void save() {
    hal::eeprom_write(0, kEepromVersion);
    record(kEepromSettingsAddr, &g_settings, sizeof(Settings), true);
}

} // namespace

void restore_defaults() {
    flash_copy(&g_settings, &kDefaults, sizeof(kDefaults));
    // The first axis repeated: a forward byte copy from one axis back.
    uint8_t* axes = reinterpret_cast<uint8_t*>(g_settings.axis);
    for (uint8_t i = 0; i < (kAxes - 1) * sizeof(AxisSettings); ++i) {
        axes[i + sizeof(AxisSettings)] = axes[i];
    }
    save();
    clear_coord();
}

namespace {
// um zeroed, and saved as the G54 record (for clear_coord() and load_coord()).
__attribute__((noinline)) void zero_coord(int32_t (&um)[kAxes]) {
    memset(um, 0, sizeof(um));
    save_coord(um);
}
} // namespace

void clear_coord() {
    // The zeros in the scratch RAM (scratch.h; motion.h says when it is free: `$RST` and app::init
    // only), not in a 16-byte frame.
    using Coords = int32_t[kAxes];
    zero_coord(scratch<Coords>());
}

bool load() {
    if (hal::eeprom_read(0) == kEepromVersion &&
        record(kEepromSettingsAddr, &g_settings, sizeof(Settings), false)) {
        return true;
    }
    restore_defaults();
    return false;
}

bool load_coord(int32_t (&um)[kAxes]) {
    if (record(kEepromCoordAddr, um, sizeof(um), false)) return true;
    zero_coord(um);
    return false;
}

void save_coord(const int32_t (&um)[kAxes]) {
    record(kEepromCoordAddr, const_cast<int32_t*>(um), sizeof(um), true);
}

uint8_t store(uint8_t n, const num::Decimal& value) {
    if (value.negative()) return status::kNegativeValue;
    const Found found = find(n);
    uint8_t* f = found.field;
    const uint8_t kind = found.kind;
    if (f == nullptr) return status::kInvalidStatement;
    if (kind >= kMilli) {
        int32_t milli;
        if (!num::to_milli(value, milli)) return status::kInvalidStatement;
        if (milli == 0 && kind == kMilliPos) return status::kNegativeValue;
        memcpy(f, &milli, sizeof(milli));
    } else {
        uint32_t v;
        static_assert(kByte == 0 && kBool == 1 && kPulse == 2 && kGroup == 3 && kMilli == 4,
                      "kMax follows the kinds");
        static const uint8_t kMax[kMilli] LL_PROGMEM = {255, 1, 255, kAxes - 1}; // by kind
        uint8_t max = flash_read_byte(&kMax[kind]);
        if (!num::to_uint(value, max, v)) return status::kInvalidStatement;
        uint8_t b = static_cast<uint8_t>(v); // v <= max <= 255
        if (kind == kPulse && b < 3) return status::kStepPulseMin;
        *f = b;
    }
    save();
    return status::kOk;
}

void report() {
    // Every number in turn, looked up as `$N=` would be: the rows are in increasing order, so
    // this prints them in `$$` order without a second walk over the table.
    uint8_t n = 0;
    do {
        const Found found = find(n);
        const uint8_t* f = found.field;
        const uint8_t kind = found.kind;
        if (f == nullptr) continue;
        out::ch('$');
        out::u8(n);
        out::ch('=');
        if (kind >= kMilli) {
            int32_t milli;
            memcpy(&milli, f, sizeof(milli));
            out::fixed(milli, 3);
        } else {
            out::u8(*f);
        }
        out::eol();
    } while (++n != 0);
}

} // namespace settings
} // namespace ll
