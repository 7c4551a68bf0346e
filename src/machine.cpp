#include "lowlevel/machine.h"

#include "lowlevel/step_timing.h"

namespace ll {

void machine_build(Machine& m, const Settings& s) {
    m.settings = &s;
    for (uint8_t a = 0; a < kAxes; ++a) {
        const uint32_t spu = s.axis[a].steps_per_unit;
        const uint32_t spm = spu < 1000 ? 1000 : spu; // T >= 1 step per unit
        m.um_q8_per_step[a].set(256000000ul).div(spm);
        step_length_inv2(m.lengths.inv2[a], spm); // (step_lengths_build(), in this loop)
        uint8_t mask = 0, bit = 1;
        for (uint8_t b = 0; b < kAxes; ++b, bit = static_cast<uint8_t>(bit << 1)) {
            if (s.axis_group[b] == s.axis_group[a]) mask = static_cast<uint8_t>(mask | bit);
        }
        m.group_of[a] = mask;
    }
    m.junction_dev_um = s.junction_dev;
    // The step interrupt's own contract (step_timing.h): pulse width plus the run-change path.
    m.min_period = step_timing::min_period(static_cast<uint16_t>(s.pulse_us * (kCpuHz / 1000000)));
}

} // namespace ll
