// SIMAVR-NOTES 5 (UART poll sleep), against selftest_poll: POLLS reads of UCSR0A with nothing
// received. This executable replaces the C library's usleep() (libsimavr calls it through the
// PLT, so the definition here wins) to count the calls stock simavr makes on the host.
#include <dlfcn.h>
#include <unistd.h>

#include <chrono>

#include "selftest_elf.h"

using namespace ll::sim;
using ll::sim::test::all_but;
using ll::sim::test::options;

namespace {

unsigned g_usleep_calls = 0;
constexpr unsigned kPolls = 5000; // selftest_poll.c POLLS

struct PollRun {
    uint64_t done_cycle = 0; ///< cycle of label poll_done
    unsigned usleeps = 0;
    double wall_seconds = 0;
};

PollRun run_poll(const Corrections& c) {
    Sim sim(options("selftest_poll", c));
    const unsigned before = g_usleep_calls;
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_TRUE(sim.run_until_pc(sim.symbol("poll_done"), ms(100)));
    PollRun r;
    r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.done_cycle = sim.cycle();
    r.usleeps = g_usleep_calls - before;
    return r;
}

} // namespace

extern "C" int usleep(useconds_t usec) {
    using Fn = int (*)(useconds_t);
    static Fn real = reinterpret_cast<Fn>(dlsym(RTLD_NEXT, "usleep"));
    ++g_usleep_calls;
    return real ? real(usec) : 0;
}

TEST(SimUartPollSleep, CorrectedNeverSleepsTheHost) {
    REQUIRE_SELFTEST("selftest_poll");
    const PollRun r = run_poll(Corrections::all());
    EXPECT_EQ(r.usleeps, 0u);
    RecordProperty("wall_ms", std::to_string(r.wall_seconds * 1000));
}

TEST(SimUartPollSleep, StockSimavrSleepsOnEveryPoll) {
    REQUIRE_SELFTEST("selftest_poll");
    const PollRun stock = run_poll(all_but(&Corrections::uart_no_poll_sleep));
    const PollRun fixed = run_poll(Corrections::all());
    EXPECT_EQ(stock.usleeps, kPolls);              // one usleep(1) per UCSR0A read
    EXPECT_GE(stock.wall_seconds, kPolls * 1e-6);  // at least 1 us of wall time each
    EXPECT_EQ(stock.done_cycle, fixed.done_cycle); // simulated time is not affected
    RecordProperty("stock_wall_ms", std::to_string(stock.wall_seconds * 1000));
    RecordProperty("corrected_wall_ms", std::to_string(fixed.wall_seconds * 1000));
}
