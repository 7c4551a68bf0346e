#include "lowlevel/curve.h"

#include "lowlevel/fixmath.h"
#include "lowlevel/pgm.h"

// Size on the ATmega328P: every 64-bit addition, shift or product is a library call wrapped in
// long register moves, and every Num operation a call sequence. So the few such operations are
// written once, in the out-of-line helpers below, and the three axes are loops, not copies.

namespace ll {
namespace {

constexpr int32_t kOneQ30 = 1l << 30;
constexpr int32_t kOneQ29 = 1l << 29;
// Pieces of an arc are at most 21.5 degrees (their cubic is within 7e-8 R of the ellipse) and at
// most this many ticks long, so that N <= 4096 samples keep the forward-difference error below
// 0.02 tick.
constexpr uint32_t kMaxPieceTicks = 2000;

// (a b) >> 30: products of Q30 factors, and Q8 coordinates times Q30 factors.
__attribute__((noinline)) int32_t mul_q30(int32_t a, int32_t b) {
    return static_cast<int32_t>((static_cast<int64_t>(a) * b) >> 30);
}

// x / 3, exactly (truncated towards zero as `/` does), by a multiplication: no division routine.
__attribute__((noinline)) int32_t third(int32_t x) {
    int32_t q = static_cast<int32_t>((static_cast<uint64_t>(abs32(x)) * 0xAAAAAAABull) >> 33);
    return x < 0 ? -q : q;
}

// Taylor coefficients (Q30) of cos x, sin x / x and tan x / x as polynomials in x^2, with the
// signs of cos and sin taken by evaluating at -x^2. For |x| <= 0.4 rad the first term left out is
// below 2^-31.
const uint32_t kSeriesQ30[3][5] LL_PROGMEM = {
    {1073741824, 536870912, 44739243, 1491308, 26631},       // 1, 1/2, 1/24, 1/720, 1/40320
    {1073741824, 178956971, 8947849, 213044, 2959},          // 1, 1/6, 1/120, 1/5040, 1/362880
    {1073741824, 357913941, 143165577, 57947971, 23482185}}; // 1, 1/3, 2/15, 17/315, 62/2835

// Series `which` of kSeriesQ30 at y (Horner's rule), Q30.
int32_t series(uint8_t which, int32_t y) {
    int32_t r = 0;
    for (uint8_t i = 5; i-- > 0;) {
        r = static_cast<int32_t>(flash_read_u32(&kSeriesQ30[which][i])) + mul_q30(r, y);
    }
    return r;
}

// cos h and sin h for |h| <= 0.4 rad, all Q30.
void rotation(int32_t h, int32_t& c, int32_t& s) {
    int32_t y = -mul_q30(h, h);
    c = series(0, y);
    s = mul_q30(h, series(1, y));
}

// (c, s) turned by the angle whose cosine and sine are (rc, rs), Q30.
void rotate(int32_t& c, int32_t& s, int32_t rc, int32_t rs) {
    int32_t cn = mul_q30(c, rc) - mul_q30(s, rs);
    s = mul_q30(s, rc) + mul_q30(c, rs);
    c = cn;
}

// sqrt(a^2 + b^2 + cc).
Num hypot(Num a, Num b, const Num& cc) {
    a.mul(a);
    b.mul(b);
    return a.add(b).add(cc).sqrt();
}

// A 64-bit magnitude as a Num (truncated to its 32 leading bits).
Num num64(uint64_t v) {
    int8_t e = 0;
    while (v >> 32) {
        v >>= 1;
        ++e;
    }
    return Num(static_cast<uint32_t>(v), e);
}

// num / den as a signed fixed-point value with `bits` fraction bits, at most 1 in magnitude.
int32_t unit_part(Num num, const Num& den, bool negative, uint8_t bits) {
    uint32_t u = num.div(den).shift(static_cast<int8_t>(bits)).u32();
    if (u > (1ul << bits)) u = 1ul << bits;
    return negative ? -static_cast<int32_t>(u) : static_cast<int32_t>(u);
}

// v[0..2] = (x, y, z) / |(x, y, z)|, Q29, from magnitudes and sign bits (1 = x, 2 = y, 4 = z).
void unit3(const Num m[3], uint8_t negative, int32_t out[3]) {
    Num zz = m[2];
    Num n = hypot(m[0], m[1], zz.mul(m[2]));
    for (uint8_t k = 0; k < 3; ++k) {
        out[k] = n.m ? unit_part(m[k], n, (negative >> k) & 1, 29) : 0;
    }
}

// Updates a position by one sample: the bit of the axis in `moved` (and `neg` when it goes down).
void move_to(int32_t& pos, int32_t p, uint8_t bit, uint8_t& moved, uint8_t& neg) {
    if (p == pos) return;
    moved = static_cast<uint8_t>(moved | bit);
    if (p < pos) neg = static_cast<uint8_t>(neg | bit);
    pos = p;
}

// One sample of a cubic by forward differencing: f += d1, d1 += d2, d2 += d3 (v = f, d1, d2, d3).
__attribute__((noinline)) void fd_step(int64_t v[4]) {
    v[0] += v[1];
    v[1] += v[2];
    v[2] += v[3];
}

// x / 2^s in Q40 for x in Q8 (s <= 36): exact for s <= 32, floored beyond.
__attribute__((noinline)) int64_t q40(int32_t x, uint8_t s) {
    return (static_cast<int64_t>(x) << 32) >> s;
}

// ((b a) >> 20) + add: one step of Horner's rule with a in [0, 1] as Q20.
__attribute__((noinline)) int64_t horner(int64_t b, uint32_t a_q20, int64_t add) {
    return ((b * a_q20) >> 20) + add;
}

} // namespace

void ellipse_direction(int32_t x_q8, int32_t y_q8, const uint32_t radii_q8[2], int32_t& c,
                       int32_t& s) {
    const int32_t v[2] = {x_q8, y_q8};
    Num q[2];
    for (uint8_t k = 0; k < 2; ++k) q[k] = Num(abs32(v[k])).div(radii_q8[k]);
    Num n = hypot(q[0], q[1], Num{});
    c = unit_part(q[0], n, x_q8 < 0, 30);
    s = unit_part(q[1], n, y_q8 < 0, 30);
}

int64_t arc_sweep_q29(int32_t c0, int32_t s0, int32_t c1, int32_t s1, bool clockwise,
                      uint8_t turns) {
    int64_t sweep = static_cast<int64_t>(atan2_q29(s1, c1)) - atan2_q29(s0, c0); // (-2 pi, 2 pi)
    const int64_t turn = clockwise ? -2ll * kPiQ29 : 2ll * kPiQ29;
    uint16_t k = turns;
    if (clockwise ? sweep >= 0 : sweep <= 0) ++k; // a closed arc is a full turn
    while (k--) sweep += turn;
    return sweep;
}

void CurveWalker::begin(const Ends& e, const int32_t p0_q8[2], uint8_t kind) {
    for (uint8_t a = 0; a < 3; ++a) {
        pos[a] = e.start[a];
        end_[a] = e.end[a];
    }
    // w moves linearly along the curve (a helix); without it, only u and v are walked.
    w0_q8_ = e.start[2] * 256;
    dw_q8_ = (e.end[2] - e.start[2]) * 256;
    axes_ = dw_q8_ ? 3 : 2;
    prev_q8_[0] = p0_q8[0];
    prev_q8_[1] = p0_q8[1];
    prev_q8_[2] = w0_q8_;
    kind_ = kind;
    left_ = 0;
}

void CurveWalker::start_piece(const int32_t p[4][3]) {
    // Polynomial of the piece relative to its start (ticks x 256): d1 t + d2 t^2 + d3 t^3.
    int32_t d[3][3];
    uint32_t bound = 0; // largest axis speed over the piece, ticks x 256 per unit of t
    for (uint8_t a = 0; a < 3; ++a) {
        d[a][0] = 3 * (p[1][a] - p[0][a]);
        d[a][1] = 3 * (p[0][a] - 2 * p[1][a] + p[2][a]);
        d[a][2] = p[3][a] - p[0][a] + 3 * (p[1][a] - p[2][a]);
        uint32_t b = abs32(d[a][0]) + 2 * abs32(d[a][1]) + 3 * abs32(d[a][2]);
        if (b > bound) bound = b;
    }
    // N = 2^m > bound (ticks): at most one tick per sample and axis.
    uint8_t m = 0;
    while ((1ul << (m + 8)) <= bound) ++m;
    left_ = static_cast<uint16_t>(1u << m);
    for (uint8_t a = 0; a < 3; ++a) {
        base_[a] = p[0][a] >> 8;
        int64_t* v = fd_[a];
        // Differences at t = 0 for the step 1/N: d1/N + d2/N^2 + d3/N^3, 2 d2/N^2 + 6 d3/N^3,
        // 6 d3/N^3.
        int64_t t2 = q40(d[a][1], static_cast<uint8_t>(2 * m)),
                t3 = q40(d[a][2], static_cast<uint8_t>(3 * m));
        v[0] = static_cast<int64_t>(p[0][a] & 0xFF) << 32;
        v[1] = q40(d[a][0], m) + t2 + t3;
        v[3] = q40(6 * d[a][2], static_cast<uint8_t>(3 * m));
        v[2] = q40(2 * d[a][1], static_cast<uint8_t>(2 * m)) + v[3];
        prev_q8_[a] = p[3][a];
    }
}

void CurveWalker::arc_at(int32_t c, int32_t s, int32_t point[2], int32_t arm[2]) const {
    // X = cu + ru cos t, Y = cv + rv sin t; tangent (-ru sin t, rv cos t) times the arm factor.
    for (uint8_t k = 0; k < 2; ++k) {
        int32_t r = static_cast<int32_t>(a_.radii[k]);
        point[k] = a_.centre[k] + mul_q30(r, k ? s : c);
        arm[k] = mul_q30(mul_q30(r, k ? c : -s), a_.arm);
    }
}

bool CurveWalker::arc(const Ends& e, const int32_t centre_q8[2], const uint32_t radii_q8[2],
                      bool clockwise, uint8_t turns) {
    kind_ = 0;
    if (radii_q8[0] == 0 || radii_q8[1] == 0) return false;
    for (uint8_t k = 0; k < 2; ++k) {
        a_.centre[k] = centre_q8[k];
        a_.radii[k] = radii_q8[k];
    }
    // Directions of the start and end points (their projections on the curve), and the sweep.
    ellipse_direction(e.start_q8[0] - a_.centre[0], e.start_q8[1] - a_.centre[1], a_.radii, a_.c,
                      a_.s);
    ellipse_direction(e.end_q8[0] - a_.centre[0], e.end_q8[1] - a_.centre[1], a_.radii, end_c_,
                      end_s_);
    int64_t sweep = arc_sweep_q29(a_.c, a_.s, end_c_, end_s_, clockwise, turns);
    // Pieces: at most 3 x 2^26 / 2^29 rad (21.5 degrees) and kMaxPieceTicks long. The sweep is
    // below 2^40 (255 turns).
    uint64_t mag = static_cast<uint64_t>(sweep < 0 ? -sweep : sweep);
    uint32_t rmax = (a_.radii[0] > a_.radii[1] ? a_.radii[0] : a_.radii[1]) >> 8;
    uint32_t n = static_cast<uint16_t>(mag >> 26) / 3u + 1u;
    // length = sweep x radius = (mag / 2^29) rmax ticks
    uint32_t by_length =
        Num(static_cast<uint32_t>(mag >> 9), -20).mul(rmax + 1).div(kMaxPieceTicks).u32() + 1;
    if (by_length > n) n = by_length;
    if (n > 0xFFFF) return false;
    piece_count_ = pieces_ = static_cast<uint16_t>(n);
    // Piece angle, Q30 (at most 21.5 degrees, so the series apply), and the arm of its cubic:
    // 4/3 tan(h/4).
    int32_t h = static_cast<int32_t>(Num(static_cast<uint32_t>(mag >> 10)).div(n).shift(11).u32());
    if (sweep < 0) h = -h;
    rotation(h, a_.rot_c, a_.rot_s);
    int32_t x = h / 4;
    a_.arm = mul_q30(mul_q30(x, series(2, mul_q30(x, x))), 1431655765); // x 4/3
    int32_t p[2], arm[2];
    arc_at(a_.c, a_.s, p, arm);
    begin(e, p, 1);
    return true;
}

void CurveWalker::bezier_at(uint32_t a_q20, int32_t point[2], int32_t arm[2]) const {
    // B(a) and the arm of the piece starting or ending there, B'(a) / (3 2^j), ticks x 256, by
    // Horner's rule in 64-bit fixed point.
    for (uint8_t k = 0; k < 2; ++k) {
        int64_t b = 0, d = 0;
        for (uint8_t i = 4; i-- > 0;) {
            b = horner(b, a_q20, poly_[i][k]);
            if (i) d = horner(d, a_q20, poly_[i][k] * i);
        }
        point[k] = static_cast<int32_t>(b);
        arm[k] = third(static_cast<int32_t>(d >> log_pieces_));
    }
}

bool CurveWalker::bezier(const Ends& e, const int32_t p1_q8[2], const int32_t p2_q8[2]) {
    kind_ = 0;
    uint64_t bound = 0;
    for (uint8_t k = 0; k < 2; ++k) {
        int64_t p0 = e.start_q8[k], p1 = p1_q8[k], p2 = p2_q8[k], p3 = e.end_q8[k];
        poly_[0][k] = p0;
        poly_[1][k] = 3 * (p1 - p0);
        poly_[2][k] = 3 * (p0 - 2 * p1 + p2);
        poly_[3][k] = p3 - p0 + 3 * (p1 - p2);
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
    end_c_ = e.end_q8[0]; // the last piece lands on the commanded end
    end_s_ = e.end_q8[1];
    begin(e, e.start_q8, 2);
    return true;
}

bool CurveWalker::next_piece() {
    if (pieces_ == 0) return false;
    uint16_t index = static_cast<uint16_t>(piece_count_ - pieces_); // 0-based
    --pieces_;
    bool last = pieces_ == 0;
    int32_t p[4][3]; // control points, ticks x 256
    for (uint8_t a = 0; a < 3; ++a) p[0][a] = prev_q8_[a];
    // Helix: w moves linearly, the last piece landing exactly on the end.
    int32_t w3 = dw_q8_;
    if (!last) {
        w3 = static_cast<int32_t>(
            Num(abs32(dw_q8_)).mul(static_cast<uint32_t>(index) + 1).div(piece_count_).u32());
        if (dw_q8_ < 0) w3 = -w3;
    }
    w3 += w0_q8_;
    int32_t dw = third(w3 - p[0][2]);
    p[1][2] = p[0][2] + dw;
    p[2][2] = w3 - dw;
    p[3][2] = w3;
    // The ends of the piece on the curve and the arms of its cubic there.
    int32_t arm0[2], arm3[2];
    if (kind_ == 1) {
        int32_t c = a_.c, s = a_.s;
        rotate(c, s, a_.rot_c, a_.rot_s);
        if (last) { // land on the end point's direction: no drift left over
            c = end_c_;
            s = end_s_;
        }
        arc_at(a_.c, a_.s, p[3], arm0); // p[3] is overwritten just below
        arc_at(c, s, p[3], arm3);
        a_.c = c;
        a_.s = s;
    } else {
        // Bezier part [a, a + 1/n]: ends and tangents of the curve.
        uint32_t a0 = static_cast<uint32_t>(index) << (20 - log_pieces_);
        bezier_at(a0, p[3], arm0);
        bezier_at(a0 + (1ul << (20 - log_pieces_)), p[3], arm3);
        if (last) {
            p[3][0] = end_c_;
            p[3][1] = end_s_;
        }
    }
    for (uint8_t k = 0; k < 2; ++k) {
        p[1][k] = p[0][k] + arm0[k];
        p[2][k] = p[3][k] - arm3[k];
    }
    start_piece(p);
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
                move_to(pos[a], end_[a], static_cast<uint8_t>(1u << a), moved, neg);
            }
            return moved != 0;
        }
    }
    --left_;
    for (uint8_t a = 0; a < axes_; ++a) {
        int64_t* v = fd_[a];
        fd_step(v);
        // round(f / 2^40) from the high word: floor((hi + 2^7) / 2^8)
        int32_t hi = static_cast<int32_t>(v[0] >> 32);
        move_to(pos[a], base_[a] + ((hi + 128) >> 8), static_cast<uint8_t>(1u << a), moved, neg);
    }
    return true;
}

