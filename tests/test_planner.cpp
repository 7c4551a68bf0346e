// Look-ahead planner: junction deviation and deceleration feasibility.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "lowlevel/planner.h"
#include "lowlevel/stepgen.h"

namespace {

struct Fixture {
    ll::Settings s{};
    ll::Machine m{};
    ll::Planner p{};
    Fixture(double spm = 80, double accel = 1000, double rate = 6000, double jd = 0.01) {
        for (uint8_t a = 0; a < ll::kAxes; ++a) {
            s.axis[a].steps_per_unit = static_cast<uint32_t>(spm * 1000);
            s.axis[a].max_rate = static_cast<uint32_t>(rate * 1000);
            s.axis[a].accel = static_cast<uint32_t>(accel * 1000);
            s.axis_group[a] = a < 3 ? 0 : 1;
        }
        s.junction_dev = static_cast<uint32_t>(jd * 1000);
        s.pulse_us = 2;
        ll::machine_build(m, s);
        p.configure(&m);
        int32_t zero[ll::kAxes] = {};
        p.reset(zero);
    }
    void add_mm(double x, double y, double feed, double z = 0) {
        int32_t t[ll::kAxes] = {static_cast<int32_t>(std::lround(x * 80)),
                                static_cast<int32_t>(std::lround(y * 80)),
                                static_cast<int32_t>(std::lround(z * 80)), 0};
        int32_t um[ll::kAxes] = {static_cast<int32_t>(std::lround(x * 1000)),
                                 static_cast<int32_t>(std::lround(y * 1000)),
                                 static_cast<int32_t>(std::lround(z * 1000)), 0};
        p.add(t, um, static_cast<uint32_t>(feed * 1000));
    }
    const ll::PlanBlock& block(uint8_t i) { return p.block(i); }
    ll::MoveLimits limits(uint8_t i) {
        int32_t d[ll::kAxes];
        for (uint8_t a = 0; a < ll::kAxes; ++a) d[a] = ll::Planner::delta(p.block(i), a);
        ll::MoveLimits lim;
        ll::move_limits(m, d, p.block(i).group, lim);
        return lim;
    }
};

// GRBL 1.1's junction speed (planner.c), in doubles: the reference for the integer planner.
double grbl_junction2(const double u_prev[3], const double u[3], double accel_mm_min2, double jd) {
    double cos_theta = 0, jv[3], jn = 0;
    for (int i = 0; i < 3; ++i) {
        cos_theta -= u_prev[i] * u[i];
        jv[i] = u[i] - u_prev[i];
        jn += jv[i] * jv[i];
    }
    if (cos_theta > 0.999999) return 0;
    if (cos_theta < -0.999999) return 1e30;
    jn = std::sqrt(jn);
    double limit = 1e30;
    for (int i = 0; i < 3; ++i) {
        if (jv[i] != 0) limit = std::min(limit, accel_mm_min2 / std::fabs(jv[i] / jn));
    }
    double sin_d2 = std::sqrt(0.5 * (1 - cos_theta));
    return limit * jd * sin_d2 / (1 - sin_d2);
}

} // namespace

TEST(Planner, RightAngleJunctionMatchesTheHandComputedSpeed) {
    // u = (1,0), u' = (0,1): sin(theta/2) = sqrt(2)/2; junction acceleration along (-1,1)/sqrt2
    // limited per axis: 3.6e6 / 0.7071 = 5.091e6 mm/min^2;
    // v^2 = 5.091e6 * 0.01 * 0.7071 / 0.2929 = 122,914 (mm/min)^2, v = 350.6 mm/min.
    Fixture f;
    f.add_mm(10, 0, 3000);
    f.add_mm(10, 10, 3000);
    EXPECT_NEAR(f.block(1).v_max_entry2, 122914.0, 122914.0 * 1e-4);
}

TEST(Planner, StraightContinuationKeepsNominalAndReversalStops) {
    Fixture f;
    f.add_mm(10, 0, 3000);
    f.add_mm(20, 0, 3000);
    f.add_mm(10, 0, 3000);
    EXPECT_NEAR(f.block(1).v_max_entry2, 9000000.0, 1.0);
    EXPECT_EQ(f.block(2).v_max_entry2, 0u);
}

