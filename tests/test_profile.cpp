// Speed as a function of distance (seed §4, §8): closed-form shape, and the speed implied by
// the step times of real moves against sqrt(V0^2 +- 2 a l).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "lowlevel/profile.h"
#include "motion_util.h"

namespace {

constexpr double kF = 16e6;

// Expected speed (ticks/s) at reference position l of a 1-axis line of d ticks.
double expected_speed(double l, double d, double v0, double vc, double v1, double a) {
    double start = v0 <= vc ? std::min(std::sqrt(v0 * v0 + 2 * a * l), vc)
                            : std::max(std::sqrt(std::max(0.0, v0 * v0 - 2 * a * l)), vc);
    double end = std::sqrt(v1 * v1 + 2 * a * (d - l));
    return std::min(start, end);
}

struct SpeedCheck {
    double worst_ratio = 0; // max |error| / tolerance over all steps
    double worst_error = 0; // max |relative error| over all steps
    double first_step_error = 0;
    size_t steps = 0;
};

// The stated tolerance (docs/motion.md, "Speed accuracy"): with A = s (l_d + l) the scaled
// squared speed at the step,
//   |v_measured / v - 1| <= 1/sqrt(A) + s L / (4 A) + 1/Delta + 2^-12
// 1/sqrt(A): R = floor(sqrt(A)) underestimates; s L / (4 A): the speed is evaluated once per
// macro segment of L <= 16 ticks, at its midpoint; 1/Delta: whole cycles; 2^-12: the
// fixed-point factors (K, D, A rounding).
SpeedCheck check_line(const lltest::Machine& mach, int32_t ticks, double feed, double accel,
                      double entry, double exit) {
    ll::StepGen gen{};
    gen.configure(&mach.lengths, 64);
    ll::MoveSpec spec = mach.move({ticks}, feed, accel, entry, exit);
    auto ev = lltest::run_move(gen, spec);
    const double T = mach.steps_per_mm[0];
    const double a = accel * T, v0 = entry / 60 * T, vc = feed / 60 * T, v1 = exit / 60 * T;
    const double s = std::ldexp(1.0, gen.profile().log_s);
    SpeedCheck c;
    uint64_t prev = 0;
    for (size_t k = 0; k < ev.size(); ++k) {
        double dt = static_cast<double>(ev[k].t - prev) / kF;
        prev = ev[k].t;
        double v = 1.0 / dt;
        double l = k + 0.5;
        double want = expected_speed(l, ticks, v0, vc, v1, a);
        double A = s * want * want / (2 * a);
        double tol = 1 / std::sqrt(A) + s * 16 / (4 * A) + 1 / (dt * kF) + 1.0 / 4096;
        double err = v / want - 1;
        c.worst_ratio = std::max(c.worst_ratio, std::fabs(err) / tol);
        c.worst_error = std::max(c.worst_error, std::fabs(err));
        if (k == 0) c.first_step_error = err;
    }
    c.steps = ev.size();
    EXPECT_EQ(static_cast<int32_t>(ev.size()), ticks);
    return c;
}

const lltest::Machine kMachine{80, 80, 80, 80};

// docs/motion.md ("Speed accuracy") quotes these lines.
void report(const char* what, const SpeedCheck& c) {
    std::printf("%s: %zu steps, worst error %.2f%% (%.2f of tolerance), first step %+.2f%%\n", what,
                c.steps, 100 * c.worst_error, c.worst_ratio, 100 * c.first_step_error);
}

} // namespace

TEST(ProfileShape, PeakAndDecelerationPointComeFromTheClosedForm) {
    ll::Profile p{};
    p.log_s = 1; // s = 2
    p.d = 1000;
    p.a_entry = 100;
    p.a_cruise = 1000000; // unreachable
    p.a_exit = 300;
    // x_decel = (A_exit - A_entry + s d) / (2 s) = 550 ticks = 1100 half ticks
    uint32_t x2 = ll::profile_x2_decel(p);
    EXPECT_EQ(x2, 1100u);
    // The switch from accelerating to decelerating happens exactly there, at the closed-form
    // peak v_p^2 = (v0^2 + v1^2)/2 + a L  <=>  A_p = (A_entry + A_exit + s d) / 2.
    EXPECT_EQ(ll::profile_a(p, x2), (100u + 300u + 2000u) / 2);
    EXPECT_LT(ll::profile_a(p, x2 - 1), ll::profile_a(p, x2));
    EXPECT_LT(ll::profile_a(p, x2 + 1), ll::profile_a(p, x2));

    p.a_cruise = 1000; // reachable: accelerate 450 ticks, cruise, decelerate 350 ticks
    x2 = ll::profile_x2_decel(p);
    EXPECT_EQ(x2, 2 * (1000u - 350u));
    EXPECT_EQ(ll::profile_a(p, 900), 1000u); // cruise reached after 450 ticks
    EXPECT_LT(ll::profile_a(p, 898), 1000u);
    EXPECT_EQ(ll::profile_a(p, x2), 1000u);
    EXPECT_LT(ll::profile_a(p, x2 + 2), 1000u);
}

