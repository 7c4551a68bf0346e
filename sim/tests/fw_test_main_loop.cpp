// Two properties of the main loop that every timing check depends on, measured instruction by
// instruction through a session that takes the deep and the interrupt-sensitive paths: boot from
// a blank EEPROM, every report, settings, G-code lines planned while motion runs, status during
// motion, feed hold and resume, a soft reset in motion.
//
// - Stack: the ATmega328P has 2048 bytes of RAM; whatever .data + .bss leave is the stack, and
//   nothing stops it from growing into motion::g_motion (the last object of .bss).
// - Interrupt latency: a step edge is late by as long as the main loop keeps interrupts off
//   (step_timing.h: kPulseGuard = 16 cycles is what the pulse widening absorbs).
#include "fw_check.h"
#include "lowlevel/step_timing.h"

using namespace ll::sim;
using namespace ll::sim::fw;

namespace {

constexpr uint16_t kTccr1b = 0x81; // data-space address
/// Headroom for what a session cannot force: interrupts nested on top of the deepest main-loop
/// point. Receive stub + drain 12 bytes, then the transmit (10) and Timer2 (9) handlers, which
/// re-enable interrupts, then the step interrupt (7): 38 (return addresses and pushes counted in
/// the disassembly).
constexpr int kMargin = 40;

struct MainLoop {
    uint16_t min_sp = 0xFFFF;
    uint32_t min_sp_pc = 0;
    /// Longest wait a step interrupt raised in the main loop could see, cycles: from the first
    /// cycle with interrupts off to the end of the instruction that follows their re-enabling.
    uint64_t latency = 0;
    uint32_t latency_pc = 0;  ///< the instruction that turned interrupts off
    uint32_t latency_ret = 0; ///< return address on top of the stack there (the caller of a
                              ///< hal::irq_save())
    uint32_t bss_end = 0;
    uint16_t ram_end = 0; ///< 0x8FF (LLSIM_BIG_RAM: 0xFFF)
    std::string output;
};

MainLoop run_session() {
    MainLoop r;
    Sim sim(firmware_elf());
    r.bss_end = sim.symbol("__bss_end");
    r.ram_end = sim.avr()->ramend;
    for (uint8_t v = 1; v < 26; ++v) sim.record_isr(v);
    size_t closed = 0;      // isr_spans() below this index have all returned
    uint64_t off_since = 0; // first cycle of the current interrupts-off window
    uint32_t off_pc = 0;    // instruction that turned interrupts off
    uint32_t off_ret = 0;   // return address on top of the stack then
    bool off = false, reenabled = false;
    // A frame is allocated by `out SPH` ... `out SPL` (with `out SREG` between, interrupts off):
    // in between, SP reads as the new high byte with the old low byte, up to 255 bytes off. Such
    // samples are not stack depths (no interrupt can come in between either).
    bool sp_half = false;
    auto observe = [&](uint32_t pc_before, bool i_before) {
        const uint8_t* f = sim.avr()->flash + pc_before;
        const uint16_t op = static_cast<uint16_t>(f[0] | f[1] << 8);
        if ((op & 0xFE0F) == 0xBE0E) sp_half = true;  // out 0x3e (SPH), rN
        if ((op & 0xFE0F) == 0xBE0D) sp_half = false; // out 0x3d (SPL), rN
        const uint16_t sp = static_cast<uint16_t>(sim.peek(0x5D) | sim.peek(0x5E) << 8);
        if (!sp_half && sp < r.min_sp) {
            r.min_sp = sp;
            r.min_sp_pc = sim.avr()->pc;
        }
        const std::vector<IsrSpan>& spans = sim.isr_spans();
        while (closed < spans.size() && spans[closed].returned != 0) ++closed;
        bool in_isr = false;
        for (size_t k = closed; k < spans.size(); ++k) in_isr = in_isr || spans[k].returned == 0;
        const bool i_now = sim.avr()->sreg[7] != 0;
        if (in_isr) {
            off = reenabled = false; // an ISR was accepted: the window ended
            return;
        }
        // Only windows with Timer1 counting at both ends can delay a step edge (stepper_start()
        // starts it inside its own window, a period before the first event; stepper_stop()
        // stops it inside its window).
        const bool timer_on = (sim.peek(kTccr1b) & 0x07) != 0;
        if (reenabled) {
            // The instruction after SEI / OUT SREG always runs before a pending interrupt.
            if (timer_on && sim.cycle() - off_since > r.latency) {
                r.latency = sim.cycle() - off_since;
                r.latency_pc = off_pc;
                r.latency_ret = off_ret;
            }
            off = reenabled = false;
        }
        if (i_before && !i_now && timer_on) {
            off = true;
            off_since = sim.cycle();
            off_pc = pc_before;
            off_ret = static_cast<uint32_t>(sim.peek(static_cast<uint16_t>(sp + 1)) << 8 |
                                            sim.peek(static_cast<uint16_t>(sp + 2)))
                      << 1;
        } else if (off && !i_before && i_now) {
            reenabled = true;
        }
    };
    auto run = [&](uint64_t cycles) {
        const uint64_t end = sim.cycle() + cycles;
        while (sim.cycle() < end) {
            const uint64_t c = sim.cycle();
            const uint32_t pc = sim.avr()->pc;
            const bool i = sim.avr()->sreg[7] != 0;
            sim.run_until([&] { return sim.cycle() != c; }, 64);
            observe(pc, i);
        }
    };
    run(ms(150)); // boot from a blank EEPROM: error:7, the defaults written and listed
    const std::vector<std::string> session = {
        "$$", "$#", "$G", "$I", "$100=80", "$101=80", "$102=80", "$103=80", "$110=6000",
        "$111=6000", "$120=500", "$121=500", "G10 L2 P1 X1 Y2", "G92 X0",
        // Curves plan and step deepest (issue 5): small ones, each done before the next line.
        "G91 G2 X0 Y0 I0.5 J0 F3000", "G3.1 I-0.3 J0 P0.3 Q0.2",
        "G5 I0.1 J0.2 P-0.1 Q0.2 X0.9 Y0.7", "G5 P0.1 Q-0.2 X0.3 Y-0.2", "G18 G2 X-0.4 Z0.2 R0.3",
        "G17 G90 G0 X0 Y0 Z0", "G21 G90 G1 X10.125 Y-3.25 Z1.5 A2 F3000",
        "G91 G1 X-1.2345 Y0.5 Z-0.25 A-1 F2000", "G20 G1 X0.1 Y-0.05", "G21 G90 G0 X0 Y0 Z0 A0",
        "G4 P0.01", "G1 X5 Y5 F2500"};
    for (const std::string& line : session) {
        sim.send(line + "\n");
        // A curve runs long enough to be planned (an ellipse: 90 ms) and stepped for a while.
        const bool curve = line.compare(0, 2, "G2") == 0 || line.compare(0, 2, "G3") == 0 ||
                           line.compare(0, 2, "G5") == 0;
        run(ms(curve ? 150 : 12));
        sim.send("?");
        run(ms(3));
    }
    sim.send("!"); // feed hold while moving, then resume
    run(ms(40));
    sim.send("~");
    run(ms(20));
    sim.send("G91 G1 X20 Y-20 F3000\n");
    run(ms(30));
    sim.send("\x18"); // soft reset in motion
    run(ms(30));
    sim.send("$X\n");
    run(ms(20));
    r.output = sim.output();
    return r;
}

const MainLoop& session() {
    static const MainLoop r = run_session();
    return r;
}

} // namespace

