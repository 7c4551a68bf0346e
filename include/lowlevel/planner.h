// Look-ahead planner: a ring of queued straight moves whose junction speeds are limited by
// junction deviation (GRBL's $11 model) and by what the following moves can still decelerate
// from, recomputed as moves arrive (backward then forward pass). Speeds are squared, in
// (units/min)^2 of each move's regulated path (seed §3.1); integer only.
//
// A queued move costs 29 bytes of RAM (4 axes): deltas are kept on 24 bits, the group and the
// curve slot share a byte; a line's length is recomputed from its deltas when the step generator
// starts it (a square root per move, against 4 bytes per block: RAM is the limit), a curve's is
// kept in its slot (it takes a quadrature); the acceleration is derived from dv2 and the length
// instead of being stored.
#pragma once

#include <stddef.h>

#include "lowlevel/machine.h"
#include "lowlevel/stepgen.h"

namespace ll {

/// Curves queued at once (each keeps its geometry in a slot: RAM is the limit).
constexpr uint8_t kCurveSlots = 2;
static_assert(kAxes <= 6 && kCurveSlots <= 3,
              "a block's group, length flag and curve share one byte");

/// The bit of the normal axis of a curve's plane (axis 2 - plane): 4 >> plane without a shift
/// loop.
inline uint8_t normal_bit(uint8_t plane) {
    return plane ? static_cast<uint8_t>(3 - plane) : 4;
}

struct PlanBlock {
    uint8_t delta[kAxes][3];            ///< steps per machine axis, signed 24-bit little-endian
    uint8_t group : kAxes <= 5 ? 5 : 6; ///< regulated axes (seed §3.1)
    uint8_t has_len : 1;                ///< its length is kept (Planner::CurveSlot::lens)
    uint8_t curve : 2;                  ///< 0: a straight move; else 1 + the slot of its curve
    // dv2, feed, v_entry2: in MoveSpec's order (spec_of_first() copies them at once).
    uint32_t dv2;          ///< 2 a L: squared speed gained or shed over the move, (units/min)^2
    uint32_t feed;         ///< nominal speed, units/min x1000
    uint32_t v_entry2;     ///< planned entry speed squared
    uint32_t v_max_entry2; ///< junction and nominal limit on the entry speed squared
};

/// Length, acceleration and speed limit of a move along its regulated path (every axis, in
/// the group or following it, kept within its own maximum rate and acceleration).
struct MoveLimits {
    uint32_t len_q8; ///< µm x 256
    uint32_t vmax;   ///< units/min x1000
    uint32_t accel;  ///< units/min^2 (after vmax: move_limits() writes them in this order)
};
void move_limits(const Machine& m, const int32_t delta[kAxes], uint8_t group, MoveLimits& out);

/// Zero-initialised as a global (or with `Planner p{}`): no constructor, no start-up code.
class Planner {
  public:
    void configure(const Machine* m) { m_ = m; }
    /// Empties the ring; the next move starts at `steps` from rest (and, for its direction, at
    /// the commanded position in mm x1000 that matches it). Precondition: configure() was called
    /// (with the settings then, or a zero-filled machine while `steps` is zero).
    void reset(const int32_t steps[kAxes]);

    bool full() const { return count_ == kPlannerSize; }
    bool empty() const { return count_ == 0; }
    uint8_t count() const { return count_; }

    /// Queues the move from the last target to `target` (steps): straight when `curve` is null,
    /// else along `curve` (seed part IV). `target_um` is the same target as commanded (mm x1000):
    /// a line's junction angles come from it, so that rounding targets to whole steps does not
    /// turn a smooth chain of short segments into a zigzag of corners. A line's length (and so
    /// its feed) comes from the steps actually travelled. `feed` is in units/min x1000 along the
    /// regulated path; 2^32 - 1 (kRapid) uses every axis' maximum rate. Returns false when a line
    /// moves no axis (nothing queued). Preconditions: !full(), and no axis travels more than
    /// kMaxLineTicks.
    /// A curve is queued in two calls, so that the deepest computation of the firmware does not
    /// stack on top of the second one's frame. shape_curve(): the curve's length, curvature limit
    /// (v^2 <= a r) and end tangents (for the junctions) from curve_shape(), kept in the free
    /// curve slot; false for a degenerate curve (then nothing is queued, and add() must not be
    /// called). Then add() with the same `target_um` and `curve`. Precondition:
    /// curve_slot_free() and !full().
    bool add(const int32_t target[kAxes], const int32_t target_um[kAxes], uint32_t feed,
             const CurveParams* curve = nullptr);
    /// add()'s `feed` for a rapid (G0): every axis' maximum rate bounds it.
    static constexpr uint32_t kRapid = 0xFFFFFFFFul;
    /// add()'s first call for a curve (see add()).
    bool shape_curve(const int32_t target_um[kAxes], const CurveParams& curve) {
        const uint8_t w = static_cast<uint8_t>(2 - curve.plane); // the normal axis
        const bool w_regulated = regulates_w(curve.plane);
        CurveSlot* const s = free_slot_index() ? curves_ + 1 : curves_;
        const int32_t dw_um = target_um[w] - last_um_[w];
        s->shaped.dw_um = dw_um; // for add()
        s->shaped.dirs = static_cast<uint8_t>(2 + w_regulated);
        return curve_shape(curve, w_regulated ? dw_um : 0, w_regulated, s->shaped.shape);
    }
    /// A curve needs one of kCurveSlots slots besides its block.
    bool curve_slot_free() const { return curve_used_ != (1u << kCurveSlots) - 1; }

