// Curves stepped in the low level (seed part IV): circular and elliptic arcs (helical when the
// plane's normal axis moves too) and cubic Beziers, walked in tick space without chords.
//
// A curve is walked as a sequence of cubic pieces (seed §10.1: a partition of the parameter
// interval, each part with its own parameter step). A piece is sampled at N = 2^m parameter
// values, with N larger than the piece's largest axis speed (its hodograph bound), so that two
// consecutive samples are at most one tick apart on every axis: the visited positions are the
// samples rounded to the nearest tick, strictly successive, within 0.71 tick of the piece.
// Samples are produced by forward differencing in 64-bit fixed point (Q40 ticks): three
// additions per axis and per sample, no multiplication, no square root, and since N is a power
// of two the differences are set up with shifts.
//
// Arcs and ellipses (X = cu + ru cos t, Y = cv + rv sin t, docs/curves.md): pieces of at most
// 21.5 degrees (and 2000 ticks), each the cubic whose arms are 4/3 tan(h/4) long, which stays
// within 7e-8 radius of the true curve; the unit vector (cos t, sin t) is advanced from piece to
// piece by an integer rotation whose sine and cosine come from their series where the arc is
// prepared. Beziers are cut into 2^j pieces of equal parameter length, each exactly the
// corresponding part of the curve (its ends and tangents by de Casteljau's algorithm).
#pragma once

#include "lowlevel/config.h"

namespace ll {

struct Num;

enum : uint8_t { kCurveArc = 1, kCurveBezier = 2 };

/// The axes of a plane: u and v span it, w is its normal (the helix axis). G17: (X, Y, Z),
/// G18: (Z, X, Y), G19: (Y, Z, X) -- GRBL's order, so that G2 is clockwise seen from +w.
inline void plane_axes(uint8_t plane, uint8_t ax[3]) {
    ax[0] = plane == 0 ? 0 : (plane == 1 ? 2 : 1);
    ax[1] = plane == 0 ? 1 : (plane == 1 ? 0 : 2);
    ax[2] = plane == 0 ? 2 : (plane == 1 ? 1 : 0);
}

/// A curve as queued: what the planner keeps per curve and hands to the step generator.
/// Coordinates are the commanded ones, in the plane's units x1000 (µm for linear axes).
struct CurveParams {
    uint8_t kind;        ///< kCurveArc (circle or ellipse) or kCurveBezier
    uint8_t plane;       ///< 0 = G17, 1 = G18, 2 = G19 (see plane_axes)
    uint8_t clockwise;   ///< arcs: 1 for G2 / G2.1
    uint8_t turns;       ///< arcs: extra full turns
    int32_t start_um[2]; ///< start (u, v)
    int32_t end_um[2];   ///< end (u, v)
    int32_t a_um[2];     ///< arc: centre; Bezier: first control point
    int32_t b_um[2];     ///< arc: semi-axes along u, v (equal for a circle); Bezier: second one
};

/// What the planner needs of a curve (seed §10.2: the length is what the acceleration and
/// deceleration distances are measured along).
struct CurveShape {
    uint32_t len_q8;        ///< length, µm x 256 (with the normal axis' travel when regulated)
    uint32_t min_radius_um; ///< smallest radius of curvature (speed limit: v^2 <= a r)
    int32_t start_dir[3];   ///< unit tangent at the start (u, v, w), Q29
    int32_t end_dir[3];     ///< unit tangent at the end, Q29
};

/// Length, curvature and end tangents of a curve whose normal axis travels `dw_um`
/// (`w_regulated`: w counts in the path length). Returns false for a degenerate curve.
/// Circles and circular helices in closed form. Ellipses and Beziers (and their helices) by
/// Gauss-Legendre quadrature of the speed, 3 nodes per panel, each panel at most half the local
/// scale |P'| / |P''| wide: panels shrink where the curve turns tightly (the ends of an
/// eccentric ellipse's major axis, near-cusps), so the length is good to 1e-6 relative
/// (docs/curves.md: no closed form exists for an ellipse). The smallest radius of curvature of a
/// Bezier is the smallest |B'|^3 / |B' x B''| at the panel ends, which crowd where it is small.
bool curve_shape(const CurveParams& c, int32_t dw_um, bool w_regulated, CurveShape& out);

/// Direction of the point (x, y) seen from an ellipse's centre, normalised in the ellipse's
/// own scale: the unit vector (cos t, sin t) with (x, y) = (ru cos t, rv sin t) on the curve.
void ellipse_direction(int32_t x, int32_t y, const uint32_t radii[2], int32_t& c, int32_t& s);
/// Signed sweep from direction (c0, s0) to (c1, s1), radians x 2^29: in (0, 2 pi] anticlockwise,
/// [-2 pi, 0) clockwise (a closed arc is a full turn), plus `turns` full turns.
int64_t arc_sweep_q29(int32_t c0, int32_t s0, int32_t c1, int32_t s1, bool clockwise,
                      uint8_t turns);

/// Walks one curve in the plane (u, v), with an optional third axis w moving linearly along it
/// (a helix). Coordinates are ticks; `_q8` values are ticks x 256.
class CurveWalker {
  public:
    /// Where a curve starts and ends: the machine's positions (ticks: the walk starts at
    /// `start` and its last step lands exactly on `end`) and the commanded points of the plane
    /// (ticks x 256, not rounded: the curve's geometry is computed from these).
    struct Ends {
        int32_t start[3], end[3];
        int32_t start_q8[2], end_q8[2];
    };

