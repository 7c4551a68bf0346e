// Datasheet corrections for simavr 1.6 (Debian 1.6+dfsg). Each one restores what the ATmega328P
// datasheet specifies where stock simavr deviates; each is switchable so that a self-test can show
// the deviation (off) and the datasheet behaviour (on). All of them act from outside the library,
// through its public headers only: register callbacks (IoHooks), the public timer / UART / external
// interrupt structures, the cycle-timer pool and the interrupt IRQs.
//
// Numbers refer to /work/shared/SIMAVR-NOTES.md; "found here" items were found while building
// these self-tests and are described in sim/README.md.
#pragma once

#include <stdint.h>

#include <memory>
#include <string>
#include <vector>

#include "io_hooks.h"

extern "C" {
#include <avr_extint.h>
#include <avr_timer.h>
#include <avr_uart.h>
#include <sim_avr.h>
}

namespace ll {
namespace sim {

struct Corrections {
    /// SIMAVR-NOTES 1: Timer CTC with OCRnA = 0 at prescaler 1 raises the compare interrupt on
    /// every timer tick (simavr never raises it).
    bool timer_ctc_top_zero = true;
    /// SIMAVR-NOTES 2: the counter keeps its value: starting a stopped timer counts from the
    /// preloaded TCNTn, a stopped timer reads back its frozen count, a TCNTn write takes effect
    /// exactly, and in CTC mode an OCRnA written below the count is missed until the counter wraps
    /// at MAX (simavr counts from zero, reads 0, rescales the written value, and compares at once
    /// when TOP drops below the count, hiding the classic CTC bug).
    bool timer_keeps_count = true;
    /// SIMAVR-NOTES 3: a UART frame is start + data + parity (only if enabled) + stop bits
    /// (simavr always adds a parity bit: 11 bits at 8N1), recomputed whenever UBRRn, U2Xn, UCSZn,
    /// UPMn or USBSn change (simavr only on a UBRRnL write).
    bool uart_frame_time = true;
    /// SIMAVR-NOTES 5: no host usleep(1) on each UCSRnA poll (wall time only, cycles unchanged).
    bool uart_no_poll_sleep = true;
    /// SIMAVR-NOTES 7: INT0/INT1 low-level polling (a cycle timer every cycle while PD2/PD3 are
    /// low) only while the firmware has enabled that interrupt (wall time only).
    bool extint_idle_poll_off = true;
    /// Found here: the interrupt response takes 4 cycles (datasheet 6.7 "Reset and Interrupt
    /// Handling"), 8 when it wakes the CPU from sleep; simavr 1.6 charges 0, and wakes a sleeping
    /// CPU one cycle after the event that wakes it.
    bool irq_response_cycles = true;
    /// Found here: after SEI or RETI exactly one instruction runs before a pending interrupt is
    /// served (datasheet 6.7); simavr 1.6 runs two.
    bool irq_one_instruction_after_sei = true;
    /// Found here: SBI/CBI on PINx and TIFRn act on the addressed bit only (datasheet 7.4
    /// / 14.2.2); simavr 1.6 does a read-modify-write of the whole register, which toggles every
    /// other pin that reads high (PINx) or clears every other pending flag (TIFRn).
    bool sbi_cbi_single_bit = true;
    /// Found here: writing TIFRn clears exactly the flags written as one (datasheet 15.11.9 "OCF1A
    /// is cleared by writing a logic one to its bit location"); simavr 1.6 clears every pending
    /// flag of the register on any write, so `TIFR1 = 1 << OCF1A` also drops a pending OCF1B.
    bool timer_flags_write_one_to_clear = true;
    /// Not a datasheet item: the SLEEP instruction must not make the host usleep() for the
    /// simulated sleep time (simavr's raw run loop does). Wall time only.
    bool no_wallclock_sleep = true;

