// What the motion side derives from the settings once per change, so that a move costs no
// division by a setting: step lengths per axis set (seed §3.2), length per step, limits in the
// planner's units, speed groups (seed §3.1).
#pragma once

#include "lowlevel/fixmath.h"
#include "lowlevel/settings.h"
#include "lowlevel/waits.h"

namespace ll {

struct Machine {
    StepLengths lengths;
    const Settings* settings;  ///< rates and accelerations are read from here directly
    Num um_q8_per_step[kAxes]; ///< µm x 256 travelled per step (1 / T_a)
    uint8_t group_of[kAxes];   ///< axis bits sharing axis a's speed group
    uint32_t junction_dev_um;  ///< $11, µm
    uint16_t min_period;       ///< shortest step period the interrupt honours, CPU cycles
};

void machine_build(Machine& m, const Settings& s);

} // namespace ll
