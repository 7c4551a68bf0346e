// A store beyond RAMEND (selftest_stray_write): simavr 1.6 reports the crash and then performs
// the store all the same, into its host buffer. The harness gives that buffer the whole 64 KiB
// data space, so that a runaway firmware (GRBL 1.1h's nesting step interrupts in llbench --grbl)
// ends its run with SimError instead of corrupting the host's heap.
#include <malloc.h>

#include "selftest_elf.h"

using namespace ll::sim;
using ll::sim::test::options;

TEST(SimStrayWrite, StoreBeyondRamEndEndsTheRunAsACrashInsideTheHostBuffer) {
    REQUIRE_SELFTEST("selftest_stray_write");
    Sim sim(options("selftest_stray_write"));
    // The buffer reaches every 16-bit address (without the harness' fix: RAMEND + 1 = 2,304 B).
    ASSERT_GE(malloc_usable_size(sim.avr()->data), 0x10000u);
    bool crashed = false;
    try {
        sim.run_for(ms(1));
    } catch (const SimError& e) {
        crashed = std::string(e.what()).find("crashed") != std::string::npos;
    }
    EXPECT_TRUE(crashed);
    // The store landed inside the buffer, where nothing of the simulated chip lives.
    EXPECT_EQ(sim.avr()->data[0xF000], 0x5A);
}
