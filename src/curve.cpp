#include "lowlevel/curve.h"

#include "lowlevel/fixmath.h"

namespace ll {
namespace {

constexpr int32_t kOneQ30 = 1l << 30;
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

// Unit vector (x / rx, y / ry) normalised, Q30, for a point seen from an ellipse's centre.
void direction(int32_t x_q8, int32_t y_q8, const uint32_t radii_q8[2], int32_t& c, int32_t& s) {
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

} // namespace

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
    out[0] = centre_[0] + scale_q30(static_cast<int32_t>(radii_[0]), c);
    out[1] = centre_[1] + scale_q30(static_cast<int32_t>(radii_[1]), s);
}

bool CurveWalker::arc(const Ends& e, const int32_t centre_q8[2], const uint32_t radii_q8[2],
                      bool clockwise, uint8_t turns) {
    const int32_t* start = e.start;
    const int32_t* end = e.end;
    kind_ = 0;
    if (radii_q8[0] == 0 || radii_q8[1] == 0) return false;
    for (uint8_t a = 0; a < 2; ++a) {
        centre_[a] = centre_q8[a];
        radii_[a] = radii_q8[a];
    }
    for (uint8_t a = 0; a < 3; ++a) {
        pos[a] = start[a];
        end_[a] = end[a];
    }
    // Directions of the start and end points (their projections on the curve), and the sweep.
    direction(e.start_q8[0] - centre_[0], e.start_q8[1] - centre_[1], radii_, c_, s_);
    direction(e.end_q8[0] - centre_[0], e.end_q8[1] - centre_[1], radii_, end_c_, end_s_);
    int64_t sweep = static_cast<int64_t>(atan2_q29(end_s_, end_c_)) - atan2_q29(s_, c_);
    const int64_t turn = 2ll * kPiQ29;
    if (clockwise) {
        while (sweep >= 0) sweep -= turn; // a closed arc is a full turn
        sweep -= turns * turn;
    } else {
        while (sweep <= 0) sweep += turn;
        sweep += turns * turn;
    }
    // Pieces: at most 22.5 degrees and kMaxPieceTicks long.
    uint64_t mag = static_cast<uint64_t>(sweep < 0 ? -sweep : sweep);
    uint32_t rmax = (radii_[0] > radii_[1] ? radii_[0] : radii_[1]) >> 8;
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
    small_angle_q30(h, rot_c_, rot_s_, arm_);
    // Helix axis: linear along the curve.
    w0_q8_ = start[2] * 256;
    dw_q8_ = (end[2] - start[2]) * 256;
    int32_t p[2];
    arc_point(c_, s_, p);
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
        int32_t c = mul_q30(c_, rot_c_) - mul_q30(s_, rot_s_);
        int32_t s = mul_q30(s_, rot_c_) + mul_q30(c_, rot_s_);
        if (last) { // land on the end point's direction: no drift left over
            c = end_c_;
            s = end_s_;
        }
        int32_t q[2];
        arc_point(c, s, q);
        p3[0] = q[0];
        p3[1] = q[1];
        // Arms along the tangents (dX/dt = -ru sin t, dY/dt = rv cos t), 4/3 tan(h/4) long.
        int32_t arm = arm_;
        p1[0] = p0[0] + scale_q30(scale_q30(static_cast<int32_t>(radii_[0]), -s_), arm);
        p1[1] = p0[1] + scale_q30(scale_q30(static_cast<int32_t>(radii_[1]), c_), arm);
        p2[0] = p3[0] - scale_q30(scale_q30(static_cast<int32_t>(radii_[0]), -s), arm);
        p2[1] = p3[1] - scale_q30(scale_q30(static_cast<int32_t>(radii_[1]), c), arm);
        c_ = c;
        s_ = s;
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

void CurveWalker::next_delta_q16(int32_t d[3]) const {
    for (uint8_t a = 0; a < 3; ++a) d[a] = static_cast<int32_t>(d1_[a] >> 24);
}

} // namespace ll