uint16_t CurveWalker::peek(int32_t d[3]) {
    while (left_ == 0 && kind_ != 0 && pieces_ != 0) next_piece();
    for (uint8_t a = 0; a < 3; ++a) d[a] = static_cast<int32_t>(fd_[a][1] >> 24);
    return left_;
}

namespace {

// (1 - sqrt(3/5)) / 2, Q30: the outer Gauss-Legendre nodes of a panel [0, 1].
constexpr int32_t kGaussQ30 = 121012492;
// Panel width bounds, parameter units x 2^29: an ellipse's angle (the series apply up to 0.4
// rad), a Bezier's t, and the narrowest panel (a cusp: |B'| -> 0).
constexpr uint32_t kWidestArcQ29 = kPiQ29 / 8;
constexpr uint32_t kWidestBezierQ29 = kOneQ29 / 16;
constexpr uint32_t kNarrowestQ29 = kOneQ29 >> 16;

// A curve as the length integral walks it: its first and second derivatives with respect to its
// parameter, x 2^scale (scaled so that the largest coefficient has 28 bits: relative precision
// whatever the size of the curve).
struct Track {
    bool bezier;
    bool clockwise;  ///< ellipse: the angle decreases
    int32_t r[2];    ///< ellipse: radii
    int32_t c, s;    ///< ellipse: direction (cos t, sin t) of the current point, Q30
    uint32_t t;      ///< Bezier: parameter of the current point, Q29
    int32_t h[3][2]; ///< Bezier: B'(t) = h0 + t (h1 + t h2)
    Num ww;          ///< (dw / dparameter)^2: the helix' rise
};

// Shifts v[0..n-1] left or right so that the largest magnitude is in [2^27, 2^28); the shift.
int8_t normalise(int32_t* v, uint8_t n) {
    uint32_t big = 0;
    for (uint8_t i = 0; i < n; ++i) {
        if (abs32(v[i]) > big) big = abs32(v[i]);
    }
    int8_t sh = 0;
    if (big == 0) return 0;
    while (big >= (1ul << 28)) {
        big >>= 1;
        --sh;
    }
    while (big < (1ul << 27)) {
        big <<= 1;
        ++sh;
    }
    for (uint8_t i = 0; i < n; ++i) v[i] = sh < 0 ? v[i] >> -sh : v[i] * (1l << sh);
    return sh;
}

// P' and P'' (x 2^scale) at `off` (Q29) past the current point; with `move`, that point becomes
// the current one.
void track_at(Track& k, uint32_t off, bool move, int32_t d1[2], int32_t d2[2]) {
    if (k.bezier) {
        uint32_t t = k.t + off;
        if (move) k.t = t;
        int32_t t30 = static_cast<int32_t>(t << 1);
        for (uint8_t i = 0; i < 2; ++i) {
            int32_t q = k.h[1][i] + mul_q30(k.h[2][i], t30);
            d1[i] = k.h[0][i] + mul_q30(q, t30);
            d2[i] = q + mul_q30(k.h[2][i], t30);
        }
        return;
    }
    int32_t c = k.c, s = k.s;
    if (off) {
        int32_t rc, rs, h = static_cast<int32_t>(off << 1);
        rotation(k.clockwise ? -h : h, rc, rs);
        rotate(c, s, rc, rs);
    }
    if (move) {
        k.c = c;
        k.s = s;
    }
    // (-ru sin t, rv cos t) and (-ru cos t, -rv sin t): only their sizes matter.
    d1[0] = mul_q30(k.r[0], s);
    d1[1] = mul_q30(k.r[1], c);
    d2[0] = mul_q30(k.r[0], c);
    d2[1] = mul_q30(k.r[1], s);
}

// Length of the track over `span` (Q29) from its current point, x 2^29 x 18 x 2^scale: panels
// of 3 Gauss-Legendre nodes, each at most half the local scale |P'| / |P''| wide (so that the
// nearest singularity of |P'| in the complex plane is at least two widths away: 1e-7 relative),
// and at most `widest`. With `rmin`, the smallest |P'|^3 / |P' x P''| (x 2^scale) over the
// panel ends is kept there (Beziers).
Num track_length(Track& k, uint32_t span, uint32_t widest, Num* rmin) {
    Num total{};
    for (;;) {
        int32_t d1[2], d2[2];
        track_at(k, 0, false, d1, d2);
        Num n1 = hypot(Num(abs32(d1[0])), Num(abs32(d1[1])), Num{});
        Num n2 = hypot(Num(abs32(d2[0])), Num(abs32(d2[1])), Num{});
        if (rmin) {
            int64_t cross =
                static_cast<int64_t>(d1[0]) * d2[1] - static_cast<int64_t>(d1[1]) * d2[0];
            if (cross != 0 && n1.m != 0) {
                Num rc = n1;
                rc.mul(n1).mul(n1).div(num64(static_cast<uint64_t>(cross < 0 ? -cross : cross)));
                if (rmin->m == 0 || rc.cmp(*rmin) < 0) *rmin = rc;
            }
        }
        if (span == 0) return total;
        uint32_t w = widest;
        if (n2.m != 0) {
            uint32_t half = n1.div(n2).shift(28).u32(); // |P'| / |P''| / 2, Q29
            if (half < w) w = half;
        }
        if (w < kNarrowestQ29) w = kNarrowestQ29;
        if (w > span) w = span;
        // Nodes at g, w / 2 and w - g, weights 5, 8, 5 (/ 18).
        const uint32_t g = static_cast<uint32_t>(mul_q30(static_cast<int32_t>(w), kGaussQ30));
        const uint32_t at[3] = {g, w / 2, w - g};
        Num f[3];
        for (uint8_t i = 0; i < 3; ++i) {
            track_at(k, at[i], false, d1, d2);
            f[i] = hypot(Num(abs32(d1[0])), Num(abs32(d1[1])), k.ww);
        }
        total.add(f[0].add(f[2]).mul(5).add(f[1].mul(8)).mul(w));
        track_at(k, w, true, d1, d2);
        span -= w;
    }
}

} // namespace

