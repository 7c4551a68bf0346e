// The host side of the serial line and the GRBL protocol helpers, EEPROM persistence, reset and
// driven inputs, against selftest_echo (a GRBL-like responder with GRBL's buffer sizes).
#include <stdio.h>
#include <unistd.h>

#include <algorithm>

#include "grbl_client.h"
#include "selftest_elf.h"

using namespace ll::sim;
using ll::sim::test::options;

namespace {

constexpr uint64_t kFrame = 1360; // one 8N1 byte at U2X0 = 1, UBRR0 = 16

std::vector<std::string> lines_of(const Grbl& g, char first) {
    std::vector<std::string> out;
    for (const OutputLine& l : g.other_lines())
        if (!l.text.empty() && l.text[0] == first) out.push_back(l.text);
    return out;
}

std::vector<std::string> gcode_lines(size_t n) {
    std::vector<std::string> lines;
    for (size_t i = 0; i < n; ++i) {
        char buf[40];
        snprintf(buf, sizeof buf, "G1 X%zu.125 Y%zu.250 F1500", i * 3, i * 7 % 100);
        lines.push_back(buf);
    }
    return lines;
}

} // namespace

TEST(SimSerial, SendAndWaitGetsOkOrError) {
    REQUIRE_SELFTEST("selftest_echo");
    Sim sim(options("selftest_echo"));
    Grbl grbl(sim);
    ASSERT_TRUE(grbl.wait_banner(ms(50)));
    EXPECT_EQ(grbl.other_lines().back().text, "Grbl 1.1h ['$' for help]");

    const Reply ok = grbl.send_line("G1 X1", ms(50));
    EXPECT_TRUE(ok.ok);
    EXPECT_FALSE(ok.timeout);
    // 6 bytes on the wire, then the firmware works 2 ms, then "ok\r\n".
    EXPECT_GT(ok.answered, ok.sent + 6 * kFrame + ms(2));

    const Reply err = grbl.send_line("E20", ms(50));
    EXPECT_FALSE(err.ok);
    EXPECT_EQ(err.error, 20);

    EXPECT_TRUE(grbl.send_line("BOOT", ms(50)).ok);
    EXPECT_EQ(lines_of(grbl, '[').back(), "[BOOT:1]");
}

TEST(SimSerial, HostBytesGoBackToBackOneFrameEach) {
    REQUIRE_SELFTEST("selftest_echo");
    Sim sim(options("selftest_echo"));
    Grbl grbl(sim);
    ASSERT_TRUE(grbl.wait_banner(ms(50)));
    sim.send("G1 X1 Y2\n");
    sim.run_for(ms(5));
    const std::vector<SerialByte>& in = sim.input_bytes();
    ASSERT_EQ(in.size(), 9u);
    for (size_t i = 1; i < in.size(); ++i) EXPECT_EQ(in[i].cycle - in[i - 1].cycle, kFrame);
}

TEST(SimSerial, CharacterCountingKeepsTheBufferFullButNeverOverflows) {
    REQUIRE_SELFTEST("selftest_echo");
    Sim sim(options("selftest_echo"));
    Grbl grbl(sim);
    ASSERT_TRUE(grbl.wait_banner(ms(50)));
    const std::vector<std::string> lines = gcode_lines(60);
    const uint64_t t0 = sim.cycle();
    const std::vector<Reply> replies = grbl.stream(lines, ms(2000));
    const uint64_t streamed = sim.cycle() - t0;
    ASSERT_EQ(replies.size(), lines.size());
    for (const Reply& r : replies) EXPECT_TRUE(r.ok) << r.line;
    EXPECT_LE(grbl.max_in_flight(), kGrblRxBuffer);
    EXPECT_GT(grbl.max_in_flight(), kGrblRxBuffer - 30); // the buffer was really kept full
    EXPECT_EQ(sim.overruns(), 0u);
    EXPECT_TRUE(grbl.send_line("STAT", ms(50)).ok);
    EXPECT_EQ(lines_of(grbl, '[').back(), "[RXOVF:0]"); // the firmware's ring never overflowed

    // Send-and-wait leaves the line idle while the firmware works: slower for the same lines.
    Sim sim2(options("selftest_echo"));
    Grbl g2(sim2);
    ASSERT_TRUE(g2.wait_banner(ms(50)));
    const uint64_t t1 = sim2.cycle();
    for (const std::string& l : lines) ASSERT_TRUE(g2.send_line(l, ms(100)).ok);
    EXPECT_GT(sim2.cycle() - t1, streamed);
}

TEST(SimSerial, RealTimeBytesAtACycleAndEveryPeriod) {
    REQUIRE_SELFTEST("selftest_echo");
    Sim sim(options("selftest_echo"));
    Grbl grbl(sim);
    ASSERT_TRUE(grbl.wait_banner(ms(50)));
    const uint64_t t0 = sim.cycle();
    // '?' every 50 ms for 250 ms, while G-code streams: 6 reports, and every line still gets its
    // own ok (real-time bytes do not count in character counting).
    sim.send_every('?', t0 + ms(10), ms(50), t0 + ms(260));
    const std::vector<Reply> replies = grbl.stream(gcode_lines(40), ms(400));
    for (const Reply& r : replies) EXPECT_TRUE(r.ok) << r.line;
    sim.run_until_cycle(t0 + ms(300));
    grbl.collect();
    const std::vector<std::string> reports = lines_of(grbl, '<');
    EXPECT_EQ(reports.size(), 6u);
    // A byte at a chosen cycle: '?' starts on the wire exactly then.
    sim.send_at(t0 + ms(320), "?");
    sim.run_until_cycle(t0 + ms(330));
    ASSERT_FALSE(sim.input_bytes().empty());
    EXPECT_EQ(sim.input_bytes().back().byte, '?');
    EXPECT_EQ(sim.input_bytes().back().cycle, t0 + ms(320));
    EXPECT_EQ(grbl.status(ms(10)).substr(0, 5), "<Idle");
}