    /// An arc of the ellipse (circle when ru = rv) with centre `centre_q8` and semi-axes
    /// `radii_q8`, from the commanded start to the commanded end (their directions seen from
    /// the centre), clockwise or not, plus `turns` extra full turns. A closed arc (start = end)
    /// is a full turn. Returns false when the geometry is degenerate.
    bool arc(const Ends& e, const int32_t centre_q8[2], const uint32_t radii_q8[2], bool clockwise,
             uint8_t turns);
    /// The cubic Bezier from the commanded start through the control points `p1_q8`, `p2_q8`
    /// (u, v) to the commanded end; w moves linearly with the parameter.
    bool bezier(const Ends& e, const int32_t p1_q8[2], const int32_t p2_q8[2]);

    /// Advances to the next sample. `moved` gets the bits (u = 1, v = 2, w = 4) of the axes that
    /// step to reach it, `neg` those that step towards negative coordinates. A sample may move
    /// no axis. Returns false once the curve is complete (the position is then `end`).
    bool next(uint8_t& moved, uint8_t& neg);

    /// Makes the next sample's piece current (starting the next piece when needed) and gives
    /// that sample's displacement, ticks x 2^16 per axis: its chord, from which the step
    /// generator times it. Returns the samples left in the piece (0: only the final step to
    /// the exact end remains, or nothing at all).
    uint16_t peek(int32_t d[3]) {
        const uint16_t left = peek();
        chord(d);
        return left;
    }
    /// peek() in two parts, for a step generator that needs the displacement now and then only:
    /// the samples left (making the next sample's piece current), and the displacement.
    uint16_t peek() {
        if (left_ == 0 && kind_ != 0) next_piece(); // (a piece has at least one sample)
        return left_;
    }
    void chord(int32_t d[3]) const;
    /// The length of the next sample (its chord) along the axes whose bit (u = 1, v = 2,
    /// w = 4) is set in `timed`, µm x 256, at least 1: sqrt(sum of d^2 / T^2) for the machine
    /// axes `machine[k]` of step lengths T (`inv2`: 1/T^2, mm^2 per step^2, per machine axis).
    uint32_t chord_q8(uint8_t timed, const uint8_t machine[3], const Num inv2[]) const;
    bool done() const { return kind_ == 0; }
    /// Changes with every piece (the low byte of the pieces not started yet): tells a piece of
    /// few samples from the one before it, where the samples left alone cannot.
    uint8_t piece_tag() const { return static_cast<uint8_t>(pieces_); }

    int32_t pos[3]; ///< current position, ticks (u, v, w)
    // The walker's own (public only to follow pos in memory, as Ends' start and end do: begin()
    // copies both in one piece).
    int32_t end_[3]; ///< final position, ticks

  private:
    void begin(const Ends& e, uint16_t pieces, uint8_t kind);
    bool next_piece();
    /// A piece: 3 x its arm at the start, its end and 3 x its arm at the end, ticks x 256 (u, v,
    /// w); start_piece() turns the three into the cubic's coefficients c1, c2, c3 in place.
    struct Piece {
        int32_t v[3][3];
    };
    enum : uint8_t { kArm0 = 0, kP3 = 1, kArm3 = 2 };
    void start_piece(Piece& g);
    void arc_at(const int32_t dir[2], int32_t point[2], int32_t arm[2]) const;
    void bezier_at(uint16_t at, int32_t point[2], int32_t arm[2]) const;

    // The small fields first, the forward differences last: on the ATmega328P a field within 63
    // bytes of the object is reached by displacement, one beyond costs a pointer computation.
    uint16_t left_; ///< samples left in the current piece
    // Curve
    uint8_t kind_;          ///< 0 done, 1 arc, 2 bezier
    uint8_t axes_;          ///< axes walked: 2 (u, v), or 3 when w moves (a helix)
    uint16_t pieces_;       ///< pieces not started yet
    uint16_t piece_count_;  ///< pieces in the curve
    uint8_t log_pieces_;    ///< Bezier: 2^j pieces
    int32_t w0_q8_, dw_q8_; ///< helix: w at the start, and its change over the curve
    int32_t prev_q8_[3];    ///< end of the last piece started (start of the next), ticks x 256
    // An arc or a Bezier, never both.
    struct ArcState {
        int32_t centre[2];
        uint32_t radii[2];
        int32_t dir[2][2]; ///< (cos t, sin t) of the next piece's start and of the end, Q30
        int32_t rot[2];    ///< cosine and sine of the piece angle h, Q30
        int32_t arm;       ///< 4 tan(h/4): 3 x a piece's arm per unit of radius, Q30
    };
    union {
        ArcState a_;
        int32_t pts_[2][4]; ///< Bezier: control points, u then v, ticks x 256
    };
    // Current piece, per axis: the position and its forward differences (f, d1, d2, d3), Q40
    // ticks.
    int64_t fd_[3][4];
};

} // namespace ll
