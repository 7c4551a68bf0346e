#include "lowlevel/planner.h"

namespace ll {
namespace {

constexpr uint32_t kOneQ29 = 1ul << 29;

// min over axes with comp[a] > 0 of lim[a] * norm / comp[a]: the largest value along a
// direction that keeps every axis within its own limit (GRBL's limit_value_by_axis_maximum).
// The winner is found by cross-multiplication, so a single division is made.
uint32_t limit_along(const uint32_t lim[kAxes], const uint32_t comp[kAxes], uint64_t norm) {
    int8_t best = -1;
    for (uint8_t a = 0; a < kAxes; ++a) {
        if (comp[a] == 0) continue;
        if (best < 0 || static_cast<uint64_t>(lim[a]) * comp[best] <
                            static_cast<uint64_t>(lim[best]) * comp[a]) {
            best = static_cast<int8_t>(a);
        }
    }
    if (best < 0) return 0xFFFFFFFFul;
    uint8_t b = static_cast<uint8_t>(best);
    Ratio r = make_ratio(norm, comp[b]);
    return r.apply(lim[b]);
}

// x * value of a ratio for a 64-bit x (kept to 32 significant bits), saturated to 32 bits.
uint32_t apply_wide(const Ratio& r, uint64_t x) {
    Ratio t = r;
    uint8_t bl = bit_length(x);
    if (bl > 32) {
        uint8_t k = static_cast<uint8_t>(bl - 32);
        x >>= k;
        int16_t sh = static_cast<int16_t>(t.shift - k);
        t.shift = static_cast<int8_t>(sh < -127 ? -127 : sh);
    }
    return t.apply(static_cast<uint32_t>(x));
}

uint32_t min32(uint32_t a, uint32_t b) {
    return a < b ? a : b;
}

} // namespace

void Planner::reset(const int32_t steps[kAxes], const int32_t um[kAxes]) {
    head_ = 0;
    count_ = 0;
    prev_group_ = 0;
    for (uint8_t a = 0; a < kAxes; ++a) {
        last_[a] = steps[a];
        last_um_[a] = um[a];
    }
}

uint32_t Planner::dv2(const PlanBlock& b) const {
    // v^2 gained over the move: 2 a L, (units/min)^2 = 2 * accel * len_q8 / 256000.
    return saturate32(static_cast<uint64_t>(b.accel) * b.len_q8 / 128000);
}

bool Planner::add(const int32_t target[kAxes], const int32_t target_um[kAxes], uint32_t feed,
                  bool rapid) {
    PlanBlock& b = ring_[index(count_)];
    bool moves = false;
    int32_t du[kAxes];
    for (uint8_t a = 0; a < kAxes; ++a) {
        b.delta[a] = target[a] - last_[a];
        du[a] = target_um[a] - last_um_[a];
        if (b.delta[a] != 0) moves = true;
    }
    for (uint8_t a = 0; a < kAxes; ++a) last_um_[a] = target_um[a];
    if (!moves) return false;
    for (uint8_t a = 0; a < kAxes; ++a) last_[a] = target[a];

    // Per-axis travel in µm x 256 (units of the axis: mm or degrees).
    uint32_t x[kAxes];
    uint8_t big = 0;
    for (uint8_t a = 0; a < kAxes; ++a) {
        int32_t d = b.delta[a];
        uint32_t steps = d < 0 ? static_cast<uint32_t>(-(d + 1)) + 1u : static_cast<uint32_t>(d);
        x[a] = m_->um_q8_per_step[a].apply(steps);
        uint8_t bl = bit_length(x[a]);
        if (bl > big) big = bl;
    }
    // Regulated length: Euclidean over the move's group (seed §3.1). Squares are summed on a
    // scale that keeps six of them within 64 bits.
    b.group = regulated_group(*m_, b.delta);
    uint8_t down = big > 30 ? static_cast<uint8_t>(big - 30) : 0;
    uint64_t sum = 0;
    for (uint8_t a = 0; a < kAxes; ++a) {
        if (!(b.group & (1u << a))) continue;
        uint64_t v = x[a] >> down;
        sum += v * v;
    }
    uint64_t len = static_cast<uint64_t>(isqrt64(sum)) << down;
    if (len == 0) len = 1;
    b.len_q8 = saturate32(len);

    // Limits along the move: every axis (in its own group or following) keeps to its own
    // maximum rate and acceleration.
    uint32_t vmax = limit_along(m_->max_rate, x, b.len_q8);
    b.accel = limit_along(m_->accel, x, b.len_q8);
    if (b.accel == 0) b.accel = 1;
    b.feed = rapid || feed > vmax ? vmax : feed;
    if (b.feed == 0) b.feed = 1;
    b.v_nominal2 = saturate32(static_cast<uint64_t>(b.feed) * b.feed / 1000000);
    b.begun = 0;

    // Junction with the previous move (GRBL's junction deviation, $11): with u, u' the unit
    // vectors and theta the angle between -u and u',
    //   v_junction^2 = a * delta * sin(theta/2) / (1 - sin(theta/2)).
    // With d = u' - u and q = |d|^2 / 4: sin(theta/2) = sqrt(1 - q) and
    // 1 - sin(theta/2) = q / (1 + sin(theta/2)), so
    //   v_junction^2 = a * delta * sin (1 + sin) / q,
    // which keeps full precision on nearly straight paths (no 1 - sin cancellation, and the
    // rounding of |u| cancels out of d), where a chain of short segments spends its time.
    int32_t unit[kAxes];
    {
        uint32_t xu[kAxes];
        uint8_t bl_max = 0;
        for (uint8_t a = 0; a < kAxes; ++a) {
            int32_t d = (b.group & (1u << a)) ? du[a] : 0;
            xu[a] = d < 0 ? static_cast<uint32_t>(-(d + 1)) + 1u : static_cast<uint32_t>(d);
            uint8_t bl = bit_length(xu[a]);
            if (bl > bl_max) bl_max = bl;
        }
        // Scale the commanded deltas to 30 significant bits before the square root, so the
        // norm (and every unit vector) is exact to about 2^-30 even for a 0.1 mm segment.
        uint64_t su = 0;
        for (uint8_t a = 0; a < kAxes; ++a) {
            uint64_t v = bl_max > 30 ? xu[a] >> (bl_max - 30)
                                     : static_cast<uint64_t>(xu[a]) << (30 - bl_max);
            xu[a] = static_cast<uint32_t>(v);
            su += v * v;
        }
        uint64_t lu = isqrt64(su);
        Ratio to_unit = make_ratio(kOneQ29, lu != 0 ? lu : 1);
        for (uint8_t a = 0; a < kAxes; ++a) {
            uint32_t u = to_unit.apply(xu[a]);
            if (u > kOneQ29) u = kOneQ29;
            unit[a] = du[a] < 0 ? -static_cast<int32_t>(u) : static_cast<int32_t>(u);
        }
    }
    uint32_t v_junction2 = 0;
    if (prev_group_ == b.group && count_ > 0) {
        // q = |d|^2 / 4 = 1 - sin^2 and p = |w|^2 / 4 = sin^2 with w = u' + u, Q58. Each is
        // precise where it is small (d near a straight path, w near a reversal).
        uint64_t d2 = 0, w2 = 0;
        uint32_t dcomp[kAxes];
        for (uint8_t a = 0; a < kAxes; ++a) {
            int64_t d = static_cast<int64_t>(unit[a]) - prev_unit_[a];
            int64_t w = static_cast<int64_t>(unit[a]) + prev_unit_[a];
            d2 += static_cast<uint64_t>(d * d);
            w2 += static_cast<uint64_t>(w * w);
            dcomp[a] = static_cast<uint32_t>(d < 0 ? -d : d);
        }
        const uint64_t one_q58 = 1ull << 58;
        uint64_t q = d2 / 4;
        uint64_t p = w2 / 4;
        // GRBL's thresholds: |cos theta| > 0.999999 is straight on (no limit) or a reversal
        // (stop), i.e. q or p below 5e-7.
        const uint64_t eps_q58 = one_q58 / 2000000;
        if (q <= eps_q58) {
            v_junction2 = 0xFFFFFFFFul;
        } else if (p > eps_q58) {
            uint64_t sin_q29 = q < one_q58 / 2 ? isqrt64(one_q58 - q) : isqrt64(p);
            if (sin_q29 > kOneQ29) sin_q29 = kOneQ29;
            // Acceleration along the junction vector d, limited per axis.
            uint32_t ja = limit_along(m_->accel, dcomp, isqrt64(d2));
            uint64_t t = static_cast<uint64_t>(ja) * m_->junction_dev_um; // (units/min^2) µm
            Ratio r = make_ratio(sin_q29 * (kOneQ29 + sin_q29), q);
            r.shift = static_cast<int8_t>(r.shift + 10);  // µm -> mm: / 1000 ~ 2^-10 * 1.024
            v_junction2 = apply_wide(r, t + t * 3 / 125); // x 1.024 restores the /1000 exactly
        }
    }
    for (uint8_t a = 0; a < kAxes; ++a) prev_unit_[a] = unit[a];
    uint32_t prev_nominal2 = count_ > 0 ? ring_[index(count_ - 1)].v_nominal2 : 0;
    prev_group_ = b.group;
    b.v_max_entry2 = min32(v_junction2, min32(b.v_nominal2, prev_nominal2));
    b.v_entry2 = 0;
    ++count_;
    recalculate();
    return true;
}

void Planner::recalculate() {
    // Backward pass: each move must be able to slow down to the next one's entry (0 after the
    // last move). The move being executed keeps its entry speed.
    uint32_t next_entry = 0;
    for (uint8_t i = count_; i-- > 0;) {
        PlanBlock& b = ring_[index(i)];
        if (b.begun) break;
        b.v_entry2 = min32(b.v_max_entry2, saturate32(static_cast<uint64_t>(next_entry) + dv2(b)));
        next_entry = b.v_entry2;
    }
    // Forward pass: no move can enter faster than the previous one can accelerate to.
    for (uint8_t i = 0; i + 1 < count_; ++i) {
        const PlanBlock& b = ring_[index(i)];
        PlanBlock& n = ring_[index(static_cast<uint8_t>(i + 1))];
        if (n.begun) continue;
        uint32_t reach = saturate32(static_cast<uint64_t>(b.v_entry2) + dv2(b));
        if (n.v_entry2 > reach) n.v_entry2 = reach;
    }
}

MoveSpec Planner::spec_of_first() const {
    const PlanBlock& b = ring_[head_];
    MoveSpec s;
    for (uint8_t a = 0; a < kAxes; ++a) s.delta[a] = b.delta[a];
    s.len_q8 = b.len_q8;
    s.accel = b.accel;
    s.feed = b.feed;
    s.v_entry2 = b.v_entry2;
    s.v_nominal2 = b.v_nominal2;
    s.v_exit2 = exit2_of_first();
    s.group = b.group;
    return s;
}

uint32_t Planner::exit2_of_first() const {
    return count_ > 1 ? ring_[index(1)].v_entry2 : 0;
}

void Planner::begin_first() {
    if (count_) ring_[head_].begun = 1;
}

void Planner::discard_first() {
    if (!count_) return;
    head_ = index(1);
    --count_;
}

void Planner::restart_first(uint32_t remaining, uint32_t total) {
    if (!count_) return;
    PlanBlock& b = ring_[head_];
    if (total != 0) b.len_q8 = saturate32(static_cast<uint64_t>(b.len_q8) * remaining / total);
    b.v_entry2 = 0;
    b.begun = 1;
    for (uint8_t i = 1; i < count_; ++i) ring_[index(i)].begun = 0;
    recalculate();
}

} // namespace ll
