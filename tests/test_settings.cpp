#include <gtest/gtest.h>

#include <string>

#include "host_hal.h"
#include "lowlevel/settings.h"
#include "lowlevel/status.h"

using ll::g_settings;
namespace settings = ll::settings;
namespace status = ll::status;

namespace {

ll::num::Decimal dec(const char* text) {
    ll::num::Decimal d{};
    uint8_t pos = 0;
    EXPECT_TRUE(ll::num::parse(text, pos, d));
    return d;
}

class Settings : public ::testing::Test {
  protected:
    void SetUp() override {
        ll::host::reset_model(true);
        settings::load(); // blank: defaults written
        ll::host::take_output();
    }
};

} // namespace

TEST_F(Settings, BlankEepromRestoresAndWritesTheDefaults) {
    ll::host::reset_model(true);
    g_settings.axis[0].steps_per_unit = 1;
    EXPECT_FALSE(settings::load());
    EXPECT_EQ(g_settings.pulse_us, 10);
    EXPECT_EQ(g_settings.idle_delay_ms, 25);
    EXPECT_EQ(g_settings.status_mask, 3);
    EXPECT_EQ(g_settings.junction_dev, 10u);
    EXPECT_EQ(g_settings.arc_tolerance, 2u);
    for (uint8_t a = 0; a < ll::kAxes; ++a) {
        EXPECT_EQ(g_settings.axis[a].steps_per_unit, 250000u);
        EXPECT_EQ(g_settings.axis[a].max_rate, 500000u);
        EXPECT_EQ(g_settings.axis[a].accel, 10000u);
        EXPECT_EQ(g_settings.axis[a].max_travel, 200000u);
        EXPECT_EQ(g_settings.axis_group[a], a < 3 ? 0 : 1);
    }
    EXPECT_EQ(ll::host::eeprom()[0], settings::kEepromVersion);
    EXPECT_TRUE(settings::load()); // written: the next start finds them
}

TEST_F(Settings, CorruptChecksumRestoresTheDefaults) {
    ASSERT_EQ(settings::store(100, dec("80")), status::kOk);
    ll::host::eeprom()[settings::kEepromSettingsAddr + 3] ^= 0x01;
    EXPECT_FALSE(settings::load());
    EXPECT_EQ(g_settings.axis[0].steps_per_unit, 250000u);
    EXPECT_TRUE(settings::load());
}

TEST_F(Settings, GrblsOwnLayoutIsNotMistakenForOurs) {
    ll::host::eeprom()[0] = 10; // GRBL 1.1's settings version
    EXPECT_FALSE(settings::load());
}

TEST_F(Settings, StoredValueSurvivesAReload) {
    ASSERT_EQ(settings::store(101, dec("80.125")), status::kOk);
    g_settings.axis[1].steps_per_unit = 0;
    ASSERT_TRUE(settings::load());
    EXPECT_EQ(g_settings.axis[1].steps_per_unit, 80125u);
}

TEST_F(Settings, EverySupportedNumberIsStored) {
    struct Case {
        uint8_t n;
        const char* v;
    };
    for (Case c : {Case{0, "5"},
                   {1, "255"},
                   {2, "7"},
                   {3, "3"},
                   {4, "1"},
                   {5, "1"},
                   {6, "1"},
                   {10, "1"},
                   {11, "0.02"},
                   {12, "0.004"},
                   {13, "1"},
                   {100, "80"},
                   {110, "900"},
                   {120, "50.5"},
                   {130, "300"},
                   {140, "2"},
                   {143, "0"}}) {
        EXPECT_EQ(settings::store(c.n, dec(c.v)), status::kOk) << int(c.n);
    }
    EXPECT_EQ(g_settings.pulse_us, 5);
    EXPECT_EQ(g_settings.idle_delay_ms, 255);
    EXPECT_EQ(g_settings.step_invert, 7);
    EXPECT_EQ(g_settings.dir_invert, 3);
    EXPECT_EQ(g_settings.enable_invert, 1);
    EXPECT_EQ(g_settings.limit_invert, 1);
    EXPECT_EQ(g_settings.probe_invert, 1);
    EXPECT_EQ(g_settings.status_mask, 1);
    EXPECT_EQ(g_settings.junction_dev, 20u);
    EXPECT_EQ(g_settings.arc_tolerance, 4u);
    EXPECT_EQ(g_settings.report_inches, 1);
    EXPECT_EQ(g_settings.axis[0].steps_per_unit, 80000u);
    EXPECT_EQ(g_settings.axis[0].max_rate, 900000u);
    EXPECT_EQ(g_settings.axis[0].accel, 50500u);
    EXPECT_EQ(g_settings.axis[0].max_travel, 300000u);
    EXPECT_EQ(g_settings.axis_group[0], 2);
    EXPECT_EQ(g_settings.axis_group[3], 0);
}