    static Corrections all() { return Corrections(); }
    static Corrections none();
    /// Names as used by the CLI (--no-correction NAME): the field names above.
    static std::vector<std::string> names();
    /// Sets one correction by name; returns false for an unknown name.
    bool set(const std::string& name, bool on);
};

/// Applies the peripheral corrections to one simulated chip and carries the interrupt ones for
/// the harness run loop (Sim), which calls on_irq_entry(), on_sleep() and after_step().
class Corrector {
  public:
    Corrector(avr_t* avr, IoHooks& hooks, const Corrections& c);
    Corrector(const Corrector&) = delete;
    Corrector& operator=(const Corrector&) = delete;

    const Corrections& corrections() const { return c_; }

    /// After avr_reset(): simavr's reset re-arms the INT0/INT1 polling and drops every cycle
    /// timer, so the state that depends on them is set again.
    void after_reset();

    /// Called when the CPU accepts an interrupt (simavr raised the vector's RUNNING IRQ).
    void on_irq_entry();
    /// Called each time simavr's run loop lets a sleeping CPU skip to the next cycle timer.
    void on_sleep();
    /// Called after every instruction step of the run loop.
    void after_step() {
        // simavr sets interrupt_state = -2 on SEI/RETI and counts it up once per step; -1 right
        // after the step means "the instruction just executed enabled interrupts". The datasheet
        // lets exactly one more instruction run, so resolve the wait now.
        if (c_.irq_one_instruction_after_sei && avr_->interrupt_state == -1)
            avr_->interrupt_state = avr_has_pending_interrupts(avr_) ? 1 : 0;
    }

    /// UART frame time in cycles, as the datasheet gives it for the current register values.
    uint32_t datasheet_frame_cycles() const;

  private:
    struct TimerFix;
    /// A compare that happens while the counter runs up to MAX past a lowered TOP.
    struct RunUp {
        TimerFix* fix;
        int comp; ///< AVR_TIMER_COMPB or AVR_TIMER_COMPC
    };
    struct TimerFix {
        Corrector* self = nullptr;
        avr_timer_t* t = nullptr;
        bool top_zero_active = false;    ///< our tick replaces simavr's missing one (item 1)
        uint32_t top_zero_prescaler = 0; ///< CPU cycles per timer tick while active
        RunUp run_up[AVR_TIMER_COMP_COUNT] = {};
    };

    void install_timer(avr_timer_t* t);
    void install_uart(avr_uart_t* u);
    void install_extint(avr_extint_t* e);
    void install_sbi_cbi(uint16_t addr);
    void install_flag_clear(avr_timer_t* t);

    uint32_t prescaler(const avr_timer_t* t) const; ///< CPU cycles per tick; 0 = stopped/external
    uint16_t count(const avr_timer_t* t) const;     ///< TCNTn as stored in the data space
    uint16_t ocr(const avr_timer_t* t, int comp) const;
    avr_timer_wgm_t mode(const avr_timer_t* t) const;
    void update_top_zero(TimerFix& f);
    uint16_t live_count(TimerFix& f);
    void top_below_count(TimerFix& f, uint16_t count);
    void cancel_run_up(TimerFix& f);
    static avr_cycle_count_t run_up_compare(avr_t* avr, avr_cycle_count_t when, void* param);
    void align_count(avr_timer_t* t, uint16_t value);
    void shift_timer(avr_timer_t* t, int64_t delta_cycles);
    static avr_cycle_count_t top_zero_tick(avr_t* avr, avr_cycle_count_t when, void* param);
    void update_frame_time();
    void update_extint_polling();

    avr_t* avr_;
    IoHooks& hooks_;
    Corrections c_;
    std::vector<std::unique_ptr<TimerFix>> timers_; ///< stable addresses: cycle-timer params
    avr_uart_t* uart0_ = nullptr;
    avr_extint_t* extint_ = nullptr;
    bool extint_armed_[2] = {false, false}; ///< INTn enabled in low-level mode
    bool slept_ = false;
};

} // namespace sim
} // namespace ll
