// fixmath.h on the ATmega328P (fixmath_check.elf in simavr) gives exactly the host's results.
#include <gtest/gtest.h>

#include <fstream>

#include "fixmath_check.h"
#include "harness.h"

namespace {

// The same as firmware/fixmath_check.cpp's (which computes it on the chip).
// The edges that the random workload of fixmath_check.h rarely reaches, hashed: every root
// s >= 2^15 at s^2 and at (s + 1)^2 - 1 (where isqrt32's Newton step on the chip overshoots
// most) through isqrt32 and Num::sqrt, and Num::div by divisors at both ends of every top byte
// (the byte-wise division's estimates fall furthest short there), of dividends just below and
// above them and at the ends of the range.
inline uint32_t fixmath_edges() {
    ll::check::Hash h;
    for (uint32_t s = 0x8000; s <= 0xFFFF; ++s) {
        uint32_t lo = s * s, hi = s == 0xFFFF ? 0xFFFFFFFFul : (s + 1) * (s + 1) - 1;
        h.add(ll::isqrt32(lo));
        h.add(ll::isqrt32(hi));
        h.add(ll::Num(hi).sqrt());
    }
    const uint32_t lows[3] = {0, 0x7FFFFFul, 0xFFFFFFul};
    for (uint32_t top = 0x80; top <= 0xFF; ++top) {
        for (uint8_t k = 0; k < 3; ++k) {
            uint32_t d = top << 24 | lows[k];
            const uint32_t as[4] = {d - 1, d == 0xFFFFFFFFul ? d : d + 1, 0x80000000ul,
                                    0xFFFFFFFFul};
            for (uint8_t j = 0; j < 4; ++j) {
                h.add(ll::Num(as[j]).div(ll::Num(d)));
                h.add(ll::Num(as[j]).div(d));
            }
        }
    }
    // Products and quotients at the ends of the exponent range: saturated, zero, just inside.
    const int8_t es[7] = {-128, -97, -64, 0, 64, 95, 127};
    for (uint8_t i = 0; i < 7; ++i) {
        for (uint8_t j = 0; j < 7; ++j) {
            ll::Num x(0xC0000001ul, es[i]), y(0x80000003ul, es[j]);
            h.add(ll::Num(x).mul(y));
            h.add(ll::Num(y).mul(x));
            h.add(ll::Num(x).div(y));
            h.add(ll::Num(y).div(x));
        }
    }
    return h.h;
}

} // namespace

#ifndef LL_FIXMATH_CHECK_ELF
#define LL_FIXMATH_CHECK_ELF "build/avr/firmware/fixmath_check.elf"
#endif

TEST(FixMathAvr, AssemblyGivesThePortableResults) {
    const std::string elf = LL_FIXMATH_CHECK_ELF;
    ASSERT_TRUE(std::ifstream(elf).good())
        << "missing " << elf << ": build the firmware first (cmake --build --preset avr)";
    ll::sim::Sim sim(elf);
    const uint16_t done = static_cast<uint16_t>(sim.symbol("g_fixmath_done") & 0xFFFF);
    const uint16_t hash = static_cast<uint16_t>(sim.symbol("g_fixmath_hash") & 0xFFFF);
    ASSERT_TRUE(sim.run_until([&] { return sim.peek(done) != 0; }, 16000000ull * 60));
    uint32_t got = 0;
    for (int i = 3; i >= 0; --i) got = got << 8 | sim.peek(static_cast<uint16_t>(hash + i));
    EXPECT_EQ(got, ll::check::fixmath_hash(LL_FIXMATH_CHECK_ROUNDS));
    const uint16_t edges = static_cast<uint16_t>(sim.symbol("g_fixmath_edges") & 0xFFFF);
    uint32_t got_edges = 0;
    for (int i = 3; i >= 0; --i)
        got_edges = got_edges << 8 | sim.peek(static_cast<uint16_t>(edges + i));
    EXPECT_EQ(got_edges, fixmath_edges());
    std::printf("%d rounds in %.1f M cycles\n", LL_FIXMATH_CHECK_ROUNDS, sim.cycle() / 1e6);
}