bool curve_shape(const CurveParams& cp, int32_t dw_um, bool w_regulated, CurveShape& out) {
    const int32_t dw = w_regulated ? dw_um : 0;
    Track k{};
    Num len{};
    Num tangent[2][3];   // unit tangents at both ends: magnitudes, ...
    uint8_t negative[2]; // ... and sign bits (1 = u, 2 = v, 4 = w)
    if (cp.kind == kCurveArc) {
        const uint32_t r[2] = {static_cast<uint32_t>(cp.b_um[0]),
                               static_cast<uint32_t>(cp.b_um[1])};
        if (r[0] == 0 || r[1] == 0) return false;
        int32_t c0, s0, c1, s1;
        ellipse_direction(cp.start_um[0] - cp.a_um[0], cp.start_um[1] - cp.a_um[1], r, c0, s0);
        ellipse_direction(cp.end_um[0] - cp.a_um[0], cp.end_um[1] - cp.a_um[1], r, c1, s1);
        const bool cw = cp.clockwise != 0;
        // The sweep in (0, 2 pi], plus the extra full turns: radians.
        int64_t sweep = arc_sweep_q29(c0, s0, c1, s1, cw, 0);
        const uint32_t part = static_cast<uint32_t>(sweep < 0 ? -sweep : sweep);
        constexpr uint32_t kTurnQ29 = 2ul * kPiQ29;
        Num angle = Num(kTurnQ29, -29).mul(cp.turns).add(Num(part, -29));
        // w rises linearly with the angle: dw / |sweep| per radian.
        Num rise = Num(abs32(dw_um)).div(angle);
        uint32_t lo = r[0] < r[1] ? r[0] : r[1], hi = r[0] < r[1] ? r[1] : r[0];
        if (r[0] == r[1]) {
            len = angle;
            len.mul(r[0]); // r |sweep|
            out.min_radius_um = r[0];
        } else {
            k.r[0] = static_cast<int32_t>(r[0]);
            k.r[1] = static_cast<int32_t>(r[1]);
            const int8_t scale = normalise(k.r, 2);
            k.c = c0;
            k.s = s0;
            k.clockwise = cw;
            if (dw != 0) {
                k.ww = Num(abs32(dw)).div(angle).shift(scale);
                k.ww.mul(k.ww);
            }
            len = track_length(k, part, kWidestArcQ29, nullptr);
            if (cp.turns) {
                k.c = c0;
                k.s = s0;
                len.add(track_length(k, kTurnQ29, kWidestArcQ29, nullptr).mul(cp.turns));
            }
            len.div(18).shift(static_cast<int8_t>(-29 - scale));
            out.min_radius_um = Num(lo).mul(lo).div(hi).u32(); // a^2 / b at the flat ends
        }
        // Tangents: (-ru sin t, rv cos t, rise), reversed when clockwise.
        const int32_t cs[2][2] = {{c0, s0}, {c1, s1}};
        for (uint8_t e = 0; e < 2; ++e) {
            const int32_t c = cs[e][0], s = cs[e][1];
            tangent[e][0] = Num(r[0]).mul(abs32(s)).shift(-30);
            tangent[e][1] = Num(r[1]).mul(abs32(c)).shift(-30);
            tangent[e][2] = rise;
            negative[e] = static_cast<uint8_t>(((s > 0) != cw ? 1 : 0) | ((c < 0) != cw ? 2 : 0) |
                                               (dw_um < 0 ? 4 : 0));
        }
        if (r[0] == r[1] && dw != 0) { // circular helix: sqrt(plane^2 + dw^2)
            Num w(abs32(dw));
            Num l2 = len;
            len = l2.mul(len).add(w.mul(w)).sqrt();
        }
    } else {
        // Hodograph B'(t) = a (1-t)^2 + 2 b (1-t) t + c t^2 with a, b, c three times the arms,
        // as h0 + t (h1 + t h2). The G-code checks (error:33) keep the control polygon below
        // 2^23 µm, so these fit.
        const int32_t p[4][2] = {{cp.start_um[0], cp.start_um[1]},
                                 {cp.a_um[0], cp.a_um[1]},
                                 {cp.b_um[0], cp.b_um[1]},
                                 {cp.end_um[0], cp.end_um[1]}};
        for (uint8_t i = 0; i < 2; ++i) {
            k.h[0][i] = 3 * (p[1][i] - p[0][i]);
            k.h[1][i] = 6 * (p[2][i] - 2 * p[1][i] + p[0][i]);
            k.h[2][i] = 3 * (p[3][i] - p[0][i]) + 9 * (p[1][i] - p[2][i]);
        }
        const int8_t scale = normalise(&k.h[0][0], 6);
        k.bezier = true;
        if (dw != 0) {
            k.ww = Num(abs32(dw)).shift(scale);
            k.ww.mul(k.ww);
        }
        Num rmin{};
        len = track_length(k, kOneQ29, kWidestBezierQ29, &rmin);
        len.div(18).shift(static_cast<int8_t>(-29 - scale));
        out.min_radius_um = rmin.m ? rmin.shift(static_cast<int8_t>(-scale)).u32() : 0xFFFFFFFFul;
        // Tangents: the first non-degenerate arm at each end, 3 arms per unit of t as B' is;
        // w rises by dw per unit of t.
        const int32_t ends[2][2][2] = {
            {{p[1][0] - p[0][0], p[1][1] - p[0][1]}, {p[2][0] - p[0][0], p[2][1] - p[0][1]}},
            {{p[3][0] - p[2][0], p[3][1] - p[2][1]}, {p[3][0] - p[1][0], p[3][1] - p[1][1]}}};
        for (uint8_t e = 0; e < 2; ++e) {
            const int32_t* arm = ends[e][0];
            if (arm[0] == 0 && arm[1] == 0) arm = ends[e][1];
            tangent[e][0] = Num(abs32(arm[0])).mul(3);
            tangent[e][1] = Num(abs32(arm[1])).mul(3);
            tangent[e][2] = Num(abs32(dw_um));
            negative[e] = static_cast<uint8_t>((arm[0] < 0 ? 1 : 0) | (arm[1] < 0 ? 2 : 0) |
                                               (dw_um < 0 ? 4 : 0));
        }
    }
    unit3(tangent[0], negative[0], out.start_dir);
    unit3(tangent[1], negative[1], out.end_dir);
    if (len.m == 0) return false;
    out.len_q8 = len.shift(8).u32();
    return true;
}

} // namespace ll