TEST_F(Settings, NegativeValueIsError4) {
    EXPECT_EQ(settings::store(1, dec("-1")), status::kNegativeValue);
    EXPECT_EQ(settings::store(100, dec("-250")), status::kNegativeValue);
}

TEST_F(Settings, ZeroWhereADivisorIsNeededIsError4) {
    EXPECT_EQ(settings::store(100, dec("0")), status::kNegativeValue);
    EXPECT_EQ(settings::store(111, dec("0")), status::kNegativeValue);
    EXPECT_EQ(settings::store(122, dec("0")), status::kNegativeValue);
    EXPECT_EQ(settings::store(12, dec("0")), status::kNegativeValue);
    EXPECT_EQ(settings::store(130, dec("0")), status::kOk); // travel may be zero
    EXPECT_EQ(settings::store(11, dec("0")), status::kOk);  // exact stops
}

TEST_F(Settings, StepPulseBelow3usIsError6) {
    EXPECT_EQ(settings::store(0, dec("2")), status::kStepPulseMin);
    EXPECT_EQ(g_settings.pulse_us, 10);
    EXPECT_EQ(settings::store(0, dec("3")), status::kOk);
}

TEST_F(Settings, OutOfRangeOrFractionalIntegerIsError3) {
    EXPECT_EQ(settings::store(1, dec("256")), status::kInvalidStatement);
    EXPECT_EQ(settings::store(1, dec("2.5")), status::kInvalidStatement);
    EXPECT_EQ(settings::store(4, dec("2")), status::kInvalidStatement);
    EXPECT_EQ(settings::store(140, dec("4")), status::kInvalidStatement); // groups 0..kAxes-1
    EXPECT_EQ(settings::store(100, dec("2147484")), status::kInvalidStatement);
    EXPECT_EQ(g_settings.idle_delay_ms, 25);
}

TEST_F(Settings, UnknownNumberIsError3) {
    for (uint8_t n : {7, 9, 14, 20, 22, 32, 99, 104, 150, 200}) {
        EXPECT_EQ(settings::store(n, dec("1")), status::kInvalidStatement) << int(n);
    }
}

TEST_F(Settings, ReportPrintsEveryValueLikeGrbl) {
    ll::host::take_output();
    settings::report();
    EXPECT_EQ(ll::host::take_output(),
              "$0=10\r\n$1=25\r\n$2=0\r\n$3=0\r\n$4=0\r\n$5=0\r\n$6=0\r\n$10=3\r\n"
              "$11=0.010\r\n$12=0.002\r\n$13=0\r\n"
              "$100=250.000\r\n$101=250.000\r\n$102=250.000\r\n$103=250.000\r\n"
              "$110=500.000\r\n$111=500.000\r\n$112=500.000\r\n$113=500.000\r\n"
              "$120=10.000\r\n$121=10.000\r\n$122=10.000\r\n$123=10.000\r\n"
              "$130=200.000\r\n$131=200.000\r\n$132=200.000\r\n$133=200.000\r\n"
              "$140=0\r\n$141=0\r\n$142=0\r\n$143=1\r\n");
}

TEST_F(Settings, WorkOffsetsPersistWithTheirOwnChecksum) {
    int32_t g54[ll::kAxes] = {1000, -2000, 3, 0};
    settings::save_coord(g54);
    int32_t back[ll::kAxes] = {};
    EXPECT_TRUE(settings::load_coord(back));
    EXPECT_EQ(back[0], 1000);
    EXPECT_EQ(back[1], -2000);
    ll::host::eeprom()[settings::kEepromCoordAddr + 1] ^= 0x40;
    EXPECT_FALSE(settings::load_coord(back));
    EXPECT_EQ(back[0], 0);
    EXPECT_TRUE(settings::load_coord(back)); // zeros were written back
}
