#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "host_hal.h"
#include "lowlevel/gcode.h"
#include "lowlevel/motion.h"
#include "lowlevel/numparse.h"
#include "lowlevel/settings.h"
#include "lowlevel/status.h"

namespace gcode = ll::gcode;
namespace status = ll::status;
using ll::g_settings;
using ll::kAxes;

namespace {

class GCode : public ::testing::Test {
  protected:
    void SetUp() override {
        // Power-up: blank EEPROM (defaults), machine at zero, fresh parser state.
        ll::host::reset_model(true);
        ll::settings::load();
        ll::motion::init();
        ll::motion::settings_changed();
        gcode::reset();
        ASSERT_EQ(gcode::g_state.position_steps[0], 0);
        ll::host::take_output();
    }

    uint8_t run(const std::string& line, uint8_t flags = 0) {
        uint8_t r = gcode::execute(line.c_str(), flags, outcome);
        if (outcome.move) ll::motion::push_line(*outcome.move);
        return r;
    }
    // Runs a line that must succeed, waiting out nothing (dwell lines are re-run as the protocol
    // does once the dwell is over).
    void ok(const std::string& line) {
        uint8_t r = run(line);
        for (int spins = 0; r == gcode::kRetryWhenAccepting || r == gcode::kRetryWhenIdle;
             ++spins) {
            ASSERT_LT(spins, 10000000) << line; // let simulated time run the queued moves
            ll::motion::poll();
            ll::host::advance_to(ll::host::now() + 1600);
            r = run(line);
        }
        if (r == gcode::kDwell) r = run(line, gcode::kDwellDone);
        ASSERT_EQ(r, status::kOk) << line;
    }
    // The step target sent to the planner for `axis` (the machine gets there in its own time).
    int32_t steps(uint8_t axis) { return gcode::g_state.position_steps[axis]; }
    int32_t machine_steps(uint8_t axis) {
        int32_t s[kAxes];
        ll::motion::position(s);
        return s[axis];
    }
    void set_steps_per_mm(uint8_t axis, uint32_t milli) {
        g_settings.axis[axis].steps_per_unit = milli;
        gcode::settings_changed();
    }
    // A bad line must leave the whole parser state as it was.
    void rejected(const std::string& line, uint8_t code) {
        gcode::State before = gcode::g_state;
        int32_t s0[kAxes];
        ll::motion::position(s0);
        EXPECT_EQ(run(line), code) << line;
        EXPECT_EQ(std::memcmp(&before, &gcode::g_state, sizeof before), 0) << line;
        int32_t s1[kAxes];
        ll::motion::position(s1);
        EXPECT_EQ(std::memcmp(s0, s1, sizeof s0), 0) << line;
    }
    gcode::Outcome outcome{};
};

} // namespace

TEST_F(GCode, ResetStateIsGrblsPowerUpState) {
    EXPECT_EQ(gcode::g_state.modal.motion, gcode::Motion::Seek);
    ll::host::take_output();
    gcode::report_modes();
    EXPECT_EQ(ll::host::take_output(), "[GC:G0 G54 G17 G21 G90 G94 M5 M9 T0 F0 S0]\r\n");
}

TEST_F(GCode, LinearMoveTargetsStepsAndMicrometres) {
    ok("G1X10Y-2.5F500");
    EXPECT_EQ(gcode::g_state.position[0], 10000);
    EXPECT_EQ(gcode::g_state.position[1], -2500);
    EXPECT_EQ(steps(0), 2500);
    EXPECT_EQ(steps(1), -625);
    EXPECT_EQ(gcode::g_state.feed, 500000u);
    EXPECT_EQ(gcode::g_state.modal.motion, gcode::Motion::Linear);
}

TEST_F(GCode, RapidNeedsNoFeedAndKeepsTheFeed) {
    ok("G0X1Z2A3");
    EXPECT_EQ(steps(2), 500);
    EXPECT_EQ(steps(3), 750);
    EXPECT_EQ(gcode::g_state.feed, 0u);
}

TEST_F(GCode, AxisWordsAloneUseTheModalMotion) {
    ok("G1F100");
    ok("X4");
    EXPECT_EQ(steps(0), 1000);
    ok("G0");
    ok("X1");
    EXPECT_EQ(gcode::g_state.modal.motion, gcode::Motion::Seek);
    EXPECT_EQ(steps(0), 250);
}

