// The pseudo-terminal bridge: a program opens the pty as it would open an Uno's serial port.
#include <fcntl.h>
#include <limits.h>
#include <unistd.h>

#include "pty_bridge.h"
#include "selftest_elf.h"

using namespace ll::sim;
using ll::sim::test::options;

namespace {

/// Steps the bridge (1 ms of simulated time each) until `fd` has delivered `text`.
bool read_until(int fd, PtyBridge& bridge, const std::string& text, std::string& got,
                int max_steps = 300) {
    for (int i = 0; i < max_steps; ++i) {
        bridge.step();
        char buf[256];
        ssize_t n;
        while ((n = read(fd, buf, sizeof buf)) > 0) got.append(buf, static_cast<size_t>(n));
        if (got.find(text) != std::string::npos) return true;
    }
    return false;
}

PtyBridge::Options fast() {
    PtyBridge::Options o;
    o.realtime = false; // tests need no wall-clock pacing
    return o;
}

} // namespace

TEST(SimPty, SenderTalksToTheBoard) {
    REQUIRE_SELFTEST("selftest_echo");
    Sim sim(options("selftest_echo"));
    PtyBridge bridge(sim, fast());
    EXPECT_EQ(bridge.path().compare(0, 9, "/dev/pts/"), 0) << bridge.path();
    const int fd = open(bridge.path().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    ASSERT_GE(fd, 0);
    std::string got;
    EXPECT_TRUE(read_until(fd, bridge, "[MSG:boot 1]\r\n", got)) << got;
    EXPECT_TRUE(bridge.connected());
    ASSERT_EQ(write(fd, "BOOT\n", 5), 5);
    got.clear();
    EXPECT_TRUE(read_until(fd, bridge, "[BOOT:1]\r\nok\r\n", got)) << got;
    close(fd);
    bridge.step();
    EXPECT_FALSE(bridge.connected());
}

TEST(SimPty, ResetOnOpenLikeTheUno) {
    REQUIRE_SELFTEST("selftest_echo");
    Sim sim(options("selftest_echo"));
    PtyBridge::Options o = fast();
    o.reset_on_open = true;
    PtyBridge bridge(sim, o);
    for (int i = 0; i < 20; ++i) bridge.step(); // nobody connected: output is dropped
    int fd = open(bridge.path().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    ASSERT_GE(fd, 0);
    std::string got;
    EXPECT_TRUE(read_until(fd, bridge, "[MSG:boot 2]\r\n", got)) << got; // reset at the open
    EXPECT_EQ(got.find("boot 1"), std::string::npos);
    close(fd);
    bridge.step();
    fd = open(bridge.path().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    ASSERT_GE(fd, 0);
    got.clear();
    EXPECT_TRUE(read_until(fd, bridge, "[MSG:boot 3]\r\n", got)) << got;
    close(fd);
    EXPECT_EQ(sim.resets(), 2u);
}

TEST(SimPty, OptionalLinkPointsToThePty) {
    REQUIRE_SELFTEST("selftest_echo");
    Sim sim(options("selftest_echo"));
    PtyBridge::Options o = fast();
    o.link = "/tmp/llsim_test_link_" + std::to_string(getpid());
    {
        PtyBridge bridge(sim, o);
        char target[PATH_MAX] = {0};
        ASSERT_GT(readlink(o.link.c_str(), target, sizeof target - 1), 0);
        EXPECT_EQ(bridge.path(), target);
    }
    EXPECT_NE(access(o.link.c_str(), F_OK), 0); // removed with the bridge
}
