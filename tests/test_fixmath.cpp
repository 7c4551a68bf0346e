#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "lowlevel/fixmath.h"

namespace {

long double value(const ll::Num& s) {
    return std::ldexp(static_cast<long double>(s.m), s.e);
}

ll::Num random_num(std::mt19937_64& rng) {
    uint32_t m = static_cast<uint32_t>(rng()) | 1u;
    int8_t e = static_cast<int8_t>(static_cast<int>(rng() % 60) - 30); // results stay in range
    return ll::Num(m >> (rng() % 31), e);
}

} // namespace

TEST(FixMath, IntegerSquareRootsAreFloors) {
    std::mt19937_64 rng(1);
    for (int i = 0; i < 100000; ++i) {
        uint32_t v = static_cast<uint32_t>(rng());
        uint32_t r = ll::isqrt32(v);
        EXPECT_LE(static_cast<uint64_t>(r) * r, v);
        EXPECT_GT(static_cast<uint64_t>(r + 1) * (r + 1), v);
    }
    EXPECT_EQ(ll::isqrt32(0xFFFFFFFFu), 65535u);
    EXPECT_EQ(ll::isqrt32(0), 0u);
}

TEST(FixMath, DivFracIsTheExactScaledQuotient) {
    std::mt19937 rng(2);
    for (int i = 0; i < 100000; ++i) {
        uint32_t den = 1 + (rng() % (1u << 24));
        uint32_t num = rng() % (den + 1);
        uint8_t bits = static_cast<uint8_t>(rng() % 8 + 20);
        uint64_t want = (static_cast<uint64_t>(num) << bits) / den;
        if (want >> 32) continue;
        EXPECT_EQ(ll::div_frac(num, den, bits), want);
    }
}

TEST(FixMath, MulShrIsExactAndSaturates) {
    EXPECT_EQ(ll::mul_shr(0xFFFFFFFFu, 0xFFFFFFFFu, 32), 0xFFFFFFFEu);
    EXPECT_EQ(ll::mul_shr(3000000000u, 3u, 0), 0xFFFFFFFFu);
    EXPECT_EQ(ll::mul_shr(123456789u, 1u << 20, 20), 123456789u);
    EXPECT_EQ(ll::shl_sat(3, 31), 0xFFFFFFFFu);
    EXPECT_EQ(ll::shl_sat(1, 31), 0x80000000u);
    EXPECT_EQ(ll::add_sat(0xFFFFFFF0u, 0x20u), 0xFFFFFFFFu);
}

TEST(FixMath, NumArithmeticKeepsThirtyOneBitsOverManyDecades) {
    std::mt19937_64 rng(3);
    const long double tol = std::ldexp(1.0L, -30);
    for (int i = 0; i < 200000; ++i) {
        ll::Num a = random_num(rng), b = random_num(rng);
        if (a.m == 0 || b.m == 0) continue;
        long double va = value(a), vb = value(b);
        ll::Num p = a, q = a, r = a, s = a;
        p.mul(b);
        q.div(b);
        r.sqrt();
        s.add(b);
        EXPECT_NEAR(static_cast<double>(value(p) / (va * vb)), 1.0, tol);
        EXPECT_NEAR(static_cast<double>(value(q) / (va / vb)), 1.0, tol);
        EXPECT_NEAR(static_cast<double>(value(r) / std::sqrt(va)), 1.0, tol);
        EXPECT_NEAR(static_cast<double>(value(s) / (va + vb)), 1.0, tol);
        EXPECT_EQ(a.cmp(b), va < vb ? -1 : (va > vb ? 1 : 0));
        // Products and quotients are truncated, never rounded up.
        EXPECT_LE(value(p), va * vb);
        EXPECT_LE(value(q), va / vb);
        EXPECT_GE(p.m, 0x80000000u);
        EXPECT_GE(q.m, 0x80000000u);
    }
}

TEST(FixMath, NumConversionFloorsAndSaturates) {
    EXPECT_EQ(ll::Num(1000000).u32(), 1000000u);
    EXPECT_EQ(ll::Num(7, -1).u32(), 3u); // 3.5 -> 3
    EXPECT_EQ(ll::Num(1, 40).u32(), 0xFFFFFFFFu);
    EXPECT_EQ(ll::Num(1, -40).u32(), 0u);
    EXPECT_EQ(ll::Num(1).div(3).of(3000000), 999999u);                  // floor of 999999.99...
    EXPECT_EQ(ll::Num(1, 100).mul(ll::Num(1, 100)).u32(), 0xFFFFFFFFu); // saturates
    EXPECT_EQ(ll::Num(1, -100).mul(ll::Num(1, -100)).u32(), 0u);        // underflows to zero
}

