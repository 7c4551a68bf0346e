#include "recorder.h"

#include <inttypes.h>
#include <stdio.h>

#include <algorithm>
#include <ostream>
#include <stdexcept>

extern "C" {
#include <avr_ioport.h>
}

namespace ll {
namespace sim {

std::vector<Signal> cnc_shield_signals() {
    return {
        {"step_x", 'D', 2}, {"step_y", 'D', 3}, {"step_z", 'D', 4},
        {"dir_x", 'D', 5},  {"dir_y", 'D', 6},  {"dir_z", 'D', 7},
        {"enable", 'B', 0}, {"step_a", 'B', 4}, {"dir_a", 'B', 5},
    };
}

Signal parse_signal(const std::string& spec) {
    const size_t eq = spec.find('=');
    if (eq == std::string::npos || eq == 0 || spec.size() != eq + 4 || spec[eq + 1] != 'P' ||
        spec[eq + 2] < 'B' || spec[eq + 2] > 'D' || spec[eq + 3] < '0' || spec[eq + 3] > '7')
        throw std::invalid_argument("signal must look like name=PD2 (ports B, C, D; bits 0-7): " +
                                    spec);
    return Signal{spec.substr(0, eq), spec[eq + 2], static_cast<uint8_t>(spec[eq + 3] - '0')};
}

Recorder::Recorder(avr_t* avr, std::vector<Signal> signals) : avr_(avr) {
    for (const Signal& s : signals) add(s);
}

Recorder::~Recorder() {
    for (size_t i = 0; i < hooks_.size(); ++i) {
        const Signal& s = signals_[i];
        avr_irq_t* irq = avr_io_getirq(avr_, AVR_IOCTL_IOPORT_GETIRQ(s.port), s.bit);
        if (irq) avr_irq_unregister_notify(irq, &Recorder::on_pin, hooks_[i].get());
    }
}

uint16_t Recorder::add(const Signal& s) {
    avr_irq_t* irq = avr_io_getirq(avr_, AVR_IOCTL_IOPORT_GETIRQ(s.port), s.bit);
    if (!irq) throw std::invalid_argument("no such pin: P" + std::string(1, s.port));
    const uint16_t index = static_cast<uint16_t>(signals_.size());
    signals_.push_back(s);
    const uint8_t now = read_level(s);
    levels_.push_back(now);
    initial_.push_back(now);
    hooks_.push_back(std::unique_ptr<Hook>(new Hook{this, index}));
    avr_irq_register_notify(irq, &Recorder::on_pin, hooks_.back().get());
    return index;
}

int Recorder::find(const std::string& name) const {
    for (size_t i = 0; i < signals_.size(); ++i)
        if (signals_[i].name == name) return static_cast<int>(i);
    return -1;
}

void Recorder::on_pin(avr_irq_t*, uint32_t value, void* param) {
    Hook* h = static_cast<Hook*>(param);
    Recorder* r = h->self;
    // simavr raises a pin IRQ on every port write, changed or not; only changes are edges.
    const uint8_t level = static_cast<uint8_t>(value & 1);
    if (r->levels_[h->signal] == level) return;
    r->levels_[h->signal] = level;
    r->edges_.push_back(Edge{r->avr_->cycle, h->signal, level});
}

uint8_t Recorder::read_level(const Signal& s) const {
    avr_ioport_state_t st;
    if (avr_ioctl(avr_, AVR_IOCTL_IOPORT_GETSTATE(s.port), &st) < 0) return 0;
    const unsigned ddr = st.ddr, port = st.port, pin = st.pin;
    const unsigned v = ((ddr >> s.bit) & 1) ? (port >> s.bit) : (pin >> s.bit);
    return static_cast<uint8_t>(v & 1);
}

void Recorder::resync() {
    for (uint16_t i = 0; i < signals_.size(); ++i) {
        const uint8_t now = read_level(signals_[i]);
        if (now == levels_[i]) continue;
        levels_[i] = now;
        edges_.push_back(Edge{avr_->cycle, i, now});
    }
}

void Recorder::clear() {
    edges_.clear();
    initial_ = levels_;
}

std::vector<Edge> Recorder::edges_of(uint16_t signal) const {
    std::vector<Edge> out;
    for (const Edge& e : edges_)
        if (e.signal == signal) out.push_back(e);
    return out;
}

std::string cycles_to_us_string(uint64_t cycle, uint32_t cpu_hz) {
    char buf[48];
    if (cpu_hz % 1000000u == 0 && 10000u % (cpu_hz / 1000000u) == 0) {
        // Exact: at 16 MHz one cycle is 0.0625 us, so four decimals always suffice.
        const uint64_t per_us = cpu_hz / 1000000u;
        const uint64_t frac = (cycle % per_us) * (10000u / per_us);
        snprintf(buf, sizeof buf, "%" PRIu64 ".%04" PRIu64, cycle / per_us, frac);
    } else {
        snprintf(buf, sizeof buf, "%.4f", static_cast<double>(cycle) * 1e6 / cpu_hz);
    }
    return buf;
}

void Recorder::write_csv(std::ostream& out, uint32_t cpu_hz) const {
    out << "cycle,time_us,signal,level\n";
    for (const Edge& e : edges_) {
        out << e.cycle << ',' << cycles_to_us_string(e.cycle, cpu_hz) << ','
            << signals_[e.signal].name << ',' << unsigned(e.level) << '\n';
    }
}

void Recorder::write_vcd(std::ostream& out, uint32_t cpu_hz) const {
    // VCD allows only 1, 10 or 100 of a unit; 100 ps makes a 16 MHz cycle exactly 625 units.
    const uint64_t units_per_cycle = 10000000000ull / cpu_hz;
    auto id = [](size_t i) {
        std::string s;
        do {
            s += static_cast<char>('!' + i % 94); // printable identifier characters
            i /= 94;
        } while (i);
        return s;
    };
    out << "$version llsim (Low Level simavr harness) $end\n";
    out << "$comment time unit 100ps; CPU " << cpu_hz << " Hz, one cycle = " << units_per_cycle
        << " units $end\n";
    out << "$timescale 100ps $end\n";
    out << "$scope module board $end\n";
    for (size_t i = 0; i < signals_.size(); ++i)
        out << "$var wire 1 " << id(i) << ' ' << signals_[i].name << " $end\n";
    out << "$upscope $end\n$enddefinitions $end\n";
    out << "#0\n$dumpvars\n";
    for (size_t i = 0; i < signals_.size(); ++i) out << unsigned(initial_[i]) << id(i) << '\n';
    out << "$end\n";
    uint64_t last = 0;
    bool first = true;
    for (const Edge& e : edges_) {
        const uint64_t t = e.cycle * units_per_cycle;
        if (first || t != last) {
            if (!(first && t == 0)) out << '#' << t << '\n';
            last = t;
            first = false;
        }
        out << unsigned(e.level) << id(e.signal) << '\n';
    }
}

} // namespace sim
} // namespace ll
