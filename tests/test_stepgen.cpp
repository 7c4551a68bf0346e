// The step generator: wait times per axis set (seed §3.2, §5), whole moves, feed hold.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "lowlevel/curve.h"
#include "motion_util.h"

namespace {

constexpr double kF = 16e6;

// Seed §3.2 in CPU cycles: Delta_P = F_cpu * sqrt(sum_{j in P∩G} 1/T_j^2) / V, V in mm/s.
double seed_wait(const lltest::Machine& m, uint8_t set, uint8_t group, double v_mm_s) {
    double s = 0;
    for (uint8_t a = 0; a < ll::kAxes; ++a) {
        if ((set & group) & (1u << a)) s += 1.0 / (m.steps_per_mm[a] * m.steps_per_mm[a]);
    }
    return kF * std::sqrt(s) / v_mm_s;
}

// The speed at which the generator times a line's tick path so that the ideal line is covered
// at `feed` (docs/motion.md, "Feed along the line"): V_eff = V * staircase / line, with the
// staircase of the §8 run order (all axes, then all but the shortest, ...).
double effective_speed(const lltest::Machine& m, const int32_t delta[ll::kAxes], double v) {
    std::vector<std::pair<uint32_t, uint8_t>> d;
    for (uint8_t a = 0; a < ll::kAxes; ++a) {
        if (delta[a]) d.push_back({static_cast<uint32_t>(std::abs(delta[a])), a});
    }
    std::stable_sort(d.begin(), d.end(), [](auto x, auto y) { return x.first > y.first; });
    double stair = 0;
    uint8_t set = 0;
    for (size_t i = 0; i < d.size(); ++i) {
        set = static_cast<uint8_t>(set | (1u << d[i].second));
        uint32_t n = d[i].first - (i + 1 < d.size() ? d[i + 1].first : 0);
        stair += n * seed_wait(m, set, 0xFF, 1.0) / kF;
    }
    return v * stair / m.length_mm(delta);
}

} // namespace

TEST(Waits, TabulatedStepLengthsGiveTheSeedFormulaWithinOneCycle) {
    const double spm[] = {5, 40, 80, 100, 160, 250, 400, 800, 1600, 3200};
    const double feeds[] = {30, 300, 1000, 3000, 12000, 60000}; // mm/min
    double worst = 0;
    for (double tx : spm) {
        for (double ty : spm) {
            lltest::Machine m{tx, ty, 400, 100};
            for (double f : feeds) {
                for (uint8_t set = 1; set < 16; ++set) {
                    double want = seed_wait(m, set, 0xFF, f / 60);
                    if (want > 65535 * 4) continue; // long waits are split into idle runs
                    uint32_t got = ll::wait_q8(m.lengths, set, 0xFF,
                                               static_cast<uint32_t>(std::lround(f * 1000)));
                    double err = std::fabs(got / 256.0 - want);
                    worst = std::max(worst, err);
                    ASSERT_LE(err, 1.0)
                        << "T=" << tx << "," << ty << " F" << f << " set " << int(set);
                }
            }
        }
    }
    std::printf("worst |Delta_P - seed §3.2| = %.3f cycle\n", worst);
}

TEST(Waits, OnlyTheRegulatedGroupCountsInTheWaitTime) {
    lltest::Machine m{80, 80, 400, 10};
    // X+A regulated on XYZ: the A part of the diagonal adds no time.
    uint32_t xa = ll::wait_q8(m.lengths, 0b1001, 0b0111, 600000);
    uint32_t x = ll::wait_q8(m.lengths, 0b0001, 0b0111, 600000);
    EXPECT_EQ(xa, x);
    EXPECT_NEAR(x / 256.0, seed_wait(m, 1, 0xFF, 10), 1.0);
}

