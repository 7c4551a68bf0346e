// The step generator: the producer side of the compute windows (seed §6). It turns one
// straight move into runs (axis set, count, period) for the step interrupt, a macro segment at
// a time, from the main loop, while the interrupt executes the runs queued before.
//
// Per macro segment (docs/motion.md, "Compute windows"):
//   1. the segment length L (reference-axis ticks, a power of two <= kMaxSegmentTicks) is the
//      smallest that makes the segment last at least kSegmentCycles at the current speed, so
//      that producing the next segment always takes less time than executing this one;
//   2. the speed at the segment's midpoint comes from the sqrt-free profile (profile.h);
//   3. the next macro position comes from the line (line.h), the runs from the micro-stepper
//      (microstep.h), and each run's period is K_P * Delta_1 (seed §5) from the move's K table.
#pragma once

#include "lowlevel/curve.h"
#include "lowlevel/fixmath.h"
#include "lowlevel/line.h"
#include "lowlevel/microstep.h"
#include "lowlevel/profile.h"
#include "lowlevel/run_queue.h"
#include "lowlevel/waits.h"

namespace ll {

/// Minimum duration of a macro segment, CPU cycles. Producing one segment costs about 2,400
/// to 3,500 cycles on the chip (docs/motion.md; lowlevel.elf in simavr), plus 54 per step for
/// the step interrupt, and the segments must leave room for the per-line work too: parsing
/// and planning a G1 line and starting its move took about 35,000 cycles in the 0.5 mm, 100
/// mm/s stream of FirmwareRunQueue, 44 % of the 80,000 cycles such a line lasts. 2048 (the
/// first value) and 4096 were below that budget and the run queue ran dry mid-move (22
/// times at the 264-cycle minimum period with 2048; 57 times in that stream with 4096).
constexpr uint16_t kMinSegmentCycles = 6144;
/// Duration a macro segment is given where the speed tolerance allows (next_segment()), CPU
/// cycles: fewer segments per move leave the main loop more time for short lines. A 0.1 mm line
/// at 50 mm/s lasts 32,000 cycles and has 6 to 8 reference ticks: 6144 cut it into 7 segments
/// of about 3,000 cycles each, and the circle of such lines (docs/benchmarks.md) ran at
/// 1.74 x its ideal time, the CPU being the limit.
constexpr uint16_t kSegmentCycles = 32768;
// fill_curve() gives a curve segment its most samples (3) whenever a sample lasts at most 0xFFFF
// cycles, without next_segment(): what next_segment() gave for 8 x the line duration, 4 samples
// or more, as long as kSegmentCycles x 256 exceeds a quarter of 0xFFFF00.
static_assert(kSegmentCycles >= 16384, "curve segments of 3 samples up to 0xFFFF cycles each");
/// How far ahead of the step interrupt the generator commits motion, CPU cycles (4 ms). Motion
/// not yet produced can still be replanned (a later move raising this one's exit speed, a feed
/// hold), so the generator stays this close behind the interrupt; the main loop must come back
/// to poll() within this time, which is the budget of the compute windows (docs/motion.md).
constexpr uint32_t kHorizonCycles = 64000;

/// Longest wait before one step (idle waits included), CPU cycles: 1.04 s. Slower steps are
/// taken at this rate.
constexpr uint32_t kMaxPeriodCycles = 256ul * 65000;

/// One move as the planner hands it over: a straight line, or a curve (seed part IV).
struct MoveSpec {
    int32_t delta[kAxes]; ///< ticks per machine axis
    uint32_t accel;       ///< acceleration along the regulated path, mm/min^2 (unless dv2)
    /// 2 a L along the path, (mm/min)^2, as the planner has it (0: from len_q8 and accel). The
    /// profile is derived from it directly, which spares a division.
    uint32_t dv2;
    uint32_t feed;     ///< nominal speed along the regulated path, mm/min x1000
    uint32_t v_entry2; ///< entry speed squared, (mm/min)^2
    // (v_nominal2, v_exit2, len_q8: in the order of StepGen's copy, one block)
    uint32_t v_nominal2; ///< nominal speed squared, (mm/min)^2
    uint32_t v_exit2;    ///< exit speed squared, (mm/min)^2
    uint32_t len_q8;     ///< length of the regulated path (axes of `group`), µm x 256
    uint8_t group;       ///< regulated axes G (bit a = machine axis a)
    /// The curve followed from the current position to `delta` further, or nullptr for a line.
    /// Must stay valid until the move is fully produced (the planner keeps it in a slot).
    const CurveParams* curve;
};

/// Counters for the benchmarks and the docs.
struct StepGenStats {
    uint32_t segments;
    uint32_t runs;
    uint32_t divisions; ///< Delta_1 = D / R evaluations (one per change of R)
    uint32_t clamped;   ///< periods raised to the minimum period
};

class StepGen {
  public:
    /// `lengths` must outlive the generator; `min_period` is the shortest period the step
    /// interrupt honours (pulse width + its own margins), CPU cycles; `um_q8_per_step` (µm x 256
    /// per step of each axis, Machine) is needed for curves only.
    void configure(const StepLengths* lengths, uint16_t min_period,
                   const Num* um_q8_per_step = nullptr);

