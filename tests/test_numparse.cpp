#include <gtest/gtest.h>

#include <random>
#include <string>

#include "lowlevel/numparse.h"

using ll::num::Decimal;

namespace {

// Parses `text` whole; fails the test if anything is left over.
Decimal parse_all(const std::string& text) {
    Decimal d{};
    uint8_t pos = 0;
    EXPECT_TRUE(ll::num::parse(text.c_str(), pos, d)) << text;
    EXPECT_EQ(pos, text.size()) << text;
    return d;
}

int32_t milli(const std::string& text) {
    int32_t v = 0;
    EXPECT_TRUE(ll::num::to_milli(parse_all(text), v)) << text;
    return v;
}

int32_t inch(const std::string& text) {
    int32_t v = 0;
    EXPECT_TRUE(ll::num::inch_to_milli(parse_all(text), v)) << text;
    return v;
}

} // namespace

TEST(NumParse, ReadsSignDigitsAndDecimals) {
    EXPECT_EQ(milli("12"), 12000);
    EXPECT_EQ(milli("-12.5"), -12500);
    EXPECT_EQ(milli("+0.125"), 125);
    EXPECT_EQ(milli(".5"), 500);
    EXPECT_EQ(milli("7."), 7000);
    EXPECT_EQ(milli("-.001"), -1);
    EXPECT_EQ(milli("0012.340"), 12340);
}

TEST(NumParse, RejectsAValueWithoutDigits) {
    for (const char* bad : {"", "-", "+", ".", "-.", "X"}) {
        Decimal d;
        uint8_t pos = 0;
        EXPECT_FALSE(ll::num::parse(bad, pos, d)) << bad;
        EXPECT_EQ(pos, 0) << bad;
    }
}

TEST(NumParse, StopsAtTheNextWordAndAdvances) {
    const char* line = "12.5Y-3.2.1";
    uint8_t pos = 0;
    Decimal d;
    ASSERT_TRUE(ll::num::parse(line, pos, d));
    EXPECT_EQ(pos, 4);
    pos = 5;
    ASSERT_TRUE(ll::num::parse(line, pos, d));
    EXPECT_EQ(pos, 9); // a second '.' is not part of the number
    EXPECT_TRUE(d.negative());
}

TEST(NumParse, RoundsHalfAwayFromZeroBeyondTheThirdDecimal) {
    EXPECT_EQ(milli("1.2345"), 1235);
    EXPECT_EQ(milli("-1.2345"), -1235);
    EXPECT_EQ(milli("1.23449999"), 1234);
    EXPECT_EQ(milli("-1.23449999"), -1234);
    EXPECT_EQ(milli("0.0005"), 1);
    EXPECT_EQ(milli("-0.0005"), -1);
    EXPECT_EQ(milli("0.0004"), 0);
    EXPECT_EQ(milli("0.9995"), 1000);
}

TEST(NumParse, MinusZeroIsNotNegative) {
    EXPECT_FALSE(parse_all("-0").negative());
    EXPECT_FALSE(parse_all("-0.000").negative());
    EXPECT_TRUE(parse_all("-0.0000001").negative());
}

TEST(NumParse, OverflowIsAnErrorNeverAWrap) {
    int32_t v;
    EXPECT_TRUE(ll::num::to_milli(parse_all("2147483.647"), v));
    EXPECT_EQ(v, 2147483647);
    EXPECT_TRUE(ll::num::to_milli(parse_all("-2147483.647"), v));
    EXPECT_EQ(v, -2147483647);
    EXPECT_FALSE(ll::num::to_milli(parse_all("2147483.648"), v));
    EXPECT_FALSE(ll::num::to_milli(parse_all("2147483.6475"), v));
    EXPECT_FALSE(ll::num::to_milli(parse_all("99999999"), v));
    Decimal d;
    uint8_t pos = 0;
    EXPECT_FALSE(ll::num::parse("1234567890", pos, d)); // 10 integer digits
    pos = 0;
    EXPECT_TRUE(ll::num::parse("0000000000123", pos, d)); // leading zeros are not digits of value
}