TEST_F(GCode, HundredRelativeTenthsEndExactlyOnTarget) {
    set_steps_per_mm(0, 80000);
    ok("G91G1F1000");
    for (int i = 0; i < 100; ++i) ok("X0.1");
    EXPECT_EQ(steps(0), 800);
    EXPECT_EQ(gcode::g_state.position[0], 10000);
    // The same with a step size that does not divide 0.1 mm: still from the absolute target.
    set_steps_per_mm(1, 3333);
    for (int i = 0; i < 100; ++i) ok("Y0.1");
    EXPECT_EQ(steps(1), 33); // 10 mm x 3.333 = 33.33
}

TEST_F(GCode, StepTargetsRoundHalfAwayFromZero) {
    set_steps_per_mm(0, 2000); // 2 steps/mm: 0.25 mm is half a step
    ok("G0X0.25");
    EXPECT_EQ(steps(0), 1);
    ok("G0X-0.25");
    EXPECT_EQ(steps(0), -1);
    ok("G0X0.249");
    EXPECT_EQ(steps(0), 0);
    ok("G0X-0.75");
    EXPECT_EQ(steps(0), -2);
    ok("G0X0.75");
    EXPECT_EQ(steps(0), 2);
}

TEST_F(GCode, InchesConvertToMicrometres) {
    ok("G20G0X1Y0.0001");
    EXPECT_EQ(gcode::g_state.position[0], 25400);
    EXPECT_EQ(gcode::g_state.position[1], 3);
    EXPECT_EQ(steps(0), 6350);
    ok("G1X0F10"); // 10 in/min
    EXPECT_EQ(gcode::g_state.feed, 254000u);
    ok("G21X1"); // units change in the same block applies to it
    EXPECT_EQ(gcode::g_state.position[0], 1000);
}

TEST_F(GCode, UnitsWordAfterTheAxisWordStillApplies) {
    ok("X1G20");
    EXPECT_EQ(gcode::g_state.position[0], 25400);
}

TEST_F(GCode, IncrementalAndAbsoluteDistance) {
    ok("G91G0X1");
    ok("X1");
    EXPECT_EQ(gcode::g_state.position[0], 2000);
    ok("G90X1");
    EXPECT_EQ(gcode::g_state.position[0], 1000);
}

TEST_F(GCode, G92OffsetsWorkCoordinatesAndG921ClearsThem) {
    ok("G0X10");
    ok("G92X0Y5");
    EXPECT_EQ(gcode::g_state.g92[0], 10000);
    EXPECT_EQ(gcode::g_state.g92[1], -5000);
    ok("X1");
    EXPECT_EQ(gcode::g_state.position[0], 11000);
    EXPECT_EQ(gcode::g_state.wco_changed, 1);
    ok("G92.1");
    EXPECT_EQ(gcode::g_state.g92[0], 0);
    ok("X1");
    EXPECT_EQ(gcode::g_state.position[0], 1000);
}

TEST_F(GCode, G53MovesInMachineCoordinates) {
    ok("G92X0"); // nothing moved: offset 0
    ok("G0X5");
    ok("G92X0"); // work 0 = machine 5
    ok("G53G0X1");
    EXPECT_EQ(gcode::g_state.position[0], 1000);
    ok("G91G53X2"); // G53 is absolute even in G91
    EXPECT_EQ(gcode::g_state.position[0], 2000);
}

TEST_F(GCode, G10SetsG54AndStoresIt) {
    ok("G0X10Y10");
    ok("G10L20P1X0");
    EXPECT_EQ(gcode::g_state.g54[0], 10000);
    ok("G10L2P0Y-3");
    EXPECT_EQ(gcode::g_state.g54[1], -3000);
    int32_t stored[kAxes];
    ASSERT_TRUE(ll::settings::load_coord(stored));
    EXPECT_EQ(stored[0], 10000);
    EXPECT_EQ(stored[1], -3000);
    ok("G0X1");
    EXPECT_EQ(gcode::g_state.position[0], 11000);
    ll::host::take_output();
    gcode::report_offsets();
    std::string out = ll::host::take_output();
    EXPECT_EQ(out.substr(0, 36), "[G54:10.000,-3.000,0.000,0.000]\r\n[G5");
}

TEST_F(GCode, G10IsRejectedWithoutItsWords) {
    rejected("G10L20X0", status::kValueWordMissing);
    rejected("G10P1X0", status::kValueWordMissing);
    rejected("G10L20P1", status::kNoAxisWords);
    rejected("G10L3P1X0", status::kUnsupportedCommand);
    rejected("G10L20P2X0", status::kUnsupportedCoordSys);
}

TEST_F(GCode, DwellAsksToWaitThenRuns) {
    EXPECT_EQ(run("G4P1.5"), gcode::kDwell);
    EXPECT_EQ(outcome.dwell_ms, 1500u);
    EXPECT_EQ(run("G4P1.5", gcode::kDwellDone), status::kOk);
    EXPECT_EQ(run("G4P1.5", gcode::kCheckMode), status::kOk); // no wait in check mode
}

