// Step timer: Timer1 in CTC mode at prescaler 1 consumes g_runs (run_queue.h) with exactly the
// semantics of the host model (tools/host/host_hal.cpp):
//
//   TIMER1_COMPA (the event, every `period` cycles) toggles the step pins of the current run at
//     a fixed offset from the compare match, before any branch, and counts the event.
//   TIMER1_COMPB (OCR1B + 1 cycles after each event) toggles them back: the pulse end.
//
// A run's last event is the one place with work to do. COMPA does all of it, at once, so the
// producer's minimum period is as short as possible: while the pulse is high it looks at the
// queue head and computes which direction pins change; it then waits for the OCF1B flag (the
// instant COMPB would run), ends the pulse and changes the direction pins with the same two
// writes COMPB would use, clears OCF1B (COMPB must not toggle again) and loads the next run:
// step masks, count and OCR1A, or stops the timer when the queue was empty. Direction pins thus
// change exactly at the pulse end, as in the model, never during a pulse.
//
// Both handlers are naked and written in assembly: the C version measured 55 + 59 cycles per
// step with the edge 25 cycles after the match (it pushes r0, r1, SREG and every register of
// the rare path first). These cost 32 + 22 cycles per step (common path), with the edge 10
// cycles after the match. They call nothing, divide nothing, never re-enable interrupts (no
// nesting), and take their pin masks from board.h as constants. docs/firmware.md has the
// cycle counts; cmake/check_step_isr.cmake checks the image after every link.
//
// State of the handlers (the main loop writes it only while the timer is stopped):
//   GPIOR1   step toggle mask, port D, of the current run
//   s_step_b step toggle mask, port B, of the current run
//   GPIOR2   pulse-end toggle mask, port D (= GPIOR1, plus the direction pins that change)
//   s_end_b  pulse-end toggle mask, port B
//   GPIOR0   bit 7: first COMPB after stepper_start(), which only sets GPIOR2 and s_end_b
#include <avr/interrupt.h>
#include <avr/io.h>

#include "board.h"
#include "fw.h"
#include "lowlevel/hal.h"
#include "lowlevel/run_queue.h"
#include "lowlevel/step_timing.h"

namespace ll {
namespace {

using board::Port;
namespace st = step_timing;

constexpr uint8_t kBitArm = 7; ///< GPIOR0 bit, tested with sbic (no SREG change)
static_assert(kBitArm == 7, "literal in COMPB's asm");

constexpr uint8_t kTccr1bStopped = _BV(WGM12);             // CTC, no clock
constexpr uint8_t kTccr1bRunning = _BV(WGM12) | _BV(CS10); // CTC, prescaler 1

static_assert(sizeof(Run) == 5, "COMPA indexes g_runs.buf by head * 5");
static_assert(__builtin_offsetof(Run, steps) == 0 && __builtin_offsetof(Run, dirs) == 1 &&
                  __builtin_offsetof(Run, count) == 2 && __builtin_offsetof(Run, period) == 3,
              "COMPA reads a Run field by field (ldd Z+0..4)");
static_assert(kRunQueueSize * sizeof(Run) <= 256, "head * 5 is computed in 8 bits");
static_assert(__builtin_offsetof(RunQueue, tail) == __builtin_offsetof(RunQueue, head) + 1,
              "COMPA reads tail at head + 1");
static_assert(__builtin_offsetof(StepExec, remaining) == 0 &&
                  __builtin_offsetof(StepExec, steps) == 1 &&
                  __builtin_offsetof(StepExec, dirs) == 2 &&
                  __builtin_offsetof(StepExec, running) == 3 &&
                  __builtin_offsetof(StepExec, starved) == 4,
              "COMPA addresses g_exec fields as g_exec + offset");
static_assert(_SFR_MEM_ADDR(OCR1AH) == _SFR_MEM_ADDR(OCR1AL) + 1, "OCR1A byte order");
static_assert(_SFR_IO_ADDR(TIFR1) < 0x20, "sbis on TIFR1");

volatile uint8_t s_step_b;      // see the file comment
volatile uint8_t s_end_b;       // see the file comment
volatile uint16_t s_min_period; // guard for OCR1A, cycles (step_timing::min_period)
uint16_t s_ocr1b;               // pulse width - 1 + kPulseGuard
uint8_t s_idle_d;               // step pin levels at rest ($2), port D
uint8_t s_idle_b;               // step pin levels at rest ($2), port B
uint8_t s_dir_invert;           // $3, axis bits
uint8_t s_enable_invert;        // $4

} // namespace
} // namespace ll

