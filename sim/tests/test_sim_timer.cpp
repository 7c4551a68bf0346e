// SIMAVR-NOTES 1 (Timer1 CTC with OCR1A = 0) and the interrupt timing corrections, against
// selftest_timer. Cycle arithmetic (ATmega328P datasheet 6.7.1, AVR Instruction Set Manual):
//   interrupt response 4; ISR = jmp 3 + push 2 + ldi 1 + out 1 + pop 2 + reti 4 = 13, with the
//   step_x OUT 6 cycles after the vector is entered; after RETI exactly one main instruction runs.
//   Timer1 at prescaler 1: a compare flag rises (OCR1A + 1) cycles after the counter was cleared.
// Absolute offsets use the harness convention that a register write takes effect at the cycle its
// instruction starts (the cycle of label timer_start / ocr_write); intervals need no convention.
#include "selftest_elf.h"

using namespace ll::sim;
using ll::sim::test::all_but;
using ll::sim::test::options;

namespace {

constexpr uint64_t kResponse = 4;    // interrupt response (datasheet 6.7.1)
constexpr uint64_t kToOut = 6;       // vector jmp 3 + push 2 + ldi 1
constexpr uint64_t kIsr = 13;        // whole TOGGLE_ISR including reti
constexpr uint64_t kPhaseBOcr = 299; // selftest_timer.c PHASE_B_OCR
constexpr int kPhaseANops = 20;      // selftest_timer.c PHASE_A_NOPS

struct TimerRun {
    uint64_t start = 0;            ///< cycle of the STS that starts Timer1 with OCR1A = 0
    uint64_t ocr_write = 0;        ///< cycle of the STS OCR1AL that makes OCR1A = 299
    std::vector<uint64_t> phase_a; ///< step_x toggles up to and including the one after ocr_write
    std::vector<uint64_t> phase_b; ///< step_x toggles caused by OCR1A = 299 compares
};

TimerRun run_timer(const Corrections& c) {
    Sim sim(options("selftest_timer", c));
    TimerRun r;
    EXPECT_TRUE(sim.run_until_pc(sim.symbol("timer_start"), ms(1)));
    r.start = sim.cycle();
    EXPECT_TRUE(sim.run_until_pc(sim.symbol("ocr_write"), ms(1)));
    r.ocr_write = sim.cycle();
    sim.run_until_cycle(r.ocr_write + 1900); // still inside the 2000-nop sled
    for (const Edge& e : sim.edges_of("step_x")) {
        // The last phase-A toggle follows the OCR write within one ISR; phase B starts 300 later.
        if (e.cycle <= r.ocr_write + 2 + kResponse + kToOut)
            r.phase_a.push_back(e.cycle);
        else
            r.phase_b.push_back(e.cycle);
    }
    return r;
}

std::vector<uint64_t> intervals(const std::vector<uint64_t>& v) {
    std::vector<uint64_t> d;
    for (size_t i = 1; i < v.size(); ++i) d.push_back(v[i] - v[i - 1]);
    return d;
}

/// Phase B toggles: first compare (OCR1A + 1) after the counter was cleared at ocr_write, then
/// every OCR1A + 1; the OUT follows `to_out` cycles after each flag.
void expect_phase_b(const TimerRun& r, uint64_t to_out) {
    ASSERT_GE(r.phase_b.size(), 6u);
    for (size_t k = 0; k < r.phase_b.size(); ++k)
        EXPECT_EQ(r.phase_b[k], r.ocr_write + (kPhaseBOcr + 1) * (k + 1) + to_out) << k;
}

} // namespace