    /// Prepares a move (seed §7: sort axes, slopes; §5: K table; §4: profile). The entry speed
    /// is `spec.v_entry2` unless a previous move handed over its actual exit speed.
    /// Returns false (and stays idle) for a move with no step.
    bool begin(const MoveSpec& spec);
    bool active() const { return active_; }

    /// Produces segments into `q` while it has room for one more segment and holds less than
    /// kHorizonCycles of motion. Returns the number of runs pushed. When the move is fully
    /// produced, active() becomes false.
    uint8_t fill(RunQueue& q);

    /// Motion queued ahead of the interrupt, CPU cycles (1024-cycle resolution).
    uint32_t queued_cycles(const RunQueue& q);
    /// Forget the queued-time accounting (the queue was cleared).
    void clear_queue_time();

    /// The planner raised the exit speed of the current move. Ignored once the end deceleration
    /// has begun (the seed's profile never accelerates at the end of a move, seed §4.1).
    /// (Called at every poll, usually with no change: that test inline, before the call and the
    /// registers it saves.)
    void set_exit(uint32_t v_exit2) {
        if (v_exit2 != v_exit2_) raise_exit(v_exit2);
    }

    /// Feed hold: from the next segment on, decelerate to a stop (possibly across moves).
    void hold();
    bool holding() const { return holding_; }
    /// True when a hold has brought the speed to zero: nothing more is produced until resume().
    bool stopped() const { return stopped_; }
    /// Resumes the current move from rest after a hold, with a new exit speed (the planner
    /// replans the remaining path from zero speed).
    void resume(uint32_t v_exit2);

    /// Speed at the end of the last produced segment, (mm/min)^2 of the current move's path.
    uint32_t speed2() const;
    /// Reference ticks left in the current move, and the move's reference length.
    uint32_t remaining() const { return ref_len() - progress(); }
    uint32_t length() const { return ref_len(); }

    /// Position after every run pushed so far, steps: the move's start plus the macro
    /// position reached (the interrupt never counts steps; this is derived when asked).
    void pushed_position(int32_t out[kAxes]) const;
    /// Sets the position (power-up, after an abort); the current move is forgotten.
    void set_position(const int32_t steps[kAxes]);
    /// Forgets the current move (soft reset); the position is kept.
    void abort();

#if LL_STATS
    StepGenStats stats;
#endif

    // Exposed for the tests: the prepared move.
    const LineGeometry& line() const {
        return ln_.g;
    }
    const Profile& profile() const {
        return prof_;
    }
    /// K table: normalised wait-time factor of each axis set containing the reference axis,
    /// indexed by (sorted-position set >> 1), Q20. Delta_P = K[P] * Delta_1 >> 20.
    uint32_t k(uint8_t index) const {
        return ln_.k[index];
    }
    uint8_t segment_ticks() const {
        return seg_len_;
    }

  private:
    /// set_exit() with a new exit.
    void raise_exit(uint32_t v_exit2);
    bool begin_curve(const MoveSpec& spec);
    /// A line's part of begin() (out of line: begin()'s frame, under begin_curve(), stays
    /// small).
    bool begin_line(const MoveSpec& spec);
    /// The profile from origin_ (set first) to the move's end, from `v_entry2` to v_exit2_; also
    /// clears stopped_ and makes the first segment one tick when starting from rest.
    void prepare_profile(uint32_t v_entry2);
    void take_spec(const MoveSpec& spec);
    /// What begin() does after begin_line() or begin_curve(): the speeds and the profile over the
    /// whole move (one call for both; out of line: begin()'s frame, under begin_curve(), stays
    /// small).
    bool start_profile(const MoveSpec& spec);
    void build_k_table(uint8_t group);
    uint32_t a_of(uint32_t v2) const;
    /// Sets prof_.a_exit to a_of(v_exit2_), at most A_cruise.
    void set_a_exit();
    void emit(RunQueue& q, uint8_t steps, uint8_t dirs, uint8_t count, uint32_t period_q8);
    /// queued_cycles(q) >= kHorizonCycles.
    bool horizon_full(const RunQueue& q);
    /// Queues one run and counts its duration (1024-cycle units) in the horizon.
    void push(RunQueue& q, uint8_t steps, uint8_t dirs, uint8_t count, uint16_t period,
              uint8_t units);
    /// Delta_1 (cycles x 256 per reference unit) at half-unit position x2 of the move (origin_
    /// not taken out); sets stopped_ when a hold brings the speed to zero before x2.
    uint32_t delta_at(uint32_t x2);
    /// Length of the next segment, reference units: the shortest power of two lasting
    /// kSegmentCycles at `delta`, 1 when `longest` (the largest period, x 256) needs idle waits.
    /// At most 16, or kMaxSegmentTicks where the speed changes little over that many ticks:
    /// `a` (the profile's A there; 0: never) at least s (4 longest + 64) (docs/verification.md).
    uint8_t next_segment(uint32_t delta, uint32_t longest, uint32_t a) const;
    void fill_line(RunQueue& q);
    void fill_curve(RunQueue& q);
    void finish_move();
    /// The move's reference length and the reference ticks produced (out of line: one call is
    /// smaller than the test of curve_ and the far member reads).
    uint32_t ref_len() const;
    uint32_t progress() const;
    /// Where the last segment ended, half ticks from origin_.
    uint32_t x2_now() const;