TEST(Planner, JunctionSpeedsMatchGrblFormulaOverRandomAngles) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> ang(-M_PI, M_PI);
    double worst = 0;
    for (int i = 0; i < 2000; ++i) {
        Fixture f(80, 500, 60000, 0.02);
        double a0 = ang(rng), a1 = ang(rng);
        double l0 = 5 + (rng() % 100), l1 = 5 + (rng() % 100);
        double x0 = 50 + l0 * std::cos(a0), y0 = 50 + l0 * std::sin(a0);
        f.add_mm(50, 50, 60000); // from the origin: not part of the junction under test
        f.add_mm(x0, y0, 60000);
        f.add_mm(x0 + l1 * std::cos(a1), y0 + l1 * std::sin(a1), 60000);
        // Reference from the commanded geometry (µm targets), as the planner sees it.
        const ll::PlanBlock& b2 = f.block(2);
        double p1[3] = {std::lround(x0 * 1000) - 50000.0, std::lround(y0 * 1000) - 50000.0, 0};
        double p2[3] = {std::lround((x0 + l1 * std::cos(a1)) * 1000) - std::lround(x0 * 1000) * 1.0,
                        std::lround((y0 + l1 * std::sin(a1)) * 1000) - std::lround(y0 * 1000) * 1.0,
                        0};
        double u0[3], u1[3], n0 = 0, n1 = 0;
        for (int k = 0; k < 3; ++k) {
            u0[k] = p1[k];
            u1[k] = p2[k];
            n0 += u0[k] * u0[k];
            n1 += u1[k] * u1[k];
        }
        for (int k = 0; k < 3; ++k) {
            u0[k] /= std::sqrt(n0);
            u1[k] /= std::sqrt(n1);
        }
        double want = std::min(grbl_junction2(u0, u1, 500 * 3600, 0.02), 3.6e9);
        double got = b2.v_max_entry2;
        // Squared speeds are whole (mm/min)^2, rounded down: within 1.5 units (the floor plus
        // the fixed-point factors), or 1e-5 of the value for fast junctions.
        double err = std::fabs(got - want);
        double tol = 1e-5 * want + 1.5;
        worst = std::max(worst, err / tol);
        EXPECT_LE(err, tol) << "angle " << a0 << " -> " << a1 << " want " << want;
    }
    std::printf("worst junction error: %.2f of the tolerance\n", worst);
}

TEST(Planner, SixteenShortMovesNeverAskForAnImpossibleDeceleration) {
    std::mt19937 rng(9);
    for (int round = 0; round < 200; ++round) {
        Fixture f(80, 200 + rng() % 2000, 6000, 0.01 * (1 + rng() % 10));
        double x = 0, y = 0;
        for (int i = 0; i < ll::kPlannerSize; ++i) {
            x += (static_cast<int>(rng() % 200) - 100) / 100.0; // up to 1 mm
            y += (static_cast<int>(rng() % 200) - 100) / 100.0;
            f.add_mm(x, y, 1000 + rng() % 5000);
        }
        uint32_t prev_entry = 0;
        std::vector<ll::PlanBlock> blocks;
        std::vector<ll::MoveLimits> lims;
        for (uint8_t i = 0; i < f.p.count(); ++i) {
            blocks.push_back(f.block(i));
            lims.push_back(f.limits(i));
        }
        for (size_t i = 0; i < blocks.size(); ++i) {
            const ll::PlanBlock& b = blocks[i];
            uint64_t exit2 = i + 1 < blocks.size() ? blocks[i + 1].v_entry2 : 0;
            uint64_t dv2 = static_cast<uint64_t>(lims[i].accel) * lims[i].len_q8 / 128000;
            EXPECT_NEAR(static_cast<double>(b.dv2), static_cast<double>(dv2), 1.0 + 1e-8 * dv2);
            // Can decelerate from entry to exit, and could accelerate from the previous entry.
            ASSERT_LE(b.v_entry2, exit2 + dv2) << "round " << round << " move " << i;
            ASSERT_LE(b.v_entry2, b.v_max_entry2);
            ASSERT_LE(b.v_entry2, ll::Planner::nominal2(b));
            if (i > 0) {
                uint64_t pdv2 =
                    static_cast<uint64_t>(lims[i - 1].accel) * lims[i - 1].len_q8 / 128000;
                ASSERT_LE(b.v_entry2, prev_entry + pdv2);
            }
            prev_entry = b.v_entry2;
        }
        EXPECT_EQ(blocks.front().v_entry2, 0u);
    }
}

TEST(Planner, EveryLineHandsOverItsExactLengthWhetherKeptOrMeasuredAgain) {
    // spec_of_first() takes a short line's length from where add() kept it (curve slot 1's RAM,
    // while no curve is queued) or measures it again: either way it must be move_limits()'s.
    // Random queues of short and long lines and semicircles (which borrow that RAM), consumed
    // as a running machine would, between the adds.
    std::mt19937 rng(21);
    size_t lines = 0;
    for (int round = 0; round < 40; ++round) {
        Fixture f;
        double x = 0, y = 0;
        for (int step = 0; step < 300; ++step) {
            const unsigned r = rng() % 10;
            if (r < 4 && !f.p.empty()) {
                ll::MoveSpec s{};
                f.p.spec_of_first(s);
                if (!s.curve) {
                    ll::MoveLimits lim;
                    ll::move_limits(f.m, s.delta, s.group, lim);
                    ASSERT_EQ(s.len_q8, lim.len_q8) << "round " << round << " step " << step;
                    ++lines;
                }
                f.p.discard_first();
            } else if (r < 6 && !f.p.full() && f.p.curve_slot_free()) {
                // A semicircle of radius 1 mm along +X (G2), centre 1 mm ahead.
                const double nx = x + 2;
                ll::CurveParams c{};
                c.kind = ll::kCurveArc;
                c.clockwise = 1;
                c.start_um[0] = static_cast<int32_t>(std::lround(x * 1000));
                c.start_um[1] = static_cast<int32_t>(std::lround(y * 1000));
                c.end_um[0] = static_cast<int32_t>(std::lround(nx * 1000));
                c.end_um[1] = c.start_um[1];
                c.a_um[0] = c.start_um[0] + 1000;
                c.a_um[1] = c.start_um[1];
                c.b_um[0] = c.b_um[1] = 1000;
                int32_t t[ll::kAxes] = {static_cast<int32_t>(std::lround(nx * 80)),
                                        static_cast<int32_t>(std::lround(y * 80)), 0, 0};
                int32_t um[ll::kAxes] = {c.end_um[0], c.end_um[1], 0, 0};
                if (f.p.shape_curve(um, c)) {
                    f.p.add(t, um, 3000000, &c);
                    x = nx;
                }
            } else if (!f.p.full()) {
                // Mostly 0.1 mm chords (kept), sometimes a 2 mm line (measured again).
                const double len = rng() % 4 ? 0.1 : 2.0;
                const double th = (rng() % 628) / 100.0;
                x += len * std::cos(th);
                y += len * std::sin(th);
                f.add_mm(x, y, 3000);
            }
        }
    }
    EXPECT_GT(lines, 3000u);
}