TEST(SimTimerCtcTopZero, CorrectedComparesOnEveryTick) {
    REQUIRE_SELFTEST("selftest_timer");
    const TimerRun r = run_timer(Corrections::all());
    // Flag 1 cycle after the start, STS done at +2, response 4, OUT 6 later: +12.
    ASSERT_EQ(r.phase_a.size(), size_t(kPhaseANops) + 5);
    EXPECT_EQ(r.phase_a.front(), r.start + 1 + 1 + kResponse + kToOut);
    // Back to back: response 4 + ISR 13 + one 1-cycle main instruction (nop, ldi) = 18; the two
    // STS of the OCR1A write take 2 cycles: 19.
    const std::vector<uint64_t> d = intervals(r.phase_a);
    for (size_t i = 0; i < d.size(); ++i) {
        const uint64_t main_instruction = i + 2 >= d.size() ? 2 : 1;
        EXPECT_EQ(d[i], kResponse + kIsr + main_instruction) << i;
    }
    EXPECT_EQ(r.phase_a.back(), r.ocr_write + 2 + kResponse + kToOut);
    expect_phase_b(r, kResponse + kToOut);
}

TEST(SimTimerCtcTopZero, StockSimavrNeverComparesAtZero) {
    REQUIRE_SELFTEST("selftest_timer");
    const TimerRun r = run_timer(all_but(&Corrections::timer_ctc_top_zero));
    EXPECT_TRUE(r.phase_a.empty()); // no TIMER1_COMPA at all while OCR1A = 0
    // Main ran straight through: STS 2 + 20 nops + 2 ldi + STS 2.
    EXPECT_EQ(r.ocr_write, r.start + 2 + kPhaseANops + 2 + 2);
    // And the timer never got a phase reference: simavr counts OCR1A = 299 from cycle 0 and skips
    // its first compare, so the first one comes at cycle 600 instead of ocr_write + 300.
    ASSERT_FALSE(r.phase_b.empty());
    EXPECT_EQ(r.phase_b.front(), 600 + kResponse + kToOut);
    EXPECT_NE(r.phase_b.front(), r.ocr_write + 300 + kResponse + kToOut);
}

TEST(SimIrqResponse, CorrectedTakesFourCycles) {
    REQUIRE_SELFTEST("selftest_timer");
    const TimerRun r = run_timer(Corrections::all());
    ASSERT_FALSE(r.phase_a.empty());
    EXPECT_EQ(r.phase_a.front() - r.start, 2 + kResponse + kToOut);
    EXPECT_EQ(r.phase_a[1] - r.phase_a[0], kResponse + kIsr + 1);
}

TEST(SimIrqResponse, StockSimavrTakesNone) {
    REQUIRE_SELFTEST("selftest_timer");
    const TimerRun r = run_timer(all_but(&Corrections::irq_response_cycles));
    ASSERT_GE(r.phase_a.size(), 2u);
    EXPECT_EQ(r.phase_a.front() - r.start, 2 + kToOut); // 4 cycles early
    EXPECT_EQ(r.phase_a[1] - r.phase_a[0], kIsr + 1);   // 14 instead of 18
    expect_phase_b(r, kToOut);
}

TEST(SimIrqAfterReti, CorrectedRunsOneInstruction) {
    REQUIRE_SELFTEST("selftest_timer");
    const TimerRun r = run_timer(Corrections::all());
    // One ISR per main instruction: 1 after the start, 20 nops, 2 ldi, STS H, STS L.
    EXPECT_EQ(r.phase_a.size(), size_t(kPhaseANops) + 5);
    EXPECT_EQ(r.phase_a[1] - r.phase_a[0], kResponse + kIsr + 1);
}

TEST(SimIrqAfterReti, StockSimavrRunsTwoInstructions) {
    REQUIRE_SELFTEST("selftest_timer");
    const TimerRun r = run_timer(all_but(&Corrections::irq_one_instruction_after_sei));
    ASSERT_GE(r.phase_a.size(), 2u);
    EXPECT_EQ(r.phase_a[1] - r.phase_a[0], kResponse + kIsr + 2); // two nops between ISRs
    // Two main instructions per ISR: about half as many ISRs before the OCR1A write.
    EXPECT_LT(r.phase_a.size(), size_t(kPhaseANops) / 2 + 5);
}
