// Issue 4, item 3: step pulses are never shorter than $0 and a direction pin is set at least 1 us
// before the next step edge of its axis, on every edge, at $0 = 3 and 10 us and with the step,
// direction and enable pins inverted ($2, $3, $4). Each job is also compared edge by edge with
// the host model (fw_timing.h), so inverted levels are checked too.
#include "fw_timing.h"

using namespace ll::sim;
using namespace ll::sim::fw;

namespace {

// Back and forth on every axis with short moves: a direction change on each axis at nearly every
// move, at the rates of fast_machine().
std::vector<std::string> zigzag() {
    const std::vector<std::string> moves = {"G91 G1 X2 Y-1 Z0.5 A1 F3000",
                                            "X-1.5 Y1.5 Z-0.25 A-2",
                                            "X0.5 Y-2 Z1 A0.5",
                                            "X-0.25 Y0.25 Z-0.5 A-0.25",
                                            "X0.0125 Y-0.0125",
                                            "X-0.0125 Z0.0125 A0.0125",
                                            "X3 Y2 Z-1 A-1",
                                            "X-3 Y-2 Z1 A1"};
    std::vector<std::string> out;
    for (size_t i = 0; i < moves.size() && i < ll::kPlannerSize; ++i) out.push_back(moves[i]);
    return out;
}

} // namespace

TEST(FirmwarePulses, ThreeMicrosecondPulsesWithXAndZStepAndYAndADirectionInverted) {
    REQUIRE_FIRMWARE();
    // $2 = 5: X and Z step pins idle high; $3 = 10: Y and A direction inverted; $4 = 1: the
    // enable pin is active high.
    check_against_model("$0=3 $2=5 $3=10 $4=1",
                        Job{fast_machine({"$0=3", "$2=5", "$3=10", "$4=1"}), zigzag()},
                        PinSettings{3, 5, 10});
}

TEST(FirmwarePulses, TenMicrosecondPulsesWithYAndAStepAndXAndZDirectionInverted) {
    REQUIRE_FIRMWARE();
    check_against_model("$0=10 $2=10 $3=5", Job{fast_machine({"$0=10", "$2=10", "$3=5"}), zigzag()},
                        PinSettings{10, 10, 5});
}

TEST(FirmwarePulses, TenMicrosecondPulsesAtTheShortestPeriodKeepTheirWidth) {
    REQUIRE_FIRMWARE();
    // $0 = 10 us: the shortest period is 160 + 104 = 264 cycles (60.6 k steps/s); a pulse every
    // 264 cycles still lasts 160 cycles or more, and the direction setup at a reversal stays
    // above 1 us.
    check_against_model("$0=10 at min period",
                        Job{fast_machine({"$0=10", "$100=400", "$110=9999", "$120=3000"}),
                            {"G91 G1 X10 F9999", "X-10"}},
                        PinSettings{10, 0, 0});
}