TEST(ProfileShape, EntryAboveCruiseDeceleratesAtTheStartOnly) {
    ll::Profile p{};
    p.log_s = 1;
    p.d = 1000;
    p.a_entry = 1500;
    p.a_cruise = 1000;
    p.a_exit = 0;
    EXPECT_EQ(ll::profile_a(p, 0), 1500u);
    EXPECT_GT(ll::profile_a(p, 498), 1000u);
    EXPECT_EQ(ll::profile_a(p, 500), 1000u); // 250 ticks to shed 500 units of A at s = 2
    EXPECT_EQ(ll::profile_x2_decel(p), 1000u);
    EXPECT_EQ(ll::profile_a(p, 2000), 0u);
}

TEST(SqrtTracker, FollowsTheIntegerSquareRootBothWays) {
    ll::SqrtTracker t;
    t.reset(0);
    for (uint32_t a = 0; a < 200000; a += 37) {
        t.seek(a);
        ASSERT_EQ(t.r, ll::isqrt32(a));
        ASSERT_EQ(t.c, static_cast<uint32_t>(t.r) * t.r);
    }
    for (uint32_t a = 200000; a > 1000; a -= 53) {
        t.seek(a);
        ASSERT_EQ(t.r, ll::isqrt32(a));
    }
    t.seek(3000000000u); // a jump: one full square root
    EXPECT_EQ(t.r, ll::isqrt32(3000000000u));
}

TEST(SpeedProfile, AccelerationFromRestFollowsSqrtTwoAL) {
    SpeedCheck c = check_line(kMachine, 2000, 3000, 1000, 0, 0);
    EXPECT_LE(c.worst_ratio, 1.0);
    std::printf(
        "from rest: %zu steps, worst error %.2f%% (%.2f of tolerance), first step %+.2f%%\n",
        c.steps, 100 * c.worst_error, c.worst_ratio, 100 * c.first_step_error);
}

TEST(SpeedProfile, AccelerationFromANonZeroSpeed) {
    SpeedCheck c = check_line(kMachine, 3000, 6000, 500, 1200, 0);
    EXPECT_LE(c.worst_ratio, 1.0);
    report("from F1200", c);
}

TEST(SpeedProfile, DecelerationToANonZeroExitSpeed) {
    SpeedCheck c = check_line(kMachine, 3000, 6000, 500, 0, 1800);
    EXPECT_LE(c.worst_ratio, 1.0);
    report("to F1800", c);
}

TEST(SpeedProfile, EntryFasterThanCruiseDeceleratesAtTheStart) {
    SpeedCheck c = check_line(kMachine, 3000, 1200, 500, 3000, 600);
    EXPECT_LE(c.worst_ratio, 1.0);
    report("entry F3000 above cruise F1200", c);
}

TEST(SpeedProfile, TriangleWhenCruiseIsOutOfReach) {
    // 120 ticks at 80 steps/mm, 1000 mm/s^2: 100 ticks to reach F3000 and 100 to stop do not
    // fit, so the peak is v_p^2 = a L: 3098 ticks/s.
    SpeedCheck c = check_line(kMachine, 120, 3000, 1000, 0, 0);
    EXPECT_LE(c.worst_ratio, 1.0);
    report("triangle", c);
    ll::StepGen gen{};
    gen.configure(&kMachine.lengths, 64);
    auto ev = lltest::run_move(gen, kMachine.move({120}, 3000, 1000));
    double fastest = 0;
    for (size_t k = 1; k < ev.size(); ++k) {
        fastest = std::max(fastest, kF / static_cast<double>(ev[k].t - ev[k - 1].t));
    }
    EXPECT_NEAR(fastest, std::sqrt(80000.0 * 120), 0.02 * std::sqrt(80000.0 * 120));
    std::printf("triangle: fastest step %.1f steps/s, closed-form peak %.1f\n", fastest,
                std::sqrt(80000.0 * 120));
    const ll::Profile& pr = gen.profile();
    EXPECT_LT(ll::profile_a(pr, ll::profile_x2_decel(pr)), pr.a_cruise); // never cruises
}

TEST(SpeedProfile, ToleranceHoldsAcrossResolutionsAndAccelerations) {
    const double spm[] = {5, 40, 80, 250, 800, 3200};
    const double acc[] = {10, 100, 1000, 5000};
    double worst_ratio = 0, worst_error = 0, worst_t = 0, worst_a = 0;
    size_t steps = 0;
    for (double t : spm) {
        lltest::Machine m{t};
        for (double a : acc) {
            // Long enough to reach F1500 from rest, limited to 200k ticks.
            double vc = 1500 / 60.0;
            int32_t ticks = static_cast<int32_t>(std::min(200000.0, t * (vc * vc / a + 20)));
            SpeedCheck c = check_line(m, ticks, 1500, a, 0, 0);
            EXPECT_LE(c.worst_ratio, 1.0) << "T=" << t << " a=" << a;
            worst_ratio = std::max(worst_ratio, c.worst_ratio);
            if (c.worst_error > worst_error) {
                worst_error = c.worst_error;
                worst_t = t;
                worst_a = a;
            }
            steps += c.steps;
        }
    }
    std::printf("24 machines (5..3200 steps/mm, 10..5000 mm/s^2): %zu steps, worst error %.2f%% "
                "(%g steps/mm, %g mm/s^2), worst %.2f of tolerance\n",
                steps, 100 * worst_error, worst_t, worst_a, worst_ratio);
}