TEST(Planner, EachAxisKeepsItsOwnRateAndAcceleration) {
    Fixture f(80, 1000, 6000, 0.01);
    f.s.axis[1].max_rate = 1000 * 1000; // Y: 1000 mm/min
    f.s.axis[1].accel = 100 * 1000;     // Y: 100 mm/s^2
    ll::machine_build(f.m, f.s);
    f.add_mm(30, 40, 6000); // u = (0.6, 0.8)
    const ll::PlanBlock& b = f.block(0);
    // Y limits the path: 1000 / 0.8 = 1250 mm/min, 100 / 0.8 = 125 mm/s^2.
    EXPECT_NEAR(b.feed / 1000.0, 1250.0, 0.01);
    EXPECT_NEAR(f.limits(0).accel / 3600.0, 125.0, 0.01);
}

TEST(Planner, ForwardPassStopsOnlyWhereNothingWouldChange) {
    // The forward pass stops at the first move of the trailing deceleration chain that keeps its
    // entry. Every entry must be the one of the full passes (the planner before that stop),
    // replayed here on a copy of the queue: random feeds, corners and reversals (entries at
    // their maximum), chains of short moves, moves begun and discarded in between.
    struct Ref {
        uint32_t dv2, vmax, entry;
    };
    std::mt19937 rng(34);
    size_t checked = 0;
    for (int round = 0; round < 80; ++round) {
        Fixture f;
        double x = 0, y = 0, th = 0;
        for (int step = 0; step < 400; ++step) {
            const unsigned r = rng() % 10;
            if (r < 3 && !f.p.empty()) {
                if (!f.p.first_begun()) {
                    f.p.begin_first();
                } else {
                    f.p.discard_first();
                }
                continue;
            }
            if (f.p.full()) continue;
            std::vector<Ref> q;
            for (uint8_t i = 0; i < f.p.count(); ++i) {
                const ll::PlanBlock& b = f.block(i);
                q.push_back({b.dv2, b.v_max_entry2, b.v_entry2});
            }
            const bool begun = f.p.first_begun();
            th +=
                (rng() % 5 == 0) ? (rng() % 628) / 100.0 : (static_cast<int>(rng() % 7) - 3) * 0.01;
            const double len = rng() % 3 ? 0.1 : 1.5;
            x += len * std::cos(th);
            y += len * std::sin(th);
            const uint8_t before = f.p.count();
            f.add_mm(x, y, 500 + rng() % 5000);
            if (f.p.count() == before) continue;
            const ll::PlanBlock& nb = f.block(before);
            q.push_back({nb.dv2, nb.v_max_entry2, 0});
            // The full passes (backward, stopping where an entry at its maximum was already
            // there while the oldest move is begun; then forward from there).
            const size_t n = q.size();
            size_t from = 0;
            uint32_t next = 0;
            for (size_t pos = n; pos-- > (begun ? 1u : 0u);) {
                uint32_t v = next + q[pos].dv2 < next ? 0xFFFFFFFFu : next + q[pos].dv2;
                if (v >= q[pos].vmax) {
                    v = q[pos].vmax;
                    if (begun && q[pos].entry == v) {
                        from = pos;
                        break;
                    }
                }
                q[pos].entry = next = v;
            }
            for (size_t i = from; i + 1 < n; ++i) {
                const uint32_t reach =
                    q[i].entry + q[i].dv2 < q[i].entry ? 0xFFFFFFFFu : q[i].entry + q[i].dv2;
                if (q[i + 1].entry > reach) q[i + 1].entry = reach;
            }
            for (uint8_t i = 0; i < n; ++i) {
                ASSERT_EQ(f.block(i).v_entry2, q[i].entry)
                    << "round " << round << " step " << step << " move " << int(i);
            }
            ++checked;
        }
    }
    EXPECT_GT(checked, 5000u);
}
