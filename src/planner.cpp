#include "lowlevel/planner.h"

namespace ll {
namespace {

uint32_t min32(uint32_t a, uint32_t b) {
    return a < b ? a : b;
}

// The per-axis limits, read straight from the settings: maximum rates (units/min x1000) and
// accelerations (units/s^2 x1000, which scale to units/min^2 by x3.6).
enum Limit : uint8_t { kRate = 0, kAccel = 1 };
uint32_t axis_limit(const Settings& s, uint8_t a, Limit which) {
    return which == kRate ? s.axis[a].max_rate : s.axis[a].accel;
}

// min over axes with comp[a] > 0 of lim[a] / comp[a], times `scale`: the largest value along a
// direction that keeps every axis within its own limit (GRBL's limit_value_by_axis_maximum).
uint32_t limit_along(const Settings& s, Limit which, const uint32_t comp[kAxes], Num scale) {
    Num best{};
    bool any = false;
    for (uint8_t a = 0; a < kAxes; ++a) {
        if (comp[a] == 0) continue;
        Num v(axis_limit(s, a, which));
        v.div(comp[a]);
        if (!any || v.cmp(best) < 0) best = v;
        any = true;
    }
    if (!any) return 0xFFFFFFFFul;
    if (which == kAccel) scale.mul(Num(18)).div(5); // units/s^2 x1000 -> units/min^2
    uint32_t v = best.mul(scale).u32();
    return v ? v : 1;
}

// Euclidean norm of kAxes 32-bit components.
Num norm(const uint32_t v[kAxes]) {
    Num sum{};
    for (uint8_t a = 0; a < kAxes; ++a) {
        Num x(v[a]);
        sum.add(x.mul(x));
    }
    return sum.sqrt();
}

// Acceleration along a curve, units/min^2: its tangent turns through the plane, so the smaller
// of the plane's two axes bounds it (and the normal axis' when a helix moves it).
uint32_t curve_accel(const Machine& m, uint8_t plane, bool w_moves) {
    uint8_t ax[3];
    plane_axes(plane, ax);
    uint32_t acc = 0xFFFFFFFFul;
    for (uint8_t k = 0; k < (w_moves ? 3 : 2); ++k) acc = min32(acc, m.settings->axis[ax[k]].accel);
    uint32_t v = Num(acc).mul(18).div(5).u32(); // units/s^2 x1000 -> units/min^2
    return v ? v : 1;
}

} // namespace

void move_limits(const Machine& m, const int32_t delta[kAxes], uint8_t group, MoveLimits& out) {
    // Per-axis travel in µm x 256 (units of the axis: mm or degrees), and the regulated
    // length: Euclidean over the move's group (seed §3.1).
    uint32_t x[kAxes], xg[kAxes];
    for (uint8_t a = 0; a < kAxes; ++a) {
        x[a] = m.um_q8_per_step[a].of(abs32(delta[a]));
        xg[a] = (group & (1u << a)) ? x[a] : 0;
    }
    out.len_q8 = norm(xg).u32();
    if (out.len_q8 == 0) out.len_q8 = 1;
    Num len(out.len_q8);
    out.vmax = limit_along(*m.settings, kRate, x, len);
    out.accel = limit_along(*m.settings, kAccel, x, len);
}

int32_t Planner::delta(const PlanBlock& b, uint8_t axis) {
    const uint8_t* d = b.delta[axis];
    uint32_t v = d[0] | static_cast<uint32_t>(d[1]) << 8 | static_cast<uint32_t>(d[2]) << 16;
    if (v & 0x800000ul) v |= 0xFF000000ul; // sign extension
    return static_cast<int32_t>(v);
}

void Planner::reset(const int32_t steps[kAxes], const int32_t um[kAxes]) {
    head_ = 0;
    count_ = 0;
    curve_used_ = 0;
    first_begun_ = 0;
    prev_group_ = 0;
    for (uint8_t a = 0; a < kAxes; ++a) {
        last_[a] = steps[a];
        last_um_[a] = um[a];
    }
}

uint32_t Planner::nominal2(const PlanBlock& b) {
    Num v(b.feed);
    return v.mul(v).div(1000000).u32();
}

// Junction speed squared with the previous move (GRBL's junction deviation, $11), from the
// commanded geometry. With u, u' the unit vectors (Q29), d = u' - u, w = u' + u, q = |d|^2/4,
// p = |w|^2/4 (p + q = 1) and theta the angle between -u and u':
//   sin(theta/2) = sqrt(p) = |w| / 2,  1 - sin(theta/2) = q / (1 + sin(theta/2)),
//   v_junction^2 = a * delta * sin (1 + sin) / q.
// Writing 1 - sin as q / (1 + sin) keeps full precision on nearly straight paths, where a
// chain of short segments spends its time; |w| keeps it near reversals.
uint32_t Planner::junction2(const int32_t unit[kAxes]) const {
    uint32_t dc[kAxes], wc[kAxes];
    for (uint8_t a = 0; a < kAxes; ++a) {
        dc[a] = abs32(unit[a] - prev_unit_[a]); // <= 2^30
        wc[a] = abs32(unit[a] + prev_unit_[a]);
    }
    Num dn = norm(dc);
    Num q = dn;
    q.mul(dn).shift(-60);
    Num sin_half = norm(wc).shift(-30);
    // GRBL's thresholds: |cos theta| > 0.999999 is straight on (no limit) or a reversal
    // (stop), i.e. q or p below 5e-7.
    Num eps(1);
    eps.div(2000000);
    if (q.cmp(eps) <= 0) return 0xFFFFFFFFul;
    Num p = sin_half;
    if (p.mul(sin_half).cmp(eps) <= 0) return 0;
    // Acceleration along the junction vector d, limited per axis; delta in µm / 1000.
    uint32_t ja = limit_along(*m_->settings, kAccel, dc, dn);
    Num r(1);
    r.add(sin_half).mul(sin_half).div(q).mul(ja).mul(m_->junction_dev_um).div(1000);
    return r.u32();
}

bool Planner::add(const int32_t target[kAxes], const int32_t target_um[kAxes], uint32_t feed,
                  bool rapid) {
    PlanBlock& b = ring_[index(count_)];
    bool moves = false;
    int32_t d[kAxes], du[kAxes];
    for (uint8_t a = 0; a < kAxes; ++a) {
        d[a] = target[a] - last_[a];
        du[a] = target_um[a] - last_um_[a];
        if (d[a] != 0) moves = true;
    }
    for (uint8_t a = 0; a < kAxes; ++a) last_um_[a] = target_um[a];
    if (!moves) return false;
    for (uint8_t a = 0; a < kAxes; ++a) {
        last_[a] = target[a];
        uint32_t v = static_cast<uint32_t>(d[a]);
        b.delta[a][0] = static_cast<uint8_t>(v);
        b.delta[a][1] = static_cast<uint8_t>(v >> 8);
        b.delta[a][2] = static_cast<uint8_t>(v >> 16);
    }
    b.group = regulated_group(*m_, d);
    MoveLimits lim;
    move_limits(*m_, d, b.group, lim);
    b.feed = rapid || feed > lim.vmax ? lim.vmax : feed;
    if (b.feed == 0) b.feed = 1;
    // 2 a L in (units/min)^2: 2 * accel * len_q8 / 256000.
    b.dv2 = Num(lim.len_q8).mul(lim.accel).div(128000).u32();

    // Unit vector of the commanded move (Q29), for the junction.
    int32_t unit[kAxes];
    uint32_t xu[kAxes];
    for (uint8_t a = 0; a < kAxes; ++a) xu[a] = (b.group & (1u << a)) ? abs32(du[a]) : 0;
    Num to_unit(1, 29);
    to_unit.div(norm(xu));
    for (uint8_t a = 0; a < kAxes; ++a) {
        uint32_t u = to_unit.of(xu[a]);
        if (u > (1ul << 29)) u = 1ul << 29;
        unit[a] = du[a] < 0 ? -static_cast<int32_t>(u) : static_cast<int32_t>(u);
    }
    b.curve = 0;
    finish_block(b, unit, unit);
    return true;
}

void Planner::finish_block(PlanBlock& b, const int32_t unit_in[kAxes],
                           const int32_t unit_out[kAxes]) {
    uint32_t v_junction2 = prev_group_ == b.group && count_ > 0 ? junction2(unit_in) : 0;
    for (uint8_t a = 0; a < kAxes; ++a) prev_unit_[a] = unit_out[a];
    uint32_t prev_nominal2 = count_ > 0 ? nominal2(ring_[index(count_ - 1)]) : 0;
    prev_group_ = b.group;
    b.v_max_entry2 = min32(v_junction2, min32(nominal2(b), prev_nominal2));
    b.v_entry2 = 0;
    ++count_;
    recalculate();
}

bool Planner::add_curve(const int32_t target[kAxes], const int32_t target_um[kAxes], uint32_t feed,
                        const CurveParams& curve) {
    uint8_t ax[3];
    plane_axes(curve.plane, ax);
    int32_t d[kAxes];
    for (uint8_t a = 0; a < kAxes; ++a) d[a] = target[a] - last_[a];
    const uint8_t group = m_->group_of[ax[0] < ax[1] ? ax[0] : ax[1]];
    const bool w_reg = (group & (1u << ax[2])) != 0;
    const int32_t dw_um = target_um[ax[2]] - last_um_[ax[2]];
    CurveShape shape;
    if (!curve_shape(curve, w_reg ? dw_um : 0, w_reg, shape)) return false;
    uint8_t slot = 0;
    while (curve_used_ & (1u << slot)) ++slot;
    curve_used_ = static_cast<uint8_t>(curve_used_ | (1u << slot));
    curves_[slot] = curve;
    curves_[slot].len_q8 = shape.len_q8;
    PlanBlock& b = ring_[index(count_)];
    b.curve = static_cast<uint8_t>(slot + 1);
    for (uint8_t a = 0; a < kAxes; ++a) {
        last_[a] = target[a];
        last_um_[a] = target_um[a];
        uint32_t v = static_cast<uint32_t>(d[a]);
        b.delta[a][0] = static_cast<uint8_t>(v);
        b.delta[a][1] = static_cast<uint8_t>(v >> 8);
        b.delta[a][2] = static_cast<uint8_t>(v >> 16);
    }
    b.group = group;
    // Speed: the requested feed, within the plane axes' rates (the tangent takes every
    // direction of the plane), the normal axis' rate along a helix (it moves at v dw / L), and
    // the curvature: v^2 / r <= a at the tightest point (DESIGN.md, part IV), in units/min x1000
    // sqrt(a r 1000) with a in units/min^2 and r in µm.
    const Settings& st = *m_->settings;
    uint32_t vmax = min32(st.axis[ax[0]].max_rate, st.axis[ax[1]].max_rate);
    if (dw_um != 0) {
        uint32_t vw =
            Num(st.axis[ax[2]].max_rate).mul(shape.len_q8).div(abs32(dw_um)).shift(-8).u32();
        vmax = min32(vmax, vw);
    }
    const uint32_t accel = curve_accel(*m_, curve.plane, d[ax[2]] != 0);
    vmax = min32(vmax, Num(accel).mul(shape.min_radius_um).mul(1000).sqrt().u32());
    b.feed = min32(feed, vmax);
    if (b.feed == 0) b.feed = 1;
    b.dv2 = Num(shape.len_q8).mul(accel).div(128000).u32();
    // Junctions from the tangents at both ends (w counts only when it is regulated).
    int32_t in[kAxes] = {}, out[kAxes] = {};
    for (uint8_t k = 0; k < 3; ++k) {
        if (k == 2 && !w_reg) continue;
        in[ax[k]] = shape.start_dir[k];
        out[ax[k]] = shape.end_dir[k];
    }
    finish_block(b, in, out);
    return true;
}

void Planner::recalculate() {
    // Backward pass: each move must be able to slow down to the next one's entry (0 after the
    // last move). The move being executed keeps its entry speed.
    uint32_t next_entry = 0;
    for (uint8_t i = count_; i-- > first_begun_;) {
        PlanBlock& b = ring_[index(i)];
        b.v_entry2 = min32(b.v_max_entry2, add_sat(next_entry, b.dv2));
        next_entry = b.v_entry2;
    }
    // Forward pass: no move can enter faster than the previous one can accelerate to.
    for (uint8_t i = 0; i + 1 < count_; ++i) {
        const PlanBlock& b = ring_[index(i)];
        PlanBlock& n = ring_[index(static_cast<uint8_t>(i + 1))];
        uint32_t reach = add_sat(b.v_entry2, b.dv2);
        if (n.v_entry2 > reach) n.v_entry2 = reach;
    }
}

MoveSpec Planner::spec_of_first() const {
    const PlanBlock& b = ring_[head_];
    MoveSpec s;
    for (uint8_t a = 0; a < kAxes; ++a) s.delta[a] = delta(b, a);
    if (b.curve) {
        const CurveParams& c = curves_[b.curve - 1];
        s.len_q8 = c.len_q8;
        uint8_t ax[3];
        plane_axes(c.plane, ax);
        s.accel = curve_accel(*m_, c.plane, s.delta[ax[2]] != 0);
        s.curve = &c;
    } else {
        MoveLimits lim;
        move_limits(*m_, s.delta, b.group, lim);
        s.len_q8 = lim.len_q8;
        s.accel = lim.accel;
        s.curve = nullptr;
    }
    s.feed = b.feed;
    s.v_entry2 = b.v_entry2;
    s.v_nominal2 = nominal2(b);
    s.v_exit2 = exit2_of_first();
    s.group = b.group;
    return s;
}

uint32_t Planner::exit2_of_first() const {
    return count_ > 1 ? ring_[index(1)].v_entry2 : 0;
}

void Planner::discard_first() {
    if (!count_) return;
    const PlanBlock& b = ring_[head_];
    if (b.curve) curve_used_ = static_cast<uint8_t>(curve_used_ & ~(1u << (b.curve - 1)));
    head_ = index(1);
    --count_;
    first_begun_ = 0;
}

void Planner::restart_first(uint32_t remaining, uint32_t total) {
    if (!count_) return;
    PlanBlock& b = ring_[head_];
    if (total != 0) b.dv2 = Num(remaining).div(total).of(b.dv2);
    b.v_entry2 = 0;
    first_begun_ = 1;
    recalculate();
}

} // namespace ll
