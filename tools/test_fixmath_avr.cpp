// fixmath.h on the ATmega328P (fixmath_check.elf in simavr) gives exactly the host's results.
#include <gtest/gtest.h>

#include <fstream>

#include "fixmath_check.h"
#include "harness.h"

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
    EXPECT_EQ(got_edges, ll::check::fixmath_edges());
    const uint16_t parse = static_cast<uint16_t>(sim.symbol("g_parse_hash") & 0xFFFF);
    uint32_t got_parse = 0;
    for (int i = 3; i >= 0; --i)
        got_parse = got_parse << 8 | sim.peek(static_cast<uint16_t>(parse + i));
    EXPECT_EQ(got_parse, ll::check::parse_hash(LL_FIXMATH_CHECK_ROUNDS));
    std::printf("%d rounds in %.1f M cycles\n", LL_FIXMATH_CHECK_ROUNDS, sim.cycle() / 1e6);
}