    /// The i-th queued move (0 = oldest). Precondition: i < count().
    const PlanBlock& block(uint8_t i) const { return ring_[index(i)]; }
    /// The oldest move as the step generator needs it (entry and planned exit speeds).
    void spec_of_first(MoveSpec& s) const;
    /// Planned exit speed squared of the oldest move (the next one's entry, 0 at the end).
    uint32_t exit2_of_first() const;
    /// The step generator started the oldest move: its entry speed is now fixed.
    void begin_first() { first_begun_ = 1; }
    /// True from begin_first() until the oldest move is discarded (or the ring reset).
    bool first_begun() const { return first_begun_ != 0; }
    /// Drops the oldest move. Precondition: !empty().
    void discard_first();

    /// After a feed hold stopped the oldest move with `remaining` of its `total` reference
    /// ticks left: it restarts from rest, and every queued move is replanned. Precondition:
    /// !empty() (motion calls it only for a begun move).
    void restart_first(uint32_t remaining, uint32_t total);

    const int32_t* last_target() const { return last_; }
    const int32_t* last_target_um() const { return last_um_; }

    /// Nominal speed squared of a move, (units/min)^2.
    static uint32_t nominal2(const PlanBlock& b);
    /// Steps of a move along an axis (its 24-bit delta, sign-extended).
    static int32_t delta(const PlanBlock& b, uint8_t axis) {
        const uint8_t* d = b.delta[axis];
        uint32_t v = d[0] | static_cast<uint32_t>(d[1]) << 8 | static_cast<uint32_t>(d[2]) << 16;
        if (v & 0x800000ul) v |= 0xFF000000ul; // sign extension
        return static_cast<int32_t>(v);
    }

  private:
    uint8_t index(uint8_t i) const { return static_cast<uint8_t>((head_ + i) % kPlannerSize); }
    /// The i-th queued move (0 = oldest; count_ for the one being queued).
    PlanBlock* at(uint8_t i);
    /// The look-ahead passes (from the oldest move when it is not begun, else stopping where
    /// nothing changes any more).
    void recalculate();
    /// Junction speed squared with the previous move, at most `limit` (min(junction, limit):
    /// the early outs return `limit` itself).
    uint32_t junction2(const int32_t unit[kAxes], uint32_t limit) const;

    /// Keeps a line's length `len` (µm x 256) for spec_of_first() when it can (sets b.has_len).
    void keep_len(PlanBlock& b, uint32_t len);
    /// Writes the move from the last target to `target` (steps) into `b` and `d`; `target`
    /// becomes the last target. Returns the move's regulated group, 0 when no axis moves.
    uint8_t open(PlanBlock& b, const int32_t target[kAxes], int32_t d[kAxes]);
    /// A curve's slot: its length and parameters while its move is queued; before that, while
    /// the move is being queued, the curve's shape (shape_curve()). The length leads both (a
    /// common initial sequence): the shape's stays in place when the parameters replace the rest.
    struct QueuedCurve {
        uint32_t len_q8; ///< µm x 256
        CurveParams params;
    };
    struct ShapedCurve {
        CurveShape shape;
        int32_t dw_um; ///< the normal axis' commanded travel (shape_curve() has it)
        uint8_t dirs;  ///< components of the end tangents: 2, 3 when w is regulated
    };
    union CurveSlot {
        ShapedCurve shaped;
        QueuedCurve queued;
        /// Slot 1, while no curve is queued: the lengths of the queued lines below 2^16 (µm x
        /// 256: 256 µm), by ring index, for spec_of_first() (a chain of short lines spares a
        /// travel() per move, for no RAM). A block's has_len says its length is kept: it was
        /// written while no curve was queued, and holds while none is. (Slot 1 takes a curve
        /// only while slot 0 holds one, queued after every line kept before it.)
        uint16_t lens[kPlannerSize];
    };
    static_assert(offsetof(CurveShape, len_q8) == 0 && sizeof(ShapedCurve) <= sizeof(QueuedCurve),
                  "the shape costs no RAM");
    static_assert(sizeof(CurveSlot::lens) <= sizeof(QueuedCurve), "the lengths cost no RAM");
    /// The free slot (there is one): with two slots, slot 1 when slot 0 is taken.
    uint8_t free_slot_index() const {
        static_assert(kCurveSlots == 2, "one free slot out of two");
        return curve_used_ & 1;
    }
    /// True when the normal axis of `plane` is regulated with the plane's axes (it counts in a
    /// curve's length).
    bool regulates_w(uint8_t plane) const {
        // The group of the plane's first machine axis (plane >> 1: Y for G19, else X), and the
        // normal axis.
        return (m_->group_of[plane >> 1] & normal_bit(plane)) != 0;
    }

    // The small fields first: within 64 bytes of `this`, the ATmega328P reaches them with one
    // displacement instruction instead of an address computation.
    const Machine* m_;
    uint8_t head_;
    uint8_t count_;
    uint8_t first_begun_; ///< the oldest move is in the step generator: its entry is fixed
    uint8_t curve_used_;  ///< bit i: curves_[i] belongs to a queued move
    int32_t last_[kAxes];
    int32_t last_um_[kAxes];
    int32_t prev_unit_[kAxes]; ///< unit vector of the last move, Q29
    CurveSlot curves_[kCurveSlots];
    PlanBlock ring_[kPlannerSize];
};

} // namespace ll