TEST(StepGen, CruiseRunsFollowTheSeedWaitTimesAtTheCompensatedSpeed) {
    // Within every macro segment at cruise, each run lasts seed §3.2's wait for its axis set at
    // one speed, within one cycle: the compensated speed V_eff, corrected per segment so that the
    // feed along the line stays exact (docs/motion.md, "Feed along the line"). Each period is
    // rounded to a whole cycle, so the segment's speed is fitted to its runs.
    std::mt19937 rng(7);
    const double spm[] = {5, 80, 100, 250, 400, 800, 3200};
    double worst = 0, spread = 0;
    for (int i = 0; i < 400; ++i) {
        lltest::Machine m{spm[rng() % 7], spm[rng() % 7], spm[rng() % 7], spm[rng() % 7]};
        int32_t delta[ll::kAxes];
        for (auto& d : delta) d = static_cast<int32_t>(rng() % 3000) - 1500;
        double feed = 100 + rng() % 6000;
        ll::MoveSpec spec = m.move({delta[0], delta[1], delta[2], delta[3]}, feed, 100000, feed,
                                   feed); // entry = exit = cruise: cruise throughout
        if (spec.len_q8 == 0) continue;
        ll::StepGen gen{};
        gen.configure(&m.lengths, 64);
        const double veff = effective_speed(m, spec.delta, feed / 60);
        for (const auto& seg : lltest::run_segments(gen, spec)) {
            // Each step run's wait (an idle run before it belongs to its first step), and the
            // speed that makes the segment's longest wait exact.
            std::vector<std::pair<uint8_t, double>> waits; // set, cycles before one step
            double idle = 0, v = 0, longest = 0;
            for (const auto& r : seg) {
                if (r.steps == 0) {
                    idle += static_cast<double>(r.count) * r.period;
                    continue;
                }
                if (idle == 0 && r.period >= 65) waits.push_back({r.steps, r.period});
                idle = 0;
            }
            for (const auto& w : waits) {
                if (w.second > longest) {
                    longest = w.second;
                    v = seed_wait(m, w.first, 0xFF, 1.0) / w.second;
                }
            }
            if (v == 0) continue;
            spread = std::max(spread, std::fabs(v / veff - 1));
            for (const auto& w : waits) {
                double err = std::fabs(w.second - seed_wait(m, w.first, 0xFF, v));
                worst = std::max(worst, err);
                ASSERT_LE(err, 1.0) << "move " << i << " set " << int(w.first);
            }
        }
    }
    std::printf("worst |period - seed §3.2 at the segment's speed| = %.3f cycle; segment speeds "
                "within %.2f%% of V_eff\n",
                worst, 100 * spread);
}

TEST(StepGen, ShortLinesAtSpeedAreProducedInOneSegmentEach) {
    // 0.1 mm lines at 50 mm/s, as in the circle of G1 lines (docs/benchmarks.md): 8 reference
    // ticks of about 4,000 cycles. From rest the first segment is one tick; a line entering at
    // speed keeps the last segment length, and at cruise a segment lasts up to kSegmentCycles
    // (8 ticks here), so each further line is a single segment: 6,144-cycle segments made 5.
    lltest::Machine m{80, 80};
    ll::StepGen gen{};
    gen.configure(&m.lengths, 64);
    auto ticks = [](const std::vector<ll::Run>& seg) {
        int n = 0;
        for (const auto& r : seg) n += (r.steps & 1) ? r.count : 0; // X is the reference axis
        return n;
    };
    auto first = lltest::run_segments(gen, m.move({8, 1}, 3000, 1000, 3000, 3000));
    ASSERT_GE(first.size(), 2u);
    EXPECT_EQ(ticks(first[0]), 1);
    for (int32_t dy : {2, 1, 0, 3}) {
        auto segs = lltest::run_segments(gen, m.move({8, dy}, 3000, 1000, 3000, 3000));
        ASSERT_EQ(segs.size(), 1u) << "dy " << dy;
        EXPECT_EQ(ticks(segs[0]), 8);
    }
}

