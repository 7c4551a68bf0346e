#include "lowlevel/stepgen.h"

namespace ll {
namespace {

// Delta_1 at cruise, cycles x 256 = 60 s/min * kCpuHz * 256 / 1000 * len_um / (v d_1) with v in
// mm/min (seed §3.2 with the reference axis' ticks per mm of path, d_1 / len). With lengths in
// µm x 256 and feeds in mm/min x 1000: 960000000 * len_q8 / (feed * d_1).
constexpr uint32_t kCruiseNum = 960000000ul;
static_assert(60ull * kCpuHz * 256 / 1000 * 1000 / 256 == kCruiseNum, "units");
// floor(60 * kCpuHz * 256 / 1000 * sqrt(500) / 2): D = 2 * kSqrtCHalf * sqrt(s len_um / (a d_1)),
// the numerator of Delta_1 = D / sqrt(A) (docs/motion.md, "Wait numerator").
constexpr uint32_t kSqrtCHalf = 2747680330ul;
// Idle waits used to build periods above 65535 cycles stay below this, so that the final wait
// (which absorbs the remainder) still fits in 16 bits.
constexpr uint32_t kIdleChunk = 65000;
static_assert(kMaxPeriodCycles <= 256ul * kIdleChunk, "idle waits of one event fit a run count");
// A is kept below this bound (so that A values and s d add without overflow).
constexpr uint32_t kMaxA = 1ul << 31;

uint32_t max3(uint32_t a, uint32_t b, uint32_t c) {
    uint32_t m = a > b ? a : b;
    return m > c ? m : c;
}

} // namespace

void StepGen::configure(const StepLengths* lengths, uint16_t min_period) {
    lengths_ = lengths;
    min_period_ = min_period;
}

bool StepGen::begin(const MoveSpec& spec) {
    pushed_position(start_); // the previous move is complete: start from its end
    if (!line_setup(line_, spec.delta)) {
        line_.m = 0;
        return false;
    }
    len_q8_ = spec.len_q8;
    accel_ = spec.accel;
    feed_ = spec.feed;
    v_nominal2_ = spec.v_nominal2;
    v_exit2_ = spec.v_exit2;
    line_start(line_, cursor_);
    build_k_table(spec.group);
    uint32_t entry = have_handover_ ? handover_v2_ : spec.v_entry2;
    have_handover_ = false;
    origin_ = 0;
    prepare_profile(entry, spec.v_exit2, line_.dist[0]);
    if (holding_) {
        a_hold_ = prof_.a_entry;
        x2_hold_ = 0;
    }
    active_ = true;
    stopped_ = false;
    seg_len_ = 1;
    return true;
}

void StepGen::build_k_table(uint8_t group) {
    const uint8_t m = line_.m;
    const uint8_t sets = static_cast<uint8_t>(1u << (m - 1));
    for (uint8_t sub = 0; sub < sets; ++sub) {
        uint8_t mask = static_cast<uint8_t>(1u << line_.axis[0]);
        for (uint8_t j = 1; j < m; ++j) {
            if (sub & (1u << (j - 1))) mask = static_cast<uint8_t>(mask | (1u << line_.axis[j]));
        }
        k_mask_[sub] = mask;
    }
    // Feed along the line (docs/motion.md): a line of d_1 micro steps takes len / V, so the
    // micro steps share that time in proportion to their regulated lengths L_P. Over the runs
    // of the §8 order (run i has the axes of sorted positions 0..i and lasts dist[i] -
    // dist[i+1] micro steps), the regulated steps sum to sum_g over count_g steps. Runs where no
    // regulated axis steps (seed §3.1: the other groups follow) take the mean regulated step
    // time, so the followers move at their average rate rather than in bursts. Altogether
    //   K[P] = L_P * count_g / sum_g  (Q20), and 1 for a run without a regulated axis.
    uint32_t lens[1u << (kAxes - 1)];
    for (uint8_t sub = 0; sub < sets; ++sub) {
        lens[sub] = step_length(*lengths_, static_cast<uint8_t>(k_mask_[sub] & group));
    }
    Num sum_g{};
    uint32_t count_g = 0;
    for (uint8_t i = 0; i < m; ++i) {
        uint32_t n = line_.dist[i] - (i + 1 < m ? line_.dist[i + 1] : 0);
        uint32_t len = lens[(1u << i) - 1];
        if (len != 0) {
            sum_g.add(Num(n).mul(len));
            count_g += n;
        }
    }
    if (count_g == 0) {
        // No axis of the regulated group moves: regulate the moving axes themselves.
        build_k_table(0xFF);
        return;
    }
    Num r(count_g, 20);
    r.div(sum_g);
    kmax_ = 0;
    for (uint8_t sub = 0; sub < sets; ++sub) {
        k_[sub] = lens[sub] != 0 ? r.of(lens[sub]) : 1ul << 20;
        if (k_[sub] > kmax_) kmax_ = k_[sub];
    }
}

uint32_t StepGen::a_of(uint32_t v2) const {
    uint32_t a = a_per_v2_.of(v2);
    return a > kMaxA ? kMaxA : a;
}

void StepGen::prepare_profile(uint32_t v_entry2, uint32_t v_exit2, uint32_t remaining_ticks) {
    const uint32_t d1 = line_.dist[0];
    // Fictive distance from rest per (mm/min)^2, reference ticks (seed §4.5 l_0^t):
    // l = v^2 rho / (2 a), rho = 1000 d_1 / len_um = 256000 d_1 / len_q8 ticks per mm.
    Num phi(128000);
    phi.mul(d1).div(len_q8_).div(accel_);
    // D at s = 2: 2 kSqrtCHalf sqrt(2 len_um / (a d_1)), len_um = len_q8 / 256.
    Num dn(len_q8_, -7);
    dn.div(accel_).div(d1).sqrt().mul(kSqrtCHalf).shift(1);
    // Largest scale s = 2 * 4^m (m <= 4) that keeps every A below 2^31 and D below 2^32
    // (D grows as sqrt(s) = 2^m sqrt(2)).
    uint32_t l_max = add_sat(phi.of(max3(v_entry2, v_nominal2_, v_exit2)), remaining_ticks);
    uint8_t m = 4;
    while (m > 0 && (shl_sat(l_max, static_cast<uint8_t>(2 * m + 1)) > kMaxA ||
                     Num(dn).shift(static_cast<int8_t>(m)).u32() == 0xFFFFFFFFul)) {
        --m;
    }
    prof_.log_s = static_cast<uint8_t>(2 * m + 1);
    a_per_v2_ = phi.shift(static_cast<int8_t>(prof_.log_s));
    prof_.d = remaining_ticks;
    prof_.a_entry = a_of(v_entry2);
    prof_.a_cruise = a_of(v_nominal2_);
    prof_.a_exit = a_of(v_exit2);
    if (prof_.a_exit > prof_.a_cruise) prof_.a_exit = prof_.a_cruise;
    prof_.d_num = dn.shift(static_cast<int8_t>(m)).u32();
    // Exact cruise wait of the reference axis along the line: once per move.
    prof_.cruise = Num(kCruiseNum).mul(len_q8_).div(feed_).div(d1).u32();
    x2_decel_ = profile_x2_decel(prof_);
    root_valid_ = false;
}

void StepGen::set_exit(uint32_t v_exit2) {
    if (!active_ || holding_) return;
    if (2 * (cursor_.x1 - origin_) >= x2_decel_) return; // end deceleration already begun
    v_exit2_ = v_exit2;
    prof_.a_exit = a_of(v_exit2);
    if (prof_.a_exit > prof_.a_cruise) prof_.a_exit = prof_.a_cruise;
    x2_decel_ = profile_x2_decel(prof_);
}

void StepGen::hold() {
    if (holding_) return;
    holding_ = true;
    if (active_) {
        a_hold_ = a_last_;
        x2_hold_ = 2 * (cursor_.x1 - origin_);
    }
}

void StepGen::resume(uint32_t v_exit2) {
    holding_ = false;
    if (!stopped_) return;
    stopped_ = false;
    v_exit2_ = v_exit2;
    origin_ = cursor_.x1;
    prepare_profile(0, v_exit2, line_.dist[0] - cursor_.x1);
    seg_len_ = 1;
}

uint32_t StepGen::speed2() const {
    if (a_last_ == 0 || a_per_v2_.m == 0) return 0;
    return Num(a_last_).div(a_per_v2_).u32();
}

void StepGen::pushed_position(int32_t out[kAxes]) const {
    for (uint8_t a = 0; a < kAxes; ++a) out[a] = start_[a];
    for (uint8_t j = 0; j < line_.m; ++j) {
        uint8_t a = line_.axis[j];
        int32_t p = static_cast<int32_t>(cursor_.pos[j]);
        out[a] += (line_.dirs & (1u << a)) ? -p : p;
    }
}

void StepGen::set_position(const int32_t steps[kAxes]) {
    for (uint8_t a = 0; a < kAxes; ++a) start_[a] = steps[a];
    line_.m = 0;
    active_ = false;
}

void StepGen::abort() {
    active_ = false;
    holding_ = false;
    stopped_ = false;
    have_handover_ = false;
    a_last_ = 0;
}

uint32_t StepGen::queued_cycles(const RunQueue& q) {
    // Runs the interrupt has taken since the last look no longer count.
    uint8_t head = q.head;
    while (seen_head_ != head) {
        queued_ = static_cast<uint16_t>(queued_ - slot_time_[seen_head_]);
        seen_head_ = static_cast<uint8_t>((seen_head_ + 1) & (kRunQueueSize - 1));
    }
    return static_cast<uint32_t>(queued_) << 10;
}

void StepGen::clear_queue_time() {
    queued_ = 0;
    seen_head_ = 0;
}

void StepGen::emit(RunQueue& q, uint8_t steps, uint8_t count, uint32_t period_q8) {
    uint32_t period = period_q8 > 0xFFFFFF7Ful ? 0xFFFFFFul : (period_q8 + 128) >> 8;
    if (period < min_period_) {
        period = min_period_;
#if LL_STATS
        ++stats.clamped;
#endif
    }
    if (period > kMaxPeriodCycles) period = kMaxPeriodCycles;
    const uint8_t dirs = line_.dirs;
    if (period <= 0xFFFF) {
        uint32_t units = (period * count) >> 10; // < 2^14
        slot_time_[q.tail] = units > 255 ? 255 : static_cast<uint8_t>(units);
        queued_ = static_cast<uint16_t>(queued_ + slot_time_[q.tail]);
        q.push(Run{steps, dirs, count, static_cast<uint16_t>(period)});
#if LL_STATS
        ++stats.runs;
#endif
    } else {
        // Below 245 steps/s: each event is preceded by idle waits (steps == 0) so that every
        // compare value fits the 16-bit timer without changing its prescaler.
        uint32_t parts = (period + kIdleChunk - 1) / kIdleChunk;
        uint16_t each = static_cast<uint16_t>(period / parts);
        uint16_t last = static_cast<uint16_t>(period - (parts - 1) * each);
        for (uint8_t i = 0; i < count; ++i) {
            slot_time_[q.tail] = 255;
            q.push(Run{0, dirs, static_cast<uint8_t>(parts - 1), each});
            slot_time_[q.tail] = 63;
            q.push(Run{steps, dirs, 1, last});
            queued_ = static_cast<uint16_t>(queued_ + 255 + 63);
#if LL_STATS
            stats.runs += 2;
#endif
        }
    }
}

uint8_t StepGen::fill(RunQueue& q) {
    uint8_t pushed_before = q.used();
    while (active_ && !stopped_) {
        // Room for the worst case of one segment: m runs, each possibly split in two; and no
        // more than the horizon committed ahead of the interrupt.
        if (q.free_slots() < 2 * line_.m) break;
        if (queued_cycles(q) >= kHorizonCycles) break;
        uint32_t left = line_.dist[0] - cursor_.x1;
        uint8_t len = left < seg_len_ ? static_cast<uint8_t>(left) : seg_len_;
        uint32_t x2 = 2 * (cursor_.x1 - origin_) + len; // segment midpoint, half ticks
        uint32_t a = profile_a(prof_, x2);
        if (holding_) {
            uint32_t dec = shl_sat(x2 - x2_hold_, static_cast<uint8_t>(prof_.log_s - 1));
            if (dec >= a_hold_) {
                stopped_ = true; // the speed reaches zero before this segment's midpoint
                break;
            }
            uint32_t ah = a_hold_ - dec;
            if (ah < a) a = ah;
        }
        a_last_ = a;
        uint32_t delta;
        if (a == prof_.a_cruise && !holding_) {
            delta = prof_.cruise;
        } else {
            bool changed = !root_valid_;
            if (!root_valid_) {
                root_.reset(a);
                root_valid_ = true;
            } else {
                changed = root_.seek(a);
            }
            if (changed) {
                delta_root_ = prof_.d_num / (root_.r != 0 ? root_.r : 1);
#if LL_STATS
                ++stats.divisions;
#endif
            }
            delta = delta_root_;
            if (a <= prof_.a_cruise && delta < prof_.cruise) delta = prof_.cruise;
        }

        uint8_t e[kAxes];
        line_advance(line_, cursor_, len, e);
        MicroRun runs[kAxes];
        uint8_t n = micro_split(e, line_.m, runs);
        for (uint8_t i = 0; i < n; ++i) {
            uint8_t idx = static_cast<uint8_t>(runs[i].set >> 1);
            emit(q, k_mask_[idx], runs[i].count, mul_shr(delta, k_[idx], 20));
        }
#if LL_STATS
        ++stats.segments;
#endif

        // Next segment: the shortest power of two lasting kSegmentCycles at this speed, and a
        // single tick whenever a period needs idle waits (so a segment never needs more than
        // two queue slots per run).
        uint8_t next = 1;
        if (mul_shr(delta, kmax_, 20) <= 0xFFFF00ul) {
            // delta * next, not target / next: a division here is a libgcc call (~600 cycles on
            // the ATmega328P, up to 4 per segment). No overflow: this branch has delta < 2^24
            // (kmax_ >= 1.0 in Q20), next <= 8.
            const uint32_t target = static_cast<uint32_t>(kSegmentCycles) << 8;
            while (next < kMaxSegmentTicks && delta * next < target) {
                next = static_cast<uint8_t>(next << 1);
            }
        }
        seg_len_ = next;

        if (cursor_.x1 == line_.dist[0]) {
            active_ = false;
            have_handover_ = true;
            handover_v2_ = holding_ ? speed2() : v_exit2_;
        }
    }
    return static_cast<uint8_t>(q.used() - pushed_before);
}

} // namespace ll