TEST(FixMath, Atan2IsExactTo2ToTheMinus24) {
    std::mt19937 rng(4);
    double worst = 0;
    for (int i = 0; i < 100000; ++i) {
        int32_t x = static_cast<int32_t>(rng()) >> (rng() % 31);
        int32_t y = static_cast<int32_t>(rng()) >> (rng() % 31);
        if (x == 0 && y == 0) continue;
        double want = std::atan2(static_cast<double>(y), static_cast<double>(x));
        double got = ll::atan2_q29(y, x) / std::ldexp(1.0, 29);
        double err = std::fabs(got - want);
        if (err > 3.0) err = std::fabs(err - 2 * M_PI); // +pi and -pi are the same angle
        worst = std::max(worst, err);
    }
    EXPECT_LT(worst, std::ldexp(1.0, -24));
    EXPECT_NEAR(ll::atan2_q29(0, 5), 0, 4);
    EXPECT_NEAR(ll::atan2_q29(5, 0), ll::kPiQ29 / 2, 4);
    EXPECT_NEAR(ll::atan2_q29(0, -5), ll::kPiQ29, 4);
}

TEST(FixMath, SmallAngleSeriesGiveCosSinAndTheArcControlArm) {
    for (double h = -0.4; h <= 0.4; h += 0.001) {
        int32_t c, s, k;
        ll::small_angle_q30(static_cast<int32_t>(std::lround(h * std::ldexp(1.0, 30))), c, s, k);
        EXPECT_NEAR(c / std::ldexp(1.0, 30), std::cos(h), 4e-9) << h;
        EXPECT_NEAR(s / std::ldexp(1.0, 30), std::sin(h), 4e-9) << h;
        EXPECT_NEAR(k / std::ldexp(1.0, 30), 4.0 / 3 * std::tan(h / 4), 4e-9) << h;
    }
}

// sum_squares is the truncated exact sum on both sides of the chip's short path (at most 4
// values, all below 2^15: squares summed in 32 bits) and of its general one (num64 of a 64-bit
// sum): the bounds where the chip changes path.
TEST(FixMath, SumSquaresIsTheTruncatedExactSumAcrossTheShortPathBounds) {
    auto exact = [](const uint32_t* v, uint8_t n, uint8_t mask) {
        unsigned __int128 s = 0;
        bool drop = false;
        for (uint8_t i = 0; i < n; ++i) drop = drop || v[i] >= 0x40000000u;
        for (uint8_t i = 0; i < n && i < 8; ++i) {
            if (!(mask >> i & 1)) continue;
            unsigned __int128 x = drop ? v[i] >> 2 : v[i];
            s += x * x;
        }
        return std::ldexp(static_cast<long double>(s), drop ? 4 : 0);
    };
    const uint32_t edges[] = {0, 1, 0x7FFF, 0x8000, 0xFFFF, 0x10000, 0x3FFFFFFF, 0x40000000};
    std::mt19937 rng(5);
    for (int i = 0; i < 20000; ++i) {
        uint32_t v[6];
        for (uint32_t& x : v) x = edges[rng() % 8];
        uint8_t n = static_cast<uint8_t>(rng() % 7), mask = static_cast<uint8_t>(rng());
        ll::Num got = ll::sum_squares(v, n, mask);
        long double want = exact(v, n, mask);
        // Truncated to 32 significant bits: within one unit of the last place, never above.
        EXPECT_LE(value(got), want);
        EXPECT_GT(value(got), want * (1 - std::ldexp(1.0L, -31)) - 1e-30L);
    }
    const uint32_t four[4] = {0x7FFF, 0x7FFF, 0x7FFF, 0x7FFF}; // the short path's largest sum
    EXPECT_EQ(value(ll::sum_squares(four, 4)), 4.0L * 0x7FFF * 0x7FFF);
    const uint32_t over[2] = {0x8000, 0x7FFF}; // one value at 2^15: the general path
    EXPECT_EQ(value(ll::sum_squares(over, 2)), 1073741824.0L + 0x7FFFL * 0x7FFF);
}
