#include "lowlevel/stepgen.h"

#include <stddef.h>
#include <string.h>

namespace ll {
namespace {

// Delta_1 at cruise, cycles x 256 = 60 s/min * kCpuHz * 256 / 1000 * len_um / (v d_1) with v in
// mm/min (seed §3.2 with the reference axis' ticks per mm of path, d_1 / len). With lengths in
// µm x 256 and feeds in mm/min x 1000: 960000000 * len_q8 / (feed * d_1).
constexpr uint32_t kCruiseNum = 960000000ul;
static_assert(60ull * kCpuHz * 256 / 1000 * 1000 / 256 == kCruiseNum, "units");
static_assert(kCruiseNum >> 30 == 0 && (kCruiseNum << 2) >> 31 == 1, "kCruiseNum << 2 normalised");
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

// x (1 - f), f in Q20 with |f| <= 1/4: x - floor(x f) for f > 0, x + floor(x |f|) otherwise.
__attribute__((noinline)) uint32_t less(uint32_t x, int32_t f) {
#if defined(__AVR__)
    // r17 and Y marked as used: with them the saved registers are one run (r8..r17, r28, r29),
    // which -mcall-prologues saves through its shared routines, not 9 pushes and pops (-16 B;
    // 6 B of stack, about 22 cycles a call).
    asm volatile("" ::: "r17", "r28", "r29");
#endif
    if (f == 0) return x; // the common case: no product
    uint32_t p = mul_shr(x, abs32(f), 20);
    if (f > 0) p = 0 - p;
    return x + p;
}

} // namespace

void StepGen::configure(const StepLengths* lengths, uint16_t min_period,
                        const Num* um_q8_per_step) {
    lens_valid_ = false; // the step lengths may have changed
    lengths_ = lengths;
    min_period_ = min_period;
    um_q8_per_step_ = um_q8_per_step;
}

bool StepGen::begin(const MoveSpec& spec) {
    pushed_position(start_); // the previous move is complete: start from its end
    curve_ = nullptr;
    if (!(spec.curve ? begin_curve(spec) : begin_line(spec))) {
        // Refused: nothing of it moves (begin_curve() may have written over the line state, or
        // left the last line's in place).
        ln_.g.m = 0;
        return false;
    }
    return start_profile(spec);
}

bool StepGen::begin_line(const MoveSpec& spec) {
    if (!line_setup(ln_.g, spec.delta)) return false; // (it leaves m = 0)
    line_start(ln_.g, ln_.c);
    build_k_table(spec.group);
    ln_.k_err = 0;
    return true;
}

inline void StepGen::take_spec(const MoveSpec& spec) {
    static_assert(offsetof(MoveSpec, v_exit2) == offsetof(MoveSpec, v_nominal2) + 4 &&
                      offsetof(MoveSpec, len_q8) == offsetof(MoveSpec, v_nominal2) + 8,
                  "v_nominal2, v_exit2, len_q8 in StepGen's order");
    memcpy(&v_nominal2_, &spec.v_nominal2, 12);
    feed_ = spec.feed;
    if (spec.dv2) {
        dv2_.set(spec.dv2);
    } else {
        dv2_.set(spec.len_q8).mul(spec.accel).mulc(0x83126E97ul, -48); // 2 a L
    }
}

bool StepGen::start_profile(const MoveSpec& spec) {
    take_spec(spec);
    uint32_t entry = have_handover_ ? handover_v2_ : spec.v_entry2;
    have_handover_ = false;
    origin_ = 0;
    prepare_profile(entry);
    // (read only while holding: a hold begun later sets them again)
    a_hold_ = prof_.a_entry;
    x2_hold_ = 0;
    active_ = true;
    return true;
}

// Inline in begin_line(), its one caller (-8 B; its frame there, 48 B, stays below
// begin_curve()'s 66 B under the same begin() and start_profile()).
__attribute__((always_inline)) inline void StepGen::build_k_table(uint8_t group) {
    const uint8_t m = ln_.g.m;
    // Machine-axis bits of each set: the sets with sorted position j (bit j - 1 of the index)
    // are those without it plus its axis (the reference axis joins the empty set in place).
    uint8_t* mask = ln_.mask;
    mask[0] = 0;
    uint8_t sets = 1;
    for (uint8_t j = 0; j < m; ++j) {
        const uint8_t bit = static_cast<uint8_t>(1u << ln_.g.axis[j]);
        const uint8_t to = j ? sets : 0;
        for (uint8_t s = 0; s < sets; ++s) mask[to + s] = static_cast<uint8_t>(mask[s] | bit);
        if (j) sets = static_cast<uint8_t>(sets << 1);
    }
    // Feed along the line (docs/motion.md): a line of d_1 micro steps takes len / V, so the
    // micro steps share that time in proportion to their regulated lengths L_P. Over the runs
    // of the §8 order (run i has the axes of sorted positions 0..i and lasts dist[i] -
    // dist[i+1] micro steps), the regulated steps sum to sum_g over count_g steps. Runs where no
    // regulated axis steps (seed §3.1: the other groups follow) take the mean regulated step
    // time, so the followers move at their average rate rather than in bursts. Altogether
    //   K[P] = L_P * count_g / sum_g  (Q20), and 1 for a run without a regulated axis.
    // The step lengths (one square root each) depend on the axis sets only: kept from the
    // previous line (consecutive lines mostly move the same axes in the same order).
    // Every entry is forgotten when the lengths are not valid (a curve's state overwrote them,
    // or the settings changed), not only the first `sets`: a later line with more axes would
    // otherwise read entries that a curve left, where a stale byte can look like its set. 0xFF
    // is no set (mask < 2^kAxes).
    if (!lens_valid_) {
        for (uint8_t& set : ln_.lens_set) set = 0xFF;
        ln_.feed = 0; // (no feed: per_feed is not valid either)
    }
    lens_valid_ = true;
    uint32_t* lens = ln_.lens;
    uint32_t sum_hi, sum_lo, count_g;
    for (;;) {
        for (uint8_t sub = 0; sub < sets; ++sub) {
            uint8_t set = static_cast<uint8_t>(ln_.mask[sub] & group);
            if (ln_.lens_set[sub] != set) {
                ln_.lens_set[sub] = set;
                lens[sub] = step_length(*lengths_, set);
            }
        }
        // sum_g exact in two halves (n < 2^23, len < 2^32, m <= 6 terms): mul_wide() and a carry
        // are smaller than avr-gcc 5.4's uint64_t (__umulsidi3, __adddi3, __lshrdi3 and the moves)
        sum_hi = sum_lo = count_g = 0;
        uint32_t below = 0; // dist[i + 1], 0 past the last position
        for (uint8_t i = m, set = static_cast<uint8_t>(sets - 1); i-- > 0; set >>= 1) {
            uint32_t n = ln_.g.dist[i] - below;
            below = ln_.g.dist[i];
            uint32_t len = lens[set]; // the set of sorted positions 0..i: (1 << i) - 1
            if (len != 0 && n != 0) {
                uint32_t lo;
                sum_hi += mul_wide(n, len, lo);
                sum_lo += lo;
                if (sum_lo < lo) ++sum_hi;
                count_g += n;
            }
        }
        if (count_g != 0) break;
        // No axis of the regulated group moves: regulate the moving axes themselves.
        group = 0xFF;
    }
    Num r(count_g, 20);
    r.div(num64(sum_hi, sum_lo));
    uint32_t kmax = 0;
    uint32_t* kp = ln_.k;
    for (uint8_t sub = sets; sub; --sub) {
        const uint32_t len = *lens++;
        const uint32_t k = len != 0 ? r.of(len) : 1ul << 20;
        *kp++ = k;
        if (k > kmax) kmax = k;
    }
    ln_.kmax = kmax;
}

uint32_t StepGen::a_of(uint32_t v2) const {
    uint32_t a = a_per_v2_.of(v2);
    return a > kMaxA ? kMaxA : a;
}

bool StepGen::begin_curve(const MoveSpec& spec) {
    const CurveParams& c = *spec.curve;
    if (!um_q8_per_step_) return false;
    lens_valid_ = false; // the curve's state overwrites the lines
    // plane_axes(): (u, v, w) = (X, Y, Z), (Z, X, Y), (Y, Z, X), i.e. axis (k - plane) mod 3.
    for (uint8_t k = 0, a = static_cast<uint8_t>(3 - c.plane); k < 3; ++k, ++a) {
        if (a >= 3) a = static_cast<uint8_t>(a - 3);
        cv_.axes[k] = a;
    }
    // The path is timed along the regulated axes only (seed §3.1): the plane's, and the normal
    // axis' when it belongs to the group (the planner measured the length the same way).
    uint8_t w_bit = static_cast<uint8_t>(cv_.axes[2] + 1); // 1 << axes[2], axes[2] <= 2
    if (w_bit == 3) w_bit = 4;
    cv_.chord = spec.group & w_bit ? 7 : 3;
    // Machine positions (ticks) and commanded points of the plane (ticks x 256) for the walker:
    // µm x steps per µm, i.e. x 256 / (µm x 256 per step).
    CurveWalker::Ends e;
    for (uint8_t k = 0; k < 3; ++k) {
        uint8_t a = cv_.axes[k];
        e.start[k] = start_[a];
        e.end[k] = start_[a] + spec.delta[a];
    }
    // The commanded points: start and end into e, then a and b (arc: centre and semi-axes, of
    // which only the magnitudes count; Bezier: control points).
    const bool arc = c.kind == kCurveArc;
    int32_t(&ab)[2][2] = curve_pts_; // (the started move sets what shares its room)
    for (uint8_t k = 0; k < 2; ++k) {
        Num& per_um = dv2_; // scratch: dv2_ is set by take_spec() (start_profile()) only
        per_um.set(65536).div(um_q8_per_step_[cv_.axes[k]]); // ticks x 256 per µm
        for (uint8_t i = 0; i < 4; ++i) {
            const int32_t* um = i == 0 ? c.start_um : i == 1 ? c.end_um : i == 2 ? c.a_um : c.b_um;
            int32_t* q8 = i == 0 ? e.start_q8 : i == 1 ? e.end_q8 : ab[i - 2];
            const int32_t x = um[k];
            int32_t v = static_cast<int32_t>(per_um.of(abs32(x)));
            q8[k] = x < 0 && !(arc && i == 3) ? -v : v;
        }
    }
    // The semi-axes as unsigned values (signed and unsigned ints may alias).
    bool ok =
        arc ? cv_.w.arc(e, ab[0], reinterpret_cast<uint32_t*>(ab[1]), c.clockwise != 0, c.turns)
            : cv_.w.bezier(e, ab[0], ab[1]);
    if (!ok) return false;
    curve_ = &c;
    // The profile's reference axis is a virtual one with 1000 ticks per mm (µm) along the path.
    uint32_t ref_um = spec.len_q8 >> 8;
    if (ref_um == 0) ref_um = 1;
    cv_.ref_um = ref_um;
    cv_.x_q8 = 0;
    cv_.chord_left = 0; // no chord yet (fill_curve)
    return true;
}

void StepGen::prepare_profile(uint32_t v_entry2) {
    const uint32_t d1 = ref_len();
    const uint32_t remaining_ticks = d1 - origin_;
    // Fictive distance from rest per (mm/min)^2, reference ticks (seed §4.5 l_0^t): l = v^2 rho /
    // (2 a), rho = 256000 d_1 / len_q8 ticks per mm, dv2 = 2 a L, a = 128000 dv2 / len_q8, so
    //   phi = d_1 / dv2 (one division);
    // D at s = 2: 2 kSqrtCHalf sqrt(2 len_um / (a d_1)) = kD r sqrt(phi), with r = len_q8 / d_1
    // (µm x 256 per tick) and kD = 2 kSqrtCHalf / sqrt(2^7 128000).
    Num& phi = a_per_v2_; // phi in place: shifted to the profile's scale below
    phi.set(d1).div(dv2_);
    Num r(len_q8_);
    r.div(d1);
    Num dn = phi;                             // D in its own room
    dn.sqrt().mul(r).mulc(0xA5BA6827ul, -11); // kD = 1357645.0195
    // Largest scale s = 2 * 4^m (m <= 4) that keeps every A below 2^31 (l_max << (2m + 1)
    // <= 2^31) and D below 2^32 - 1 (D grows as sqrt(s) = 2^m sqrt(2)).
    uint32_t l_max = add_sat(phi.of(max3(v_entry2, v_nominal2_, v_exit2_)), remaining_ticks);
    // D 2^m = dn.m 2^(dn.e + m) is below 2^32 - 1 while dn.e + m <= e_lim (D = 0: always).
    int8_t e_lim = dn.m == 0xFFFFFFFFul ? -1 : 0;
    if (dn.m == 0) e_lim = 127;
    uint8_t m = 4;
    for (uint32_t lim = 1ul << 22; m > 0; --m, lim <<= 2) {
        if (l_max <= lim && static_cast<int8_t>(dn.e + m) <= e_lim) break;
    }
    prof_.log_s = static_cast<uint8_t>(2 * m + 1);
    phi.shift(static_cast<int8_t>(prof_.log_s));
    prof_.d = remaining_ticks;
    prof_.a_cruise = a_of(v_nominal2_);
    prof_.a_entry = a_of(v_entry2);
    set_a_exit();
    prof_.d_num = dn.shift(static_cast<int8_t>(m)).u32();
    // Exact cruise wait of the reference axis along the line: once per move.
    // kCruiseNum r / feed, with kCruiseNum / feed kept from the line before when the feed is the
    // same (a chain of lines mostly is): a product instead of a division.
    if (curve_) { // (its state holds no cache)
        r.mulc(kCruiseNum << 2, -2).div(feed_);
    } else {
        if (ln_.feed != feed_) {
            ln_.feed = feed_;
            ln_.per_feed.set(kCruiseNum << 2, -2).div(feed_);
        }
        r.mul(ln_.per_feed);
    }
    prof_.cruise = r.u32();
    root_valid_ = false;
    stopped_ = false;
    // The first segment: one tick from rest; a line entering at speed keeps the length of the
    // last segment before it, chosen for the same speed (the entry is the previous exit), and
    // so does not spend a segment on one tick (a 0.1 mm line has only 6 to 8). A curve sets 1
    // when it ends: its segment lengths count samples, not ticks.
    if (v_entry2 == 0 || seg_len_ == 0) seg_len_ = 1;
    // The runs' periods at cruise: computed by fill_line() at the first segment at cruise (a
    // chain of short moves limited by the look-ahead never reaches it).
    if (!curve_) ln_.cruise_seg = 0;
}

void StepGen::set_a_exit() {
    const uint32_t a = a_of(v_exit2_);
    prof_.a_exit = a > prof_.a_cruise ? prof_.a_cruise : a;
}

void StepGen::raise_exit(uint32_t v_exit2) {
    if (!active_ || holding_) return;
    // End deceleration already begun (never accelerate at the end of a move, seed §4.1): the
    // profile in force is on its end line where the last segment ended, A(x) = A_exit + s (d - x)
    // <= start(x) (profile_a(), which is that minimum; the same test as x >= profile_x2_decel(), in
    // A, without its variable shifts).
    const uint32_t x2 = x2_now();
    const uint32_t to_go2 = 2 * prof_.d - x2;
    if (to_go2 > 2 * prof_.d) return; // (a curve's samples may run past its length)
    // (A_exit < 2^31 and s (d - x) <= s d <= 2^31: no overflow, as in profile_a())
    if (profile_a(prof_, x2) >= prof_.a_exit + (to_go2 << (prof_.log_s - 1))) return;
    v_exit2_ = v_exit2;
    set_a_exit();
}

void StepGen::hold() {
    if (holding_) return;
    holding_ = true;
    // (between moves these are unused: start_profile() sets them for the next one)
    a_hold_ = a_last_;
    x2_hold_ = x2_now();
}

void StepGen::resume(uint32_t v_exit2) {
    holding_ = false;
    if (!stopped_) return;
    v_exit2_ = v_exit2;
    origin_ = progress();
    prepare_profile(0);
}

uint32_t StepGen::speed2() const {
    return Num(a_last_).div(a_per_v2_).u32(); // 0 when either is (Num::div gives 0 then)
}

void StepGen::pushed_position(int32_t out[kAxes]) const {
    if (out != start_) memcpy(out, start_, sizeof(start_)); // (begin(): in place)
    if (curve_) {
        for (uint8_t k = 0; k < 3; ++k) out[cv_.axes[k]] = cv_.w.pos[k];
        return;
    }
    const uint8_t* axis = ln_.g.axis;
    const uint32_t* pos = ln_.c.pos;
    const uint8_t dirs = ln_.g.dirs;
    for (uint8_t j = ln_.g.m; j; --j) {
        uint8_t a = *axis++;
        uint32_t p = *pos++;
        uint8_t d = dirs;
        for (uint8_t i = a; i; --i) d = static_cast<uint8_t>(d >> 1);
        if (d & 1) p = 0u - p;
        out[a] = static_cast<int32_t>(static_cast<uint32_t>(out[a]) + p);
    }
}

void StepGen::set_position(const int32_t steps[kAxes]) {
    memcpy(start_, steps, sizeof(start_));
    ln_.g.m = 0;
    curve_ = nullptr;
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
    horizon_full(q);
    // queued_ < 16 x 255 < 2^14: << 2 in 16 bits, then << 8 as a byte move
    return static_cast<uint32_t>(static_cast<uint16_t>(queued_ << 2)) << 8;
}

bool StepGen::horizon_full(const RunQueue& q) {
    // Runs the interrupt has taken since the last look no longer count.
    uint8_t head = q.head;
    while (seen_head_ != head) {
        queued_ = static_cast<uint16_t>(queued_ - slot_time_[seen_head_]);
        seen_head_ = static_cast<uint8_t>((seen_head_ + 1) & (kRunQueueSize - 1));
    }
    // queued_cycles() >= kHorizonCycles, in the 1024-cycle units (no 32-bit shift)
    return queued_ >= (kHorizonCycles + 1023) >> 10;
}

void StepGen::clear_queue_time() {
    queued_ = 0;
    seen_head_ = 0;
}

void StepGen::push(RunQueue& q, uint8_t steps, uint8_t dirs, uint8_t count, uint16_t period,
                   uint8_t units) {
    slot_time_[q.tail] = units;
    queued_ = static_cast<uint16_t>(queued_ + units);
    q.push(Run{steps, dirs, count, period});
#if LL_STATS
    ++stats.runs;
#endif
}

void StepGen::emit(RunQueue& q, uint8_t steps, uint8_t dirs, uint8_t count, uint32_t period_q8) {
    // Rounded to cycles, at most kMaxPeriodCycles (compared before rounding: no overflow).
    static_assert(kMaxPeriodCycles < 1ul << 24, "kMaxPeriodCycles << 8 fits 32 bits");
    static_assert((kMaxPeriodCycles << 8) % 65536 == 0, "compared on the top half");
    uint32_t period = static_cast<uint16_t>(period_q8 >> 16) >= (kMaxPeriodCycles << 8) >> 16
                          ? kMaxPeriodCycles
                          : (period_q8 + 128) >> 8;
    if (period < min_period_) {
        period = min_period_;
#if LL_STATS
        ++stats.clamped;
#endif
    }
    if (period <= 0xFFFF) {
        const uint16_t p16 = static_cast<uint16_t>(period);
        // 16 x 8 bits < 2^24; >> 10 as a byte move (into 16 bits) and two shifts: avr-gcc 5.4
        // makes a 10-turn loop of a 32-bit >> 10
        const uint16_t units =
            static_cast<uint16_t>((static_cast<uint32_t>(p16) * count) >> 8) >> 2;
        push(q, steps, dirs, count, p16, units > 255 ? 255 : static_cast<uint8_t>(units));
    } else {
        // Below 245 steps/s: each event is preceded by idle waits (steps == 0) so that every
        // compare value fits the 16-bit timer without changing its prescaler.
        const uint16_t parts = static_cast<uint16_t>(div32_16(period + kIdleChunk - 1, kIdleChunk));
        const uint16_t each = static_cast<uint16_t>(div32_16(period, parts));
        const uint16_t last =
            static_cast<uint16_t>(period - static_cast<uint32_t>(parts - 1u) * each);
        for (uint8_t i = 0; i < count; ++i) {
            push(q, 0, dirs, static_cast<uint8_t>(parts - 1), each, 255);
            push(q, steps, dirs, 1, last, 63);
        }
    }
}

uint32_t StepGen::delta_at(uint32_t x2) {
    // (A move that enters and leaves at cruise speed, as in chains of short moves, is at
    // A_cruise everywhere and takes the shortcut below after profile_a(): a separate test of
    // such moves before it saved its 370 cycles a segment but cost 70 B.)
    x2 -= 2 * origin_;
    uint32_t a = profile_a(prof_, x2);
    if (holding_) {
        uint32_t dec = shl_sat(x2 - x2_hold_, static_cast<uint8_t>(prof_.log_s - 1));
        if (dec >= a_hold_) {
            stopped_ = true; // the speed reaches zero before this point
            return 0;
        }
        uint32_t ah = a_hold_ - dec;
        if (ah < a) a = ah;
    }
    a_last_ = a;
    if (a == prof_.a_cruise && !holding_) return prof_.cruise;
    bool changed = !root_valid_;
    if (!root_valid_) {
        root_.reset(a);
        root_valid_ = true;
    } else {
        changed = root_.seek(a);
    }
    if (changed) {
        delta_root_ = div32_16(prof_.d_num, root_.r != 0 ? root_.r : 1);
#if LL_STATS
        ++stats.divisions;
#endif
    }
    uint32_t delta = delta_root_;
    if (a <= prof_.a_cruise && delta < prof_.cruise) delta = prof_.cruise;
    return delta;
}

__attribute__((noinline)) uint8_t StepGen::next_segment(uint32_t delta, uint32_t longest,
                                                        uint32_t a) const {
#if defined(__AVR__)
    // Y marked as used: with it the saved registers are one run (r8..r17, r28, r29), which
    // -mcall-prologues saves through its shared routines, not 10 pushes and pops (-20 B; 4 B of
    // stack, about 20 cycles a call).
    asm volatile("" ::: "r28", "r29");
#endif
    uint8_t next = 1;
    if (longest <= 0xFFFF00ul) {
        // The shortest power of two lasting kSegmentCycles, as long as the speed stays within its
        // tolerance over the segment (docs/motion.md, "Speed accuracy"): a tick u away from the
        // segment's midpoint runs off by u / (2 l), with l = A / s ticks from rest, which the
        // tolerance allows for segments of up to 16 ticks. Measured against it, segments of up to
        // 8 ticks no longer than l / 8 use about half, 16 ticks all of it, so 16 and 32 are
        // taken only where the speed is steady: 32 ticks give 8 / l where
        // 16-tick segments are allowed 4 / l, and 4 / l <= 1 / Delta (the allowance for whole
        // cycles) once l >= 4 Delta; 64 ticks more cover how far A moves until the next segment.
        // Segments shorter than kMinSegmentCycles are made only within 8 L of rest (the speed
        // falls fast there): producing one costs about 3,000 cycles when its speed changes.
        // The segment's duration, delta x next (cycles x 256), against the two constants: one
        // shift a doubling (it stays below 2^24: no overflow).
        constexpr uint32_t kTarget = static_cast<uint32_t>(kSegmentCycles) << 8;
        constexpr uint32_t kLeast = static_cast<uint32_t>(kMinSegmentCycles) << 8;
        // ticks from rest, a >> log_s (8 of the usual 9 as a byte move, not 8 turns of a loop)
        uint32_t l = a;
        uint8_t log_s = prof_.log_s;
        if (log_s & 8) { // (log_s <= 9)
            l >>= 8;
            log_s &= 7;
        }
        l >>= log_s;
        const bool steady = l >= (longest >> 6) + 64;
        uint8_t need = 16; // l wanted for a doubling below 8 ticks: 16 next
        while (next < 16 && delta < kTarget) {
            if (!(next < 8 ? l >= need : steady) && (delta >= kLeast || l < need / 2u)) break;
            next = static_cast<uint8_t>(next << 1);
            delta <<= 1;
            need = static_cast<uint8_t>(need << 1);
        }
        if (next == 16 && delta < kLeast && steady) next = kMaxSegmentTicks;
    }
    return next;
}

void StepGen::finish_move() {
    active_ = false;
    have_handover_ = true;
    // The speed reached, which is below the planned exit when a raised exit came too late for
    // a short move to accelerate to it (the next move must start from what was reached).
    // (The planned exit when the last segment's A reached the exit's: no division then.)
    handover_v2_ = holding_ || a_last_ < prof_.a_exit ? speed2() : v_exit2_;
}

void StepGen::fill_line(RunQueue& q) {
    while (active_ && !stopped_) {
        // Room for the worst case of one segment: m runs, each possibly split in two; and no
        // more than the horizon committed ahead of the interrupt.
        if (q.free_slots() < 2 * ln_.g.m) break;
        if (horizon_full(q)) break;
        uint32_t left = ln_.g.dist[0] - ln_.c.x1;
        uint8_t len = left < seg_len_ ? static_cast<uint8_t>(left) : seg_len_;
        const uint32_t delta = delta_at(2 * ln_.c.x1 + len); // segment midpoint
        if (stopped_) break;
        uint8_t e[kAxes];
        line_advance(ln_.g, ln_.c, len, e);
        MicroRun runs[kAxes];
        uint8_t n = micro_split(e, ln_.g.m, runs);
        // The K table makes the micro steps of a segment last len x Delta_1 altogether when they
        // are nested as in §8 (docs/motion.md, "Feed along the line"), which they always are
        // with one or two moving axes. With three or four, a segment whose micro steps are not
        // (a single tick at low speed, where the minor axes step on ticks of their own) sums to
        // more or less. The difference is carried over and beyond a dead band of half a tick it
        // scales the next segment's Delta_1, spread over its ticks: the waits keep the §3.2
        // proportions at a speed corrected per segment, and the feed along the whole line stays
        // exact within about half a tick's time.
        const bool tracked = ln_.g.m > 2;
        int32_t corr = 0; // per tick, Q20 of the mean K (1.0): the next ticks last (1 - corr)
        if (tracked) {
            const int32_t band = 1l << 19;
            const int32_t err = ln_.k_err;
            // beyond the dead band [-band, band] (one unsigned test of the range)
            if (static_cast<uint32_t>(err) + band > 2ul * band)
                corr = err < 0 ? err + band : err - band;
            // spread over the segment length in force (a power of two; not a short last one)
            for (uint8_t l = seg_len_; l > 1; l = static_cast<uint8_t>(l >> 1)) corr >>= 1;
            // at most a quarter: no jolt (one unsigned test of the range; past the band |corr| <=
            // 2^31 - 2^19, so the sum cannot overflow)
            if (static_cast<uint32_t>(corr + (1l << 18)) > (1ul << 19))
                corr = corr < 0 ? -(1l << 18) : 1l << 18;
        }
        const uint32_t d = corr ? less(delta, corr) : delta;
        // At cruise (most segments of a job) the periods are the move's constants.
        const bool at_cruise = delta == prof_.cruise;
        if (at_cruise && ln_.cruise_seg == 0) {
            // The runs' periods at cruise (one product per axis set and move) and the segment
            // length there. The longest is K_max's (mul_shr() is monotonic in the factor).
            const uint8_t sets = static_cast<uint8_t>(1u << (ln_.g.m - 1));
            uint32_t longest = 0;
            for (uint8_t sub = 0; sub < sets; ++sub) {
                const uint32_t p = mul_shr(delta, ln_.k[sub], 20);
                ln_.cruise_period[sub] = p;
                if (p > longest) longest = p;
            }
            ln_.cruise_seg = next_segment(delta, longest, prof_.a_cruise);
        }
        const bool constants = at_cruise && corr == 0;
        uint32_t sum = 0;
        for (const MicroRun* r = runs; n; --n, ++r) {
            const uint8_t idx = static_cast<uint8_t>(r->set >> 1);
            const uint8_t count = r->count;
            if (tracked) sum += count * ln_.k[idx];
            emit(q, ln_.mask[idx], ln_.g.dirs, count,
                 constants ? ln_.cruise_period[idx] : mul_shr(d, ln_.k[idx], 20));
        }
        if (tracked) {
            // What this segment took, in K units of the uncorrected Delta_1: sum x (1 - corr).
            int32_t took = static_cast<int32_t>(less(sum, corr));
            // len << 20 as (len << 4) << 16: a byte move, not twenty shifts
            ln_.k_err += took - static_cast<int32_t>(static_cast<uint32_t>(len << 4) << 16);
        }
#if LL_STATS
        ++stats.segments;
#endif
        seg_len_ =
            at_cruise ? ln_.cruise_seg : next_segment(delta, mul_shr(delta, ln_.kmax, 20), a_last_);
        if (left == len) finish_move(); // the line's end reached
    }
}

// A curve's samples, timed along the path as the reference axis (seed §10.2): each sample
// waits its chord's length at the profile's speed.
void StepGen::fill_curve(RunQueue& q) {
    while (active_ && !stopped_) {
        // Worst case of one segment: every sample its own run, each possibly split in two; a
        // segment is cut short to what the queue can take.
        if (horizon_full(q)) break;
        // The chord of the next sample sets the time of every sample of the segment (the
        // segment never crosses into the next piece, whose samples may be twice as long).
        const uint16_t left = cv_.w.peek();
        // The segment's length depends on the speed only, never on how full the queue is (the
        // chip and the host model must cut the same segments): wait for room for all of it.
        // At most 3 samples (6 runs in the worst case), so that the queue is still half full
        // when there is room for a whole segment.
        constexpr uint8_t kMaxSamples = 3;
        uint8_t n = seg_len_ < kMaxSamples ? seg_len_ : kMaxSamples;
        if (left != 0 && left < n) n = static_cast<uint8_t>(left);
        // (Tested before the chord is read or computed: a segment that waits costs no more.)
        if (q.free_slots() < 2 * n + 2) break;
        // The chord changes slowly along a piece: computed again (a square root) when a piece
        // starts and every 8 samples, not for every segment (chord_left: the samples left in
        // the piece when it was computed, 0: none yet). The samples since then wrap around to
        // 2^16 - left or more (a piece has at most 4096) when there is no chord yet (left >= 1
        // then) or a new piece has more samples than were left; a new piece of fewer samples
        // (a small curve's pieces have 4 to 8) is told by the walker's piece tag.
        // Kept at once: the room is there, so the segment is made unless the speed reaches zero
        // first (a hold), and then the same samples are still next and have the same chord. (The
        // chip and the host model stop at different times for room, and must still use the same
        // chord for the same samples.)
        if (static_cast<uint16_t>(cv_.chord_left - left) >= 8 ||
            cv_.chord_piece != cv_.w.piece_tag()) {
            cv_.chord_q8 = cv_.w.chord_q8(cv_.chord, cv_.axes, lengths_->inv2);
            cv_.chord_left = left;
            cv_.chord_piece = cv_.w.piece_tag();
        }
        const uint32_t chord_q8 = cv_.chord_q8;
        uint32_t mid = cv_.x_q8 + chord_q8 * n / 2;
        const uint32_t delta = delta_at(2 * (mid >> 8));
        if (stopped_) break;
        // Delta (cycles x 256 per µm) x chord (µm x 256) / 256.
        uint32_t period_q8 = mul_shr(delta, chord_q8, 8);
        // Samples of the same axes and directions make one run (compared as the walker gives
        // them: the rotation below is one to one).
        // (u, v, w) bits to machine-axis bits: axis (k - plane) mod 3 (begin_curve) is a
        // rotation of the three bits by plane = 2 - axes[2] to the right, once per run.
        const uint8_t plane = static_cast<uint8_t>(2 - cv_.axes[2]);
        uint8_t run_moved = 0, run_neg = 0, run_count = 0;
        // The runs of a segment share its period: rounded and clamped here once, and pushed as
        // emit() would when it fits 16 bits (else emit() makes each run's idle waits). emit()
        // cost 290 cycles a run, push() costs 74.
        static_assert(0xFFFF00ul < kMaxPeriodCycles << 8, "a whole period is never capped");
        static_assert((kMaxSamples * 0xFFFFul) >> 10 <= 255, "a run's time never saturates");
        const bool whole = period_q8 <= 0xFFFF00ul;
        uint16_t p16 = static_cast<uint16_t>((period_q8 + 128) >> 8);
        const bool clamped = p16 < min_period_;
        if (clamped) p16 = min_period_;
        // One push for both ends of a run: a sample that differs, or none left.
        for (;; --n) {
            uint8_t moved, neg; // (read only when next() has set them)
            const bool more = n != 0 && cv_.w.next(moved, neg);
            if (run_count != 0 && (!more || moved != run_moved || (moved && neg != run_neg))) {
                uint8_t steps = static_cast<uint8_t>(run_moved * 9u);
                uint8_t dirs = static_cast<uint8_t>(run_neg * 9u);
                for (uint8_t p = plane; p; --p) {
                    steps = static_cast<uint8_t>(steps >> 1);
                    dirs = static_cast<uint8_t>(dirs >> 1);
                }
                steps = static_cast<uint8_t>(steps & 7);
                dirs = static_cast<uint8_t>(dirs & 7);
                if (whole) {
                    // (as emit() counts a run's time)
                    const uint8_t units = static_cast<uint8_t>(
                        static_cast<uint16_t>((static_cast<uint32_t>(p16) * run_count) >> 8) >> 2);
                    push(q, steps, dirs, run_count, p16, units);
#if LL_STATS
                    if (clamped) ++stats.clamped;
#endif
                } else {
                    emit(q, steps, dirs, run_count, period_q8);
                }
                run_count = 0;
            }
            if (!more) break;
            if (run_count == 0) {
                run_moved = moved;
                if (moved) run_neg = neg;
            }
            ++run_count;
            cv_.x_q8 += chord_q8; // (a sum a sample: no product)
        }
#if LL_STATS
        ++stats.segments;
#endif
        // A curve segment costs a chord (a square root) on top of its samples: it takes the most
        // samples it may, one when a sample needs idle waits. (This is what next_segment() gives
        // for 8x the line segment duration without a speed limit: at least 4 up to a period of
        // 0xFFFF cycles, else 1; without its call, 280 cycles less a segment.)
        seg_len_ = whole ? kMaxSamples : 1;
        if (cv_.w.done()) {
            seg_len_ = 1;
            finish_move();
        }
    }
}

uint32_t StepGen::ref_len() const {
    return curve_ ? cv_.ref_um : ln_.g.dist[0];
}

uint32_t StepGen::progress() const {
    return curve_ ? (cv_.x_q8 >> 8) : ln_.c.x1;
}

uint32_t StepGen::x2_now() const {
    return 2 * (progress() - origin_);
}

uint8_t StepGen::fill(RunQueue& q) {
    // Runs pushed: how far the tail moved (the interrupt may move the head meanwhile).
    const uint8_t tail = q.tail;
    if (curve_) {
        fill_curve(q);
    } else {
        fill_line(q);
    }
    return static_cast<uint8_t>((q.tail - tail) & (kRunQueueSize - 1));
}

} // namespace ll
