#include "lowlevel/curve.h"

#include "lowlevel/fixmath.h"

namespace ll {
namespace {

constexpr int32_t kOneQ30 = 1l << 30;
constexpr int32_t kOneQ29 = 1l << 29;
// Largest piece of an arc: 22.5 degrees (radius error of its cubic: 7e-8 R) ...
constexpr int32_t kMaxPieceAngleQ29 = kPiQ29 / 8;
// ... and at most this many ticks long, so that N <= 4096 samples keep the forward-difference
// error below 0.02 tick.
constexpr uint32_t kMaxPieceTicks = 2000;

int32_t mul_q30(int32_t a, int32_t b) {
    return static_cast<int32_t>((static_cast<int64_t>(a) * b) >> 30);
}

// A Q8 coordinate times a Q30 factor, Q8.
int32_t scale_q30(int32_t v_q8, int32_t f_q30) {
    return static_cast<int32_t>((static_cast<int64_t>(v_q8) * f_q30) >> 30);
}

// round(x / 2^40) for the forward-difference accumulator.
int32_t round_q40(int64_t x) {
    return static_cast<int32_t>((x + (1ll << 39)) >> 40);
}

} // namespace

void ellipse_direction(int32_t x_q8, int32_t y_q8, const uint32_t radii_q8[2], int32_t& c,
                       int32_t& s) {
    Num a(abs32(x_q8)), b(abs32(y_q8));
    a.div(radii_q8[0]);
    b.div(radii_q8[1]);
    Num aa = a, bb = b;
    aa.mul(a);
    bb.mul(b);
    Num n = aa.add(bb).sqrt();
    uint32_t ca = a.div(n).shift(30).u32(), sb = b.div(n).shift(30).u32();
    if (ca > static_cast<uint32_t>(kOneQ30)) ca = kOneQ30;
    if (sb > static_cast<uint32_t>(kOneQ30)) sb = kOneQ30;
    c = x_q8 < 0 ? -static_cast<int32_t>(ca) : static_cast<int32_t>(ca);
    s = y_q8 < 0 ? -static_cast<int32_t>(sb) : static_cast<int32_t>(sb);
}

int64_t arc_sweep_q29(int32_t c0, int32_t s0, int32_t c1, int32_t s1, bool clockwise,
                      uint8_t turns) {
    int64_t sweep = static_cast<int64_t>(atan2_q29(s1, c1)) - atan2_q29(s0, c0);
    const int64_t turn = 2ll * kPiQ29;
    if (clockwise) {
        while (sweep >= 0) sweep -= turn; // a closed arc is a full turn
        sweep -= turns * turn;
    } else {
        while (sweep <= 0) sweep += turn;
        sweep += turns * turn;
    }
    return sweep;
}

void CurveWalker::start_piece(const int32_t p0[3], const int32_t p1[3], const int32_t p2[3],
                              const int32_t p3[3]) {
    // Polynomial of the piece relative to its start (ticks x 256): d1 t + d2 t^2 + d3 t^3.
    int32_t d1[3], d2[3], d3[3];
    uint32_t bound = 0; // largest axis speed over the piece, ticks x 256 per unit of t
    for (uint8_t a = 0; a < 3; ++a) {
        d1[a] = 3 * (p1[a] - p0[a]);
        d2[a] = 3 * (p0[a] - 2 * p1[a] + p2[a]);
        d3[a] = p3[a] - p0[a] + 3 * (p1[a] - p2[a]);
        uint32_t b = abs32(d1[a]) + 2 * abs32(d2[a]) + 3 * abs32(d3[a]);
        if (b > bound) bound = b;
    }
    // N = 2^m > bound (ticks): at most one tick per sample and axis.
    uint8_t m = 0;
    while ((1ul << (m + 8)) <= bound) ++m;
    left_ = static_cast<uint16_t>(1u << m);
    for (uint8_t a = 0; a < 3; ++a) {
        base_[a] = p0[a] >> 8;
        int64_t n1 = static_cast<int64_t>(d1[a]) << 32, n2 = static_cast<int64_t>(d2[a]) << 32,
                n3 = static_cast<int64_t>(d3[a]) << 32;
        f_[a] = static_cast<int64_t>(p0[a] & 0xFF) << 32;
        d1_[a] = (n1 >> m) + (n2 >> (2 * m)) + (n3 >> (3 * m));
        d2_[a] = 2 * (n2 >> (2 * m)) + 6 * (n3 >> (3 * m));
        d3_[a] = 6 * (n3 >> (3 * m));
        prev_q8_[a] = p3[a];
    }
}

void CurveWalker::arc_point(int32_t c, int32_t s, int32_t out[2]) const {
    out[0] = a_.centre[0] + scale_q30(static_cast<int32_t>(a_.radii[0]), c);
    out[1] = a_.centre[1] + scale_q30(static_cast<int32_t>(a_.radii[1]), s);
}

bool CurveWalker::arc(const Ends& e, const int32_t centre_q8[2], const uint32_t radii_q8[2],
                      bool clockwise, uint8_t turns) {
    const int32_t* start = e.start;
    const int32_t* end = e.end;
    kind_ = 0;
    if (radii_q8[0] == 0 || radii_q8[1] == 0) return false;
    for (uint8_t a = 0; a < 2; ++a) {
        a_.centre[a] = centre_q8[a];
        a_.radii[a] = radii_q8[a];
    }
    for (uint8_t a = 0; a < 3; ++a) {
        pos[a] = start[a];
        end_[a] = end[a];
    }
    // Directions of the start and end points (their projections on the curve), and the sweep.
    ellipse_direction(e.start_q8[0] - a_.centre[0], e.start_q8[1] - a_.centre[1], a_.radii, a_.c,
                      a_.s);
    ellipse_direction(e.end_q8[0] - a_.centre[0], e.end_q8[1] - a_.centre[1], a_.radii, end_c_,
                      end_s_);
    int64_t sweep = arc_sweep_q29(a_.c, a_.s, end_c_, end_s_, clockwise, turns);
    // Pieces: at most 22.5 degrees and kMaxPieceTicks long.
    uint64_t mag = static_cast<uint64_t>(sweep < 0 ? -sweep : sweep);
    uint32_t rmax = (a_.radii[0] > a_.radii[1] ? a_.radii[0] : a_.radii[1]) >> 8;
    // The sweep is below 2^40 (255 turns), so these quotients are of small numbers.
    uint32_t by_angle = static_cast<uint32_t>(mag >> 26) / (kMaxPieceAngleQ29 >> 26) + 1;
    // length = sweep x radius = (mag / 2^29) rmax ticks, over kMaxPieceTicks
    uint64_t len = (mag >> 13) * (rmax + 1); // ticks x 2^16
    uint32_t by_length = static_cast<uint32_t>(len >> 16) / kMaxPieceTicks + 1;
    uint32_t n = by_angle > by_length ? by_angle : by_length;
    if (n > 0xFFFF) return false;
    piece_count_ = pieces_ = static_cast<uint16_t>(n);
    // Piece angle, Q30 (at most 22.5 degrees, so the series apply).
    int32_t h = static_cast<int32_t>(Num(static_cast<uint32_t>(mag >> 10)).div(n).shift(11).u32());
    if (sweep < 0) h = -h;
    small_angle_q30(h, a_.rot_c, a_.rot_s, a_.arm);
    // Helix axis: linear along the curve.
    w0_q8_ = start[2] * 256;
    dw_q8_ = (end[2] - start[2]) * 256;
    int32_t p[2];
    arc_point(a_.c, a_.s, p);
    prev_q8_[0] = p[0];
    prev_q8_[1] = p[1];
    prev_q8_[2] = w0_q8_;
    kind_ = 1;
    left_ = 0;
    return true;
}

void CurveWalker::bezier_point(uint32_t a_q20, int32_t out[2], int32_t slope[2]) const {
    // slope: B'(a) / 2^j (the tangent over one piece), ticks x 256.
    // Horner's rule in 64-bit fixed point, a in [0, 1] as Q20.
    for (uint8_t k = 0; k < 2; ++k) {
        int64_t b = poly_[3][k];
        b = ((b * a_q20) >> 20) + poly_[2][k];
        b = ((b * a_q20) >> 20) + poly_[1][k];
        b = ((b * a_q20) >> 20) + poly_[0][k];
        out[k] = static_cast<int32_t>(b);
        int64_t d = 3 * poly_[3][k];
        d = ((d * a_q20) >> 20) + 2 * poly_[2][k];
        d = ((d * a_q20) >> 20) + poly_[1][k];
        slope[k] = static_cast<int32_t>(d >> log_pieces_);
    }
}

bool CurveWalker::bezier(const Ends& e, const int32_t p1_q8[2], const int32_t p2_q8[2]) {
    const int32_t* start = e.start;
    const int32_t* end = e.end;
    kind_ = 0;
    uint64_t bound = 0;
    for (uint8_t a = 0; a < 3; ++a) {
        pos[a] = start[a];
        end_[a] = end[a];
    }
    for (uint8_t k = 0; k < 2; ++k) {
        int64_t p0 = e.start_q8[k], p3 = e.end_q8[k];
        poly_[0][k] = p0;
        poly_[1][k] = 3 * (p1_q8[k] - p0);
        poly_[2][k] = 3 * (p0 - 2 * static_cast<int64_t>(p1_q8[k]) + p2_q8[k]);
        poly_[3][k] = p3 - p0 + 3 * (static_cast<int64_t>(p1_q8[k]) - p2_q8[k]);
        uint64_t b = 0;
        for (uint8_t i = 1; i < 4; ++i) {
            int64_t c = poly_[i][k];
            b += static_cast<uint64_t>(c < 0 ? -c : c) * i;
        }
        if (b > bound) bound = b;
    }
    // 2^j pieces, each with a hodograph bound below kMaxPieceTicks (it shrinks with 2^j).
    uint8_t j = 0;
    while (((bound >> 8) >> j) >= kMaxPieceTicks) {
        if (j == 15) return false;
        ++j;
    }
    log_pieces_ = j;
    piece_count_ = pieces_ = static_cast<uint16_t>(1u << j);
    w0_q8_ = start[2] * 256;
    dw_q8_ = (end[2] - start[2]) * 256;
    prev_q8_[0] = e.start_q8[0];
    prev_q8_[1] = e.start_q8[1];
    prev_q8_[2] = w0_q8_;
    end_c_ = e.end_q8[0]; // the last piece lands on the commanded end
    end_s_ = e.end_q8[1];
    kind_ = 2;
    left_ = 0;
    return true;
}

bool CurveWalker::next_piece() {
    if (pieces_ == 0) return false;
    uint16_t index = static_cast<uint16_t>(piece_count_ - pieces_); // 0-based
    --pieces_;
    bool last = pieces_ == 0;
    int32_t p0[3], p1[3], p2[3], p3[3];
    for (uint8_t a = 0; a < 3; ++a) p0[a] = prev_q8_[a];
    // Helix: w moves linearly, the last piece landing exactly on the end.
    int32_t w3 = last ? dw_q8_ + w0_q8_
                      : w0_q8_ + static_cast<int32_t>(Num(abs32(dw_q8_))
                                                          .mul(static_cast<uint32_t>(index) + 1)
                                                          .div(piece_count_)
                                                          .u32()) *
                                     (dw_q8_ < 0 ? -1 : 1);
    p3[2] = w3;
    p1[2] = p0[2] + (w3 - p0[2]) / 3;
    p2[2] = w3 - (w3 - p0[2]) / 3;
    if (kind_ == 1) {
        int32_t c = mul_q30(a_.c, a_.rot_c) - mul_q30(a_.s, a_.rot_s);
        int32_t s = mul_q30(a_.s, a_.rot_c) + mul_q30(a_.c, a_.rot_s);
        if (last) { // land on the end point's direction: no drift left over
            c = end_c_;
            s = end_s_;
        }
        int32_t q[2];
        arc_point(c, s, q);
        p3[0] = q[0];
        p3[1] = q[1];
        // Arms along the tangents (dX/dt = -ru sin t, dY/dt = rv cos t), 4/3 tan(h/4) long.
        int32_t arm = a_.arm;
        p1[0] = p0[0] + scale_q30(scale_q30(static_cast<int32_t>(a_.radii[0]), -a_.s), arm);
        p1[1] = p0[1] + scale_q30(scale_q30(static_cast<int32_t>(a_.radii[1]), a_.c), arm);
        p2[0] = p3[0] - scale_q30(scale_q30(static_cast<int32_t>(a_.radii[0]), -s), arm);
        p2[1] = p3[1] - scale_q30(scale_q30(static_cast<int32_t>(a_.radii[1]), c), arm);
        a_.c = c;
        a_.s = s;
    } else {
        // Bezier part [a, a + 1/n]: ends and tangents of the curve, arms = slope / (3 n).
        uint32_t a0 = static_cast<uint32_t>(index) << (20 - log_pieces_);
        uint32_t a1 = static_cast<uint32_t>(index + 1) << (20 - log_pieces_);
        int32_t q0[2], s0[2], q3[2], s3[2];
        bezier_point(a0, q0, s0);
        bezier_point(a1, q3, s3);
        if (last) {
            q3[0] = end_c_;
            q3[1] = end_s_;
        }
        for (uint8_t k = 0; k < 2; ++k) {
            p3[k] = q3[k];
            p1[k] = p0[k] + s0[k] / 3;
            p2[k] = p3[k] - s3[k] / 3;
        }
    }
    start_piece(p0, p1, p2, p3);
    return true;
}

bool CurveWalker::next(uint8_t& moved, uint8_t& neg) {
    moved = neg = 0;
    while (left_ == 0) {
        if (kind_ == 0) return false;
        if (!next_piece()) {
            // Last step: from the rounded end of the curve to the exact target (at most one
            // tick per axis: both are within 0.71 tick of the curve's end point).
            kind_ = 0;
            for (uint8_t a = 0; a < 3; ++a) {
                if (pos[a] != end_[a]) {
                    moved = static_cast<uint8_t>(moved | (1u << a));
                    if (end_[a] < pos[a]) neg = static_cast<uint8_t>(neg | (1u << a));
                    pos[a] = end_[a];
                }
            }
            return moved != 0;
        }
    }
    --left_;
    for (uint8_t a = 0; a < 3; ++a) {
        f_[a] += d1_[a];
        d1_[a] += d2_[a];
        d2_[a] += d3_[a];
        int32_t p = base_[a] + round_q40(f_[a]);
        if (p != pos[a]) {
            moved = static_cast<uint8_t>(moved | (1u << a));
            if (p < pos[a]) neg = static_cast<uint8_t>(neg | (1u << a));
            pos[a] = p;
        }
    }
    return true;
}

uint16_t CurveWalker::peek(int32_t d[3]) {
    while (left_ == 0 && kind_ != 0 && pieces_ != 0) next_piece();
    for (uint8_t a = 0; a < 3; ++a) d[a] = static_cast<int32_t>(d1_[a] >> 24);
    return left_;
}

namespace {

// |(x, y, z)| for signed components.
Num norm3(int32_t x, int32_t y, int32_t z) {
    Num a(abs32(x)), b(abs32(y)), c(abs32(z));
    Num aa = a, bb = b, cc = c;
    return aa.mul(a).add(bb.mul(b)).add(cc.mul(c)).sqrt();
}

// Unit vector of (x, y, z) in Q29.
void unit3(int32_t x, int32_t y, int32_t z, int32_t out[3]) {
    Num n = norm3(x, y, z);
    const int32_t v[3] = {x, y, z};
    for (uint8_t k = 0; k < 3; ++k) {
        if (n.m == 0) {
            out[k] = 0;
            continue;
        }
        uint32_t u = Num(abs32(v[k])).div(n).shift(29).u32();
        if (u > static_cast<uint32_t>(kOneQ29)) u = kOneQ29;
        out[k] = v[k] < 0 ? -static_cast<int32_t>(u) : static_cast<int32_t>(u);
    }
}

// Tangent of the ellipse (ru cos t, rv sin t) at direction (c, s): (-ru s, rv c) µm per
// radian, signed by the direction of travel.
void ellipse_tangent(const uint32_t r[2], int32_t c, int32_t s, bool cw, int32_t& tu, int32_t& tv) {
    tu = static_cast<int32_t>((static_cast<int64_t>(r[0]) * -s) >> 30);
    tv = static_cast<int32_t>((static_cast<int64_t>(r[1]) * c) >> 30);
    if (cw) {
        tu = -tu;
        tv = -tv;
    }
}

// Bezier B'(t) (u, v) at t in [0, 1] (Q20), from the control points p0..p3.
void bezier_slope(const int32_t p[4][2], uint32_t t_q20, int32_t out[2]) {
    for (uint8_t k = 0; k < 2; ++k) {
        int64_t a = 3ll * (p[1][k] - p[0][k]), b = 3ll * (p[2][k] - p[1][k]),
                c = 3ll * (p[3][k] - p[2][k]);
        // De Casteljau on the hodograph (a, b, c): a quadratic Bezier.
        int64_t u = 1ll << 20, t = t_q20;
        // Rounded, not truncated: a floor would bias every slope (and the length) down.
        const int64_t half = 1ll << 19;
        int64_t ab = (a * (u - t) + b * t + half) >> 20, bc = (b * (u - t) + c * t + half) >> 20;
        out[k] = static_cast<int32_t>((ab * (u - t) + bc * t + half) >> 20);
    }
}

// Simpson's rule on k intervals (fine) and k/2 (coarse) at once: node i of k gets weight
// 1, 4, 2, ... 4, 1 in the fine sum and, for even i, 1, 4, 2, ... 1 in the coarse one.
void simpson_add(Num& fine, Num& coarse, Num f, uint32_t i, uint32_t k) {
    Num g = f;
    fine.add(i == 0 || i == k ? f : f.mul(i & 1 ? 4u : 2u));
    if (i & 1) return;
    uint32_t j = i / 2;
    coarse.add(j == 0 || j == k / 2 ? g : g.mul(j & 1 ? 4u : 2u));
}

// Integral over an interval of length `width`: S = S_k + (S_k - S_k/2) / 15 (Richardson),
// with S_k = width / (3k) * fine and S_k/2 = width / (3 k/2) * coarse.
Num simpson_richardson(Num fine, Num coarse, Num width, uint32_t k) {
    // 16 S_k - S_k/2 = width / (3k) (16 fine - 2 coarse), then / 15.
    fine.mul(16);
    coarse.mul(2);
    Num r = fine;
    if (fine.cmp(coarse) > 0) {
        // fine - coarse without a subtraction routine: fine (1 - coarse / fine)
        Num q = coarse;
        q.div(fine);
        uint32_t frac = q.shift(30).u32(); // < 2^30
        r.mul(static_cast<uint32_t>((1ul << 30) - frac)).shift(-30);
    }
    return r.mul(width).div(3 * k).div(15);
}

} // namespace

bool curve_shape(const CurveParams& cp, int32_t dw_um, bool w_regulated, CurveShape& out) {
    const int32_t dw = w_regulated ? dw_um : 0;
    Num len{};
    if (cp.kind == kCurveArc) {
        const uint32_t r[2] = {static_cast<uint32_t>(cp.b_um[0]),
                               static_cast<uint32_t>(cp.b_um[1])};
        if (r[0] == 0 || r[1] == 0) return false;
        int32_t c0, s0, c1, s1;
        ellipse_direction(cp.start_um[0] - cp.a_um[0], cp.start_um[1] - cp.a_um[1], r, c0, s0);
        ellipse_direction(cp.end_um[0] - cp.a_um[0], cp.end_um[1] - cp.a_um[1], r, c1, s1);
        int64_t sweep = arc_sweep_q29(c0, s0, c1, s1, cp.clockwise != 0, cp.turns);
        uint64_t mag = static_cast<uint64_t>(sweep < 0 ? -sweep : sweep);
        uint8_t sh = 0;
        while ((mag >> sh) > 0xFFFFFFFFull) ++sh;
        Num angle(static_cast<uint32_t>(mag >> sh), static_cast<int8_t>(sh - 29)); // radians
        if (r[0] == r[1]) {
            len = angle;
            len.mul(r[0]); // r |sweep|, µm
            out.min_radius_um = r[0];
        } else {
            // Simpson's rule on |dP/dt| = sqrt(ru^2 sin^2 t + rv^2 cos^2 t) over k intervals
            // and k/2 from the same nodes, with k doubled (from 32 per turn) until both agree to
            // 1e-5, then extrapolated (Richardson): an eccentric ellipse needs more nodes near
            // the ends of its major axis. The unit vector advances by an integer rotation.
            uint32_t k = static_cast<uint32_t>(mag / (2ull * kPiQ29 / 32)) + 1;
            k = (k + 3) & ~3ul;
            for (;;) {
                int32_t h = static_cast<int32_t>(
                    Num(static_cast<uint32_t>(mag >> 10)).div(k).shift(11).u32());
                if (sweep < 0) h = -h;
                int32_t rc, rs, arm;
                small_angle_q30(h, rc, rs, arm);
                int32_t c = c0, s = s0;
                Num fine{}, coarse{};
                for (uint32_t i = 0; i <= k; ++i) {
                    Num a(r[0]), b(r[1]);
                    a.mul(abs32(s)).shift(-30);
                    b.mul(abs32(c)).shift(-30);
                    Num aa = a, bb = b;
                    Num f = aa.mul(a).add(bb.mul(b)).sqrt();
                    simpson_add(fine, coarse, f, i, k);
                    int32_t cn = mul_q30(c, rc) - mul_q30(s, rs);
                    s = mul_q30(s, rc) + mul_q30(c, rs);
                    c = cn;
                }
                len = simpson_richardson(fine, coarse, angle, k);
                // converged when 2 coarse and fine (both k/2 weighted) agree: |S_k - S_k/2| < 1e-5
                // S
                Num f2 = fine, c2 = coarse;
                c2.mul(2);
                int8_t order = f2.cmp(c2);
                Num lo_ = order < 0 ? f2 : c2, hi_ = order < 0 ? c2 : f2;
                uint32_t ratio = lo_.div(hi_).shift(30).u32();
                if ((1ul << 30) - ratio < 10737 || k >= 1024) break; // 1e-5 x 2^30
                k *= 2;
            }
            uint32_t lo = r[0] < r[1] ? r[0] : r[1], hi = r[0] < r[1] ? r[1] : r[0];
            out.min_radius_um = Num(lo).mul(lo).div(hi).u32(); // a^2 / b at the flat ends
        }
        int32_t tu, tv;
        ellipse_tangent(r, c0, s0, cp.clockwise != 0, tu, tv);
        // w rises linearly with the angle: dw / |sweep| µm per radian.
        int32_t tw = static_cast<int32_t>(Num(abs32(dw_um)).div(angle).u32());
        if (dw_um < 0) tw = -tw;
        unit3(tu, tv, tw, out.start_dir);
        ellipse_tangent(r, c1, s1, cp.clockwise != 0, tu, tv);
        unit3(tu, tv, tw, out.end_dir);
    } else {
        const int32_t p[4][2] = {{cp.start_um[0], cp.start_um[1]},
                                 {cp.a_um[0], cp.a_um[1]},
                                 {cp.b_um[0], cp.b_um[1]},
                                 {cp.end_um[0], cp.end_um[1]}};
        // Simpson's rule on |B'(t)| over k and k/2 intervals, k doubled from 32 until both
        // agree to 1e-5, extrapolated; the smallest radius of curvature |B'|^3 / |B' x B''|
        // sampled at the same points (B'' from neighbouring slopes).
        Num rmin{};
        bool have_r = false;
        for (uint32_t k = 32;; k *= 2) {
            Num fine{}, coarse{};
            int32_t prev[2] = {0, 0};
            const uint8_t log_k = static_cast<uint8_t>(
                k == 32 ? 5 : (k == 64 ? 6 : (k == 128 ? 7 : (k == 256 ? 8 : 9))));
            for (uint32_t i = 0; i <= k; ++i) {
                int32_t d[2];
                bezier_slope(p, i << (20 - log_k), d);
                simpson_add(fine, coarse, norm3(d[0], d[1], 0), i, k);
                if (i != 0 && k == 32) {
                    // |B' x dB'| / dt with dt = 1/32, |B'|^3 / that.
                    int64_t cross =
                        static_cast<int64_t>(prev[0]) * d[1] - static_cast<int64_t>(prev[1]) * d[0];
                    Num n = norm3(d[0], d[1], 0);
                    if (cross != 0 && n.m != 0) {
                        uint64_t ac = static_cast<uint64_t>(cross < 0 ? -cross : cross);
                        Num cr(static_cast<uint32_t>(ac >> 16), 16);
                        Num rc = n;
                        rc.mul(n).mul(n).div(cr).div(32);
                        if (!have_r || rc.cmp(rmin) < 0) rmin = rc;
                        have_r = true;
                    }
                }
                prev[0] = d[0];
                prev[1] = d[1];
            }
            len = simpson_richardson(fine, coarse, Num(1), k);
            Num f2 = fine, c2 = coarse;
            c2.mul(2);
            int8_t order = f2.cmp(c2);
            Num lo_ = order < 0 ? f2 : c2, hi_ = order < 0 ? c2 : f2;
            uint32_t ratio = lo_.div(hi_).shift(30).u32();
            if ((1ul << 30) - ratio < 10737 || k >= 512) break; // 1e-5 x 2^30
        }
        out.min_radius_um = have_r ? rmin.u32() : 0xFFFFFFFFul;
        // Tangents: the first non-degenerate arm at each end; w rises linearly with t.
        int32_t su = p[1][0] - p[0][0], sv = p[1][1] - p[0][1];
        if (su == 0 && sv == 0) {
            su = p[2][0] - p[0][0];
            sv = p[2][1] - p[0][1];
        }
        int32_t eu = p[3][0] - p[2][0], ev = p[3][1] - p[2][1];
        if (eu == 0 && ev == 0) {
            eu = p[3][0] - p[1][0];
            ev = p[3][1] - p[1][1];
        }
        // |B'(0)| = 3 |p1 - p0|: w' = dw per unit t, so compare with 3 x the arm.
        unit3(3 * su, 3 * sv, dw_um, out.start_dir);
        unit3(3 * eu, 3 * ev, dw_um, out.end_dir);
    }
    if (dw != 0) { // helix: sqrt(plane^2 + dw^2)
        Num w(abs32(dw));
        Num l2 = len;
        len = l2.mul(len).add(w.mul(w)).sqrt();
    }
    if (len.m == 0) return false;
    out.len_q8 = len.shift(8).u32();
    return true;
}

} // namespace ll