TEST(StepGen, CruisePeriodsAreTheMovesOwnWhenCruiseIsReachedMidMove) {
    // The periods at cruise are computed at a move's first segment at cruise, not when it
    // begins (a chain of short moves limited by the look-ahead never cruises). A move that
    // reaches cruise after accelerating must use its own, not those of the move before it (which
    // cruised from its first segment, at another feed).
    lltest::Machine m{80, 80};
    ll::StepGen gen{};
    gen.configure(&m.lengths, 64);
    for (double feed : {3000.0, 1200.0, 2400.0}) {
        const bool from_rest = feed != 3000.0;
        auto segs =
            lltest::run_segments(gen, m.move({4000, 1500}, feed, 1000, from_rest ? 0 : feed, feed));
        ASSERT_GE(segs.size(), 4u) << "F" << feed;
        const uint32_t cruise = gen.profile().cruise;
        // cycles of one step of the set of sorted positions (mask 1: X, 3: X and Y)
        auto want = [&](uint8_t idx) { return (ll::mul_shr(cruise, gen.k(idx), 20) + 128) >> 8; };
        EXPECT_NEAR(cruise / 256.0, 16e6 * 60 / (feed * 80) * std::hypot(4000, 1500) / 4000, 1.0);
        // the last segments are at cruise (the exit is the cruise speed)
        for (size_t i = segs.size() - 3; i < segs.size(); ++i) {
            for (const auto& r : segs[i]) {
                ASSERT_TRUE(r.steps == 1 || r.steps == 3) << "F" << feed;
                EXPECT_EQ(r.period, want(r.steps == 1 ? 0 : 1)) << "F" << feed << " segment " << i;
            }
        }
    }
}

TEST(StepGen, CruiseWaitKeptForTheFeedIsTheMovesOwnAfterAFeedChangeOrACurve) {
    // kCruiseNum / feed is kept from one line to the next while the feed is the same (a chain of
    // lines): each line's cruise wait must still be what a fresh generator computes for it, after
    // a line at another feed and after a curve (whose state takes the room of the kept value).
    // (The feed change is pinned; after the curve, a missing reset of the kept feed would only
    // show if the curve's bytes there happened to equal the next feed: the lines around the curve
    // check that the reset does no harm, not that it happens.)
    lltest::Machine m{80, 80};
    ll::Num um_q8[ll::kAxes];
    for (auto& n : um_q8) n = ll::Num(256000 / 80);
    ll::CurveParams c{};
    c.kind = ll::kCurveArc;
    c.clockwise = 1;
    c.a_um[0] = c.b_um[0] = c.b_um[1] = 2000;
    ll::CurveShape shape;
    ASSERT_TRUE(ll::curve_shape(c, 0, false, shape));
    ll::StepGen gen{};
    gen.configure(&m.lengths, 64, um_q8);
    int lines = 0;
    for (double feed : {3000.0, 3000.0, -3000.0, 3000.0, 1200.0, 1200.0, 3000.0}) {
        gen.clear_queue_time(); // run_move() starts from an empty queue at slot 0
        if (feed < 0) {         // a full circle at that feed, back where it started
            ll::MoveSpec arc = m.move({0, 0}, -feed, 1000, 0, 0, 0x3);
            arc.len_q8 = shape.len_q8;
            arc.curve = &c;
            ASSERT_FALSE(lltest::run_move(gen, arc).empty());
            continue;
        }
        const ll::MoveSpec spec = m.move({70 + lines, 9 + 3 * lines}, feed, 1000, feed, feed);
        ++lines;
        ll::StepGen fresh{};
        fresh.configure(&m.lengths, 64, um_q8);
        ASSERT_TRUE(fresh.begin(spec));
        ASSERT_FALSE(lltest::run_move(gen, spec).empty());
        EXPECT_EQ(gen.profile().cruise, fresh.profile().cruise) << "line " << lines << " F" << feed;
        EXPECT_EQ(gen.profile().d_num, fresh.profile().d_num) << "line " << lines;
    }
}

