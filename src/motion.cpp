// motion.h on top of the planner, the step generator and the run queue.
#include "lowlevel/motion.h"

#include <string.h>

#include "lowlevel/hal.h"
#include "lowlevel/planner.h"
#include "lowlevel/run_queue.h"
#include "lowlevel/settings.h"
#include "lowlevel/stepgen.h"

namespace ll {
namespace motion {
namespace {

// No default member initialisers: a zero-filled static object needs no constructor (init()
// sets every field).
struct Motion {
    State state;
    bool enabled;        ///< stepper drivers enabled
    uint16_t idle_since; ///< hal::millis() when motion last stopped, low 16 bits ($1 <= 254 ms)
    Machine machine;
    Planner planner;
    StepGen gen;
};

Motion g_motion;

inline Motion& mo() {
    return g_motion;
}

// Hands the planner's moves to the step generator and lets it fill the run queue, until the
// queue is full, a hold stops it or nothing is left.
void produce(Motion& m) {
    for (;;) {
        if (!m.planner.first_begun()) {
            if (m.planner.empty()) return;
            MoveSpec& spec = scratch<MoveSpec>(); // see motion.h
            m.planner.spec_of_first(spec);
            if (!m.gen.begin(spec)) { // no step: drop it
                m.planner.discard_first();
                continue;
            }
            m.planner.begin_first();
        }
        m.gen.set_exit(m.planner.exit2_of_first());
        m.gen.fill(g_runs);
        if (m.gen.active() || m.gen.stopped()) return; // queue full, or held
        m.planner.discard_first();
    }
}

bool too_long(const int32_t from[kAxes], const int32_t to[kAxes]) {
    for (uint8_t a = 0; a < kAxes; ++a) {
        // Positions stay within +-2^30 steps (the G-code layer's range check), so the
        // difference cannot overflow.
        // |d| > kMaxLineTicks as one unsigned comparison: d + max wraps above 2 max.
        uint32_t d = static_cast<uint32_t>(to[a] - from[a]) + kMaxLineTicks;
        if (d > 2u * kMaxLineTicks) return true;
    }
    return false;
}

// Where the machine is while the planner is reset (abort(), settings_changed()), in the scratch
// RAM: those run outside poll() and gcode::execute() (motion.h), and their frames shrink.
struct Here {
    int32_t steps[kAxes];
    hal::StepperConfig cfg; // settings_changed()
};
inline Here& here_scratch() {
    return scratch<Here>();
}

// Nothing queued for the step interrupt and nothing running.
__attribute__((noinline)) bool drained() {
    return g_runs.empty() && !g_exec.running;
}

__attribute__((noinline)) void enable(Motion& m, bool on) {
    if (m.enabled == on) return;
    m.enabled = on;
    hal::stepper_enable(on);
}

__attribute__((noinline)) void go_idle(Motion& m) {
    m.state = State::Idle;
    m.idle_since = static_cast<uint16_t>(hal::millis());
}

// Stops the step timer, forgets every queued run and move; the machine is at `here`, steps.
void restart(Motion& m, const int32_t here[kAxes]) {
    hal::stepper_stop();
    g_runs.clear();
    m.gen.clear_queue_time();
    g_exec.starved = 0;
    m.gen.abort();
    m.gen.set_position(here);
    m.planner.reset(here);
    go_idle(m);
}

} // namespace

void init() {
    mo().planner.configure(&mo().machine); // zero-filled until settings_changed()
    int32_t* zero = here_scratch().steps;
    memset(zero, 0, sizeof(Here::steps));
    restart(mo(), zero);
    mo().enabled = false;
    g_starvations = 0;
}

bool can_accept() {
    return !mo().planner.full();
}

bool can_accept_curve() {
    return can_accept() && mo().planner.curve_slot_free();
}

bool push_line(const LineRequest& req) {
    Motion& m = mo();
    if (too_long(m.planner.last_target(), req.target_steps)) return false;
    if (req.curve && !m.planner.shape_curve(req.target_um, *req.curve)) return false;
    uint32_t feed = req.feed;
    if (req.rapid) feed = Planner::kRapid;
    // (Idle means nothing queued: a move dropped for its zero length leaves it idle.)
    if (m.planner.add(req.target_steps, req.target_um, feed, req.curve) && m.state == State::Idle)
        m.state = State::Cycle;
    return true;
}

uint8_t blocks_free() {
    return static_cast<uint8_t>(kPlannerSize - mo().planner.count());
}

void poll() {
    Motion& m = mo();
    // (Idle: nothing queued in the planner. It goes idle only empty, and push_line() leaves
    // Idle as it queues.)
    if (m.state == State::Idle && drained()) {
        uint8_t delay = g_settings.idle_delay_ms; // read once: millis() is a call
        if (m.enabled && delay != 255 &&
            static_cast<uint16_t>(hal::millis() - m.idle_since) >= delay) {
            enable(m, false);
        }
        return;
    }
    produce(m);
    // A move is left to produce (a begun move is still the planner's first).
    bool pending = !m.planner.empty();
    if (!g_exec.running) {
        if (g_exec.starved && pending && !m.gen.stopped()) {
            g_starvations = static_cast<uint16_t>(g_starvations + 1); // dry mid-move
        }
        g_exec.starved = 0;
        if (!g_runs.empty() && m.state != State::Held) {
            enable(m, true);
            hal::stepper_start();
        }
    }
    if (!drained()) return;
    if (m.state == State::Holding) {
        if (m.gen.stopped() || !pending) m.state = State::Held;
    } else if (m.state == State::Cycle && !pending) {
        go_idle(m);
    }
}

State state() {
    return mo().state;
}

void feed_hold() {
    Motion& m = mo();
    State s = m.state;
    if (s != State::Idle && s != State::Cycle) return;
    // GRBL 1.1: a hold while idle is a complete hold. Moves sent meanwhile are planned (full
    // look-ahead) but none starts until cycle start: the generator, holding at zero speed, stops
    // at the first segment of any move it is given.
    m.gen.hold();
    if (s == State::Idle) {
        m.state = State::Held;
        return;
    }
    m.state = State::Holding;
    poll();
}

void cycle_start() {
#if defined(__AVR__)
    // Y marked as used: with it the saved registers are one run (r8..r17, r28, r29), which
    // -mcall-prologues saves through its shared routines, not 10 pushes and pops.
    asm volatile("" ::: "r28", "r29");
#endif
    Motion& m = mo();
    if (m.state != State::Held) return;
    if (m.planner.first_begun() && m.gen.stopped()) {
        m.planner.restart_first(m.gen.remaining(), m.gen.length());
        m.gen.resume(m.planner.exit2_of_first());
    } else {
        m.gen.resume(0);
    }
    if (!m.planner.empty()) {
        m.state = State::Cycle;
    } else {
        go_idle(m);
    }
    poll();
}

bool abort() {
    bool moving = g_exec.running != 0;
    int32_t* here = here_scratch().steps;
    position(here);
    restart(mo(), here);
    return moving;
}

void position(int32_t steps[kAxes]) {
    Motion& m = mo();
    uint8_t i, n, s, d;
    // Without a critical section (it kept interrupts off 10 cycles, the main loop's longest
    // window): read, then retry if the step interrupt ran in between. Each of its runs either
    // decrements `remaining` (not the run's last event), or pops a run (`head` moves), or, at
    // the last event with the queue empty, sets `remaining` from 1 to 0. Several runs cannot
    // undo each other: without a pop `remaining` only falls, and the pops in one pass are at
    // most the N - 1 runs queued when it started (this loop is the producer, so nothing is
    // queued meanwhile), so `head` cannot come back to its value. Equal `head` and `remaining`
    // at the end thus mean that the four values belong together.
    do {
        i = g_runs.head;
        n = g_exec.remaining;
        s = g_exec.steps;
        d = g_exec.dirs;
    } while (n != g_exec.remaining || i != g_runs.head);
    m.gen.pushed_position(steps);
    // Undo what is queued but not executed: the rest of the current run, then every run
    // between the consumer and the producer.
    for (;;) {
        // Until no step bit is left (they are axis bits: bit kAxes and up are never set).
        for (int32_t* p = steps; s != 0; ++p, s >>= 1, d >>= 1) {
            if (s & 1) {
                int16_t dn = n;
                if (!(d & 1)) dn = static_cast<int16_t>(-dn);
                *p += dn;
            }
        }
        if (i == g_runs.tail) return;
        const Run& r = g_runs.buf[i];
        s = r.steps;
        d = r.dirs;
        n = r.count;
        i = static_cast<uint8_t>((i + 1) & (kRunQueueSize - 1));
    }
}

uint32_t current_feed() {
    Motion& m = mo();
    if (m.state == State::Idle || m.state == State::Held) return 0;
    return isqrt32(m.gen.speed2());
}

void settings_changed() {
    Motion& m = mo();
    machine_build(m.machine, g_settings);
    m.gen.configure(&m.machine.lengths, m.machine.min_period, m.machine.um_q8_per_step);
    hal::StepperConfig& cfg = here_scratch().cfg;
    cfg.pulse_cycles = static_cast<uint16_t>(g_settings.pulse_us * (kCpuHz / 1000000));
    cfg.step_invert = g_settings.step_invert;
    cfg.dir_invert = g_settings.dir_invert;
    cfg.enable_invert = g_settings.enable_invert;
    hal::stepper_configure(cfg);
    int32_t* here = here_scratch().steps;
    position(here);
    m.planner.reset(here);
    if (g_settings.idle_delay_ms == 255) enable(m, true);
}

uint32_t starvations() {
    return g_starvations;
}

} // namespace motion
} // namespace ll
