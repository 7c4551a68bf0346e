// Wait times per axis set (seed §3.2, §5).
//
// §3.2: a micro step on the axis set P lasts Delta_P = 10^6 sqrt(sum_{j in P∩G} 1/T_j^2) / V µs,
// where G is the set of axes whose speed is regulated (§3.1). The square root is the
// regulated length of that step; it depends only on the T_j, so it is tabulated once per
// settings change for every axis set: StepLengths. §5: relative to the reference axis,
// Delta_P = K_P Delta_1; the per-move K table (stepgen.h) is built from this table with no
// square root at all.
#pragma once

#include "lowlevel/config.h"
#include "lowlevel/fixmath.h"

namespace ll {

/// Regulated length of micro steps (seed §3.2): sqrt(sum_{j in S} 1/T_j^2) mm for an axis set S
/// (bit a = machine axis a). Kept per axis as 1/T_a^2 (a table over every axis set would cost
/// 2^N x 4 bytes of RAM); the regulated group G is applied by asking for S & G.
struct StepLengths {
    Num inv2[kAxes]; ///< 1/T_a^2, mm^2 per step^2
};

/// 1/T^2 into `v` for T = `milli` / 1000 steps per unit (milli >= 1000: the callers clamp it).
/// (Inline: machine_build() takes it in its own loop over the axes.)
inline void step_length_inv2(Num& v, uint32_t milli) {
    v.set(1000).div(milli);
    v.mul(v);
}

/// Builds the table from the steps per unit of each axis (x1000, as in Settings), T_a taken as
/// at least 1 step per unit.
inline void step_lengths_build(StepLengths& t, const uint32_t steps_per_unit_milli[kAxes]) {
    for (uint8_t a = 0; a < kAxes; ++a) {
        const uint32_t tm = steps_per_unit_milli[a];
        step_length_inv2(t.inv2[a], tm < 1000 ? 1000 : tm);
    }
}

/// Length of one micro step on the axis set `set`, mm x 2^30 (Q30): below 4 mm for T >= 1.
/// (Inline: on the chip only StepGen::begin_line() calls it.)
inline uint32_t step_length(const StepLengths& t, uint8_t set) {
    Num sum{};
    for (uint8_t a = 0; a < kAxes; ++a, set >>= 1) {
        if (set & 1) sum.add(t.inv2[a]);
    }
    return sum.sqrt().shift(30).u32(); // Q30
}

/// Delta_P of §3.2 in CPU cycles x 256 for the axis set `set` restricted to `group`, at a
/// regulated speed of `speed` units/min x1000. Used where a single wait is needed outside a
/// move (and by the tests as the reference formula in integer form).
uint32_t wait_q8(const StepLengths& t, uint8_t set, uint8_t group, uint32_t speed);

} // namespace ll
