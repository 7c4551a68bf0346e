// Issue 4, item 4: the run queue never empties in the middle of a move. ll::g_starvations (the
// main loop counts every time the step timer stopped for want of runs while a move was still
// being produced) is read from the chip's RAM by symbol. The planned jobs of the timing checks
// read it after each job; this one streams many short segments with GRBL character counting,
// the way a sender runs a real job, so the main loop parses and plans while the motors run.
#include <math.h>

#include <chrono>

#include "fw_timing.h"

using namespace ll::sim;
using namespace ll::sim::fw;

namespace {

struct StreamResult {
    size_t lines = 0;
    size_t errors = 0;
    uint16_t starvations = 0;
    uint32_t overruns = 0;
    double seconds = 0; ///< simulated, first byte to Idle
    double wall = 0;    ///< host seconds
    PulseStats pulses;
    int32_t want_x = 0, want_y = 0; ///< final target, steps
    std::string status;
};

// Circle of radius `r` mm around (r, 0), `segments` chords per turn, `turns` turns, at `feed`.
StreamResult stream_circle(const std::vector<std::string>& settings, double r, int segments,
                           double turns, int feed) {
    StreamResult out;
    Sim sim(firmware_elf());
    paint_stack(sim);
    Grbl grbl(sim);
    EXPECT_TRUE(grbl.wait_banner(ms(500)));
    for (const std::string& s : settings) EXPECT_TRUE(grbl.send_line(s, ms(200)).ok) << s;
    std::vector<std::string> lines = {"G90 G1 F" + std::to_string(feed)};
    const int n = static_cast<int>(segments * turns);
    int32_t x_um = 0, y_um = 0;
    for (int i = 1; i <= n; ++i) {
        const double th = 2 * M_PI * i / segments;
        x_um = static_cast<int32_t>(lround(1000 * (r - r * cos(th))));
        y_um = static_cast<int32_t>(lround(1000 * r * sin(th)));
        char buf[48];
        snprintf(buf, sizeof buf, "X%.3f Y%.3f", x_um / 1000.0, y_um / 1000.0);
        lines.push_back(buf);
    }
    // 80 steps/mm: steps = um * 0.08, never exactly half a step with 3 decimals.
    out.want_x = static_cast<int32_t>(lround(x_um * 0.08));
    out.want_y = static_cast<int32_t>(lround(y_um * 0.08));
    const size_t from = sim.edges().size();
    const uint64_t t0 = sim.cycle();
    const auto w0 = std::chrono::steady_clock::now();
    // Bounded so that a broken image fails in about a second of host time: the jobs take 1.5 to
    // 5 s simulated.
    const std::vector<Reply> replies = grbl.stream(lines, ms(10000));
    bool timeout = false;
    for (const Reply& rep : replies) {
        out.errors += rep.ok ? 0 : 1;
        timeout = timeout || rep.timeout;
    }
    out.lines = replies.size();
    for (int i = 0; i < (timeout ? 1 : 300); ++i) {
        sim.run_for(ms(10));
        out.status = grbl.status(ms(20));
        if (out.status.compare(0, 5, "<Idle") == 0) break;
    }
    out.seconds = (sim.cycle() - t0) / 16e6;
    out.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    out.starvations = static_cast<uint16_t>(
        sim.peek(static_cast<uint16_t>(sim.symbol("_ZN2ll13g_starvationsE"))) |
        sim.peek(static_cast<uint16_t>(sim.symbol("_ZN2ll13g_starvationsE") + 1)) << 8);
    out.overruns = sim.overruns();
    out.pulses = pulse_stats(chip_edges(sim, from), 0, 0, 0);
    const std::pair<uint16_t, uint16_t> hw = stack_high_water(sim);
    EXPECT_GT(hw.second, 0u) << "the stack used all " << hw.first
                             << " bytes above the static RAM and went on into it";
    return out;
}

void check_stream(const char* label, const StreamResult& r, int feed) {
    EXPECT_EQ(r.errors, 0u);
    EXPECT_EQ(r.overruns, 0u) << "the sender overran the receive buffer";
    EXPECT_EQ(r.status.compare(0, 5, "<Idle"), 0) << r.status;
    EXPECT_EQ(r.starvations, 0u) << "the run queue ran dry in the middle of a move";
    EXPECT_EQ(r.pulses.net[0], r.want_x);
    EXPECT_EQ(r.pulses.net[1], r.want_y);
    EXPECT_GE(r.pulses.min_pulse, 160u);
    EXPECT_GE(r.pulses.min_dir_setup, 16u);
    EXPECT_EQ(r.pulses.dir_during_pulse, 0u);
    printf("[ measured ] %s: %zu lines at F%d, %zu + %zu pulses in %.3f s simulated (%.2f s "
           "host); starvations %u; pulse >= %llu cycles; dir setup >= %llu cycles\n",
           label, r.lines, feed, r.pulses.pulses[0], r.pulses.pulses[1], r.seconds, r.wall,
           r.starvations, static_cast<unsigned long long>(r.pulses.min_pulse),
           static_cast<unsigned long long>(r.pulses.min_dir_setup));
}

} // namespace

TEST(FirmwareRunQueue, NeverRunsDryWhileShortSegmentsStreamAtHighFeed) {
    REQUIRE_FIRMWARE();
    // 0.5 mm chords at 100 mm/s: a new line every 5 ms, each parsed and planned while the
    // previous ones run (8 k steps/s on the busier axis).
    const int feed = 6000;
    const StreamResult r = stream_circle(
        fast_machine({"$110=9000", "$111=9000", "$120=1000", "$121=1000"}), 15, 188, 1.5, feed);
    check_stream("stream 0.5 mm chords", r, feed);
}

TEST(FirmwareRunQueue, NeverRunsDryWhileVeryShortSegmentsStreamFasterThanTheSerialLine) {
    REQUIRE_FIRMWARE();
    // 0.2 mm chords at 150 mm/s: 1.3 ms per segment, less than a line takes on the wire, so the
    // planner drains and motion slows down as it should, but the run queue never runs dry while a
    // move is being produced.
    const int feed = 9000;
    const StreamResult r = stream_circle(
        fast_machine({"$110=9000", "$111=9000", "$120=1000", "$121=1000"}), 6, 188, 1.0, feed);
    check_stream("stream 0.2 mm chords", r, feed);
}
