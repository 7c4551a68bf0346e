// The curve module (src/curve.cpp) on the real chip: firmware/curve_check.elf runs the workload
// of tests/curve_workload.h in simavr, and its hash must equal the host's (the host tests only
// check the host build, where `long` has 64 bits); then the cycle figures of docs/curves.md.
#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <memory>

#include <gtest/gtest.h>

#include "curve_workload.h"
#include "fw_check.h"

using namespace ll::sim;

namespace {

constexpr uint16_t kGpior0 = 0x3E;

std::string curve_elf() {
    std::string elf = fw::firmware_elf(); // .../firmware/lowlevel.elf
    return elf.substr(0, elf.rfind('/') + 1) + "curve_check.elf";
}

// Word `index` of the 32-bit array (or variable) `symbol` in the chip's RAM.
uint32_t read_u32(const Sim& sim, const char* symbol, uint8_t index) {
    const uint32_t at = sim.symbol(symbol) + 4u * index;
    uint32_t v = 0;
    for (uint8_t k = 0; k < 4; ++k) {
        v |= static_cast<uint32_t>(sim.peek(static_cast<uint16_t>(at + k))) << (8 * k);
    }
    return v;
}

struct ChipRun {
    std::unique_ptr<Sim> sim;
    bool done = false;
};

ChipRun& chip() {
    static ChipRun run;
    if (!run.sim) {
        struct stat st;
        if (stat(curve_elf().c_str(), &st) != 0) return run;
        run.sim.reset(new Sim(curve_elf()));
        run.sim->watch_register(kGpior0);
        Sim& s = *run.sim;
        run.done = s.run_until([&] { return s.peek(kGpior0) == 99; }, 2000000000ull);
    }
    return run;
}

} // namespace

TEST(FirmwareCurve, ChipComputesWhatTheHostComputes) {
    ChipRun& run = chip();
    ASSERT_TRUE(run.sim) << "missing " << curve_elf()
                         << ": build the firmware first (cmake --preset avr && cmake --build "
                            "--preset avr)";
    ASSERT_TRUE(run.done) << "curve_check.elf did not finish";
    ll::test::CurveWorkload host(1);
    host.run(40);
    EXPECT_EQ(read_u32(*run.sim, "g_curve_hash", 0), host.hash);
    EXPECT_EQ(read_u32(*run.sim, "g_curve_samples", 0), host.samples);
    printf("[ measured ] curve workload: %u samples, hash %08x on both\n", host.samples, host.hash);
}

TEST(FirmwareCurve, SampleStepIsFasterThanBeforeTheRework) {
    ChipRun& run = chip();
    ASSERT_TRUE(run.sim && run.done) << "missing or unfinished " << curve_elf();
    const Sim& s = *run.sim;
    // Cycles a sample between the marks 1/2 (arc), 3/4 (helix) and 5/6 (Bezier).
    double per[3];
    for (uint8_t k = 0; k < 3; ++k) {
        const uint8_t from = static_cast<uint8_t>(1 + 2 * k);
        per[k] =
            static_cast<double>(s.marker_cycles(kGpior0, from, static_cast<uint8_t>(from + 1))) /
            read_u32(s, "g_curve_walked", k);
    }
    // The longest next() call of the Bezier (a piece start), from the marks around each call.
    uint64_t longest = 0, start = 0;
    for (const RegWrite& w : s.register_writes()) {
        if (w.value == 20) start = w.cycle;
        if (w.value == 21) longest = std::max(longest, w.cycle - start);
    }
    const uint64_t shape[3] = {s.marker_cycles(kGpior0, 7, 8), s.marker_cycles(kGpior0, 9, 10),
                               s.marker_cycles(kGpior0, 11, 12)};
    printf("[ measured ] next(): %.0f cycles a sample (arc), %.0f (helix), %.0f (Bezier); longest "
           "call %llu\n",
           per[0], per[1], per[2], static_cast<unsigned long long>(longest));
    printf("[ measured ] curve_shape(): circle %llu, 50 x 5 mm ellipse %llu, Bezier %llu cycles\n",
           static_cast<unsigned long long>(shape[0]), static_cast<unsigned long long>(shape[1]),
           static_cast<unsigned long long>(shape[2]));
    // Before the rework (docs/curves.md): about 1740 cycles a sample whatever the curve, and
    // 27.8 k for the longest call (a Bezier piece start).
    EXPECT_LT(per[0], 1000);
    EXPECT_LT(per[1], 1300);
    EXPECT_LT(per[2], 1300);
    EXPECT_LT(longest, 32000u);
}
