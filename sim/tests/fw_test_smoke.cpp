// Issue 3: the real lowlevel.elf in simavr answers as GRBL 1.1h does, keeps its settings in
// EEPROM across a chip reset, steps exactly what a job asks, and rejects bad lines without
// moving.
#include <stdio.h>

#include <regex>

#include "fw_check.h"
#include "lowlevel/config.h"

using namespace ll::sim;
using namespace ll::sim::fw;

namespace {

constexpr uint64_t kLine = ms(200);
// "Bf:<free planner blocks>,<free receive bytes>" of an idle machine.
const std::string kIdleBuffers = "Bf:" + std::to_string(ll::kPlannerSize) + ",128";

struct Booted {
    Sim sim;
    Grbl grbl;
    Booted() : sim(firmware_elf()), grbl(sim) { paint_stack(sim); }
};

std::vector<std::string> texts_since(const Grbl& g, size_t from) {
    std::vector<std::string> out;
    for (size_t i = from; i < g.other_lines().size(); ++i) out.push_back(g.other_lines()[i].text);
    return out;
}

// Step / direction edges (the enable pin excluded) from recorder index `from` on.
size_t motion_edges(const Sim& sim, size_t from) {
    size_t n = 0;
    for (const PinEdge& e : chip_edges(sim, from))
        if (e.kind != Kind::Enable) ++n;
    return n;
}

// Polls `?` every 10 ms until the report says Idle.
bool wait_idle(Booted& b, uint64_t max_cycles) {
    const uint64_t end = b.sim.cycle() + max_cycles;
    while (b.sim.cycle() < end) {
        b.sim.run_for(ms(10));
        if (b.grbl.status(ms(20)).compare(0, 5, "<Idle") == 0) return true;
    }
    return false;
}

void expect_stack_above_static_ram(const Sim& sim) {
    const std::pair<uint16_t, uint16_t> hw = stack_high_water(sim);
    EXPECT_GT(hw.second, 0u) << "the stack used all " << hw.first
                             << " bytes above the static RAM (__bss_end) and went on into it";
}

} // namespace

TEST(FirmwareSmoke, BannerIsGrbl11h) {
    REQUIRE_FIRMWARE();
    Booted b;
    ASSERT_TRUE(b.grbl.wait_banner(ms(500)));
    EXPECT_EQ(b.grbl.other_lines().back().text, "Grbl 1.1h ['$' for help]");
    // A blank EEPROM: GRBL's error:7, then the restored settings, once.
    EXPECT_EQ(b.grbl.other_lines().front().text, "error:7");
    Sim again(firmware_elf());
    again.set_eeprom(b.sim.eeprom());
    Grbl g2(again);
    ASSERT_TRUE(g2.wait_banner(ms(500)));
    ASSERT_EQ(g2.other_lines().size(), 2u); // "" and the banner: the settings were valid
    EXPECT_EQ(g2.other_lines().back().text, "Grbl 1.1h ['$' for help]");
}

TEST(FirmwareSmoke, DollarDollarListsEverySetting) {
    REQUIRE_FIRMWARE();
    Booted b;
    ASSERT_TRUE(b.grbl.wait_banner(ms(500)));
    const size_t from = b.grbl.other_lines().size();
    const Reply r = b.grbl.send_line("$$", kLine);
    ASSERT_TRUE(r.ok) << r.error;
    const std::vector<std::string> got = texts_since(b.grbl, from);
    // GRBL 1.1h's global settings we implement, then 6 per-axis settings x 4 axes (X Y Z A).
    std::vector<std::string> want = {"$0=10", "$1=25", "$2=0",      "$3=0",      "$4=0", "$5=0",
                                     "$6=0",  "$10=3", "$11=0.010", "$12=0.002", "$13=0"};
    for (int base : {100, 110, 120, 130, 140}) {
        for (int a = 0; a < 4; ++a) {
            const char* v = base == 100   ? "250.000"
                            : base == 110 ? "500.000"
                            : base == 120 ? "10.000"
                            : base == 130 ? "200.000"
                                          : (a == 3 ? "1" : "0");
            want.push_back("$" + std::to_string(base + a) + "=" + v);
        }
    }
    EXPECT_EQ(got, want);
    expect_stack_above_static_ram(b.sim);
}

