// The pin-edge recorder against selftest_pins: every CNC-shield pin toggled at an instruction-exact
// cycle, then the CSV and VCD renderings of that record.
#include <sstream>

#include "selftest_elf.h"

using namespace ll::sim;
using ll::sim::test::options;

namespace {

struct Expected {
    const char* signal;
    uint64_t offset; ///< cycles after the first instruction of pin_sequence (selftest_pins.c)
    uint8_t level;
};

// Offsets from selftest_pins.c: 9 ldi, then OUTs separated by 1, 2, ... 8 nops (1 cycle each).
const Expected kSequence[] = {
    {"step_x", 9, 1},  {"step_y", 11, 1}, {"step_z", 14, 1}, {"dir_x", 18, 1}, {"dir_y", 23, 1},
    {"dir_z", 29, 1},  {"enable", 36, 1}, {"step_a", 44, 1}, {"dir_a", 53, 1}, {"step_x", 56, 0},
    {"step_y", 56, 0}, {"step_z", 56, 0}, {"dir_x", 56, 0},  {"dir_y", 56, 0}, {"dir_z", 56, 0},
    {"enable", 57, 0}, {"step_a", 57, 0}, {"dir_a", 57, 0},  {"probe", 59, 1},
};

Options pins_options() {
    Options o = options("selftest_pins");
    o.signals.push_back(parse_signal("probe=PC0")); // any other pin can be recorded too
    return o;
}

/// Runs selftest_pins; returns the cycle at which pin_sequence starts.
uint64_t run_pins(Sim& sim) {
    const uint32_t entry = sim.symbol("pin_sequence");
    if (!sim.run_until_pc(entry, ms(1))) return kNever;
    const uint64_t e = sim.cycle();
    sim.run_for(200);
    return e;
}

} // namespace

TEST(SimRecorder, RecordsEveryPinAtItsInstructionCycle) {
    REQUIRE_SELFTEST("selftest_pins");
    Sim sim(pins_options());
    const uint64_t e = run_pins(sim);
    ASSERT_NE(e, kNever);
    const std::vector<Edge>& edges = sim.edges();
    ASSERT_EQ(edges.size(), sizeof kSequence / sizeof kSequence[0]);
    for (size_t i = 0; i < edges.size(); ++i) {
        SCOPED_TRACE(i);
        EXPECT_EQ(sim.signals()[edges[i].signal].name, kSequence[i].signal);
        EXPECT_EQ(edges[i].cycle, e + kSequence[i].offset);
        EXPECT_EQ(edges[i].level, kSequence[i].level);
    }
    for (uint8_t initial : sim.recorder().initial_levels()) EXPECT_EQ(initial, 0);
}

TEST(SimRecorder, SameInputGivesSameCycles) {
    REQUIRE_SELFTEST("selftest_pins");
    Sim a(pins_options()), b(pins_options());
    run_pins(a);
    run_pins(b);
    ASSERT_EQ(a.edges().size(), b.edges().size());
    for (size_t i = 0; i < a.edges().size(); ++i) {
        EXPECT_EQ(a.edges()[i].cycle, b.edges()[i].cycle);
        EXPECT_EQ(a.edges()[i].signal, b.edges()[i].signal);
    }
}

TEST(SimRecorder, CsvHasOneRowPerEdgeWithExactMicroseconds) {
    REQUIRE_SELFTEST("selftest_pins");
    Sim sim(pins_options());
    const uint64_t e = run_pins(sim);
    std::ostringstream want;
    want << "cycle,time_us,signal,level\n";
    for (const Expected& x : kSequence) {
        const uint64_t c = e + x.offset;
        want << c << ',' << c / 16 << '.';
        const unsigned frac = static_cast<unsigned>(c % 16) * 625; // 1 cycle = 0.0625 us
        want << (frac < 1000 ? "0" : "") << (frac < 100 ? "0" : "") << (frac < 10 ? "0" : "")
             << frac << ',' << x.signal << ',' << unsigned(x.level) << '\n';
    }
    std::ostringstream got;
    sim.recorder().write_csv(got, kCpuHz);
    EXPECT_EQ(got.str(), want.str());
}

TEST(SimRecorder, VcdDeclaresEachSignalAndTimesEveryChange) {
    REQUIRE_SELFTEST("selftest_pins");
    Sim sim(pins_options());
    const uint64_t e = run_pins(sim);
    std::ostringstream got;
    sim.recorder().write_vcd(got, kCpuHz);
    const std::string vcd = got.str();

    EXPECT_NE(vcd.find("$timescale 100ps $end\n"), std::string::npos);
    const char* names[] = {"step_x", "step_y", "step_z", "dir_x", "dir_y",
                           "dir_z",  "enable", "step_a", "dir_a", "probe"};
    for (size_t i = 0; i < 10; ++i) {
        const std::string var =
            std::string("$var wire 1 ") + char('!' + i) + ' ' + names[i] + " $end\n";
        EXPECT_NE(vcd.find(var), std::string::npos) << var;
    }
    EXPECT_NE(vcd.find("$enddefinitions $end\n#0\n$dumpvars\n0!\n0\"\n"), std::string::npos);

    // Body after $dumpvars: one "#t" per distinct cycle (t in 100 ps, 625 per cycle), then the
    // changes at that time.
    std::ostringstream body;
    uint64_t last = kNever;
    for (const Expected& x : kSequence) {
        const uint64_t t = (e + x.offset) * 625;
        if (t != last) body << '#' << t << '\n';
        last = t;
        size_t idx = 0;
        while (std::string(names[idx]) != x.signal) ++idx;
        body << unsigned(x.level) << char('!' + idx) << '\n';
    }
    const std::string tail = body.str();
    ASSERT_GE(vcd.size(), tail.size());
    EXPECT_EQ(vcd.substr(vcd.size() - tail.size()), tail);
}

TEST(SimRecorder, ParsesSignalSpecs) {
    const Signal s = parse_signal("limit_x=PB1");
    EXPECT_EQ(s.name, "limit_x");
    EXPECT_EQ(s.port, 'B');
    EXPECT_EQ(s.bit, 1);
    EXPECT_THROW(parse_signal("bad"), std::invalid_argument);
    EXPECT_THROW(parse_signal("x=PA1"), std::invalid_argument);
    EXPECT_THROW(parse_signal("x=PB8"), std::invalid_argument);
}
