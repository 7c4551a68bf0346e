// SIMAVR-NOTES 3 (UART frame time) and the harness's serial line, against selftest_uart.
// GRBL's set-up: U2X0 = 1, UBRR0 = 16 -> one bit = (16 + 1) x 8 = 136 cycles (117647 baud, the
// Uno's "115200"), one 8N1 frame = start + 8 data + stop = 10 bits = 1360 cycles (datasheet 20.3.1,
// 20.4). simavr 1.6 adds a parity bit that is not there: 11 bits = 1496 cycles.
#include "selftest_elf.h"

using namespace ll::sim;
using ll::sim::test::all_but;
using ll::sim::test::options;

namespace {

constexpr uint64_t kFrame = 10 * 136;
constexpr uint64_t kStockFrame = 11 * 136;

struct UartRun {
    uint64_t frame = 0;
    uint64_t datasheet_frame = 0;
    std::vector<SerialByte> tx;   ///< bytes the firmware sent (cycle of the UDR0 write)
    std::vector<SerialByte> wire; ///< bytes the host sent (cycle their start bit began)
    std::vector<uint64_t> rx_isr; ///< step_y toggles: one per byte received
    uint32_t overruns = 0;
};

UartRun run_uart(const Corrections& c) {
    Sim sim(options("selftest_uart", c));
    sim.run_until_output("9", ms(20));
    UartRun r;
    r.tx = sim.output_bytes();
    sim.run_for(ms(1));
    sim.send("ABCDEFGH");
    sim.run_for(ms(10));
    r.frame = sim.frame_cycles();
    r.datasheet_frame = sim.corrector().datasheet_frame_cycles();
    r.wire = sim.input_bytes();
    for (const Edge& e : sim.edges_of("step_y")) r.rx_isr.push_back(e.cycle);
    r.overruns = sim.overruns();
    return r;
}

} // namespace

TEST(SimUartFrame, CorrectedFrameIsTenBits) {
    REQUIRE_SELFTEST("selftest_uart");
    const UartRun r = run_uart(Corrections::all());
    EXPECT_EQ(r.datasheet_frame, kFrame);
    EXPECT_EQ(r.frame, kFrame);
    ASSERT_EQ(r.tx.size(), 10u);
    // The UDRE interrupt keeps the transmitter busy: one byte per frame once it is streaming.
    for (size_t i = 2; i < r.tx.size(); ++i) EXPECT_EQ(r.tx[i].cycle - r.tx[i - 1].cycle, kFrame);
    // Received bytes: the host's bytes go back to back, the RX interrupt follows each one a frame
    // after its start bit.
    ASSERT_EQ(r.wire.size(), 8u);
    ASSERT_EQ(r.rx_isr.size(), 8u);
    for (size_t i = 1; i < r.wire.size(); ++i) {
        EXPECT_EQ(r.wire[i].cycle - r.wire[i - 1].cycle, kFrame);
        EXPECT_EQ(r.rx_isr[i] - r.rx_isr[i - 1], kFrame);
    }
    EXPECT_GT(r.rx_isr[0], r.wire[0].cycle + kFrame);
    EXPECT_EQ(r.overruns, 0u);
}

TEST(SimUartFrame, StockSimavrCountsAParityBit) {
    REQUIRE_SELFTEST("selftest_uart");
    const UartRun r = run_uart(all_but(&Corrections::uart_frame_time));
    EXPECT_EQ(r.datasheet_frame, kFrame);
    EXPECT_EQ(r.frame, kStockFrame);
    ASSERT_EQ(r.tx.size(), 10u);
    for (size_t i = 2; i < r.tx.size(); ++i)
        EXPECT_EQ(r.tx[i].cycle - r.tx[i - 1].cycle, kStockFrame);
    ASSERT_EQ(r.rx_isr.size(), 8u);
    for (size_t i = 1; i < r.rx_isr.size(); ++i)
        EXPECT_EQ(r.rx_isr[i] - r.rx_isr[i - 1], kStockFrame);
}
