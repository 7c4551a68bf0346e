#include "lowlevel/planner.h"

#include <stddef.h>
#include <string.h>

namespace ll {
namespace {

// The per-axis limits are read straight from the settings: maximum rates (units/min x1000) and
// accelerations (units/s^2 x1000, which scale to units/min^2 by x3.6), one field of AxisSettings
// chosen by a member pointer (an offset: one loop serves both).
using Limit = uint32_t AxisSettings::*;
constexpr Limit kRate = &AxisSettings::max_rate;
constexpr Limit kAccel = &AxisSettings::accel;

// v, at least 1 (speeds and accelerations are divisors downstream).
__attribute__((noinline)) uint32_t at_least_1(uint32_t v) {
    if (!v) v = 1;
    return v;
}

// v = min(v, at_least_1(x)): a limit lowered in place.
__attribute__((noinline)) void lower(uint32_t& v, uint32_t x) {
    v = min32(v, at_least_1(x));
}

// Normalised constants for Num::mulc().
constexpr uint32_t k3_6 = 0xE6666666ul; // 3.6 = k3_6 * 2^-30: units/s^2 x1000 -> units/min^2
constexpr int8_t k3_6e = -30;
constexpr uint32_t kMilli = 0x83126E97ul; // 1/1000 = kMilli * 2^-41 (1/128000: 2^-48)
constexpr uint32_t kMicro = 0x8637BD05ul; // 1e-6 = kMicro * 2^-51 (5e-7: 2^-52)

// n1 / d1 < n2 / d2, exactly (64-bit products).
bool ratio_less(uint32_t n1, uint32_t d1, uint32_t n2, uint32_t d2) {
    if (n1 == n2) return d1 > d2;
    uint32_t l1, h1 = mul_wide(n1, d2, l1);
    uint32_t l2, h2 = mul_wide(n2, d1, l2);
    return h1 < h2 || (h1 == h2 && l1 < l2);
}

// The axis with comp[a] > 0 whose lim[a] / comp[a] is the smallest (the first one on a tie),
// kAxes when every comp[a] is 0.
uint8_t tightest(const AxisSettings* ax, Limit which, const uint32_t comp[kAxes]) {
    uint8_t best = kAxes;
    const uint32_t *best_lim = nullptr, *best_comp = nullptr;
    for (uint8_t a = 0; a < kAxes; ++a, ++ax, ++comp) {
        const uint32_t* lim = &(ax->*which);
        if (*comp == 0) continue;
        if (best == kAxes || ratio_less(*lim, *comp, *best_lim, *best_comp)) {
            best = a;
            best_lim = lim;
            best_comp = comp;
        }
    }
    return best;
}

// x <= 5e-7 (GRBL's junction thresholds): 5e-7 = kMicro 2^-52. A zero (exponent 0) is not
// caught here: junction2()'s q has its exponent lowered by 60 first (a zero q is tiny), and a
// zero p = 1 - q comes out as a junction speed of 0 from the exact formula, as from tiny().
__attribute__((noinline)) bool tiny(const Num& x) {
    return x.e < -52 || (x.e == -52 && x.m <= kMicro);
}

// Per-axis travel in µm x 256 (units of the axis: mm or degrees), and the regulated length:
// Euclidean over the move's group (seed §3.1), at least 1.
__attribute__((noinline)) uint32_t travel(const Machine& m, const int32_t delta[kAxes],
                                          uint8_t group, uint32_t x[kAxes]) {
    for (uint8_t a = 0; a < kAxes; ++a) x[a] = m.um_q8_per_step[a].of(abs32(delta[a]));
    return at_least_1(sum_squares(x, kAxes, group).sqrt().u32());
}

// The smallest of a limit over the axes whose bit is set in `mask` (bits below kAxes only;
// 2^32 - 1 for none). The loop ends with the mask: no counter, which leaves avr-gcc the
// call-clobbered registers for the loaded limit (it pushed r12..r15 for it).
__attribute__((noinline)) uint32_t min_over(const Machine& m, Limit which, uint8_t mask) {
    uint32_t v = 0xFFFFFFFFul;
    for (const AxisSettings* ax = m.settings->axis; mask != 0; ++ax, mask >>= 1) {
        if (mask & 1) v = min32(v, ax->*which);
    }
    return v;
}

// The axes of a plane (plane_axes(): G17 X Y, G18 Z X, G19 Y Z), as a mask; its normal is axis
// 2 - plane.
uint8_t plane_mask(uint8_t plane) {
    return static_cast<uint8_t>(7 ^ normal_bit(plane));
}

// Acceleration along a curve, units/min^2: its tangent turns through the plane, so the smaller
// of the plane's two axes bounds it (and the normal axis' when a helix moves it: `delta`, steps).
uint32_t curve_accel(const Machine& m, uint8_t plane, const int32_t delta[kAxes]) {
    const int32_t* dw = delta + 2 - plane; // the normal axis' travel (pointer arithmetic: 8 B less)
    uint32_t acc = min_over(m, kAccel, *dw != 0 ? 7 : plane_mask(plane));
    return at_least_1(Num(acc).mulc(k3_6, k3_6e).u32()); // units/s^2 x1000 -> units/min^2
}

// Squared speed of a feed (units/min x1000), (units/min)^2. The last one is kept: a job's moves
// mostly share their feed, and each line asks twice (its junction, then its profile), 560
// cycles each on the chip.
uint32_t g_last_speed2[2]; // feed, its v^2 (feed 0: v^2 0, right from the start)

__attribute__((noinline)) uint32_t speed2_of(uint32_t feed) {
    uint32_t* last = g_last_speed2;
    asm("" : "+r"(last)); // through a pointer register (ld/st), not 4-byte lds/sts
    if (feed != last[0]) {
        last[0] = feed;
        Num v(feed);
        last[1] = v.mul(v).mulc(kMicro, -51).u32(); // x 1e-6
    }
    return last[1];
}

// A curve's end tangent (u, v, w; w only when `n` is 3) as a machine-axis vector. The axes of
// the plane as plane_axes() gives them, by rotation: (u, v, w) = axes (k - plane) mod 3.
void place(int32_t out[kAxes], const int32_t dir[3], uint8_t plane, uint8_t n) {
    memset(out, 0, kAxes * sizeof(int32_t));
    uint8_t a = plane ? static_cast<uint8_t>(3 - plane) : 0;
    for (uint8_t k = 0; k < n; ++k) {
        out[a] = dir[k];
        a = a == 2 ? 0 : static_cast<uint8_t>(a + 1);
    }
}

} // namespace

void move_limits(const Machine& m, const int32_t delta[kAxes], uint8_t group, MoveLimits& out) {
    uint32_t x[kAxes];
    out.len_q8 = travel(m, delta, group, x);
    // limit_along() for the rate, then the acceleration, sharing len / x[a] when one axis bounds
    // both (the common case): one division.
    const AxisSettings* ax = m.settings->axis;
    Num r;
    uint8_t prev = kAxes;
    static_assert(offsetof(MoveLimits, accel) == offsetof(MoveLimits, vmax) + 4, "in order");
    uint32_t* o = &out.vmax; // then out.accel
    for (uint8_t k = 0; k < 2; ++k, ++o) {
        const Limit which = k ? kAccel : kRate;
        const uint8_t a = tightest(ax, which, x);
        uint32_t v = 0xFFFFFFFFul; // nothing moves
        if (a != kAxes) {
            if (a != prev) r.set(out.len_q8).div(x[a]);
            prev = a;
            if (k) r.mulc(k3_6, k3_6e); // units/s^2 x1000 -> units/min^2
            v = at_least_1(r.of(ax[a].*which));
        }
        *o = v;
    }
}

void Planner::reset(const int32_t steps[kAxes]) {
    // head_, count_, first_begun_, curve_used_: one run of bytes.
    static_assert(offsetof(Planner, curve_used_) == offsetof(Planner, head_) + 3, "in order");
    memset(&head_, 0, 4);
    memcpy(last_, steps, sizeof(last_));
    // The commanded position that matches the machine position, mm x1000 (after an abort the
    // machine is between targets; the next move's direction is taken from here): each axis'
    // travel from zero (µm x 256), in place, then signed.
    uint32_t* um = reinterpret_cast<uint32_t*>(last_um_);
    travel(*m_, steps, 0, um);
    for (uint8_t a = kAxes; a != 0; --a, ++um) {
        uint32_t v = *um >> 8;
        if (*steps++ < 0) v = 0u - v;
        *um = v;
    }
}

uint32_t Planner::nominal2(const PlanBlock& b) {
    return speed2_of(b.feed);
}

__attribute__((noinline)) PlanBlock* Planner::at(uint8_t i) {
    return &ring_[index(i)];
}

// Junction speed squared with the previous move (GRBL's junction deviation, $11), from the
// commanded geometry. With u, u' the unit vectors (Q29), d = u' - u, w = u' + u, q = |d|^2/4,
// p = |w|^2/4 (p + q = 1) and theta the angle between -u and u':
//   sin(theta/2) = sqrt(p) = |w| / 2,  1 - sin(theta/2) = q / (1 + sin(theta/2)),
//   v_junction^2 = a * delta * sin (1 + sin) / q.
// Writing 1 - sin as q / (1 + sin) keeps full precision on nearly straight paths, where a
// chain of short segments spends its time; |w| keeps it near reversals.
// (Without tree PRE: gcc's partial redundancy elimination keeps values alive across the calls
// here, a few bytes more.)
__attribute__((optimize("no-move-loop-invariants", "no-tree-pre"))) uint32_t
Planner::junction2(const int32_t unit[kAxes], uint32_t limit) const {
    const Machine& m = *m_; // loaded once
    uint32_t dc[kAxes];
    uint8_t moving = 0; // the axes of d
    for (uint8_t a = 0, bit = 1; a < kAxes; ++a, bit = static_cast<uint8_t>(bit << 1)) {
        dc[a] = abs32(unit[a] - prev_unit_[a]); // <= 2^30
        if (dc[a] != 0) moving = static_cast<uint8_t>(moving | bit);
    }
    // |d|^2 / 4. Exponents are adjusted in place below (no Num::shift()): a zero stays zero
    // whatever its exponent.
    Num q = sum_squares(dc, kAxes);
    q.e = static_cast<int8_t>(q.e - 60);
    // GRBL's thresholds: |cos theta| > 0.999999 is straight on (no limit) or a reversal
    // (stop), i.e. q or p below 5e-7.
    if (tiny(q)) return limit;
    // Only min(junction, limit) matters. With p = 1 - q = sin^2 <= 1, sin (1 + sin) >= p >= 1/2
    // when q < 1/2 (q.e < -32), and the junction acceleration (limited per axis along d) is at
    // least the smallest axis acceleration of d, so
    //   v_junction^2 >= a_min x 3.6 x delta / (2000 q) >= limit  when  a_min delta >= 1024 q limit
    // (a margin of 1.8 over every truncation below): then the junction does not limit.
    // Nearly straight chains of short segments (the common case) stop here.
    Num t, r;
    if (q.e < -32) {
        t.set(min_over(m, kAccel, moving)).mul(m.junction_dev_um);
        r.set(limit, 10).mul(q);
        if (t.cmp(r) >= 0) return limit;
    }
    // The exact formula (rare in chains of short segments).
    // p = 1 - q to 2^-32: near a reversal (p small) its relative error grows to 2^-11 at the
    // 5e-7 threshold, where v_junction^2 is a few (mm/min)^2, well within a unit.
    // From here q is kept x 2^32 (its mantissa, and so every result's, unchanged): the
    // exponents below make up for it.
    q.e = static_cast<int8_t>(q.e + 32);
    t.set(~q.u32(), -32);
    if (tiny(t)) return 0;
    t.sqrt();                      // sin(theta / 2)
    r.set(1).add(t).mul(t).div(q); // (1 + sin) sin / q, x 2^-32
    // Acceleration along the junction vector d, limited per axis (GRBL's
    // limit_value_by_axis_maximum): min over the axes of d of accel[a] |d| / d[a] (units/s^2
    // x1000 -> units/min^2: x 3.6), at least 1; |d| in Q29: sqrt(q) * 2 * 2^29. delta in µm /
    // 1000.
    // (A quotient per axis of d: this exact path is rare in chains of short segments.)
    const AxisSettings* ax = m.settings->axis;
    q.sqrt().mulc(k3_6, -16); // sqrt(q) 2^16 x 2^14 = |d| in Q29, x 3.6 (k3_6 2^-30)
    uint32_t acc = 0xFFFFFFFFul;
    const uint32_t* c = dc;
    for (uint8_t mask = moving; mask != 0; mask >>= 1, ++ax, ++c) {
        if (mask & 1) lower(acc, t.set(ax->accel).div(*c).mul(q).u32());
    }
    r.mul(acc).mul(m.junction_dev_um);
    return min32(r.mulc(kMilli, -9).u32(), limit); // / 1000 (kMilli 2^-41), x 2^32
}

uint8_t Planner::open(PlanBlock& b, const int32_t target[kAxes], int32_t d[kAxes]) {
    uint8_t group = 0;
    const uint8_t* g = m_->group_of;
    uint8_t* p = b.delta[0];
    for (uint8_t a = 0; a < kAxes; ++a, p += 3, ++g) {
        const uint32_t v = static_cast<uint32_t>(target[a] - last_[a]);
        last_[a] = target[a];
        d[a] = static_cast<int32_t>(v);
        // The regulated group (seed §3.1, LinuxCNC/g2core rule): the group of the first moving
        // axis in X, Y, Z, A, B, C order (never 0: an axis is in its own group).
        if (v != 0 && group == 0) group = *g;
        p[0] = static_cast<uint8_t>(v);
        p[1] = static_cast<uint8_t>(v >> 8);
        p[2] = static_cast<uint8_t>(v >> 16);
    }
    return group;
}

// curve_shape() is one of the deepest stacks of the firmware (with stepping a curve: poll() ->
// begin_curve()): shape_curve() (inline: curve_shape() runs straight under push_line()) keeps
// its result in the free slot, and add() fills the slot with the curve once the shape is used.
// A line and a curve share the block, the last target, the junction and the look-ahead passes;
// only their limits and end directions differ.
// A line's length for spec_of_first(), when CurveSlot::lens can keep it.
__attribute__((noinline)) void Planner::keep_len(PlanBlock& b, uint32_t len) {
    uint8_t keep = 0;
    if ((curve_used_ | static_cast<uint16_t>(len >> 16)) == 0) {
        curves_[1].lens[index(count_)] = static_cast<uint16_t>(len);
        keep = 1;
    }
    b.has_len = keep & 1;
}

bool Planner::add(const int32_t target[kAxes], const int32_t target_um[kAxes], uint32_t feed,
                  const CurveParams* curve) {
    const Machine& m = *m_; // loaded once
    // Few locals, in scopes that do not overlap (they share their stack slots): the deepest
    // stack of the firmware runs through here.
    PlanBlock& b = *at(count_);
    int32_t d[kAxes]; // steps, then the unit vector the move starts along (Q29)
    uint8_t group = open(b, target, d);
    uint8_t slot = 0; // 1 + the curve's slot
    CurveSlot* cs = nullptr;
    if (curve) {
        const uint8_t plane = curve->plane;
        const uint8_t w = static_cast<uint8_t>(2 - plane); // the normal axis
        group = m.group_of[plane >> 1];                    // see regulates_w()
        const uint8_t in_plane = plane_mask(plane);
        slot = static_cast<uint8_t>(free_slot_index() + 1);
        cs = slot == 2 ? curves_ + 1 : curves_;
        const CurveShape& shape = cs->shaped.shape;
        // Speed: the requested feed, within the plane axes' rates (the tangent takes every
        // direction of the plane), the normal axis' rate along a helix (it moves at v dw / L),
        // and the curvature: v^2 / r <= a at the tightest point (DESIGN.md, part IV), in
        // units/min x1000 sqrt(a r 1000) with a in units/min^2 and r in µm.
        feed = min32(feed, min_over(m, kRate, in_plane));
        Num t;
        const int32_t dw_um = cs->shaped.dw_um;
        if (dw_um != 0) {
            feed = min32(
                feed,
                t.set(shape.len_q8, -8).mul(m.settings->axis[w].max_rate).div(abs32(dw_um)).u32());
        }
        const uint32_t accel = curve_accel(m, plane, d);
        feed = min32(feed, t.set(accel).mul(shape.min_radius_um).mul(1000).sqrt().u32());
        b.dv2 = t.set(shape.len_q8).mul(accel).div(128000).u32();
        // Junctions from the tangents at both ends (w counts only when it is regulated).
        place(d, shape.start_dir, plane, cs->shaped.dirs);
    } else {
        if (!group) { // nothing moves
            memcpy(last_um_, target_um, sizeof(last_um_));
            return false;
        }
        {
            MoveLimits lim;
            move_limits(m, d, group, lim);
            // 2 a L in (units/min)^2: 2 * accel * len_q8 / 256000. Num::mul() keeps the top 32
            // bits of the exact product, as num64(mul_wide()) would.
            b.dv2 = Num(lim.len_q8).mul(lim.accel).mulc(kMilli, -48).u32();
            keep_len(b, lim.len_q8);
            feed = min32(feed, lim.vmax); // a rapid's 2^32 - 1 comes out as vmax
        }
        // Unit vector of the commanded move (Q29) on the regulated axes, for the junction: |du|
        // first, then the unit vector in d.
        uint32_t xu[kAxes];
        uint8_t neg = 0; // axes whose commanded travel is negative
        uint8_t in_group = group;
        for (uint8_t a = 0, bit = 1; a < kAxes;
             ++a, bit = static_cast<uint8_t>(bit << 1), in_group >>= 1) {
            int32_t du = target_um[a] - last_um_[a];
            if (du < 0) neg = static_cast<uint8_t>(neg | bit);
            xu[a] = (in_group & 1) ? abs32(du) : 0;
        }
        Num norm = sum_squares(xu, kAxes);
        Num to_unit(1, 29);
        to_unit.div(norm.sqrt());
        for (uint8_t a = 0; a < kAxes; ++a, neg >>= 1) {
            uint32_t u = to_unit.of(xu[a]);
            if (u > (1ul << 29)) u = 1ul << 29;
            if (neg & 1) u = 0u - u;
            d[a] = static_cast<int32_t>(u);
        }
    }
    memcpy(last_um_, target_um, sizeof(last_um_));
    b.group = group & 0x3F; // (has_len: a curve's is not read)
    b.curve = slot & 3;
    b.feed = at_least_1(feed);
    // From rest after no queued move or one of another group; else the junction, within
    // min(nominal2(b), nominal2(previous)) = nominal2 of the smaller feed: one product.
    uint32_t v2 = 0;
    if (count_ > 0) {
        const PlanBlock* prev = at(count_ - 1);
        if (static_cast<uint8_t>(prev->group) == group) {
            const uint32_t limit = speed2_of(min32(b.feed, prev->feed));
            v2 = junction2(d, limit);
        }
    }
    b.v_max_entry2 = v2;
    b.v_entry2 = 0;
    ++count_;
    recalculate();
    if (curve) {
        CurveSlot& s = *cs;
        curve_used_ = static_cast<uint8_t>(curve_used_ | slot);
        // The direction it ends along, for the next junction.
        place(prev_unit_, s.shaped.shape.end_dir, curve->plane, s.shaped.dirs);
        s.queued.params = *curve; // over the shape (now used) but its length
    } else {
        memcpy(prev_unit_, d, sizeof(prev_unit_));
    }
    return true;
}

void Planner::recalculate() {
    // Pointer walks (an index modulo the ring and a 33-byte stride per block cost more than the
    // passes themselves on the ATmega328P).
    PlanBlock* const first = ring_;
    PlanBlock* const last = ring_ + (kPlannerSize - 1);
    // Backward pass: each move must be able to slow down to the next one's entry (0 after the
    // last move). The move being executed keeps its entry speed.
    // A new move only raises what the moves before it may reach. Once a move's entry comes out
    // at its maximum and was already there (the forward pass only lowers), every earlier move
    // keeps its entry: the passes stop there (in a chain of short moves, a few moves from the
    // end instead of the whole ring). Only while the oldest move is being executed: its entry
    // is then fixed, as it was at the last pass; otherwise it is recomputed from scratch.
    PlanBlock* b = at(static_cast<uint8_t>(count_ - 1));
    uint32_t next_entry = 0;
    uint8_t pos = count_;
    uint8_t from = 0;    // where the forward pass starts
    uint8_t chain = 1;   // the last `chain - 1` moves entered at the next one's entry + dv2
    uint8_t growing = 1; // no move entered at its maximum yet
    while (pos-- > first_begun_) {
        uint32_t v = add_sat(next_entry, b->dv2);
        if (v < b->v_max_entry2) {
            chain = static_cast<uint8_t>(chain + growing);
        } else {
            v = b->v_max_entry2;
            growing = 0;
            if (first_begun_ && b->v_entry2 == v) {
                from = pos;
                break;
            }
        }
        b->v_entry2 = v;
        next_entry = v;
        b = b == first ? last : b - 1;
    }
    // Forward pass: no move can enter faster than the previous one can accelerate to. A move of
    // the chain whose entry this pass keeps lowers neither the next one (it enters below its
    // entry + dv2) nor, by the same token, any later one: the pass stops there (in a chain of
    // short moves, past the few accelerating from the move being executed).
    b = at(from);
    for (uint8_t n = static_cast<uint8_t>(count_ - from); n > 1; --n) {
        uint32_t reach = add_sat(b->v_entry2, b->dv2);
        b = b == last ? first : b + 1; // n - 1 moves from the end
        if (b->v_entry2 > reach) {
            b->v_entry2 = reach;
        } else if (n <= chain) {
            break;
        }
    }
}

void Planner::spec_of_first(MoveSpec& s) const {
    const PlanBlock* const b = const_cast<Planner*>(this)->at(0);
    for (uint8_t a = 0; a < kAxes; ++a) s.delta[a] = delta(*b, a);
    // dv2 (the profile from the planner's own 2 a L), feed, v_entry2: one copy.
    static_assert(offsetof(MoveSpec, feed) == offsetof(MoveSpec, dv2) + 4 &&
                      offsetof(MoveSpec, v_entry2) == offsetof(MoveSpec, dv2) + 8 &&
                      offsetof(PlanBlock, feed) == offsetof(PlanBlock, dv2) + 4 &&
                      offsetof(PlanBlock, v_entry2) == offsetof(PlanBlock, dv2) + 8,
                  "dv2, feed, v_entry2 in the same order");
    memcpy(&s.dv2, &b->dv2, 12);
    s.group = b->group;
    s.v_nominal2 = speed2_of(s.feed);
    s.v_exit2 = exit2_of_first();
    s.curve = nullptr;
    if (b->curve) {
        // Slot b->curve - 1 (two slots: no multiplication by the slot size).
        const CurveSlot& c = b->curve == 1 ? curves_[0] : curves_[1];
        s.curve = &c.queued.params;
        s.len_q8 = c.queued.len_q8;
    } else if (b->has_len && curve_used_ == 0) {
        s.len_q8 = curves_[1].lens[head_]; // add()'s, kept
    } else {
        // The length add() had: the same deltas, group and settings (they only change while
        // nothing is queued).
        uint32_t x[kAxes];
        s.len_q8 = travel(*m_, s.delta, s.group, x);
    }
    s.accel = 0;
    if (s.dv2 == 0xFFFFFFFFul) {
        // dv2 saturated: the acceleration from the limits again.
        s.dv2 = 0;
        if (s.curve) {
            const uint8_t plane = s.curve->plane;
            s.accel = curve_accel(*m_, plane, s.delta);
        } else {
            MoveLimits lim;
            move_limits(*m_, s.delta, s.group, lim);
            s.accel = lim.accel;
        }
    }
}

uint32_t Planner::exit2_of_first() const {
    return count_ > 1 ? const_cast<Planner*>(this)->at(1)->v_entry2 : 0;
}

void Planner::discard_first() {
    const PlanBlock& b = ring_[head_];
    // Slot s is bit s + 1 of curve_used_ with two slots, i.e. the block's curve field.
    curve_used_ = static_cast<uint8_t>(curve_used_ & ~b.curve);
    head_ = index(1);
    --count_;
    first_begun_ = 0;
}

void Planner::restart_first(uint32_t remaining, uint32_t total) {
#if defined(__AVR__)
    // r12, r13 marked as used: the saved registers are then one run, which -mcall-prologues
    // saves through its shared routines, not pushes and pops.
    asm volatile("" ::: "r12", "r13");
#endif
    PlanBlock* const b = ring_ + head_;
    if (total != 0) b->dv2 = Num(remaining).div(total).of(b->dv2);
    // Every move is replanned: as a move not begun yet, whose entry is held at 0 by its limit.
    b->v_max_entry2 = 0;
    first_begun_ = 0;
    recalculate();
    first_begun_ = 1;
}

} // namespace ll