TEST_F(GCode, ProgramFlowWords) {
    ASSERT_EQ(run("M0"), status::kOk);
    EXPECT_EQ(outcome.then, gcode::Then::Pause);
    ASSERT_EQ(run("M1"), status::kOk);
    EXPECT_EQ(outcome.then, gcode::Then::Nothing);
    ok("G91G1F100G18M3M8");
    ASSERT_EQ(run("M30"), status::kOk);
    EXPECT_EQ(outcome.then, gcode::Then::ProgramEnd);
    ll::host::take_output();
    gcode::report_modes();
    EXPECT_EQ(ll::host::take_output(), "[GC:G1 G54 G17 G21 G90 G94 M5 M9 T0 F100 S0]\r\n");
    ASSERT_EQ(run("M2"), status::kOk);
    EXPECT_EQ(outcome.then, gcode::Then::ProgramEnd);
}

TEST_F(GCode, TrackedWordsAppearInTheParserState) {
    ok("N12G17G21G40G49G54G61G80G90G91.1G94M4S1200T3M8");
    EXPECT_EQ(gcode::g_state.line_number, 12u);
    ll::host::take_output();
    gcode::report_modes();
    EXPECT_EQ(ll::host::take_output(), "[GC:G80 G54 G17 G21 G90 G94 M4 M8 T3 F0 S1200]\r\n");
    ok("G19");
    EXPECT_EQ(gcode::g_state.modal.plane, 2);
    ok("S1199.5"); // S rounded half up to whole rpm
    EXPECT_EQ(gcode::g_state.spindle_speed, 1200u);
    ok("S1199.499");
    EXPECT_EQ(gcode::g_state.spindle_speed, 1199u);
}

TEST_F(GCode, CheckModeUpdatesTheParserButMovesNothing) {
    int32_t before = machine_steps(0);
    ASSERT_EQ(run("G1X10F100", gcode::kCheckMode), status::kOk);
    EXPECT_EQ(gcode::g_state.position[0], 10000);
    EXPECT_EQ(steps(0), 2500);
    EXPECT_EQ(machine_steps(0), before);
    ASSERT_EQ(run("M0", gcode::kCheckMode), status::kOk);
    EXPECT_EQ(outcome.then, gcode::Then::Nothing);
}

TEST_F(GCode, SyncPositionTakesTheMachinePosition) {
    set_steps_per_mm(0, 3200000); // 3200 steps/mm: 1 um is 3.2 steps
    ok("G0X0.0013");              // 1 um -> 3 steps (3.2 rounded)
    EXPECT_EQ(steps(0), 3);
    for (long spins = 0; ll::motion::state() != ll::motion::State::Idle; ++spins) {
        ASSERT_LT(spins, 10000000L);
        ll::motion::poll();
        ll::host::advance_to(ll::host::now() + 1600);
    }
    ASSERT_EQ(machine_steps(0), 3);
    gcode::sync_position();
    EXPECT_EQ(gcode::g_state.position_steps[0], 3); // the real steps, not recomputed from um
    EXPECT_EQ(gcode::g_state.position[0], 1);
}

// ---- one test per error code ------------------------------------------------------------

TEST_F(GCode, Error1ExpectedCommandLetter) {
    rejected("1", status::kExpectedCommandLetter);
    rejected("G1X1-2F100", status::kExpectedCommandLetter);
    rejected("G0X1.2.3", status::kExpectedCommandLetter);
}

TEST_F(GCode, Error2BadNumberFormat) {
    rejected("G", status::kBadNumberFormat);
    rejected("G0X", status::kBadNumberFormat);
    rejected("G0X-", status::kBadNumberFormat);
    rejected("G0X3000000", status::kBadNumberFormat); // does not fit um in an int32
}

TEST_F(GCode, Error4NegativeValue) {
    rejected("G1X1F-100", status::kNegativeValue);
    rejected("G4P-1", status::kNegativeValue);
    rejected("N-5G0X1", status::kNegativeValue);
    rejected("S-1", status::kNegativeValue);
    rejected("T-1", status::kNegativeValue);
}

TEST_F(GCode, Error20UnsupportedCommand) {
    for (const char* line : {"G28", "G38.2Z-1", "G93", "G90.1", "G92.2", "G61.1", "M6", "M7", "G-1",
                             "M-1", "D1", "W1", "B1", "G10L5P1X0"}) {
        rejected(line, status::kUnsupportedCommand);
    }
}