    // Most used first: the ATmega328P addresses the first 64 bytes of an object directly (the
    // order was measured: image size, by a greedy search over the order of these groups, and
    // llsegcost's cycles per segment for what delta_at() reads on every segment).
    // What remains needed of the MoveSpec after begin() (in MoveSpec's order: take_spec() copies
    // them as one block).
    uint32_t v_nominal2_, v_exit2_, len_q8_;
    uint16_t queued_; ///< motion queued ahead of the interrupt, 1024-cycle units
    uint16_t min_period_;
    Profile prof_;
    const StepLengths* lengths_;
    const Num* um_q8_per_step_;
    bool active_;
    bool holding_;
    bool stopped_;
    bool have_handover_;
    bool root_valid_;
    bool lens_valid_; ///< ln_.lens holds step lengths (no curve ran since, same settings)
    uint8_t seg_len_;
    uint8_t seen_head_;
    uint32_t a_last_; ///< A of the last segment
    // The move being produced: a line or a curve, never both, so they share their memory.
    const CurveParams* curve_;
    uint32_t origin_; ///< reference tick where the profile starts (moves after a resume)
    uint32_t handover_v2_;
    SqrtTracker root_;
    // Only a started move uses these four (take_spec() sets feed_ after begin_curve()):
    // begin_curve() borrows their room for the curve's commanded points (its frame then stays
    // below the 64 bytes the ATmega addresses directly).
    union {
        struct {
            uint32_t delta_root_; ///< d_num / R for the current R
            uint32_t feed_;       ///< nominal speed, mm/min x 1000 (MoveSpec)
            // Hold: A(x) = a_hold - s (x - x_hold), half ticks.
            uint32_t a_hold_;
            uint32_t x2_hold_;
        };
        int32_t curve_pts_[2][2]; ///< begin_curve(): arc centre and semi-axes, or the Bezier's
                                  ///< control points, ticks x 256
    };
    Num a_per_v2_; ///< A per (mm/min)^2 at the profile's scale
    Num dv2_;      ///< 2 a L, (mm/min)^2 (MoveSpec::dv2)
    struct LineState {
        uint32_t kmax; ///< largest K of the move
        int32_t k_err; ///< K-time emitted beyond len x Delta_1 so far, Q20 (see fill_line)
        LineCursor c;
        LineGeometry g;
        uint8_t mask[1u << (kAxes - 1)]; ///< machine-axis bits of each sorted set
        // Step length of each sorted set (restricted to the regulated group), kept from one
        // line to the next while lens_valid_ (build_k_table()): in the room the curve state leaves.
        uint32_t lens[1u << (kAxes - 1)];
        uint8_t lens_set[1u << (kAxes - 1)];       ///< the axis set each length is for
        uint32_t k[1u << (kAxes - 1)];             ///< K table, Q20 (see k())
        uint32_t cruise_period[1u << (kAxes - 1)]; ///< K * Delta_1 at cruise, cycles x 256
        uint8_t cruise_seg; ///< segment length at cruise (0: cruise_period not computed yet)
        // kCruiseNum / feed for the feed of the last line (prepare_profile()), kept with the step
        // lengths (0: none).
        uint32_t feed;
        Num per_feed;
    };
    struct CurveState {
        uint32_t ref_um;     ///< its length, µm (the profile's reference length)
        uint32_t x_q8;       ///< distance travelled, µm x 256
        uint8_t axes[3];     ///< machine axes u, v, w
        uint8_t chord;       ///< bits (u = 1, v = 2, w = 4) of the axes the path is timed along
        uint8_t chord_piece; ///< the walker's piece_tag() at the last chord
        uint16_t chord_left; ///< samples that were left in the piece at the last chord
        uint32_t chord_q8;   ///< that chord, µm x 256
        CurveWalker w;
    };
    union {
        LineState ln_;
        CurveState cv_;
    };
    // The line state's caches (step lengths, kCruiseNum / feed) take room the curve state
    // leaves: no static RAM of their own on the chip's 4 axes.
    static_assert(kAxes != 4 || sizeof(LineState) <= sizeof(CurveState), "caches in spare room");
    int32_t start_[kAxes]; ///< position where the current (or last) move started, steps
    // Duration of each queued run in 1024-cycle units (saturated), by queue slot: keeps the
    // horizon without any help from the interrupt.
    uint8_t slot_time_[kRunQueueSize];
};

} // namespace ll
