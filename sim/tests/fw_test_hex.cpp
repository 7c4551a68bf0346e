// The harness loads an Intel hex image (what avrdude flashes; how GRBL 1.1h builds are
// published, for llbench --grbl) as well as an ELF: lowlevel.hex, made by the AVR build from
// lowlevel.elf, must give the same flash and the same run, cycle for cycle.
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "fw_check.h"

using namespace ll::sim;
using namespace ll::sim::fw;

namespace {

std::string hex_of(const std::string& elf) {
    return elf.substr(0, elf.size() - 4) + ".hex";
}

void run_job(Sim& sim) {
    ASSERT_TRUE(sim.run_until_output("['$' for help]", ms(3000)));
    sim.send("G91 G1 X2 Y-1 F600\n");
    sim.run_for(ms(400));
}

} // namespace

TEST(SimHex, SameFlashAndSameRunAsTheElf) {
    Sim elf(firmware_elf());
    Sim hex(hex_of(firmware_elf()));
    ASSERT_EQ(elf.avr()->flashend, hex.avr()->flashend);
    EXPECT_EQ(0, memcmp(elf.avr()->flash, hex.avr()->flash, elf.avr()->flashend + 1u));
    run_job(elf);
    run_job(hex);
    EXPECT_EQ(elf.output(), hex.output());
    ASSERT_EQ(elf.edges().size(), hex.edges().size());
    ASSERT_GT(elf.edges().size(), 100u); // it moved
    for (size_t i = 0; i < elf.edges().size(); ++i) {
        EXPECT_EQ(elf.edges()[i].cycle, hex.edges()[i].cycle) << "edge " << i;
        EXPECT_EQ(elf.edges()[i].signal, hex.edges()[i].signal) << "edge " << i;
        EXPECT_EQ(elf.edges()[i].level, hex.edges()[i].level) << "edge " << i;
    }
}

TEST(SimHex, BadChecksumIsRefused) {
    char path[] = "/tmp/llsim_bad_XXXXXX.hex";
    const int fd = mkstemps(path, 4);
    ASSERT_GE(fd, 0);
    // One data record whose checksum byte is wrong (0x62 instead of 0x5E), then the end record.
    const char text[] = ":020000000C9462\n:00000001FF\n";
    ASSERT_EQ(static_cast<ssize_t>(sizeof text - 1), write(fd, text, sizeof text - 1));
    close(fd);
    EXPECT_THROW(Sim{std::string(path)}, SimError);
    unlink(path);
}
