#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "lowlevel/fixmath.h"

TEST(FixMath, IntegerSquareRootsAreFloors) {
    std::mt19937_64 rng(1);
    for (int i = 0; i < 100000; ++i) {
        uint32_t v = static_cast<uint32_t>(rng());
        uint32_t r = ll::isqrt32(v);
        EXPECT_LE(static_cast<uint64_t>(r) * r, v);
        EXPECT_GT(static_cast<uint64_t>(r + 1) * (r + 1), v);
        uint64_t w = rng() >> (rng() % 64);
        uint64_t q = ll::isqrt64(w);
        EXPECT_LE(q * q, w);
        EXPECT_GT(static_cast<unsigned __int128>(q + 1) * (q + 1), w);
    }
    EXPECT_EQ(ll::isqrt32(0xFFFFFFFFu), 65535u);
    EXPECT_EQ(ll::isqrt64(~0ull), 0xFFFFFFFFu);
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

TEST(FixMath, RatiosKeepThirtyOneSignificantBitsOverManyDecades) {
    std::mt19937_64 rng(3);
    for (int i = 0; i < 100000; ++i) {
        uint64_t num = 1 + (rng() >> (rng() % 63));
        uint64_t den = 1 + (rng() >> (rng() % 63));
        ll::Ratio r = ll::make_ratio(num, den);
        EXPECT_GE(r.mant, 1u << 31);
        long double value = std::ldexp(static_cast<long double>(r.mant), -r.shift);
        long double want = static_cast<long double>(num) / den;
        if (std::fabs(static_cast<double>(r.shift)) >= 120) continue; // clamped extremes
        EXPECT_NEAR(static_cast<double>(value / want), 1.0, 2e-9) << num << "/" << den;
    }
}

TEST(FixMath, RatioApplicationSaturatesInsteadOfWrapping) {
    ll::Ratio big = ll::make_ratio(1ull << 60, 3);
    EXPECT_EQ(big.apply(1000000), 0xFFFFFFFFu);
    ll::Ratio third = ll::make_ratio(1, 3);
    EXPECT_EQ(third.apply(3000000), 999999u); // floor of 999999.9999...
}