TEST(FirmwareSmoke, SettingWrittenWithDollarSurvivesAChipReset) {
    REQUIRE_FIRMWARE();
    Booted b;
    ASSERT_TRUE(b.grbl.wait_banner(ms(500)));
    ASSERT_TRUE(b.grbl.send_line("$100=123.456", kLine).ok);
    ASSERT_TRUE(b.grbl.send_line("$0=7", kLine).ok);
    ASSERT_TRUE(b.grbl.send_line("$3=5", kLine).ok);
    b.sim.reset(); // the Uno's DTR reset: EEPROM kept
    const size_t from = b.grbl.other_lines().size();
    ASSERT_TRUE(b.grbl.wait_banner(ms(500)));
    // No error:7 this time: the settings were read back.
    for (const std::string& l : texts_since(b.grbl, from)) EXPECT_NE(l, "error:7");
    const size_t list = b.grbl.other_lines().size();
    ASSERT_TRUE(b.grbl.send_line("$$", kLine).ok);
    const std::vector<std::string> got = texts_since(b.grbl, list);
    EXPECT_NE(std::find(got.begin(), got.end(), "$100=123.456"), got.end());
    EXPECT_NE(std::find(got.begin(), got.end(), "$0=7"), got.end());
    EXPECT_NE(std::find(got.begin(), got.end(), "$3=5"), got.end());
    EXPECT_EQ(b.sim.resets(), 1u);
}

TEST(FirmwareSmoke, StatusQueryGivesAGrblReport) {
    REQUIRE_FIRMWARE();
    Booted b;
    ASSERT_TRUE(b.grbl.wait_banner(ms(500)));
    const std::string idle = b.grbl.status(ms(20));
    EXPECT_EQ(idle, "<Idle|MPos:0.000,0.000,0.000,0.000|" + kIdleBuffers +
                        "|FS:0,0|WCO:0.000,0.000,0.000,0.000>");
    // While moving: Run, a position between the ends, one block fewer free.
    ASSERT_TRUE(b.grbl.send_line("G1 X2 F300", kLine).ok);
    b.sim.run_for(ms(100));
    const std::string run = b.grbl.status(ms(20));
    const std::regex moving(
        R"(<Run\|MPos:(\d+\.\d{3}),0\.000,0\.000,0\.000\|Bf:\d+,\d+\|FS:\d+,0>)");
    std::smatch m;
    ASSERT_TRUE(std::regex_match(run, m, moving)) << run;
    const double x = std::stod(m[1].str());
    EXPECT_GT(x, 0.0);
    EXPECT_LT(x, 2.0);
    expect_stack_above_static_ram(b.sim);
}

TEST(FirmwareSmoke, G1JobMakesExactStepCountsPerAxis) {
    REQUIRE_FIRMWARE();
    Booted b;
    ASSERT_TRUE(b.grbl.wait_banner(ms(500)));
    for (const char* s : {"$100=80", "$101=100", "$102=400", "$103=50", "$110=3000", "$111=3000",
                          "$112=3000", "$113=3000", "$120=500", "$121=500", "$122=500", "$123=500"})
        ASSERT_TRUE(b.grbl.send_line(s, kLine).ok) << s;
    const size_t from = b.sim.edges().size();
    // Targets in steps: round half away from zero of mm x steps/mm, from the absolute target.
    //   G90 X10.0125 Y-3.333 Z0.5 A7   ->  801, -333 (-333.3), 200, 350
    //   G91 X-2.5 Y1 Z-0.75 A-3        ->  601, -233, -100, 200
    const std::vector<Reply> r = b.grbl.stream(
        {"G90 G1 X10.0125 Y-3.333 Z0.5 A7 F2400", "G91 G1 X-2.5 Y1 Z-0.75 A-3"}, kLine);
    for (const Reply& x : r) ASSERT_TRUE(x.ok) << x.line << " error:" << x.error;
    ASSERT_TRUE(wait_idle(b, ms(3000)));
    const std::vector<PinEdge> edges = chip_edges(b.sim, from);
    const PulseStats ps = pulse_stats(edges, 0, 0, 0);
    EXPECT_EQ(ps.pulses[0], 801u + 200u);
    EXPECT_EQ(ps.pulses[1], 333u + 100u);
    EXPECT_EQ(ps.pulses[2], 200u + 300u);
    EXPECT_EQ(ps.pulses[3], 350u + 150u);
    EXPECT_EQ(ps.net[0], 601);
    EXPECT_EQ(ps.net[1], -233);
    EXPECT_EQ(ps.net[2], -100);
    EXPECT_EQ(ps.net[3], 200);
    const std::string want = "<Idle|MPos:7.513,-2.330,-0.250,4.000|" + kIdleBuffers + "|FS";
    EXPECT_EQ(b.grbl.status(ms(20)).substr(0, want.size()), want);
    expect_stack_above_static_ram(b.sim);
}

