#include "lowlevel/waits.h"

#include "lowlevel/fixmath.h"

namespace ll {

void step_lengths_build(StepLengths& t, const uint32_t steps_per_unit_milli[kAxes]) {
    // (1/T_j)^2 in Q60: (2^30 * 1000 / t_j)^2 with t_j = 1000 T_j. Six terms of at most 2^60
    // fit in 64 bits for T_j >= 1.
    uint64_t inv2[kAxes];
    for (uint8_t a = 0; a < kAxes; ++a) {
        uint32_t tm = steps_per_unit_milli[a] < 1000 ? 1000 : steps_per_unit_milli[a];
        // 1/T in Q30, rounded: (2^30 * 1000 + t/2) / t
        uint64_t inv = ((1000ull << 30) + tm / 2) / tm;
        inv2[a] = inv * inv;
    }
    for (uint16_t s = 0; s < (1u << kAxes); ++s) {
        uint64_t sum = 0;
        for (uint8_t a = 0; a < kAxes; ++a) {
            if (s & (1u << a)) sum += inv2[a];
        }
        t.len[s] = isqrt64(sum);
    }
}

uint32_t wait_q8(const StepLengths& t, uint8_t set, uint8_t group, uint32_t speed) {
    // Delta = len / V; len in mm x 2^30, V in mm/min x 1000:
    // cycles x 256 = len * 2^-30 * 60 * kCpuHz * 1000 / speed * 256
    //              = len * 60 * kCpuHz * 1000 / (speed * 2^22)
    uint32_t len = t.len[set & group];
    Ratio r =
        make_ratio(static_cast<uint64_t>(60) * kCpuHz * 1000, static_cast<uint64_t>(speed) << 22);
    return saturate32(r.apply64(len));
}

} // namespace ll
