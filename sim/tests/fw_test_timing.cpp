// Issue 4: the real firmware's step sequence equals the host model's, edge for edge, each edge
// within 16 cycles (1 us) of the model's schedule once the offsets of step_timing.h are removed.
// Every job is planned whole before it starts (`!`, the lines, `~`), so both sides run the same
// runs from one timer start (fw_check.h). Pulse width, direction setup and the run queue are
// checked on every edge of every job as well (fw_timing.h).
#include <math.h>

#include "fw_timing.h"

using namespace ll::sim;
using namespace ll::sim::fw;

namespace {

// "X1.234" with 4 decimals (the parser keeps mm x 1000, rounded half away on the 4th).
std::string word(char axis, double mm) {
    char buf[32];
    snprintf(buf, sizeof buf, "%c%.4f", axis, mm);
    return buf;
}

} // namespace

TEST(FirmwareTiming, SingleAxisLineMatchesTheModelThroughAccelerationCruiseAndDeceleration) {
    REQUIRE_FIRMWARE();
    // 20 mm at 50 mm/s, 500 mm/s^2: 2.5 mm of acceleration, cruise, 2.5 mm of deceleration.
    check_against_model("X line", Job{fast_machine(), {"G91 G1 X20 F3000"}}, PinSettings{});
}

TEST(FirmwareTiming, TwoAxisLineMatchesTheModel) {
    REQUIRE_FIRMWARE();
    check_against_model("XY line", Job{fast_machine(), {"G91 G1 X15 Y-7 F3000"}}, PinSettings{});
}

TEST(FirmwareTiming, ThreeAxisLineMatchesTheModel) {
    REQUIRE_FIRMWARE();
    check_against_model("XYZ line", Job{fast_machine(), {"G91 G1 X10 Y-6 Z3 F3000"}},
                        PinSettings{});
}

TEST(FirmwareTiming, FourAxisLineWithTheAAxisOnPortBMatchesTheModel) {
    REQUIRE_FIRMWARE();
    // A (PB4/PB5) follows the XYZ path in its own speed group.
    check_against_model("XYZA line", Job{fast_machine(), {"G91 G1 X10 Y6 Z-3 A5 F3000"}},
                        PinSettings{});
}

TEST(FirmwareTiming, AAxisAloneMatchesTheModelWithThePortBOffsets) {
    REQUIRE_FIRMWARE();
    check_against_model("A line", Job{fast_machine(), {"G91 G1 A-12 F3000"}}, PinSettings{});
}

TEST(FirmwareTiming, JunctionsAtSpeedMatchTheModel) {
    REQUIRE_FIRMWARE();
    // A quarter helix in as many segments as the planner holds: 2 mm chords turning 5.6 degrees,
    // so the look-ahead keeps the speed up through every junction.
    Job job{fast_machine({"$11=0.020"}), {"G90"}};
    const int n = ll::kPlannerSize;
    for (int i = 1; i <= n; ++i) {
        const double th = 1.5707963 * i / n;
        job.lines.push_back("G1 " + word('X', 20 * sin(th)) + " " + word('Y', 20 - 20 * cos(th)) +
                            " " + word('Z', 0.1 * i) + (i == 1 ? " F4000" : ""));
    }
    check_against_model("helix junctions", job, PinSettings{});
}

TEST(FirmwareTiming, MovesOfAFewStepsWithReversalsMatchTheModel) {
    REQUIRE_FIRMWARE();
    // 1 to 4 steps each (0.0125 mm = 1 step), reversing, changing axis sets, every axis.
    const std::vector<std::string> moves = {"G91 G1 X0.0125 F3000",
                                            "Y0.025",
                                            "X-0.0375",
                                            "Y-0.0125 A0.0125",
                                            "X0.0125 Y0.0125",
                                            "Z0.05",
                                            "A-0.025 X-0.0125",
                                            "X0.0125 Y-0.025 Z0.0125 A0.0375",
                                            "Z-0.0125",
                                            "X0.025 Y0.05",
                                            "A-0.0125",
                                            "X-0.0125 Y-0.0125 Z-0.0125",
                                            "Y0.0375",
                                            "X0.0125",
                                            "X-0.0125",
                                            "A0.025 Y-0.0125"};
    Job job{fast_machine(), {}};
    for (size_t i = 0; i < moves.size() && i < ll::kPlannerSize; ++i) job.lines.push_back(moves[i]);
    check_against_model("short moves", job, PinSettings{});
}

TEST(FirmwareTiming, LongMoveAtTheShortestPeriodMatchesTheModel) {
    REQUIRE_FIRMWARE();
    // 32000 steps asking 120 k steps/s: the producer clamps the period to the interrupt's
    // minimum (152 cycles at $0 = 3 us, 105 k steps/s), the CPU's busiest case.
    check_against_model(
        "long at min period",
        Job{fast_machine({"$0=3", "$100=800", "$110=9000", "$120=2000"}), {"G91 G1 X40 F9000"}},
        PinSettings{3, 0, 0});
}

TEST(FirmwareTiming, VerySlowMoveWithIdleWaitsMatchesTheModel) {
    REQUIRE_FIRMWARE();
    // 16 steps/s: 1 M cycles between steps, longer than the 16-bit timer, so every step is
    // preceded by idle runs (steps == 0).
    check_against_model("very slow", Job{fast_machine(), {"G91 G1 X0.25 Y-0.125 F12"}},
                        PinSettings{});
}

TEST(FirmwareTiming, MatchesTheModelWhileASenderPollsStatusEvery20Ms) {
    REQUIRE_FIRMWARE();
    // What every sender does: `?` 5 to 50 times a second. Each one takes the receive interrupt,
    // a status report (the position read in a critical section) and the transmit interrupts.
    Job job{fast_machine(), {"G91 G1 X12 Y-9 Z2 A3 F3000", "G1 X-6 Y4 A-5"}};
    job.status_every_ms = 20;
    check_against_model("XYZA with ? every 20 ms", job, PinSettings{});
}
