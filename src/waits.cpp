#include "lowlevel/waits.h"

#include "lowlevel/fixmath.h"

namespace ll {

uint32_t wait_q8(const StepLengths& t, uint8_t set, uint8_t group, uint32_t speed) {
    // Delta = len / V; len in mm x 2^30, V in mm/min x 1000:
    // cycles x 256 = len * 2^-30 * 60 * kCpuHz * 1000 * 256 / speed
    //              = len * 937500000 * 2^10 / (speed * 2^22)
    static_assert(60ull * kCpuHz * 1000 == 937500000ull << 10, "units");
    return Num(937500000).div(speed).shift(-12).of(
        step_length(t, static_cast<uint8_t>(set & group)));
}

} // namespace ll
