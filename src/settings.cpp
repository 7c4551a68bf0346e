// Settings: defaults, EEPROM storage, `$N=value` and `$$`. See settings.h.
#include "lowlevel/settings.h"

#include "lowlevel/hal.h"
#include "lowlevel/print.h"
#include "lowlevel/status.h"

namespace ll {
namespace settings {

namespace {

static_assert(kEepromSettingsAddr + sizeof(Settings) + 2 <= kEepromCoordAddr,
              "settings record overlaps the G54 record");
static_assert(kEepromCoordAddr + 4 * kAxes + 2 <= hal::kEepromSize, "EEPROM too small");

// Fletcher-style 16-bit check over a byte range (two running 8-bit sums): catches changed,
// swapped and zeroed bytes, and a blank (all 0xFF) record never matches its own check.
uint16_t checksum(const uint8_t* p, uint16_t n) {
    uint8_t a = 0x5A, b = 0xA5;
    while (n--) {
        a = static_cast<uint8_t>(a + *p++);
        b = static_cast<uint8_t>(b + a);
    }
    return static_cast<uint16_t>(b << 8 | a);
}

void write_record(uint16_t addr, const void* data, uint16_t n) {
    const uint8_t* p = static_cast<const uint8_t*>(data);
    for (uint16_t i = 0; i < n; ++i) hal::eeprom_write(static_cast<uint16_t>(addr + i), p[i]);
    uint16_t sum = checksum(p, n);
    hal::eeprom_write(static_cast<uint16_t>(addr + n), static_cast<uint8_t>(sum));
    hal::eeprom_write(static_cast<uint16_t>(addr + n + 1), static_cast<uint8_t>(sum >> 8));
}

bool read_record(uint16_t addr, void* data, uint16_t n) {
    uint8_t* p = static_cast<uint8_t*>(data);
    for (uint16_t i = 0; i < n; ++i) p[i] = hal::eeprom_read(static_cast<uint16_t>(addr + i));
    uint16_t stored =
        static_cast<uint16_t>(hal::eeprom_read(static_cast<uint16_t>(addr + n)) |
                              hal::eeprom_read(static_cast<uint16_t>(addr + n + 1)) << 8);
    return stored == checksum(p, n);
}

void save() {
    hal::eeprom_write(0, kEepromVersion);
    write_record(kEepromSettingsAddr, &g_settings, sizeof(Settings));
}

// $N lines for a value in thousandths (printed with 3 decimals) or a small integer.
void line_prefix(uint8_t n) {
    out::ch('$');
    out::u32(n);
    out::ch('=');
}
void line_int(uint8_t n, uint8_t v) {
    line_prefix(n);
    out::u32(v);
    out::eol();
}
void line_milli(uint8_t n, uint32_t v) {
    line_prefix(n);
    out::fixed(static_cast<int32_t>(v), 3);
    out::eol();
}

// The uint8 fields of $0..$6 in setting order (Settings keeps them contiguous).
uint8_t* byte_setting(uint8_t n) {
    switch (n) {
        case 0:
            return &g_settings.pulse_us;
        case 1:
            return &g_settings.idle_delay_ms;
        case 2:
            return &g_settings.step_invert;
        case 3:
            return &g_settings.dir_invert;
        case 4:
            return &g_settings.enable_invert;
        case 5:
            return &g_settings.limit_invert;
        case 6:
            return &g_settings.probe_invert;
        case 10:
            return &g_settings.status_mask;
        case 13:
            return &g_settings.report_inches;
        default:
            return nullptr;
    }
}

} // namespace

void restore_defaults() {
    Settings& s = g_settings;
    s.pulse_us = 10;
    s.idle_delay_ms = 25;
    s.step_invert = 0;
    s.dir_invert = 0;
    s.enable_invert = 0;
    s.limit_invert = 0;
    s.probe_invert = 0;
    s.status_mask = 3; // MPos and Bf: (GRBL 1.1h: 1, MPos only; see docs/protocol.md)
    s.junction_dev = 10;
    s.arc_tolerance = 2;
    s.report_inches = 0;
    for (uint8_t a = 0; a < kAxes; ++a) {
        s.axis_group[a] = a < 3 ? 0 : 1;
        s.axis[a].steps_per_unit = 250000;
        s.axis[a].max_rate = 500000;
        s.axis[a].accel = 10000;
        s.axis[a].max_travel = 200000;
    }
    save();
    int32_t zero[kAxes] = {};
    save_coord(zero);
}

bool load() {
    if (hal::eeprom_read(0) == kEepromVersion &&
        read_record(kEepromSettingsAddr, &g_settings, sizeof(Settings))) {
        return true;
    }
    restore_defaults();
    return false;
}

bool load_coord(int32_t (&um)[kAxes]) {
    if (read_record(kEepromCoordAddr, um, sizeof(um))) return true;
    for (uint8_t a = 0; a < kAxes; ++a) um[a] = 0;
    save_coord(um);
    return false;
}

void save_coord(const int32_t (&um)[kAxes]) {
    write_record(kEepromCoordAddr, um, sizeof(um));
}

uint8_t store(uint8_t n, const num::Decimal& value) {
    if (value.negative()) return status::kNegativeValue;
    if (n >= 100) {
        uint8_t kind = static_cast<uint8_t>((n - 100) / 10);
        uint8_t a = static_cast<uint8_t>((n - 100) % 10);
        if (kind > 4 || a >= kAxes) return status::kInvalidStatement;
        if (kind == 4) { // $140+a: speed group, an integer 0..kAxes-1
            uint32_t g;
            if (!num::to_uint(value, kAxes - 1u, g)) return status::kInvalidStatement;
            g_settings.axis_group[a] = static_cast<uint8_t>(g);
        } else {
            int32_t milli;
            if (!num::to_milli(value, milli)) return status::kInvalidStatement;
            // Steps, rates and accelerations divide later: zero is refused like a negative.
            if (milli == 0 && kind != 3) return status::kNegativeValue;
            uint32_t v = static_cast<uint32_t>(milli);
            AxisSettings& ax = g_settings.axis[a];
            if (kind == 0) ax.steps_per_unit = v;
            if (kind == 1) ax.max_rate = v;
            if (kind == 2) ax.accel = v;
            if (kind == 3) ax.max_travel = v;
        }
    } else if (n == 11 || n == 12) {
        int32_t milli;
        if (!num::to_milli(value, milli)) return status::kInvalidStatement;
        if (n == 11) {
            g_settings.junction_dev = static_cast<uint32_t>(milli);
        } else {
            if (milli == 0) return status::kNegativeValue; // arcs divide by it
            g_settings.arc_tolerance = static_cast<uint32_t>(milli);
        }
    } else {
        uint8_t* field = byte_setting(n);
        if (field == nullptr) return status::kInvalidStatement;
        // Booleans are 0 or 1; masks, times and $10 are bytes.
        uint32_t max = (n >= 4 && n <= 6) || n == 13 ? 1u : 255u;
        uint32_t v;
        if (!num::to_uint(value, max, v)) return status::kInvalidStatement;
        if (n == 0 && v < 3) return status::kStepPulseMin;
        *field = static_cast<uint8_t>(v);
    }
    save();
    return status::kOk;
}

void report() {
    static const uint8_t kByteOrder[8] LL_PROGMEM = {0, 1, 2, 3, 4, 5, 6, 10};
    for (uint8_t i = 0; i < sizeof(kByteOrder); ++i) {
        uint8_t n = flash_read_byte(&kByteOrder[i]);
        line_int(n, *byte_setting(n));
    }
    line_milli(11, g_settings.junction_dev);
    line_milli(12, g_settings.arc_tolerance);
    line_int(13, g_settings.report_inches);
    for (uint8_t kind = 0; kind < 5; ++kind) {
        for (uint8_t a = 0; a < kAxes; ++a) {
            uint8_t n = static_cast<uint8_t>(100 + kind * 10 + a);
            const AxisSettings& ax = g_settings.axis[a];
            switch (kind) {
                case 0:
                    line_milli(n, ax.steps_per_unit);
                    break;
                case 1:
                    line_milli(n, ax.max_rate);
                    break;
                case 2:
                    line_milli(n, ax.accel);
                    break;
                case 3:
                    line_milli(n, ax.max_travel);
                    break;
                default:
                    line_int(n, g_settings.axis_group[a]);
                    break;
            }
        }
    }
}

} // namespace settings
} // namespace ll