TEST(SimSerial, SoftResetByteRestartsTheProtocol) {
    REQUIRE_SELFTEST("selftest_echo");
    Sim sim(options("selftest_echo"));
    Grbl grbl(sim);
    ASSERT_TRUE(grbl.wait_banner(ms(50)));
    sim.send(std::string(1, '\x18'));
    EXPECT_TRUE(grbl.wait_banner(ms(20)));
}

TEST(SimSerial, CountsBytesTheHardwareWouldLose) {
    REQUIRE_SELFTEST("selftest_poll");
    // selftest_poll stops reading UDR0 after its poll loop, with the receiver still on.
    Sim sim(options("selftest_poll"));
    ASSERT_TRUE(sim.run_until_pc(sim.symbol("poll_done"), ms(100)));
    sim.send("0123456789");
    sim.run_for(ms(20));
    // Bytes 0 and 1 fill the 2-byte receive FIFO; bytes 2..9 find it full.
    EXPECT_EQ(sim.overruns(), 8u);
}

TEST(SimChip, EepromSurvivesResetAndFiles) {
    REQUIRE_SELFTEST("selftest_echo");
    char path[] = "/tmp/llsim_eeprom_XXXXXX";
    const int fd = mkstemp(path);
    ASSERT_GE(fd, 0);
    close(fd);
    {
        Sim sim(options("selftest_echo"));
        Grbl grbl(sim);
        ASSERT_TRUE(sim.run_until_output("[MSG:boot 1]", ms(50))); // a blank chip
        sim.reset(); // as the Uno's DTR reset: EEPROM kept
        EXPECT_EQ(sim.resets(), 1u);
        ASSERT_TRUE(sim.run_until_output("[MSG:boot 2]", ms(50)));
        EXPECT_EQ(sim.eeprom().size(), 1024u);
        EXPECT_EQ(sim.eeprom()[0], 2);
        EXPECT_EQ(sim.eeprom()[1], 0xFF);
        sim.save_eeprom(path);
    }
    Options o = options("selftest_echo");
    o.eeprom_file = path;
    Sim again(o);
    EXPECT_TRUE(again.run_until_output("[MSG:boot 3]", ms(50)));
    unlink(path);
}

TEST(SimChip, DrivenInputsAreRestoredAfterReset) {
    REQUIRE_SELFTEST("selftest_echo");
    Sim sim(options("selftest_echo"));
    Grbl grbl(sim);
    ASSERT_TRUE(grbl.wait_banner(ms(50)));
    ASSERT_TRUE(grbl.send_line("PIN", ms(50)).ok);
    EXPECT_EQ(lines_of(grbl, '[').back(), "[PINB:0e]"); // PB1..PB3 pulled up by the firmware
    sim.set_input('B', 1, false);                       // X limit switch closed
    ASSERT_TRUE(grbl.send_line("PIN", ms(50)).ok);
    EXPECT_EQ(lines_of(grbl, '[').back(), "[PINB:0c]");
    sim.reset();
    EXPECT_EQ(sim.pin_register('B') & 0x02, 0); // SIMAVR-NOTES 8: still closed after the reset
    ASSERT_TRUE(grbl.wait_banner(ms(50)));
    ASSERT_TRUE(grbl.send_line("PIN", ms(50)).ok);
    EXPECT_EQ(lines_of(grbl, '[').back(), "[PINB:0c]");
    sim.set_input('B', 1, true);
    ASSERT_TRUE(grbl.send_line("PIN", ms(50)).ok);
    EXPECT_EQ(lines_of(grbl, '[').back(), "[PINB:0e]");
}

TEST(SimChip, RawAvrResetLosesPullUps) {
    // Why Sim::reset() restores the pins: after a bare avr_reset() the firmware's pull-ups read
    // low, as if every limit switch were closed (SIMAVR-NOTES 8).
    REQUIRE_SELFTEST("selftest_echo");
    Sim sim(options("selftest_echo"));
    Grbl grbl(sim);
    ASSERT_TRUE(grbl.wait_banner(ms(50)));
    avr_reset(sim.avr());
    ASSERT_TRUE(grbl.wait_banner(ms(50)));
    ASSERT_TRUE(grbl.send_line("PIN", ms(50)).ok);
    EXPECT_EQ(lines_of(grbl, '[').back(), "[PINB:00]");
}

TEST(SimChip, MissingFirmwareIsAClearError) {
    Options o;
    o.elf = "/nonexistent/firmware.elf";
    try {
        Sim sim(o);
        FAIL() << "no exception";
    } catch (const SimError& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent/firmware.elf"), std::string::npos);
    }
}

TEST(SimGcode, ReadsFilesLikeStreamPy) {
    char path[] = "/tmp/llsim_gcode_XXXXXX";
    const int fd = mkstemp(path);
    ASSERT_GE(fd, 0);
    const char text[] = "G21 ; mm\n  (a comment)\n\nG1 X1 (inline) Y2\r\nM2\n";
    ASSERT_EQ(write(fd, text, sizeof text - 1), static_cast<ssize_t>(sizeof text - 1));
    close(fd);
    const std::vector<std::string> lines = read_gcode_file(path);
    unlink(path);
    ASSERT_EQ(lines.size(), 3u);
    EXPECT_EQ(lines[0], "G21");
    EXPECT_EQ(lines[1], "G1 X1  Y2");
    EXPECT_EQ(lines[2], "M2");
}
