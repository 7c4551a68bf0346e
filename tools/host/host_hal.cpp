// Host fake of the hardware boundary. See host_hal.h.
#include "host_hal.h"

#include <deque>
#include <limits>

#include "lowlevel/realtime.h"
#include "lowlevel/run_queue.h"

namespace ll {
namespace host {
namespace {

struct Model {
    uint64_t now = 0;
    // step timer
    bool running = false;
    uint64_t next_event = 0;
    uint16_t period = 0;
    hal::StepperConfig cfg{160, 0, 0, 0};
    uint8_t dir_pins = 0; // physical levels
    uint8_t enable_pin = 1;
    uint32_t stops = 0;
    std::vector<Edge> edges;
    // serial
    std::deque<std::pair<uint64_t, uint8_t>> incoming; // arrival cycle, byte
    std::deque<uint8_t> rx;
    bool rx_overflow = false;
    std::string tx;
    // storage
    uint8_t eeprom[hal::kEepromSize];
    Model() {
        for (auto& b : eeprom) b = 0xFF;
    }
};

Model& m() {
    static Model model;
    return model;
}

void set_dirs(uint64_t at, uint8_t dirs) {
    Model& s = m();
    uint8_t levels = static_cast<uint8_t>(dirs ^ s.cfg.dir_invert);
    for (uint8_t a = 0; a < kAxes; ++a) {
        uint8_t bit = static_cast<uint8_t>(1u << a);
        if ((levels ^ s.dir_pins) & bit) {
            s.edges.push_back({at, EdgeKind::Dir, a, static_cast<uint8_t>((levels & bit) ? 1 : 0)});
        }
    }
    s.dir_pins = levels;
}

void load_next(uint64_t at_pulse_end) {
    Model& s = m();
    const Run& r = g_runs.front();
    g_exec.remaining = r.count;
    g_exec.steps = r.steps;
    g_exec.dirs = r.dirs;
    s.period = r.period;
    g_runs.pop();
    set_dirs(at_pulse_end, r.dirs);
}

// One compare match of the step timer: the body of the AVR interrupt.
void step_event(uint64_t t) {
    Model& s = m();
    uint8_t steps = g_exec.steps;
    for (uint8_t a = 0; a < kAxes; ++a) {
        uint8_t bit = static_cast<uint8_t>(1u << a);
        if (steps & bit) {
            uint8_t idle = (s.cfg.step_invert & bit) ? 1 : 0;
            s.edges.push_back({t, EdgeKind::Step, a, static_cast<uint8_t>(idle ^ 1)});
        }
    }
    uint64_t pulse_end = t + s.cfg.pulse_cycles;
    for (uint8_t a = 0; a < kAxes; ++a) {
        uint8_t bit = static_cast<uint8_t>(1u << a);
        if (steps & bit) {
            uint8_t idle = (s.cfg.step_invert & bit) ? 1 : 0;
            s.edges.push_back({pulse_end, EdgeKind::Step, a, idle});
        }
    }
    g_exec.remaining = static_cast<uint8_t>(g_exec.remaining - 1);
    if (g_exec.remaining == 0) {
        if (!g_runs.empty()) {
            load_next(pulse_end);
        } else {
            s.running = false;
            g_exec.running = 0;
            g_exec.starved = 1;
            g_exec.steps = 0;
            ++s.stops;
            return;
        }
    }
    s.next_event = t + s.period;
}

void deliver_arrivals(uint64_t t) {
    Model& s = m();
    while (!s.incoming.empty() && s.incoming.front().first <= t) {
        uint8_t b = s.incoming.front().second;
        s.incoming.pop_front();
        if (rt::filter(b)) continue;
        if (s.rx.size() >= kRxCapacity) {
            s.rx_overflow = true;
        } else {
            s.rx.push_back(b);
        }
    }
}

} // namespace

uint64_t now() {
    return m().now;
}

void advance_to(uint64_t t) {
    Model& s = m();
    while (s.running && s.next_event <= t) {
        // Bytes that arrived before this event are in the buffer before the event happens.
        deliver_arrivals(s.next_event);
        s.now = s.next_event;
        step_event(s.next_event);
    }
    if (t > s.now) s.now = t;
    deliver_arrivals(s.now);
}

uint64_t next_event() {
    return m().running ? m().next_event : std::numeric_limits<uint64_t>::max();
}
bool timer_running() {
    return m().running;
}
const std::vector<Edge>& edges() {
    return m().edges;
}
void clear_edges() {
    m().edges.clear();
}
uint32_t timer_stops() {
    return m().stops;
}

void send(const std::string& bytes, uint32_t cycles_per_byte) {
    Model& s = m();
    uint64_t t = s.incoming.empty() ? s.now : s.incoming.back().first;
    if (t < s.now) t = s.now;
    for (char c : bytes) {
        t += cycles_per_byte;
        s.incoming.emplace_back(t, static_cast<uint8_t>(c));
    }
    deliver_arrivals(s.now);
}

uint64_t next_arrival() {
    Model& s = m();
    return s.incoming.empty() ? std::numeric_limits<uint64_t>::max() : s.incoming.front().first;
}

std::string take_output() {
    std::string out;
    out.swap(m().tx);
    return out;
}

void reset_model(bool erase_eeprom) {
    Model& s = m();
    uint8_t saved[hal::kEepromSize];
    for (uint16_t i = 0; i < hal::kEepromSize; ++i) saved[i] = s.eeprom[i];
    s = Model();
    if (!erase_eeprom) {
        for (uint16_t i = 0; i < hal::kEepromSize; ++i) s.eeprom[i] = saved[i];
    }
    g_runs.clear();
    g_exec.remaining = 0;
    g_exec.steps = 0;
    g_exec.dirs = 0;
    g_exec.running = 0;
    g_exec.starved = 0;
    rt::g_pending = 0;
}

uint8_t* eeprom() {
    return m().eeprom;
}

} // namespace host

namespace hal {

bool serial_get(uint8_t& byte) {
    auto& s = host::m();
    if (s.rx.empty()) return false;
    byte = s.rx.front();
    s.rx.pop_front();
    return true;
}

uint8_t serial_rx_free() {
    return static_cast<uint8_t>(host::kRxCapacity - host::m().rx.size() > 255
                                    ? 255
                                    : host::kRxCapacity - host::m().rx.size());
}

bool serial_rx_overflowed() {
    bool o = host::m().rx_overflow;
    host::m().rx_overflow = false;
    return o;
}

void serial_rx_clear() {
    host::m().rx.clear();
}
void serial_put(uint8_t byte) {
    host::m().tx.push_back(static_cast<char>(byte));
}
void serial_flush() {}

void stepper_configure(const StepperConfig& cfg) {
    auto& s = host::m();
    s.cfg = cfg;
}

void stepper_start() {
    auto& s = host::m();
    if (s.running || g_runs.empty()) return;
    host::load_next(s.now);
    s.running = true;
    g_exec.running = 1;
    g_exec.starved = 0;
    s.next_event = s.now + s.period;
}

void stepper_stop() {
    auto& s = host::m();
    s.running = false;
    g_exec.running = 0;
    g_exec.remaining = 0;
    g_exec.steps = 0;
}

void stepper_enable(bool on) {
    auto& s = host::m();
    uint8_t level = static_cast<uint8_t>((on ? 0 : 1) ^ (s.cfg.enable_invert ? 1 : 0));
    if (level != s.enable_pin) {
        s.edges.push_back({s.now, host::EdgeKind::Enable, 0, level});
        s.enable_pin = level;
    }
}

uint32_t millis() {
    return static_cast<uint32_t>(host::m().now / (kCpuHz / 1000));
}

uint8_t eeprom_read(uint16_t addr) {
    return host::m().eeprom[addr % kEepromSize];
}
uint8_t eeprom_write(uint16_t addr, uint8_t value) {
    host::m().eeprom[addr % kEepromSize] = value;
    return value;
}

uint8_t limits() {
    return 0;
}

uint8_t irq_save() {
    return 0;
}
void irq_restore(uint8_t) {}

} // namespace hal
} // namespace ll
