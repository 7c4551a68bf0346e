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

namespace ll {

/// Regulated length of one micro step on each axis set S (bit a = machine axis a):
/// len[S] = sqrt(sum_{j in S} 1/T_j^2) mm, as a Q30 fixed-point value (mm x 2^30).
/// The regulated group G is applied by indexing with (S & G). Requires T_j >= 1 step/mm.
struct StepLengths {
    uint32_t len[1u << kAxes];
};

/// Builds the table from the steps per unit of each axis (x1000, as in Settings).
void step_lengths_build(StepLengths& t, const uint32_t steps_per_unit_milli[kAxes]);

/// Delta_P of §3.2 in CPU cycles x 256 for the axis set `set` restricted to `group`, at a
/// regulated speed of `speed` units/min x1000. Used where a single wait is needed outside a
/// move (and by the tests as the reference formula in integer form).
uint32_t wait_q8(const StepLengths& t, uint8_t set, uint8_t group, uint32_t speed);

} // namespace ll
