// A fixed, integer-only workload of the curve module (src/curve.cpp), run both by the host and
// by the AVR image firmware/curve_check.cpp: random arcs, ellipses and Beziers (with helices,
// extra turns and null end arms) through curve_shape() and the walker, every output folded
// into one hash. Equal hashes mean the chip computes exactly what the host tests checked: the
// host cannot see a difference of integer widths (`long` is 64 bits there, 32 on the AVR).
#pragma once

#include <stdint.h>

#include "lowlevel/curve.h"

namespace ll {
namespace test {

struct CurveWorkload {
    uint32_t hash = 2166136261u; ///< FNV-1a over every output, byte by byte
    uint32_t samples = 0;        ///< walker samples taken
    uint32_t seed;

    explicit CurveWorkload(uint32_t s) : seed(s) {}

    void mix(uint32_t v) {
        for (uint8_t i = 0; i < 4; ++i) {
            hash ^= (v >> (8 * i)) & 0xFF;
            hash *= 16777619u;
        }
    }
    uint32_t next_random() { // a linear congruential generator (Numerical Recipes')
        seed = seed * 1664525u + 1013904223u;
        return seed >> 8;
    }
    int32_t in(int32_t lo, int32_t hi) {
        return lo + static_cast<int32_t>(next_random() % static_cast<uint32_t>(hi - lo + 1));
    }

    void shape(uint8_t i) {
        CurveParams p{};
        p.kind = (i & 1) ? kCurveBezier : kCurveArc;
        p.clockwise = static_cast<uint8_t>(next_random() & 1);
        p.turns = i % 7 == 0 ? 1 : 0;
        int32_t* pts[4] = {p.start_um, p.end_um, p.a_um, p.b_um};
        const int32_t size = in(100, 200000); // µm
        for (int32_t* q : pts) {
            q[0] = in(-size, size);
            q[1] = in(-size, size);
        }
        if (p.kind == kCurveArc) {
            p.b_um[0] = in(size / 4 + 1, size);
            p.b_um[1] = i % 3 == 0 ? p.b_um[0] : in(size / 50 + 1, size);
        } else if (i % 5 == 1) { // a null start arm
            p.a_um[0] = p.start_um[0];
            p.a_um[1] = p.start_um[1];
        } else if (i % 5 == 3) { // a null end arm
            p.b_um[0] = p.end_um[0];
            p.b_um[1] = p.end_um[1];
        }
        const int32_t dw = i % 3 == 1 ? in(-50000, 50000) : 0;
        CurveShape sh{};
        mix(curve_shape(p, dw, (i & 2) != 0, sh));
        mix(sh.len_q8);
        mix(sh.min_radius_um);
        for (uint8_t k = 0; k < 3; ++k) {
            mix(static_cast<uint32_t>(sh.start_dir[k]));
            mix(static_cast<uint32_t>(sh.end_dir[k]));
        }
    }

    void walk(uint8_t i) {
        CurveWalker w{};
        CurveWalker::Ends e;
        const int32_t r = in(2, 400); // ticks
        for (uint8_t k = 0; k < 2; ++k) {
            e.start_q8[k] = in(-r * 256, r * 256);
            e.end_q8[k] = in(-r * 256, r * 256);
            e.start[k] = (e.start_q8[k] + 128) >> 8;
            e.end[k] = (e.end_q8[k] + 128) >> 8;
        }
        e.start[2] = 0;
        e.end[2] = i % 3 == 2 ? in(-300, 300) : 0;
        bool ok;
        if (i & 1) {
            const int32_t a[2] = {in(-r * 256, r * 256), in(-r * 256, r * 256)};
            const int32_t b[2] = {in(-r * 256, r * 256), in(-r * 256, r * 256)};
            ok = w.bezier(e, a, b);
        } else {
            const int32_t c[2] = {in(-r * 64, r * 64), in(-r * 64, r * 64)};
            uint32_t radii[2];
            radii[0] = static_cast<uint32_t>(in(r * 64, r * 256));
            radii[1] = i % 4 == 0 ? radii[0] : static_cast<uint32_t>(in(r * 32, r * 256));
            ok = w.arc(e, c, radii, (next_random() & 1) != 0, i % 9 == 0 ? 1 : 0);
        }
        mix(ok);
        if (!ok) return;
        uint8_t moved, neg;
        int32_t d[3];
        uint16_t n = 0;
        while (w.next(moved, neg)) {
            mix(static_cast<uint32_t>(moved | (neg << 4)));
            if ((++n & 63) == 0) {
                mix(w.peek(d));
                for (int32_t v : d) mix(static_cast<uint32_t>(v));
            }
            ++samples;
        }
        for (int32_t v : w.pos) mix(static_cast<uint32_t>(v));
    }

    /// `count` curves of each kind.
    void run(uint8_t count) {
        for (uint8_t i = 0; i < count; ++i) {
            shape(i);
            walk(i);
        }
    }
};

} // namespace test
} // namespace ll
