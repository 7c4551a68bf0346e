#include "lowlevel/waits.h"

#include "lowlevel/fixmath.h"

namespace ll {

void step_lengths_build(StepLengths& t, const uint32_t steps_per_unit_milli[kAxes]) {
    for (uint8_t a = 0; a < kAxes; ++a) {
        uint32_t tm = steps_per_unit_milli[a] < 1000 ? 1000 : steps_per_unit_milli[a];
        Num& v = t.inv2[a];
        v.set(1000).div(tm);
        v.mul(v);
    }
}

uint32_t wait_q8(const StepLengths& t, uint8_t set, uint8_t group, uint32_t speed) {
    // Delta = len / V; len in mm x 2^30, V in mm/min x 1000:
    // cycles x 256 = len * 2^-30 * 60 * kCpuHz * 1000 * 256 / speed
    //              = len * 937500000 * 2^10 / (speed * 2^22)
    static_assert(60ull * kCpuHz * 1000 == 937500000ull << 10, "units");
    return Num(937500000).div(speed).shift(-12).of(
        step_length(t, static_cast<uint8_t>(set & group)));
}

} // namespace ll
