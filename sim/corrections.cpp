#include "corrections.h"

#include <stdio.h>
#include <string.h>

#include <algorithm>

extern "C" {
#include <avr_ioport.h>
#include <sim_regbit.h>
}

namespace ll {
namespace sim {

namespace {

// ATmega328P bits that simavr's avr_uart_t does not describe (datasheet 20.11.4, UCSR0C).
constexpr uint8_t kUpmShift = 4; // UPM01:UPM00 = bits 5:4, 00 = parity disabled
constexpr uint8_t kUpmMask = 0x3;

// AVR opcodes of the two single-bit I/O instructions (AVR Instruction Set Manual):
// CBI A,b = 1001 1000 AAAA Abbb, SBI A,b = 1001 1010 AAAA Abbb.
constexpr uint16_t kCbiSbiMask = 0xFD00;
constexpr uint16_t kCbiSbiOpcode = 0x9800;
constexpr uint16_t kSbiBit = 0x0200;

// Extra cycles the datasheet gives for an interrupt response (6.7.1): 4, plus 4 from sleep.
constexpr avr_cycle_count_t kIrqResponseCycles = 4;
constexpr avr_cycle_count_t kIrqWakeExtraCycles = 4;

struct Field {
    const char* name;
    bool Corrections::*member;
};
const Field kFields[] = {
    {"timer_ctc_top_zero", &Corrections::timer_ctc_top_zero},
    {"timer_keeps_count", &Corrections::timer_keeps_count},
    {"uart_frame_time", &Corrections::uart_frame_time},
    {"uart_no_poll_sleep", &Corrections::uart_no_poll_sleep},
    {"extint_idle_poll_off", &Corrections::extint_idle_poll_off},
    {"irq_response_cycles", &Corrections::irq_response_cycles},
    {"irq_one_instruction_after_sei", &Corrections::irq_one_instruction_after_sei},
    {"sbi_cbi_single_bit", &Corrections::sbi_cbi_single_bit},
    {"timer_flags_write_one_to_clear", &Corrections::timer_flags_write_one_to_clear},
    {"no_wallclock_sleep", &Corrections::no_wallclock_sleep},
};

// Every simavr module struct starts with its avr_io_t, so the module list can be cast back.
template <class T>
T* find_module(avr_t* avr, const char* kind, char name) {
    for (avr_io_t* io = avr->io_port; io; io = io->next) {
        if (strcmp(io->kind, kind) != 0) continue;
        T* m = reinterpret_cast<T*>(io);
        if (m->name == name) return m;
    }
    return nullptr;
}

avr_extint_t* find_extint(avr_t* avr) {
    for (avr_io_t* io = avr->io_port; io; io = io->next)
        if (strcmp(io->kind, "extint") == 0) return reinterpret_cast<avr_extint_t*>(io);
    return nullptr;
}

} // namespace

Corrections Corrections::none() {
    Corrections c;
    for (const Field& f : kFields) c.*(f.member) = false;
    return c;
}

std::vector<std::string> Corrections::names() {
    std::vector<std::string> out;
    for (const Field& f : kFields) out.emplace_back(f.name);
    return out;
}

bool Corrections::set(const std::string& name, bool on) {
    for (const Field& f : kFields) {
        if (name == f.name) {
            this->*(f.member) = on;
            return true;
        }
    }
    return false;
}

Corrector::Corrector(avr_t* avr, IoHooks& hooks, const Corrections& c)
    : avr_(avr), hooks_(hooks), c_(c) {
    for (char n : {'0', '1', '2'})
        if (avr_timer_t* t = find_module<avr_timer_t>(avr_, "timer", n)) install_timer(t);
    uart0_ = find_module<avr_uart_t>(avr_, "uart", '0');
    if (uart0_) install_uart(uart0_);
    extint_ = find_extint(avr_);
    if (extint_) install_extint(extint_);
    for (char n : {'B', 'C', 'D'})
        if (avr_ioport_t* p = find_module<avr_ioport_t>(avr_, "port", n)) install_sbi_cbi(p->r_pin);
    for (auto& f : timers_) {
        install_sbi_cbi(f->t->overflow.raised.reg); // TIFRn; runs before the flag-clear hook
        install_flag_clear(f->t);
    }
    after_reset();
}

void Corrector::after_reset() {
    // avr_reset() emptied the cycle-timer pool, our ticks included.
    for (auto& f : timers_) f->top_zero_active = false;
    slept_ = false;
    extint_armed_[0] = extint_armed_[1] = false;
    if (uart0_) {
        // The harness reads UART output itself; simavr's STDIO flag would also print every line.
        uint32_t flags = uart0_->flags & ~static_cast<uint32_t>(AVR_UART_FLAG_STDIO);
        if (c_.uart_no_poll_sleep) flags &= ~static_cast<uint32_t>(AVR_UART_FLAG_POLL_SLEEP);
        uart0_->flags = flags;
        update_frame_time();
    }
    update_extint_polling();
}

// ---- interrupts ---------------------------------------------------------------------------

void Corrector::on_sleep() {
    slept_ = true;
    // simavr's run loop advances a sleeping CPU by 1 + (cycles to the next cycle timer), so the
    // CPU wakes one cycle after the event; take that cycle back before it is added.
    if (c_.irq_response_cycles && avr_->cycle > 0) avr_->cycle -= 1;
}

void Corrector::on_irq_entry() {
    if (c_.irq_response_cycles)
        avr_->cycle += kIrqResponseCycles + (slept_ ? kIrqWakeExtraCycles : 0);
    slept_ = false;
}

// ---- timers (SIMAVR-NOTES 1 and 2) --------------------------------------------------------

uint32_t Corrector::prescaler(const avr_timer_t* t) const {
    avr_regbit_t cs[4];
    memcpy(cs, t->cs, sizeof cs);
    const uint8_t sel = avr_regbit_get_array(avr_, cs, 4);
    if (sel == 0) return 0;
    const uint8_t div = t->cs_div[sel];
    if (div == AVR_TIMER_EXTCLK_CHOOSE) return 0; // clocked from the Tn pin: not corrected
    return 1u << div;
}

uint16_t Corrector::count(const avr_timer_t* t) const {
    return static_cast<uint16_t>(avr_->data[t->r_tcnt] |
                                 (t->r_tcnth ? avr_->data[t->r_tcnth] << 8 : 0));
}

uint16_t Corrector::ocr(const avr_timer_t* t, int comp) const {
    const avr_timer_comp_t& c = t->comp[comp];
    if (!c.r_ocr) return 0;
    return static_cast<uint16_t>(avr_->data[c.r_ocr] | (c.r_ocrh ? avr_->data[c.r_ocrh] << 8 : 0));
}

avr_timer_wgm_t Corrector::mode(const avr_timer_t* t) const {
    avr_regbit_t wgm[4];
    memcpy(wgm, t->wgm, sizeof wgm);
    return t->wgm_op[avr_regbit_get_array(avr_, wgm, 4)];
}

void Corrector::install_timer(avr_timer_t* t) {
    timers_.push_back(std::unique_ptr<TimerFix>(new TimerFix));
    TimerFix* f = timers_.back().get();
    f->self = this;
    f->t = t;

    // Registers holding clock-select or waveform bits: simavr restarts the counter from zero
    // whenever they change (item 2) and decides there whether OCRnA = 0 ticks at all (item 1).
    std::vector<uint16_t> ctrl;
    for (const avr_regbit_t& rb : t->wgm)
        if (rb.reg) ctrl.push_back(rb.reg);
    for (const avr_regbit_t& rb : t->cs)
        if (rb.reg) ctrl.push_back(rb.reg);
    std::sort(ctrl.begin(), ctrl.end());
    ctrl.erase(std::unique(ctrl.begin(), ctrl.end()), ctrl.end());

    for (uint16_t addr : ctrl) {
        hooks_.on_write(addr, [this, f](uint16_t, uint8_t v, const IoHooks::WriteNext& next) {
            avr_timer_t* tm = f->t;
            const bool was_running = prescaler(tm) != 0;
            const uint16_t before = live_count(*f); // the held value when stopped
            next(v);
            cancel_run_up(*f); // simavr re-planned this timer's compares
            if (c_.timer_keeps_count) {
                const bool running = prescaler(tm) != 0;
                if (was_running && !running) {
                    // Datasheet 15.11: a stopped counter holds its value; simavr drops it.
                    avr_->data[tm->r_tcnt] = static_cast<uint8_t>(before);
                    if (tm->r_tcnth) avr_->data[tm->r_tcnth] = static_cast<uint8_t>(before >> 8);
                } else if (running && tm->tov_cycles > 1 && tm->tov_base == avr_->cycle &&
                           before != 0) {
                    // simavr (re)started the counter from zero at this write; the hardware
                    // counter goes on from `before` (a preloaded TCNTn when it was stopped).
                    align_count(tm, before);
                }
            }
            update_top_zero(*f);
        });
    }

    // TCNTn: simavr reacts on the low byte (the high byte goes through TEMP first on hardware).
    hooks_.on_write(t->r_tcnt, [this, f](uint16_t, uint8_t v, const IoHooks::WriteNext& next) {
        next(v);
        cancel_run_up(*f);
        avr_timer_t* tm = f->t;
        // simavr rescales the written value by tov_cycles / TOP, which is off by up to one
        // timer period; the datasheet counter simply continues from the written value.
        if (c_.timer_keeps_count && prescaler(tm) != 0 && tm->tov_cycles > 1)
            align_count(tm, count(tm));
    });
    hooks_.on_read(t->r_tcnt, [this, f](uint16_t, const IoHooks::ReadNext& next) -> uint8_t {
        avr_timer_t* tm = f->t;
        if (c_.timer_keeps_count && prescaler(tm) == 0)
            return avr_->data[tm->r_tcnt]; // frozen / preloaded value (simavr would answer 0)
        if (f->top_zero_active || (c_.timer_keeps_count && tm->tov_base > avr_->cycle)) {
            const uint16_t v = live_count(*f);
            if (tm->r_tcnth) avr_->data[tm->r_tcnth] = static_cast<uint8_t>(v >> 8);
            return static_cast<uint8_t>(v);
        }
        return next();
    });

    // OCRnA is TOP in CTC mode: writing it may enter or leave the OCRnA = 0 case (item 1), or
    // drop TOP below the count (item 2).
    for (int i = AVR_TIMER_COMPB; i < AVR_TIMER_COMP_COUNT; ++i) f->run_up[i] = RunUp{f, i};
    if (t->comp[AVR_TIMER_COMPA].r_ocr) {
        hooks_.on_write(t->comp[AVR_TIMER_COMPA].r_ocr, [this, f](uint16_t, uint8_t v,
                                                                  const IoHooks::WriteNext& next) {
            avr_timer_t* tm = f->t;
            const avr_timer_wgm_t m = mode(tm);
            const bool live = c_.timer_keeps_count && prescaler(tm) != 0 && tm->tov_cycles > 1 &&
                              m.kind == avr_timer_wgm_ctc && m.top == avr_timer_wgm_reg_ocra;
            const uint16_t before = live ? live_count(*f) : 0;
            next(v);
            update_top_zero(*f);
            if (live && !f->top_zero_active && tm->tov_cycles > 1 &&
                before > ocr(tm, AVR_TIMER_COMPA))
                top_below_count(*f, before);
        });
    }
}

uint16_t Corrector::live_count(TimerFix& f) {
    avr_timer_t* t = f.t;
    const uint32_t presc = prescaler(t);
    if (presc == 0) return count(t);
    if (f.top_zero_active) return 0; // TOP = 0: cleared on every tick
    if (t->tov_base > avr_->cycle) {
        // Running up to MAX past a lowered TOP: tov_base is where the counter will be 0 again.
        const uint32_t max = t->r_tcnth ? 0xFFFF : 0xFF;
        const uint64_t ticks_left = (t->tov_base - avr_->cycle + presc - 1) / presc;
        return static_cast<uint16_t>(max + 1 - ticks_left);
    }
    (void)hooks_.read_original(t->r_tcnt); // simavr's own count, into the data space
    return count(t);
}

void Corrector::top_below_count(TimerFix& f, uint16_t before) {
    // Datasheet 15.9.2 (CTC): "If the new value written to OCR1A is lower than the current value
    // of TCNT1, the counter will miss the compare match. The counter will then have to count to
    // its maximum value (0xFFFF) and wrap around starting at 0x0000 before the compare match can
    // occur." simavr compares at once instead. Put the next period start at the wrap.
    avr_timer_t* t = f.t;
    const uint32_t presc = prescaler(t);
    const uint32_t max = t->r_tcnth ? 0xFFFF : 0xFF;
    const int64_t now = static_cast<int64_t>(avr_->cycle);
    const int64_t wrap = now + int64_t(max + 1 - before) * presc;
    shift_timer(t, wrap - static_cast<int64_t>(t->tov_base));
    // Comparators above the count still match on the way up to MAX.
    for (int i = AVR_TIMER_COMPB; i < AVR_TIMER_COMP_COUNT; ++i) {
        if (!t->comp[i].r_ocr || ocr(t, i) <= before) continue;
        const uint64_t at = uint64_t(ocr(t, i) - before + 1) * presc;
        avr_cycle_timer_register(avr_, at, &Corrector::run_up_compare, &f.run_up[i]);
    }
}

void Corrector::cancel_run_up(TimerFix& f) {
    for (int i = AVR_TIMER_COMPB; i < AVR_TIMER_COMP_COUNT; ++i)
        avr_cycle_timer_cancel(avr_, &Corrector::run_up_compare, &f.run_up[i]);
}

avr_cycle_count_t Corrector::run_up_compare(avr_t* avr, avr_cycle_count_t, void* param) {
    const RunUp* r = static_cast<const RunUp*>(param);
    avr_raise_interrupt(avr, &r->fix->t->comp[r->comp].interrupt);
    return 0;
}

void Corrector::update_top_zero(TimerFix& f) {
    avr_timer_t* t = f.t;
    const uint32_t presc = prescaler(t);
    const avr_timer_wgm_t m = mode(t);
    // simavr computes tov_cycles = prescaler x (TOP + 1) and arms nothing when that is <= 1,
    // i.e. exactly for OCRnA = 0 at prescaler 1. Only that case is taken over here.
    const bool want = c_.timer_ctc_top_zero && presc != 0 && m.kind == avr_timer_wgm_ctc &&
                      m.top == avr_timer_wgm_reg_ocra && ocr(t, AVR_TIMER_COMPA) == 0 &&
                      t->tov_cycles <= 1;
    if (want && (!f.top_zero_active || f.top_zero_prescaler != presc)) {
        f.top_zero_prescaler = presc;
        f.top_zero_active = true;
        // TCNT = TOP = 0 already matches; the flag is set at the next timer clock (15.9.2).
        avr_cycle_timer_register(avr_, presc, &Corrector::top_zero_tick, &f);
    } else if (!want && f.top_zero_active) {
        avr_cycle_timer_cancel(avr_, &Corrector::top_zero_tick, &f);
        f.top_zero_active = false;
    }
}

avr_cycle_count_t Corrector::top_zero_tick(avr_t* avr, avr_cycle_count_t when, void* param) {
    TimerFix* f = static_cast<TimerFix*>(param);
    avr_timer_t* t = f->t;
    // The counter is cleared on this tick: keep simavr's phase reference there, so that when the
    // firmware writes a non-zero OCRnA, simavr schedules the next match from this tick.
    t->tov_base = when;
    avr_raise_interrupt(avr, &t->comp[AVR_TIMER_COMPA].interrupt);
    // With TCNT stuck at 0, a comparator whose OCR is 0 matches on every tick too.
    for (int i = AVR_TIMER_COMPB; i < AVR_TIMER_COMP_COUNT; ++i)
        if (t->comp[i].r_ocr && f->self->ocr(t, i) == 0)
            avr_raise_interrupt(avr, &t->comp[i].interrupt);
    return when + f->top_zero_prescaler;
}

void Corrector::align_count(avr_timer_t* t, uint16_t value) {
    const uint32_t presc = prescaler(t);
    if (presc == 0 || value > t->tov_top) {
        // Beyond TOP the hardware counter runs to MAX and wraps; simavr cannot represent that.
        static bool warned = false;
        if (!warned && value > t->tov_top)
            fprintf(stderr, "llsim: timer%c count %u beyond TOP %u is not corrected\n", t->name,
                    value, t->tov_top);
        warned = true;
        return;
    }
    // simavr's counter value is (cycle - tov_base) / prescaler: the counter reads `value` now
    // when tov_base = cycle - value x prescaler.
    const int64_t want_base = static_cast<int64_t>(avr_->cycle) - int64_t(value) * presc;
    const int64_t delta = want_base - static_cast<int64_t>(t->tov_base);
    if (delta != 0) shift_timer(t, delta);
}

void Corrector::shift_timer(avr_timer_t* t, int64_t delta) {
    struct Pending {
        avr_cycle_timer_t fn;
        void* param;
        avr_cycle_count_t when;
    };
    std::vector<Pending> mine;
    auto belongs = [t](void* p) {
        if (p == t) return true;
        for (int i = 0; i < AVR_TIMER_COMP_COUNT; ++i)
            if (p == &t->comp[i]) return true;
        return false;
    };
    for (avr_cycle_timer_slot_p s = avr_->cycle_timers.timer; s; s = s->next)
        if (belongs(s->param)) mine.push_back({s->timer, s->param, s->when});
    for (const Pending& p : mine) avr_cycle_timer_cancel(avr_, p.fn, p.param);
    const int64_t now = static_cast<int64_t>(avr_->cycle);
    for (const Pending& p : mine) {
        const int64_t when = static_cast<int64_t>(p.when) + delta;
        // A compare whose moment is already behind the new count does not happen this period
        // (simavr re-arms every comparator at each period start).
        if (when > now)
            avr_cycle_timer_register(avr_, static_cast<avr_cycle_count_t>(when - now), p.fn,
                                     p.param);
    }
    t->tov_base = static_cast<avr_cycle_count_t>(static_cast<int64_t>(t->tov_base) + delta);
}

// ---- UART (SIMAVR-NOTES 3 and 5) ----------------------------------------------------------

void Corrector::install_uart(avr_uart_t* u) {
    const unsigned regs[] = {u->ubrrl.reg, u->ubrrh.reg, u->r_ucsra, u->r_ucsrb, u->r_ucsrc};
    for (unsigned reg : regs) {
        const uint16_t addr = static_cast<uint16_t>(reg);
        if (!addr) continue;
        hooks_.on_write(addr, [this](uint16_t, uint8_t v, const IoHooks::WriteNext& next) {
            next(v);
            update_frame_time();
        });
    }
}

uint32_t Corrector::datasheet_frame_cycles() const {
    avr_uart_t* u = uart0_;
    if (!u) return 0;
    const uint32_t ubrr =
        avr_regbit_get(avr_, u->ubrrl) | static_cast<uint32_t>(avr_regbit_get(avr_, u->ubrrh)) << 8;
    // Datasheet 20.3.1: one bit lasts (UBRR + 1) x 16 cycles, x 8 in double-speed mode.
    const uint32_t bit_cycles = (ubrr + 1) * (avr_regbit_get(avr_, u->u2x) ? 8u : 16u);
    static const uint8_t kDataBits[8] = {5, 6, 7, 8, 8, 8, 8, 9}; // UCSZn2:0 (4-6 reserved)
    const uint8_t size =
        static_cast<uint8_t>(avr_regbit_get(avr_, u->ucsz) | (avr_regbit_get(avr_, u->ucsz2) << 2));
    const uint32_t parity = ((avr_->data[u->r_ucsrc] >> kUpmShift) & kUpmMask) ? 1 : 0;
    const uint32_t stop = 1u + avr_regbit_get(avr_, u->usbs);
    return bit_cycles * (1u + kDataBits[size & 7] + parity + stop); // 20.4 "Frame Formats"
}

void Corrector::update_frame_time() {
    if (!c_.uart_frame_time || !uart0_) return;
    uart0_->cycles_per_byte = datasheet_frame_cycles();
}

// ---- external interrupts (SIMAVR-NOTES 7) -------------------------------------------------

void Corrector::install_extint(avr_extint_t* e) {
    // EIMSK enables INTn, EICRA selects its sense; both decide whether the level poll is needed.
    std::vector<uint16_t> regs = {static_cast<uint16_t>(e->eint[0].vector.enable.reg),
                                  static_cast<uint16_t>(e->eint[0].isc[0].reg)};
    std::sort(regs.begin(), regs.end());
    regs.erase(std::unique(regs.begin(), regs.end()), regs.end());
    for (uint16_t reg : regs) {
        if (!reg) continue;
        hooks_.on_write(reg, [this](uint16_t, uint8_t v, const IoHooks::WriteNext& next) {
            next(v);
            update_extint_polling();
        });
    }
}

void Corrector::update_extint_polling() {
    if (!extint_) return;
    for (uint8_t i = 0; i < 2; ++i) {
        auto& eint = extint_->eint[i];
        if (!eint.port_ioctl) continue;
        const bool enabled = avr_regbit_get(avr_, eint.vector.enable) != 0;
        // Polling a low INTn pin every cycle is how simavr makes a low-level interrupt repeat, as
        // the datasheet requires (13.1): needed only while the firmware has INTn enabled.
        avr_extint_set_strict_lvl_trig(avr_, i, (!c_.extint_idle_poll_off || enabled) ? 1 : 0);
        if (!c_.extint_idle_poll_off) continue;
        avr_regbit_t isc[2] = {eint.isc[0], eint.isc[1]};
        const bool armed = enabled && avr_regbit_get_array(avr_, isc, 2) == 0;
        if (armed && !extint_armed_[i]) {
            // simavr starts its poll only on a falling edge of the pin; stock simavr had it
            // running since the pin went low. Start it now if the pin is low already.
            avr_ioport_state_t st;
            const char port = static_cast<char>(eint.port_ioctl & 0xFF);
            if (avr_ioctl(avr_, AVR_IOCTL_IOPORT_GETSTATE(port), &st) >= 0) {
                const unsigned ddr = st.ddr, out = st.port, pin = st.pin;
                const unsigned level =
                    ((ddr >> eint.port_pin) & 1) ? (out >> eint.port_pin) : (pin >> eint.port_pin);
                if (!(level & 1)) avr_raise_irq(extint_->io.irq + i, 0);
            }
        }
        extint_armed_[i] = armed;
    }
}

// ---- SBI / CBI and timer flags (found here) ------------------------------------------------

void Corrector::install_flag_clear(avr_timer_t* t) {
    const uint16_t tifr = static_cast<uint16_t>(t->overflow.raised.reg);
    if (!tifr) return;
    hooks_.on_write(tifr, [this, t](uint16_t a, uint8_t v, const IoHooks::WriteNext& next) {
        if (!c_.timer_flags_write_one_to_clear) {
            next(v);
            return;
        }
        avr_int_vector_t* vectors[] = {&t->overflow, &t->icr, &t->comp[0].interrupt,
                                       &t->comp[1].interrupt, &t->comp[2].interrupt};
        bool was_set[5];
        for (int i = 0; i < 5; ++i)
            was_set[i] = vectors[i]->raised.reg == a && avr_regbit_get(avr_, vectors[i]->raised);
        next(v);
        // Raise again what simavr cleared although its bit was written as zero.
        for (int i = 0; i < 5; ++i) {
            avr_int_vector_t* vec = vectors[i];
            if (was_set[i] && !avr_regbit_from_value(avr_, vec->raised, v) &&
                !avr_regbit_get(avr_, vec->raised))
                avr_raise_interrupt(avr_, vec);
        }
    });
}

void Corrector::install_sbi_cbi(uint16_t addr) {
    if (!addr) return;
    hooks_.on_write(addr, [this](uint16_t a, uint8_t v, const IoHooks::WriteNext& next) {
        if (c_.sbi_cbi_single_bit) {
            // The register callback runs while the instruction executes: avr->pc is its address.
            const uint32_t pc = avr_->pc;
            const uint16_t op = static_cast<uint16_t>(avr_->flash[pc] | avr_->flash[pc + 1] << 8);
            if ((op & kCbiSbiMask) == kCbiSbiOpcode && ((op >> 3) & 0x1F) + 32u == a) {
                // Only the addressed bit is written: a one for SBI, nothing for CBI.
                v = (op & kSbiBit) ? static_cast<uint8_t>(1u << (op & 7)) : 0;
            }
        }
        next(v);
    });
}

} // namespace sim
} // namespace ll