TEST(StepGen, RaisedExitIsTakenUntilTheEndDecelerationBegins) {
    // The planner raises the exit of the move in progress as it plans the next one: taken while
    // the profile has not reached its end line, ignored once the end deceleration has begun (the
    // seed's profile never accelerates at the end of a move).
    lltest::Machine m{80, 80};
    for (bool late : {false, true}) {
        ll::StepGen gen{};
        gen.configure(&m.lengths, 64);
        ASSERT_TRUE(gen.begin(m.move({800, 300}, 3000, 1000, 0, 0)));
        const uint32_t a_exit = gen.profile().a_exit;
        bool raised = false;
        ll::RunQueue q;
        while (gen.active()) {
            q.clear();
            gen.clear_queue_time();
            gen.fill(q);
            if (raised || !gen.active()) continue;
            const uint32_t x2 = 2 * (gen.length() - gen.remaining());
            if ((x2 >= ll::profile_x2_decel(gen.profile())) != late) continue;
            gen.set_exit(1500 * 1500);
            raised = true;
            if (late) {
                EXPECT_EQ(gen.profile().a_exit, a_exit) << "x2 " << x2;
            } else {
                EXPECT_GT(gen.profile().a_exit, a_exit) << "x2 " << x2;
            }
        }
        EXPECT_TRUE(raised) << "late " << late;
        // the speed of the last segment (at its midpoint): near 1500 mm/min when the raise was
        // taken, near rest otherwise
        const double v = std::sqrt(gen.speed2());
        if (late) {
            EXPECT_LT(v, 300.0);
        } else {
            EXPECT_NEAR(v, 1500.0, 45.0);
        }
    }
}

TEST(StepGen, MovesEndExactlyOnTheirTargetWithEveryAxisStepCounted) {
    std::mt19937 rng(11);
    lltest::Machine m{80, 80, 400, 40};
    for (int i = 0; i < 300; ++i) {
        int32_t delta[ll::kAxes];
        for (auto& d : delta) d = static_cast<int32_t>(rng() % 20001) - 10000;
        ll::MoveSpec spec =
            m.move({delta[0], delta[1], delta[2], delta[3]}, 500 + rng() % 5000, 50 + rng() % 2000);
        ll::StepGen gen{};
        gen.configure(&m.lengths, 64);
        auto ev = lltest::run_move(gen, spec);
        int32_t pos[ll::kAxes] = {};
        for (const auto& e : ev) {
            for (uint8_t a = 0; a < ll::kAxes; ++a) {
                if (e.steps & (1u << a)) pos[a] += (e.dirs & (1u << a)) ? -1 : 1;
            }
        }
        int32_t pushed[ll::kAxes];
        gen.pushed_position(pushed);
        for (uint8_t a = 0; a < ll::kAxes; ++a) {
            ASSERT_EQ(pos[a], delta[a]);
            ASSERT_EQ(pushed[a], delta[a]);
        }
    }
}

TEST(StepGen, DiagonalLinesTakeLengthOverFeedNotTheStaircaseTime) {
    // Without the compensation a 22.5-degree line would take 8% longer than len / V.
    lltest::Machine m{80, 80};
    for (int32_t dy : {0, 3314, 4000, 8000}) {
        ll::MoveSpec spec = m.move({8000, dy}, 1200, 1e6, 1200, 1200);
        ll::StepGen gen{};
        gen.configure(&m.lengths, 64);
        uint64_t t = 0;
        lltest::run_move(gen, spec, &t);
        double want = m.length_mm(spec.delta) / 20.0 * kF; // 1200 mm/min = 20 mm/s
        EXPECT_NEAR(static_cast<double>(t) / want, 1.0, 2e-4) << "dy=" << dy;
    }
}

TEST(StepGen, LinesOfThreeAndFourAxesTakeLengthOverFeedAtAnySpeed) {
    // Slow lines run one tick per segment, whose micro steps are not nested as §8 assumes when
    // three or four axes move: the per-segment correction keeps the time within one tick of the
    // reference axis (half a tick of dead band, the last segment's own error, the periods'
    // rounding to whole cycles) of len / V.
    std::mt19937 rng(11);
    lltest::Machine m{80, 100, 400, 250};
    double worst = 0;
    for (int i = 0; i < 300; ++i) {
        int32_t delta[ll::kAxes];
        for (auto& d : delta) d = static_cast<int32_t>(rng() % 3000) - 1500;
        if (i % 2) delta[3] = 0; // three axes
        for (double feed : {60.0, 600.0, 3000.0}) {
            ll::MoveSpec spec =
                m.move({delta[0], delta[1], delta[2], delta[3]}, feed, 1e6, feed, feed);
            ll::StepGen gen{};
            gen.configure(&m.lengths, 64);
            uint64_t t = 0;
            lltest::run_move(gen, spec, &t);
            double want = m.length_mm(spec.delta) / (feed / 60) * kF;
            int32_t d1 = 0;
            for (int32_t d : delta) d1 = std::max(d1, std::abs(d));
            double tick = want / d1; // time of one reference tick
            double err = std::fabs(static_cast<double>(t) - want);
            worst = std::max(worst, err / tick);
            EXPECT_LE(err, tick + 2e-4 * want) << "line " << i << " F" << feed;
        }
    }
    std::printf("worst time error: %.3f reference tick\n", worst);
}

