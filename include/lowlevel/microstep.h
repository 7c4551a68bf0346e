// Micro movement between two macro positions (seed §2.2): step every moving axis together
// until one reaches its target, then the remaining ones until the next does, and so on.
//
// The seed (§8.3) claims the increments of a macro segment keep the order of the slopes
// (e_1 >= ... >= e_M) and therefore that only the M "prefix" diagonals occur. That is false
// (DESIGN.md: slopes 0.5 and 0.49 from x_1 = 2 to 3 give e = (1, 0, 1)), so the runs are
// ordered per segment here, and wait times exist for every axis set containing axis 1.
#pragma once

#include "lowlevel/config.h"

namespace ll {

/// One run of a macro segment: `count` micro steps on the axis set `set`.
struct MicroRun {
    uint8_t set;   ///< sorted-position bits (bit 0 = reference axis, always present)
    uint8_t count; ///< micro steps, >= 1
};

/// Splits the increments e[0..m) of one macro segment (e[0] >= e[j], e[0] >= 1) into at most m
/// runs, largest axis set first. Returns the number of runs written to out.
uint8_t micro_split(const uint8_t e[], uint8_t m, MicroRun out[]);

} // namespace ll
