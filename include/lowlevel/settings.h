// Machine settings, GRBL 1.1 `$` numbering, stored in EEPROM with a version and a checksum.
// Every decimal value is kept as an integer in thousandths ("milli") of the unit GRBL shows,
// so `$100=80.000` is stored as 80000 and printed back exactly.
#pragma once

#include "lowlevel/config.h"

namespace ll {

struct AxisSettings {
    uint32_t steps_per_unit; ///< $100+a: steps per mm (per degree on a rotary axis), x1000
    uint32_t max_rate;       ///< $110+a: mm/min (deg/min), x1000
    uint32_t accel;          ///< $120+a: mm/s^2 (deg/s^2), x1000
    uint32_t max_travel;     ///< $130+a: mm (deg), x1000, >= 0
};

struct Settings {
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
    AxisSettings axis[kAxes];
};

extern Settings g_settings;

} // namespace ll