TEST(FirmwareStack, DeepestPathLeavesRoomAboveTheStaticRam) {
    REQUIRE_FIRMWARE();
    const MainLoop& r = session();
    const int depth = r.ram_end - r.min_sp;
    const int room = static_cast<int>(r.min_sp) + 1 - static_cast<int>(r.bss_end);
    printf("[ measured ] stack: %d bytes deep (SP 0x%04x at pc 0x%04x), static RAM %u bytes, "
           "%d bytes left above __bss_end 0x%04x\n",
           depth, r.min_sp, r.min_sp_pc, r.bss_end - 0x100, room, r.bss_end);
    EXPECT_GE(room, kMargin) << "the stack reached 0x" << std::hex << r.min_sp << " (pc 0x"
                             << r.min_sp_pc << "), the static RAM ends at 0x" << r.bss_end
                             << std::dec << ": "
                             << (room < 0 ? "it ran " + std::to_string(-room) +
                                                " bytes into the static RAM (motion::g_motion)"
                                          : "only " + std::to_string(room) + " bytes left")
                             << "; static " << r.bss_end - 0x100 << " + stack " << depth
                             << " + margin " << kMargin << " > 2048 bytes";
}

TEST(FirmwareLatency, MainLoopNeverHoldsInterruptsOffLongerThanThePulseGuard) {
    REQUIRE_FIRMWARE();
    const MainLoop& r = session();
    printf("[ measured ] main loop: a step interrupt waits up to %llu cycles (window opened at pc "
           "0x%04x, return address 0x%04x on the stack), pulse guard %u\n",
           static_cast<unsigned long long>(r.latency), r.latency_pc, r.latency_ret,
           ll::step_timing::kPulseGuard);
    EXPECT_LE(r.latency, ll::step_timing::kPulseGuard)
        << "an interrupt raised just after the instruction at pc 0x" << std::hex << r.latency_pc
        << " (called from 0x" << r.latency_ret << ") waits " << std::dec << r.latency
        << " cycles: a step edge that late makes its pulse shorter than $0 by the difference";
}