// Per-axis port bits of the step or direction pins as constant operands (0 when the axis' pin
// is on the other port or the axis does not exist: the `.if` blocks then emit nothing).
#define LL_BIT_OPERAND(name, fn, axis, port) [name] "n"(ll::board::fn(axis, ll::board::Port::port))
#define LL_MASK_OPERANDS(p, fn)                                                                    \
    LL_BIT_OPERAND(p##d0, fn, 0, D), LL_BIT_OPERAND(p##d1, fn, 1, D),                              \
        LL_BIT_OPERAND(p##d2, fn, 2, D), LL_BIT_OPERAND(p##d3, fn, 3, D),                          \
        LL_BIT_OPERAND(p##b0, fn, 0, B), LL_BIT_OPERAND(p##b1, fn, 1, B),                          \
        LL_BIT_OPERAND(p##b2, fn, 2, B), LL_BIT_OPERAND(p##b3, fn, 3, B)

// r24 |= port bits (operands <p>0..<p>3) of the axes set in r25: 2 cycles per axis on the port.
#define LL_OR_AXES(p)                                                                              \
    ".if %[" #p "0]\n\tsbrc r25, 0\n\tori r24, %[" #p "0]\n\t.endif\n\t"                           \
    ".if %[" #p "1]\n\tsbrc r25, 1\n\tori r24, %[" #p "1]\n\t.endif\n\t"                           \
    ".if %[" #p "2]\n\tsbrc r25, 2\n\tori r24, %[" #p "2]\n\t.endif\n\t"                           \
    ".if %[" #p "3]\n\tsbrc r25, 3\n\tori r24, %[" #p "3]\n\t.endif\n\t"

// Compare match A: one step event. Two asm statements only because one may not have more than
// 30 operands; a naked function holds nothing else, so they assemble back to back (local labels
// cross from one to the other).
ISR(TIMER1_COMPA_vect, ISR_NAKED) {
    asm volatile("push r24\n\t"
                 "in   r24, %[sd_reg]\n\t"
                 "out  %[pind], r24\n\t" // step edge, X/Y/Z: fixed offset, before any branch
                 "lds  r24, %[step_b]\n\t"
                 "out  %[pinb], r24\n\t" // step edge, A
                 "in   r24, __SREG__\n\t"
                 "push r24\n\t"
                 "lds  r24, %[exec]+0\n\t" // g_exec.remaining
                 "dec  r24\n\t"
                 "sts  %[exec]+0, r24\n\t"
                 "breq 1f\n\t"
                 "0:\n\t"
                 "pop  r24\n\t"
                 "out  __SREG__, r24\n\t"
                 "pop  r24\n\t"
                 "reti\n\t"
                 // The run's last event. Decide now, as the model does at the event.
                 "1:\n\t"
                 "push r25\n\t"
                 "push r30\n\t"
                 "push r31\n\t"
                 "lds  r30, %[head]\n\t"
                 "lds  r24, %[head]+1\n\t" // tail
                 "set\n\t"                 // T = 1: the queue is empty, stop after this pulse
                 "cp   r30, r24\n\t"
                 "breq 2f\n\t"
                 "clt\n\t" // T = 0: load the head run after this pulse
                 "mov  r24, r30\n\t"
                 "lsl  r30\n\t"
                 "lsl  r30\n\t"
                 "add  r30, r24\n\t"
                 "ldi  r31, 0\n\t"
                 "subi r30, lo8(-(%[buf]))\n\t"
                 "sbci r31, hi8(-(%[buf]))\n\t" // Z = &g_runs.buf[head]
                 // Only what the pulse end needs comes before it (at $0 = 3 us this work
                 // outlasts the pulse and delays its end): the run is popped after it.
                 "ldd  r25, Z+1\n\t"       // its dirs
                 "lds  r24, %[exec]+2\n\t" // g_exec.dirs: the pins' current directions
                 "sts  %[exec]+2, r25\n\t"
                 "eor  r25, r24\n\t" // axes whose direction pin toggles at the pulse end
                 "in   r24, %[ed_reg]\n\t" LL_OR_AXES(dd) "out  %[ed_reg], r24\n\t"
                                                          "lds  r24, %[end_b]\n\t" LL_OR_AXES(
                                                              db) "sts  %[end_b], r24\n\t"
                 :
                 : [pind] "I"(_SFR_IO_ADDR(PIND)), [pinb] "I"(_SFR_IO_ADDR(PINB)),
                   [sd_reg] "I"(_SFR_IO_ADDR(GPIOR1)), [ed_reg] "I"(_SFR_IO_ADDR(GPIOR2)),
                   [step_b] "i"(&ll::s_step_b), [end_b] "i"(&ll::s_end_b), [exec] "i"(&ll::g_exec),
                   [head] "i"(&ll::g_runs.head), [buf] "i"(&ll::g_runs.buf[0]),
                   LL_MASK_OPERANDS(d, dir_bit));
    asm volatile(
        // Wait for the instant COMPB would end the pulse (its flag), end it the same way, and
        // keep COMPB from running for this event.
        "2:\n\t"
        "sbis %[tifr1], %[ocf1b]\n\t"
        "rjmp 2b\n\t"
        "ldi  r24, 1 << %[ocf1b]\n\t"
        "out  %[tifr1], r24\n\t"
        // 4 cycles: on silicon COMPB's first write comes 9 cycles after its flag (4 response,
        // 2 for the vector's rjmp, push, in: step_timing.h); this one comes 9..11 cycles after
        // it (sbis sees the flag 0..2 cycles late, skip 2, ldi, out, padding 4, in): never
        // earlier than COMPB's. (5 until the table's jmp became an rjmp: 1 cycle late.)
        "rjmp .+0\n\t"
        "rjmp .+0\n\t"
        "in   r24, %[ed_reg]\n\t"
        "out  %[pind], r24\n\t" // pulse end (+ direction change), X/Y/Z
        "lds  r24, %[end_b]\n\t"
        "out  %[pinb], r24\n\t" // pulse end (+ direction change), A
        "brts 3f\n\t"
        // Pop the run (the main loop cannot run before this handler ends) and load it (Z still
        // points at it): masks, count, period.
        "lds  r24, %[head]\n\t"
        "inc  r24\n\t"
        "andi r24, %[qmask]\n\t"
        "sts  %[head], r24\n\t"
        "ld   r25, Z\n\t" // steps
        "sts  %[exec]+1, r25\n\t"
        "ldi  r24, 0\n\t" LL_OR_AXES(
            sd) "out  %[sd_reg], r24\n\t"
                "out  %[ed_reg], r24\n\t"
                "ldi  r24, 0\n\t" LL_OR_AXES(
                    sb) "sts  %[step_b], r24\n\t"
                        "sts  %[end_b], r24\n\t"
                        "ldd  r24, Z+2\n\t" // count
                        "sts  %[exec]+0, r24\n\t"
                        "ldd  r24, Z+3\n\t" // period
                        "ldd  r25, Z+4\n\t"
                        "lds  r30, %[min_period]\n\t"
                        "lds  r31, %[min_period]+1\n\t"
                        "cp   r24, r30\n\t"
                        "cpc  r25, r31\n\t"
                        "brsh 4f\n\t"
                        "movw r24, r30\n\t" // guard: never a compare value the timer cannot honour
                        "4:\n\t"
                        "sbiw r24, 1\n\t"
                        "sts  %[ocr1a]+1, r25\n\t" // high byte first (TEMP register)
                        "sts  %[ocr1a], r24\n\t"
                        "5:\n\t"
                        "pop  r31\n\t"
                        "pop  r30\n\t"
                        "pop  r25\n\t"
                        "rjmp 0b\n\t"
                        // The queue was empty at the last event: stop (the model stops at the event
                        // itself).
                        "3:\n\t"
                        "ldi  r24, %[tccr_stopped]\n\t"
                        "sts  %[tccr1b], r24\n\t"
                        "ldi  r24, 0\n\t"
                        "sts  %[exec]+3, r24\n\t" // running
                        "sts  %[exec]+1, r24\n\t" // steps
                        "ldi  r24, 1\n\t"
                        "sts  %[exec]+4, r24\n\t" // starved
                        "rjmp 5b\n\t"
        :
        : [pind] "I"(_SFR_IO_ADDR(PIND)), [pinb] "I"(_SFR_IO_ADDR(PINB)),
          [sd_reg] "I"(_SFR_IO_ADDR(GPIOR1)), [ed_reg] "I"(_SFR_IO_ADDR(GPIOR2)),
          [step_b] "i"(&ll::s_step_b), [end_b] "i"(&ll::s_end_b), [exec] "i"(&ll::g_exec),
          [head] "i"(&ll::g_runs.head), [qmask] "M"(ll::kRunQueueSize - 1),
          [tifr1] "I"(_SFR_IO_ADDR(TIFR1)), [ocf1b] "I"(OCF1B), [min_period] "i"(&ll::s_min_period),
          [ocr1a] "n"(_SFR_MEM_ADDR(OCR1AL)), [tccr1b] "n"(_SFR_MEM_ADDR(TCCR1B)),
          [tccr_stopped] "M"(ll::kTccr1bStopped), LL_MASK_OPERANDS(s, step_bit));
}

// Compare match B: the pulse end of every event but a run's last (COMPA ends that one).
ISR(TIMER1_COMPB_vect, ISR_NAKED) {
    asm volatile("push r24\n\t"
                 "in   r24, %[ed_reg]\n\t"
                 "out  %[pind], r24\n\t" // pulse end, X/Y/Z
                 "lds  r24, %[end_b]\n\t"
                 "out  %[pinb], r24\n\t" // pulse end, A
                 "sbic %[flags], 7\n\t"  // kBitArm
                 "rjmp 1f\n\t"
                 "pop  r24\n\t"
                 "reti\n\t"
                 // First compare match B after stepper_start(): it came before any event and
                 // toggled nothing; from now on the pulse end toggles the step pins.
                 "1:\n\t"
                 "in   r24, %[sd_reg]\n\t"
                 "out  %[ed_reg], r24\n\t"
                 "lds  r24, %[step_b]\n\t"
                 "sts  %[end_b], r24\n\t"
                 "ldi  r24, 0\n\t"
                 "out  %[flags], r24\n\t"
                 "pop  r24\n\t"
                 "reti\n\t"
                 :
                 : [pind] "I"(_SFR_IO_ADDR(PIND)), [pinb] "I"(_SFR_IO_ADDR(PINB)),
                   [sd_reg] "I"(_SFR_IO_ADDR(GPIOR1)), [ed_reg] "I"(_SFR_IO_ADDR(GPIOR2)),
                   [flags] "I"(_SFR_IO_ADDR(GPIOR0)), [step_b] "i"(&ll::s_step_b),
                   [end_b] "i"(&ll::s_end_b));
}

namespace ll {
namespace hal {

void stepper_configure(const StepperConfig& cfg) {
    uint16_t pulse = st::effective_pulse(cfg.pulse_cycles);
    s_ocr1b = static_cast<uint16_t>(pulse - 1 + st::kPulseGuard);
    s_min_period = static_cast<uint16_t>(pulse + st::kPeriodMargin); // st::min_period()
    uint8_t idle_d = board::step_port_bits<Port::D>(cfg.step_invert);
    uint8_t idle_b = board::step_port_bits<Port::B>(cfg.step_invert);
    s_idle_d = idle_d;
    s_idle_b = idle_b;
    s_dir_invert = cfg.dir_invert;
    s_enable_invert = cfg.enable_invert;
    fw::IrqGuard g;
    PORTD = static_cast<uint8_t>((PORTD & ~board::kStepMaskD) | idle_d);
    PORTB = static_cast<uint8_t>((PORTB & ~board::kStepMaskB) | idle_b);
}

void stepper_start() {
    if (g_exec.running) return;
    // The timer is stopped: head only changes here, so it is read once (volatile).
    uint8_t head = g_runs.head;
    if (head == g_runs.tail) return;
    const Run& r = g_runs.buf[head];
    uint8_t steps = r.steps;
    uint8_t dirs = r.dirs;
    uint8_t count = r.count; // read before the volatile guard: r is not looked up again
    uint16_t period = r.period;
    uint16_t min_period = s_min_period;
    if (period < min_period) period = min_period;
    StepExec* e = &g_exec;
    asm("" : "+e"(e)); // std through a pointer register, not sts by address
    e->remaining = count;
    e->steps = steps;
    e->dirs = dirs;
    e->starved = 0;
    e->running = 1;
    g_runs.head = static_cast<uint8_t>((head + 1) & (kRunQueueSize - 1)); // pop()

    GPIOR1 = board::step_port_bits<Port::D>(steps);
    s_step_b = board::step_port_bits<Port::B>(steps);
    // The first compare match B comes before the first event: it toggles nothing and restores
    // the pulse-end masks.
    GPIOR2 = 0;
    s_end_b = 0;
    GPIOR0 = _BV(kBitArm);
    OCR1A = static_cast<uint16_t>(period - 1);
    OCR1B = s_ocr1b;
    TCNT1 = 0;
    TIFR1 = _BV(OCF1A) | _BV(OCF1B);

    uint8_t levels = static_cast<uint8_t>(dirs ^ s_dir_invert);
    uint8_t dir_d = board::dir_port_bits<Port::D>(levels);
    uint8_t dir_b = board::dir_port_bits<Port::B>(levels);
    // The model sets the direction pins and starts counting at the same instant: start the
    // timer, then write the pins within a few cycles (the first event is a period later, the
    // first interrupt a pulse width later). The masks are computed before interrupts go off
    // (the compiler would otherwise schedule the shifts inside the critical section).
    asm volatile("" : "+r"(dir_d), "+r"(dir_b));
    fw::IrqGuard g;
    TCCR1B = kTccr1bRunning;
    PORTD = static_cast<uint8_t>((PORTD & ~board::kDirMaskD) | dir_d);
    PORTB = static_cast<uint8_t>((PORTB & ~board::kDirMaskB) | dir_b);
}

void stepper_stop() {
    uint8_t idle_d = s_idle_d;
    uint8_t idle_b = s_idle_b;
    asm volatile("" : "+r"(idle_d), "+r"(idle_b)); // loaded before interrupts go off
    {
        fw::IrqGuard g;
        TCCR1B = kTccr1bStopped;
        TIFR1 = _BV(OCF1A) | _BV(OCF1B);
        GPIOR0 = 0;
        // End a pulse in progress: step pins back to their idle level.
        PORTD = static_cast<uint8_t>((PORTD & ~board::kStepMaskD) | idle_d);
        PORTB = static_cast<uint8_t>((PORTB & ~board::kStepMaskB) | idle_b);
    }
    // The timer is stopped and its flags clear: the step interrupt cannot run any more.
    g_exec.running = 0;
    g_exec.remaining = 0;
    g_exec.steps = 0;
}

void stepper_enable(bool on) {
    // One sbi/cbi: atomic against the step interrupt's PINB toggles.
    // High when enabled with $4 = 1, or disabled with $4 = 0.
    if (static_cast<uint8_t>(on) == s_enable_invert) { // both 0 or 1 (hal.h, $4)
        PORTB |= board::Enable::kMask;
    } else {
        PORTB &= static_cast<uint8_t>(~board::Enable::kMask);
    }
}

} // namespace hal
} // namespace ll
