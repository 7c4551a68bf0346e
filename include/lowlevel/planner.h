// Look-ahead planner: a ring of queued straight moves whose junction speeds are limited by
// junction deviation (GRBL's $11 model) and by what the following moves can still decelerate
// from, recomputed as moves arrive (backward then forward pass). Speeds are squared, in
// (units/min)^2 of each move's regulated path (seed §3.1); integer only.
#pragma once

#include "lowlevel/machine.h"
#include "lowlevel/stepgen.h"

namespace ll {

struct PlanBlock {
    int32_t delta[kAxes];  ///< steps per machine axis
    uint32_t len_q8;       ///< regulated path length, µm x 256
    uint32_t accel;        ///< acceleration along the path, units/min^2
    uint32_t feed;         ///< nominal speed, units/min x1000
    uint32_t dv2;          ///< 2 a L: squared speed gained or shed over the move, (units/min)^2
    uint32_t v_entry2;     ///< planned entry speed squared
    uint32_t v_max_entry2; ///< junction and nominal limit on the entry speed squared
    uint8_t group;         ///< regulated axes
    uint8_t begun;         ///< 1 once the step generator started it: its entry is fixed
};

class Planner {
  public:
    void configure(const Machine* m) { m_ = m; }
    /// Empties the ring; the next move starts at `steps` (and `um`, the same position in
    /// mm x1000) from rest.
    void reset(const int32_t steps[kAxes], const int32_t um[kAxes]);

    bool full() const { return count_ == kPlannerSize; }
    bool empty() const { return count_ == 0; }
    uint8_t count() const { return count_; }

    /// Queues the straight move from the last target to `target` (steps). `target_um` is the
    /// same target as commanded (mm x1000): the junction angles come from it, so that rounding
    /// targets to whole steps does not turn a smooth chain of short segments into a zigzag of
    /// corners. The length (and so the feed) comes from the steps actually travelled. `feed` is
    /// in units/min x1000 along the regulated path; `rapid` uses every axis' maximum rate.
    /// Returns false when no axis moves (nothing queued). Precondition: !full().
    bool add(const int32_t target[kAxes], const int32_t target_um[kAxes], uint32_t feed,
             bool rapid);

    PlanBlock* first() { return count_ ? &ring_[head_] : nullptr; }
    /// The oldest move as the step generator needs it (entry and planned exit speeds).
    MoveSpec spec_of_first() const;
    /// Planned exit speed squared of the oldest move (the next one's entry, 0 at the end).
    uint32_t exit2_of_first() const;
    void begin_first();
    void discard_first();

    /// After a feed hold stopped the oldest move with `remaining` of its `total` reference
    /// ticks left: it restarts from rest, and every queued move is replanned.
    void restart_first(uint32_t remaining, uint32_t total);

    const int32_t* last_target() const { return last_; }
    const int32_t* last_target_um() const { return last_um_; }

    /// Nominal speed squared of a move, (units/min)^2.
    static uint32_t nominal2(const PlanBlock& b);

  private:
    uint8_t index(uint8_t i) const { return static_cast<uint8_t>((head_ + i) % kPlannerSize); }
    void recalculate();
    uint32_t junction2(const int32_t unit[kAxes]) const;

    const Machine* m_;
    PlanBlock ring_[kPlannerSize];
    uint8_t head_;
    uint8_t count_;
    int32_t last_[kAxes];
    int32_t last_um_[kAxes];
    int32_t prev_unit_[kAxes]; ///< unit vector of the last move, Q29
    uint8_t prev_group_;       ///< 0: no previous move (start from rest)
};

} // namespace ll
