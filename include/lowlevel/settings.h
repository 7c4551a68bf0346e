// Machine settings, GRBL 1.1 `$` numbering, stored in EEPROM with a version and a checksum.
// Every decimal value is kept as an integer in thousandths ("milli") of the unit GRBL shows,
// so `$100=80.000` is stored as 80000 and printed back exactly.
#pragma once

#include "lowlevel/config.h"
#include "lowlevel/numparse.h"

namespace ll {

struct AxisSettings {
    uint32_t steps_per_unit; ///< $100+a: steps per mm (per degree on a rotary axis), x1000
    uint32_t max_rate;       ///< $110+a: mm/min (deg/min), x1000
    uint32_t accel;          ///< $120+a: mm/s^2 (deg/s^2), x1000
    uint32_t max_travel;     ///< $130+a: mm (deg), x1000, >= 0
};

/// The settings with `AxisRecords` records of AxisSettings: Settings has kAxes of them (the
/// flash copy of the defaults only one, settings.cpp).
template <uint8_t AxisRecords>
struct SettingsFor {
    uint8_t pulse_us;          ///< $0: step pulse width, microseconds
    uint8_t idle_delay_ms;     ///< $1: stepper idle lock time, ms (255 = keep enabled)
    uint8_t step_invert;       ///< $2: step port invert, axis mask
    uint8_t dir_invert;        ///< $3: direction port invert, axis mask
    uint8_t enable_invert;     ///< $4: step enable invert, boolean
    uint8_t limit_invert;      ///< $5: limit pins invert, boolean
    uint8_t probe_invert;      ///< $6: probe pin invert, boolean
    uint8_t status_mask;       ///< $10: status report options, mask
    uint32_t junction_dev;     ///< $11: junction deviation, mm x1000
    uint32_t arc_tolerance;    ///< $12: arc tolerance, mm x1000 (end-point check of arcs)
    uint8_t report_inches;     ///< $13: report in inches, boolean
    uint8_t axis_group[kAxes]; ///< $140+a: speed group of each axis (seed §3.1; issue 6)
    AxisSettings axis[AxisRecords];
};
using Settings = SettingsFor<kAxes>;

extern Settings g_settings;

// EEPROM layout (docs/protocol.md): byte 0 holds kEepromVersion, then the Settings image of this
// build and a 16-bit checksum; from kEepromCoordAddr the G54 offsets (kAxes x int32 um) and their
// checksum. A version byte that differs (blank chip 0xFF, GRBL's own layout 10, another axis
// count) or a checksum that fails means "restore the defaults".
namespace settings {

constexpr uint8_t kEepromVersion = 0xA0 + kAxes; ///< layout 1 of Low Level, for kAxes axes
constexpr uint16_t kEepromSettingsAddr = 1;
constexpr uint16_t kEepromCoordAddr = 256;

/// Loads g_settings from EEPROM. When the record is blank or corrupt, restores the defaults,
/// writes them (settings and G54 offsets) and returns false; the caller reports it.
bool load();
/// GRBL 1.1h's generic defaults ($0=10 us, $1=25 ms, 250 steps/mm, 500 mm/min, 10 mm/s^2,
/// 200 mm travel), $10=3 and axis groups X,Y,Z -> 0, others -> 1. Writes them to EEPROM.
void restore_defaults();
/// `$number=value`: validates, stores in g_settings and EEPROM. Returns status::kOk or the GRBL
/// error (negative or zero where a positive value is needed: 4; $0 < 3: 6; unknown number,
/// out of range or a fraction where an integer is needed: 3). The caller then tells the motion
/// side (motion::settings_changed()).
uint8_t store(uint8_t number, const num::Decimal& value);
/// `$$`: every setting as `$N=value` lines, GRBL 1.1 format (integers for masks and booleans,
/// 3 decimals for values in units).
void report();

/// G54 work offsets, um. False (and zeros, rewritten) when the record is blank or corrupt.
bool load_coord(int32_t (&um)[kAxes]);
void save_coord(const int32_t (&um)[kAxes]);
/// Writes zero G54 offsets (`$RST=#`).
void clear_coord();

} // namespace settings

} // namespace ll