TEST(NumParse, InchesConvertExactlyToMicrometres) {
    EXPECT_EQ(inch("1"), 25400);
    EXPECT_EQ(inch("-2.5"), -63500);
    EXPECT_EQ(inch("0.0001"), 3);      // 2.54 um
    EXPECT_EQ(inch("-0.0001"), -3);    // half away from zero on the magnitude
    EXPECT_EQ(inch("0.00005"), 1);     // 1.27 um
    EXPECT_EQ(inch("0.00002"), 1);     // 0.508 um
    EXPECT_EQ(inch("0.00001"), 0);     // 0.254 um
    EXPECT_EQ(inch("1.23456"), 31358); // 31357.824 um
    EXPECT_EQ(inch("84546"), 2147468400);
    int32_t v;
    EXPECT_FALSE(ll::num::inch_to_milli(parse_all("84547"), v));
}

TEST(NumParse, IntegersRequireNoFraction) {
    uint32_t v;
    EXPECT_TRUE(ll::num::to_uint(parse_all("5"), 255, v));
    EXPECT_EQ(v, 5u);
    EXPECT_TRUE(ll::num::to_uint(parse_all("5.000"), 255, v));
    EXPECT_FALSE(ll::num::to_uint(parse_all("5.5"), 255, v));
    EXPECT_FALSE(ll::num::to_uint(parse_all("5.0000001"), 255, v));
    EXPECT_FALSE(ll::num::to_uint(parse_all("-1"), 255, v));
    EXPECT_FALSE(ll::num::to_uint(parse_all("256"), 255, v));
}

TEST(MulDivRound, RoundsHalfAwayFromZeroInBothSigns) {
    int32_t v;
    EXPECT_TRUE(ll::num::mul_div_round(1, 1, 2, v));
    EXPECT_EQ(v, 1);
    EXPECT_TRUE(ll::num::mul_div_round(-1, 1, 2, v));
    EXPECT_EQ(v, -1);
    EXPECT_TRUE(ll::num::mul_div_round(3, 1, 2, v));
    EXPECT_EQ(v, 2);
    EXPECT_TRUE(ll::num::mul_div_round(-3, 1, 2, v));
    EXPECT_EQ(v, -2);
    EXPECT_TRUE(ll::num::mul_div_round(499, 1, 1000, v));
    EXPECT_EQ(v, 0);
    EXPECT_TRUE(ll::num::mul_div_round(-500, 1, 1000, v));
    EXPECT_EQ(v, -1);
}

TEST(MulDivRound, MatchesA64BitReferenceEverywhere) {
    std::mt19937 rng(1234);
    for (int i = 0; i < 200000; ++i) {
        int32_t a = static_cast<int32_t>(rng());
        uint32_t b = rng() >> (rng() % 32);
        uint32_t c = (rng() >> (1 + rng() % 31)) | 1u;
        __int128 p = static_cast<__int128>(a < 0 ? -static_cast<int64_t>(a) : a) * b;
        __int128 q = (p + c / 2) / c;
        if (a < 0) q = -q;
        int32_t v;
        bool ok = ll::num::mul_div_round(a, b, c, v);
        bool fits = q >= INT32_MIN + 1 && q <= INT32_MAX;
        if (q == INT32_MIN) continue; // representable, but the magnitude check refuses it
        ASSERT_EQ(ok, fits) << a << " " << b << " " << c;
        if (ok) {
            ASSERT_EQ(v, static_cast<int32_t>(q)) << a << " " << b << " " << c;
        }
    }
}

TEST(MulDivRound, SaturatesOnOverflow) {
    int32_t v;
    EXPECT_FALSE(ll::num::mul_div_round(2147483647, 2, 1, v));
    EXPECT_EQ(v, INT32_MAX);
    EXPECT_FALSE(ll::num::mul_div_round(-2147483647, 1000000, 1000, v));
    EXPECT_EQ(v, INT32_MIN);
}