TEST(FirmwareSmoke, BadLinesAreRejectedAndCauseNoStep) {
    REQUIRE_FIRMWARE();
    Booted b;
    ASSERT_TRUE(b.grbl.wait_banner(ms(500)));
    ASSERT_TRUE(b.grbl.send_line("$100=80", kLine).ok);
    const size_t from = b.sim.edges().size();
    struct Bad {
        std::string line;
        int error;
    };
    const std::vector<Bad> bad = {
        {"G1 X\xC2\xB0"
         "1 F600",
         20},                  // a non-ASCII byte (UTF-8 degree sign): error:20
        {"G1 X1 W2 F600", 20}, // W is no G-code word
        {"G7 X1 F600", 20},    // no such G command
        {"G1 X1." + std::string(90, '0') + " F600", 11}, // 100 characters: over the 79 limit
        {"G1 X1 X2 F600", 25},                           // a word twice
        {"G1 X1", 22},                                   // G1 with no feed rate yet
    };
    for (const Bad& x : bad) {
        const Reply r = b.grbl.send_line(x.line, kLine);
        EXPECT_FALSE(r.ok) << x.line;
        EXPECT_EQ(r.error, x.error) << x.line;
    }
    b.sim.run_for(ms(50));
    EXPECT_EQ(motion_edges(b.sim, from), 0u);
    const std::string want = "<Idle|MPos:0.000,0.000,0.000,0.000|" + kIdleBuffers + "|FS";
    EXPECT_EQ(b.grbl.status(ms(20)).substr(0, want.size()), want);
    // The firmware is still in step: the next good line runs, exactly.
    ASSERT_TRUE(b.grbl.send_line("G1 X0.5 F600", kLine).ok);
    ASSERT_TRUE(wait_idle(b, ms(1000)));
    const PulseStats ps = pulse_stats(chip_edges(b.sim, from), 0, 0, 0);
    EXPECT_EQ(ps.pulses[0], 40u);
    EXPECT_EQ(ps.net[0], 40);
    EXPECT_EQ(ps.pulses[1] + ps.pulses[2] + ps.pulses[3], 0u);
    expect_stack_above_static_ram(b.sim);
}

TEST(FirmwareSmoke, ReceiveInterruptConsumesExtendedBytesAndLosesNothingBeforeTheRingIsFull) {
    // The receive interrupt's tail is assembly (firmware/serial.cpp) with the tests of
    // rt::filter(): GRBL 1.1's extended real-time bytes are consumed inside a line, their
    // neighbours reach the line (a non-ASCII byte: error:20), and a full 128-byte ring loses the
    // byte after it, with the overflow flag set.
    REQUIRE_FIRMWARE();
    Booted b;
    ASSERT_TRUE(b.grbl.wait_banner(ms(500)));
    ASSERT_TRUE(b.grbl.send_line("$100=80", kLine).ok);
    const std::string consumed = "\x84\x85\x86\x87\x90\x97\x9D\xA0\xA1";
    ASSERT_TRUE(b.grbl.send_line("G1" + consumed + "X0.1F600", kLine).ok);
    for (char c : std::string("\x83\x88\x8F\x9E\x9F\xA2")) {
        const Reply r = b.grbl.send_line(std::string("G1X0.2") + c + "F600", kLine);
        EXPECT_FALSE(r.ok) << static_cast<int>(static_cast<uint8_t>(c));
        EXPECT_EQ(r.error, 20) << static_cast<int>(static_cast<uint8_t>(c));
    }
    ASSERT_TRUE(wait_idle(b, ms(1000)));
    // Fill the planner with slow moves: the next line waits for room, and while it waits the main
    // loop reads no byte (docs/protocol.md), so the ring fills from the interrupt alone.
    for (unsigned i = 1; i <= ll::kPlannerSize + 1; ++i)
        b.sim.send("G1X" + std::to_string(i) + "F60\n");
    b.sim.run_for(ms(200));
    const uint16_t head = static_cast<uint16_t>(b.sim.symbol("_ZN2ll12_GLOBAL__N_19s_rx_headE"));
    const uint16_t tail = static_cast<uint16_t>(b.sim.symbol("_ZN2ll12_GLOBAL__N_19s_rx_tailE"));
    const uint16_t lost =
        static_cast<uint16_t>(b.sim.symbol("_ZN2ll12_GLOBAL__N_113s_rx_overflowE"));
    const uint8_t queued = static_cast<uint8_t>(b.sim.peek(tail) - b.sim.peek(head));
    ASSERT_LT(queued, 100u) << "the main loop should be waiting with few bytes queued";
    EXPECT_EQ(b.sim.peek(lost), 0u);
    // Exactly as many bytes as the ring has room for: none lost.
    b.sim.send(std::string(128u - queued, 'X'));
    b.sim.run_for(ms(20));
    EXPECT_EQ(static_cast<uint8_t>(b.sim.peek(tail) - b.sim.peek(head)), 128u);
    EXPECT_EQ(b.sim.peek(lost), 0u);
    // One more: lost, and flagged.
    b.sim.send("X");
    b.sim.run_for(ms(1));
    EXPECT_EQ(static_cast<uint8_t>(b.sim.peek(tail) - b.sim.peek(head)), 128u);
    EXPECT_EQ(b.sim.peek(lost), 1u);
}
