// Straight lines in tick space (seed part III, §7).
//
// §7.1: axes that do not move are dropped and the others sorted by distance, decreasing; the
// longest one ("axis 1", sorted position 0 here) is the reference variable x_1.
// §7.2: positions are x_j = (S_j * x_1 + P/2) >> k with P = 2^k and S_j = round(s_j * P): one
// integer multiplication (done incrementally, as an addition per macro segment) and a shift.
// The +P/2 rounds to the nearest tick instead of the seed's floor, which halves the deviation;
// with P >= 8 d_1 every macro position is within 0.5 + 1/16 tick of the ideal line and the end
// point is reached exactly (docs/motion.md, "Line positions").
#pragma once

#include "lowlevel/config.h"
#include "lowlevel/fixmath.h"

namespace ll {

/// Longest distance of one line on any axis, ticks (8.4 million: 104 m at 80 steps/mm). It keeps
/// S_j * L + P within 32 bits (k <= 26 with P >= 8 d_1) and a planned move's deltas within
/// 24 bits. The G-code layer refuses longer moves (error:33).
constexpr uint32_t kMaxLineTicks = (1ul << 23) - 1;
/// Longest macro segment (reference-axis ticks between two computed positions). 32, not 16:
/// a segment costs about 3,000 cycles to produce while the speed changes (docs/motion.md), and
/// at the 152-cycle minimum period 16 ticks last 2,432 cycles, 864 of them in the step
/// interrupt, so an acceleration above about 70 k steps/s could not be produced in time.
constexpr uint8_t kMaxSegmentTicks = 32;

/// Fixed-point unit of slopes and fractions: 2^kLineUnit stands for one tick, whatever k (k <=
/// 26 = kLineUnit), so that line_advance() shifts by a constant (a variable shift is a loop on
/// the ATmega328P) and S_j * kMaxSegmentTicks + P stays within 32 bits.
constexpr uint8_t kLineUnit = 26;
static_assert((kMaxSegmentTicks + 1ull) << kLineUnit <= 1ull << 32,
              "line_advance: S_j * len + frac within 32 bits");

struct LineGeometry {
    uint8_t m;            ///< moving axes
    uint8_t shift;        ///< k, with 2^k >= 8 * dist[0]
    uint8_t dirs;         ///< machine-axis bits travelling towards negative coordinates
    uint8_t axis[kAxes];  ///< machine axis at each sorted position (0 = reference axis)
    uint32_t dist[kAxes]; ///< ticks to travel at each sorted position, decreasing
    /// S_j = round(dist[j] * 2^k / dist[0]) in units of 2^(kLineUnit - k) (slope[0]: one tick)
    uint32_t slope[kAxes];
};

/// Sets up the line from the per-axis deltas (ticks). Returns false (with m = 0) for a
/// zero-length line or one longer than kMaxLineTicks on its reference axis.
/// (Inline: StepGen::begin_line() takes it without a call.)
inline bool line_setup(LineGeometry& g, const int32_t delta[kAxes]) {
    g.m = 0;
    g.dirs = 0;
    // §7.1: drop still axes, insertion-sort the rest by distance, decreasing. Ties keep the
    // machine-axis order so that the result is deterministic.
    uint8_t bit = 1;
    for (uint8_t a = 0; a < kAxes; ++a, bit = static_cast<uint8_t>(bit << 1)) {
        int32_t d = delta[a];
        if (d == 0) continue;
        uint32_t dist = abs32(d);
        if (d < 0) g.dirs = static_cast<uint8_t>(g.dirs | bit);
        uint8_t i = g.m;
        while (i > 0 && g.dist[i - 1] < dist) {
            g.dist[i] = g.dist[i - 1];
            g.axis[i] = g.axis[i - 1];
            --i;
        }
        g.dist[i] = dist;
        g.axis[i] = a;
        ++g.m;
    }
    if (g.m == 0 || g.dist[0] > kMaxLineTicks) {
        g.m = 0; // refused: nothing to move
        return false;
    }

    // §7.2: P = 2^k, the smallest power of two with P >= 8 d_1.
    uint32_t d1 = g.dist[0];
    uint8_t k = 3;
    for (uint32_t v = d1 - 1; v; v >>= 1) ++k; // 2^(k - 3) >= d_1: the bits of d_1 - 1
    g.shift = k;
    g.slope[0] = 1ul << kLineUnit;
    for (uint8_t j = 1; j < g.m; ++j) {
        // round(d_j * 2^k / d_1) = floor((2 d_j * 2^k / d_1 + 1) / 2), then in units of
        // 2^(kLineUnit - k) (the same value, aligned: line_advance shifts by a constant).
        uint32_t slope = (div_frac(g.dist[j], d1, static_cast<uint8_t>(k + 1)) + 1) >> 1;
        // << (kLineUnit - k) (S_j <= 2^k: no overflow), 16 of it as a word move: a short line
        // shifts by about 20, 20 turns of a 32-bit loop
        uint8_t up = static_cast<uint8_t>(kLineUnit - k);
        if (up & 16) { // (up <= kLineUnit - 3 < 32)
            slope <<= 16;
            up &= 15;
        }
        g.slope[j] = slope << up;
    }
    return true;
}

/// Macro position along a line (seed §2.1), in ticks travelled per sorted position.
struct LineCursor {
    union {
        uint32_t x1;         ///< reference-axis ticks travelled (pos[0]: one counter, not two)
        uint32_t pos[kAxes]; ///< ticks travelled at each sorted position
    };
    uint32_t frac[kAxes]; ///< fractional part of S_j * x_1 + P/2, k bits, in kLineUnit units
};

/// (Inline: StepGen::begin() takes it without a call.)
inline void line_start(const LineGeometry& g, LineCursor& c) {
    uint32_t* pos = c.pos; // (x1 is pos[0])
    uint32_t* frac = c.frac;
    for (uint8_t j = g.m; j; --j) {
        *pos++ = 0;
        *frac++ = 1ul << (kLineUnit - 1); // P/2
    }
}

/// Moves the macro position `len` reference ticks further (1 <= len <= kMaxSegmentTicks and
/// len <= dist[0] - x1) and writes the increment of each sorted position into e[0..m).
/// Precondition: g.m >= 1 (line_setup() refuses a line that moves no axis; the loop over the
/// minor axes counts down from m).
/// e[0] == len and e[j] <= len.
void line_advance(const LineGeometry& g, LineCursor& c, uint8_t len, uint8_t e[kAxes]);

} // namespace ll