TEST(StepGen, SlowMovesUseIdleWaitsAndKeepTheirTiming) {
    // 5 steps/mm at 6 mm/min: 0.5 step/s, 32 M cycles per step, far above the 16-bit timer.
    lltest::Machine m{5};
    ll::MoveSpec spec = m.move({3}, 6, 1e6, 6, 6);
    ll::StepGen gen{};
    gen.configure(&m.lengths, 64);
    ll::RunQueue q;
    q.clear();
    ASSERT_TRUE(gen.begin(spec));
    uint64_t t = 0;
    std::vector<uint64_t> steps;
    while (gen.active() || !q.empty()) {
        gen.fill(q);
        while (!q.empty()) {
            ll::Run r = q.front();
            q.pop();
            ASSERT_GE(r.period, 64);
            for (uint8_t i = 0; i < r.count; ++i) {
                t += r.period;
                if (r.steps) steps.push_back(t);
            }
        }
    }
    ASSERT_EQ(steps.size(), 3u);
    // Waits are capped at kMaxPeriodCycles (1.04 s): slower moves run at about 1 step/s.
    EXPECT_EQ(steps[1] - steps[0], ll::kMaxPeriodCycles);
}

TEST(StepGen, PeriodsNeverGoBelowTheMinimumThePulseNeeds) {
    lltest::Machine m{800};
    ll::MoveSpec spec = m.move({20000}, 30000, 1e5); // 400 kHz asked
    ll::StepGen gen{};
    gen.configure(&m.lengths, 200);
    auto ev = lltest::run_move(gen, spec);
    for (const auto& e : ev) ASSERT_GE(e.period, 200);
    EXPECT_GT(gen.stats.clamped, 0u);
}

TEST(StepGen, FeedHoldStopsAlongThePathAndResumeFinishesTheMove) {
    lltest::Machine m{80, 80};
    ll::MoveSpec spec = m.move({16000, 8000}, 3000, 500);
    ll::StepGen gen{};
    gen.configure(&m.lengths, 64);
    ll::RunQueue q;
    q.clear();
    ASSERT_TRUE(gen.begin(spec));
    int32_t pos[2] = {0, 0};
    uint64_t t = 0;
    std::vector<std::pair<uint64_t, uint32_t>> x_steps; // time, axis-0 position
    auto drain = [&] {
        while (!q.empty()) {
            ll::Run r = q.front();
            q.pop();
            for (uint8_t i = 0; i < r.count; ++i) {
                t += r.period;
                if (r.steps & 1) {
                    ++pos[0];
                    x_steps.push_back({t, static_cast<uint32_t>(pos[0])});
                }
                if (r.steps & 2) ++pos[1];
            }
        }
    };
    while (gen.active() && pos[0] < 8000) {
        gen.fill(q);
        drain();
    }
    gen.hold();
    while (gen.active() && !gen.stopped()) {
        gen.fill(q);
        drain();
    }
    ASSERT_TRUE(gen.stopped());
    // Stopped inside the move, after decelerating: the last steps are slow.
    EXPECT_LT(pos[0], 16000);
    size_t n = x_steps.size();
    double last_rate = kF / static_cast<double>(x_steps[n - 1].first - x_steps[n - 2].first);
    EXPECT_LT(last_rate, 0.1 * 4000); // below 10% of the cruise step rate
    // Deceleration distance at 500 mm/s^2 from 50 mm/s: 2.5 mm = 200 ticks, plus the queue.
    EXPECT_LT(pos[0] - 8000, 200 + 16 * 32);
    gen.resume(0);
    while (gen.active()) {
        gen.fill(q);
        drain();
    }
    drain();
    EXPECT_EQ(pos[0], 16000);
    EXPECT_EQ(pos[1], 8000);
}