TEST_F(GCode, Error21ModalGroupViolation) {
    rejected("G0G80", status::kModalGroupViolation);
    rejected("G90G91", status::kModalGroupViolation);
    rejected("M3M5", status::kModalGroupViolation);
    rejected("G4P1G53X1", status::kModalGroupViolation);
}

TEST_F(GCode, Error22UndefinedFeedRate) {
    rejected("G1X1", status::kUndefinedFeedRate);
    rejected("G1", status::kUndefinedFeedRate);
    rejected("G1X1F0", status::kUndefinedFeedRate);
}

TEST_F(GCode, Error23CommandValueNotInteger) {
    rejected("G1.5X1F1", status::kCommandValueNotInteger);
    rejected("G0.01X1", status::kCommandValueNotInteger);
    rejected("M3.5", status::kCommandValueNotInteger);
    rejected("G59.1", status::kCommandValueNotInteger);
    rejected("T1.5", status::kCommandValueNotInteger);
}

TEST_F(GCode, Error24AxisCommandConflict) {
    rejected("G0G92X1", status::kAxisCommandConflict);
    rejected("G10G1L20P1X1", status::kAxisCommandConflict);
    rejected("G0G1X1", status::kAxisCommandConflict); // checked before the modal group, as GRBL
}

TEST_F(GCode, Error25WordRepeated) {
    rejected("G0X1X2", status::kWordRepeated);
    rejected("G1X1F1F2", status::kWordRepeated);
}

TEST_F(GCode, Error26NoAxisWords) {
    rejected("G92", status::kNoAxisWords);
}

TEST_F(GCode, Error27InvalidLineNumber) {
    rejected("N10000001G0X1", status::kInvalidLineNumber);
    rejected("N1.5G0X1", status::kInvalidLineNumber);
    ok("N10000000G0X1");
}

TEST_F(GCode, Error28ValueWordMissing) {
    rejected("G4", status::kValueWordMissing);
}

TEST_F(GCode, Error29UnsupportedCoordinateSystem) {
    rejected("G55", status::kUnsupportedCoordSys);
    rejected("G59X1", status::kUnsupportedCoordSys);
}

TEST_F(GCode, Error30G53NeedsG0OrG1) {
    rejected("G53G80", status::kG53InvalidMotionMode);
}

TEST_F(GCode, Error31AxisWordsWithG80) {
    rejected("G80X1", status::kAxisWordsExist);
    ok("G80");
    rejected("X1", status::kAxisWordsExist);
}

TEST_F(GCode, Error33TargetOutOfRange) {
    set_steps_per_mm(0, 2000000);                   // 2000 steps/mm: 2000 m is 4e9 steps
    rejected("G0X2000000", status::kInvalidTarget); // 4e9 steps
    set_steps_per_mm(0, 1000);
    ok("G91G0X2000000");
    rejected("X2000000", status::kInvalidTarget); // 4000 m does not fit an int32 of um
}

TEST_F(GCode, Error36UnusedWords) {
    rejected("G0X1P1", status::kUnusedWords);
    rejected("G1X1F100I1", status::kUnusedWords);
    rejected("L2", status::kUnusedWords);
    rejected("G80G4P1X1", status::kAxisWordsExist);
}

TEST_F(GCode, Error38ToolNumberAbove255) {
    rejected("T256", status::kMaxValueExceeded);
}

TEST_F(GCode, ARejectedLineChangesNoModalState) {
    ok("G1F200");
    rejected("G91G20G18M3S100T2N5X1Q1", status::kUnusedWords);
    EXPECT_EQ(gcode::g_state.modal.incremental, 0);
    EXPECT_EQ(gcode::g_state.modal.inches, 0);
    ok("X2"); // the next valid line runs as if the bad one never came
    EXPECT_EQ(gcode::g_state.position[0], 2000);
    EXPECT_EQ(gcode::g_state.feed, 200000u);
}

TEST_F(GCode, StepScalingMatchesTheExactRoundedQuotient) {
    uint32_t scales[] = {1,      999,     1000,    80000,   250000,   3333,
                         999999, 1000000, 1000001, 3200000, 51200000, 2147483647};
    uint32_t seed = 12345;
    for (uint32_t s : scales) {
        set_steps_per_mm(0, s);
        for (int i = 0; i < 20000; ++i) {
            seed = seed * 1664525u + 1013904223u;
            int32_t um = static_cast<int32_t>(seed) >> (seed % 31);
            int32_t expect = 0, got = 0;
            bool fits = ll::num::mul_div_round(um, s, 1000000u, expect);
            bool ok = gcode::um_to_steps(0, um, got);
            ASSERT_EQ(ok, fits && expect != INT32_MIN) << s << " " << um;
            if (ok) {
                ASSERT_EQ(got, expect) << s << " " << um;
            }
        }
    }
}
