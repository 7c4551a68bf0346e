#include "fw_check.h"

#include <stdio.h>
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <map>

#include "host_driver.h"
#include "host_hal.h"
#include "lowlevel/motion.h"
#include "lowlevel/protocol.h"
#include "lowlevel/run_queue.h"
#include "lowlevel/step_timing.h"

namespace ll {
namespace sim {
namespace fw {

namespace {

namespace st = ll::step_timing;

constexpr uint16_t kTccr1b = 0x81; // data-space address of TCCR1B
constexpr uint8_t kPaint = 0xA5;
constexpr uint8_t kClockSelect = 0x07; // CS12..CS10: non-zero while Timer1 counts
constexpr uint64_t kLineTimeout = 200ull * 16000;

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

bool is_ok_reply(const std::string& out) {
    return out.find("ok\r\n") != std::string::npos && out.find("error:") == std::string::npos;
}

// The CNC shield's map: is this axis' step / direction pin on port B?
bool on_port_b(uint8_t axis) {
    const std::string want = std::string("step_") + static_cast<char>(axis_name(axis) + 32);
    for (const Signal& s : cnc_shield_signals())
        if (s.name == want) return s.port == 'B';
    return false;
}

int64_t step_edge_offset(uint8_t axis) {
    return on_port_b(axis) ? st::kStepEdgeOffsetB : st::kStepEdgeOffsetD;
}
int64_t pulse_end_offset(uint8_t axis) {
    return on_port_b(axis) ? st::kPulseEndOffsetB : st::kPulseEndOffsetD;
}
int64_t start_dir_offset(uint8_t axis) {
    return on_port_b(axis) ? st::kStartDirOffsetB : st::kStartDirOffsetD;
}

// Signal key for per-pin pairing.
int key_of(const PinEdge& e) {
    return static_cast<int>(e.kind) * 8 + e.axis;
}

std::string describe(const PinEdge& e) {
    char buf[64];
    if (e.kind == Kind::Enable)
        snprintf(buf, sizeof buf, "enable->%u", e.level);
    else
        snprintf(buf, sizeof buf, "%s_%c->%u", kind_name(e.kind), axis_name(e.axis), e.level);
    return buf;
}

int64_t iabs(int64_t v) {
    return v < 0 ? -v : v;
}

uint16_t peek16(const Sim& sim, uint32_t addr) {
    return static_cast<uint16_t>(sim.peek(static_cast<uint16_t>(addr)) |
                                 sim.peek(static_cast<uint16_t>(addr + 1)) << 8);
}

} // namespace

std::string firmware_elf() {
    return LLSIM_FIRMWARE_ELF;
}

bool firmware_exists() {
    struct stat st;
    return stat(firmware_elf().c_str(), &st) == 0;
}

const char* kind_name(Kind k) {
    switch (k) {
        case Kind::Step:
            return "step";
        case Kind::Dir:
            return "dir";
        case Kind::Enable:
            return "enable";
    }
    return "?";
}

char axis_name(uint8_t axis) {
    return "XYZABC"[axis < 6 ? axis : 0];
}

std::vector<PinEdge> chip_edges(const Sim& sim, size_t from) {
    // Signal index -> (kind, axis) from the names of the CNC-shield map.
    std::vector<std::pair<Kind, uint8_t>> map;
    std::vector<bool> known;
    for (const Signal& s : sim.signals()) {
        Kind k = Kind::Enable;
        uint8_t axis = 0;
        bool ok = true;
        if (s.name == "enable") {
        } else if (s.name.size() == 6 && s.name.compare(0, 5, "step_") == 0) {
            k = Kind::Step;
            axis = static_cast<uint8_t>(std::string("xyza").find(s.name[5]));
        } else if (s.name.size() == 5 && s.name.compare(0, 4, "dir_") == 0) {
            k = Kind::Dir;
            axis = static_cast<uint8_t>(std::string("xyza").find(s.name[4]));
        } else {
            ok = false;
        }
        map.emplace_back(k, axis);
        known.push_back(ok && axis < 4);
    }
    std::vector<PinEdge> out;
    const std::vector<Edge>& all = sim.edges();
    for (size_t i = from; i < all.size(); ++i) {
        const Edge& e = all[i];
        if (!known[e.signal]) continue;
        out.push_back(PinEdge{e.cycle, map[e.signal].first, map[e.signal].second, e.level});
    }
    return out;
}

// ---- the chip -----------------------------------------------------------------------------

void paint_stack(Sim& sim) {
    const uint32_t bss_end = sim.symbol("__bss_end");
    // Below the current stack pointer only: what is above it is in use.
    const uint16_t sp = static_cast<uint16_t>(sim.peek(0x5D) | sim.peek(0x5E) << 8);
    const uint32_t ram_end = sim.avr()->ramend; // 0x8FF (LLSIM_BIG_RAM: 0xFFF)
    for (uint32_t a = bss_end; a <= sp && a <= ram_end; ++a) sim.avr()->data[a] = kPaint;
}

std::pair<uint16_t, uint16_t> stack_high_water(const Sim& sim) {
    const uint32_t bss_end = sim.symbol("__bss_end");
    const uint32_t ram_end = sim.avr()->ramend;
    uint32_t a = bss_end;
    while (a <= ram_end && sim.peek(static_cast<uint16_t>(a)) == kPaint) ++a;
    return {static_cast<uint16_t>(ram_end + 1 - a), static_cast<uint16_t>(a - bss_end)};
}

Trace run_on_chip(const Job& job) {
    Options opt;
    opt.elf = firmware_elf();
    Sim sim(opt);
    return run_on_chip(sim, job);
}

Trace run_on_chip(Sim& sim, const Job& job) {
    Trace t;
    const auto t0 = Clock::now();
    if (sim.cycle() == 0) paint_stack(sim);
    Grbl grbl(sim);
    if (!grbl.wait_banner(ms(500))) {
        t.errors.push_back("(no banner)");
        return t;
    }
    for (const std::string& s : job.settings) {
        const Reply r = grbl.send_line(s, kLineTimeout);
        if (!r.ok) t.errors.push_back(s);
    }
    const uint32_t exec = sim.symbol("_ZN2ll6g_execE");
    const uint16_t running = static_cast<uint16_t>(exec + 3);
    sim.watch_register(kTccr1b);
    sim.send("!");
    sim.run_for(ms(1));
    for (const std::string& l : job.lines) {
        const Reply r = grbl.send_line(l, kLineTimeout);
        if (!r.ok) t.errors.push_back(l);
    }
    // Nothing may move before cycle start.
    if (sim.peek(running) != 0) t.errors.push_back("(timer running before ~)");

    const size_t from_edge = sim.edges().size();
    for (uint16_t i = 0; i < sim.signals().size(); ++i) {
        const std::string& n = sim.signals()[i].name;
        if (n.size() == 5 && n.compare(0, 4, "dir_") == 0 && sim.recorder().level(i)) {
            const size_t axis = std::string("xyza").find(n[4]);
            if (axis < 4) t.dir_levels0 = static_cast<uint8_t>(t.dir_levels0 | 1u << axis);
        }
    }
    const size_t from_write = sim.register_writes().size();
    const size_t from_isr = sim.isr_spans().size();
    for (uint8_t v = 1; v < 26; ++v) sim.record_isr(v); // for the enable lead (compare())
    const uint64_t c0 = sim.cycle();
    sim.send("~");
    const int poll =
        job.status_every_ms == 0 ? 0 : sim.send_every('?', c0 + ms(1), ms(job.status_every_ms));
    const uint64_t limit = c0 + ms(job.limit_ms);
    // Run until the timer has stopped and stayed stopped for kTail.
    sim.run_until([&] { return sim.peek(running) != 0; }, ms(50));
    for (;;) {
        sim.run_until([&] { return sim.peek(running) == 0; }, limit - sim.cycle());
        if (sim.cycle() >= limit) {
            t.errors.push_back("(job did not end)");
            break;
        }
        if (!sim.run_until([&] { return sim.peek(running) != 0; }, kTail)) break;
    }
    if (poll != 0) sim.stop_periodic(poll);
    t.cycles = sim.cycle() - c0;
    t.wall_seconds = seconds_since(t0);

    t.edges = chip_edges(sim, from_edge);
    const std::vector<RegWrite>& w = sim.register_writes();
    for (size_t i = from_write; i < w.size(); ++i) {
        if (w[i].addr != kTccr1b) continue;
        if (w[i].value & kClockSelect)
            t.starts.push_back(w[i].cycle);
        else
            t.stops.push_back(w[i].cycle);
    }
    const std::vector<IsrSpan>& spans = sim.isr_spans();
    for (size_t i = from_isr; i < spans.size(); ++i) {
        if (!t.starts.empty() && spans[i].accepted >= t.starts.front()) break;
        t.isr_before_start.emplace_back(spans[i].accepted,
                                        spans[i].returned ? spans[i].returned : sim.cycle());
    }
    t.starvations = peek16(sim, sim.symbol("_ZN2ll13g_starvationsE"));
    t.final_status = grbl.status(ms(20));
    const std::pair<uint16_t, uint16_t> hw = stack_high_water(sim);
    t.stack_bytes = hw.first;
    t.stack_free = hw.second;
    return t;
}

// ---- the host model -----------------------------------------------------------------------

Trace run_on_model(const Job& job) {
    Trace t;
    const auto t0 = Clock::now();
    test::HostDriver d;
    d.boot(true); // blank EEPROM, as the simulated chip
    for (const std::string& s : job.settings)
        if (!is_ok_reply(d.command(s))) t.errors.push_back(s);
    d.send("!");
    d.run_for(16000);
    for (const std::string& l : job.lines)
        if (!is_ok_reply(d.command(l))) t.errors.push_back(l);
    if (host::timer_running()) t.errors.push_back("(timer running before ~)");

    const size_t from_edge = host::edges().size();
    for (const host::Edge& e : host::edges()) {
        if (e.kind != host::EdgeKind::Dir) continue;
        const uint8_t bit = static_cast<uint8_t>(1u << e.axis);
        t.dir_levels0 =
            static_cast<uint8_t>(e.level ? (t.dir_levels0 | bit) : (t.dir_levels0 & ~bit));
    }
    const uint64_t c0 = host::now();
    d.send("~");
    const uint64_t limit = c0 + ms(job.limit_ms);
    uint64_t quiet_since = host::now();
    for (;;) {
        const bool was = host::timer_running();
        const uint32_t stops = host::timer_stops();
        const uint64_t now = host::now();
        d.step();
        if (!was && (host::timer_running() || host::timer_stops() != stops))
            t.starts.push_back(now);
        if (host::timer_stops() != stops) t.stops.push_back(host::now());
        const bool idle =
            protocol::idle() && motion::state() == motion::State::Idle && !host::timer_running();
        if (!idle) quiet_since = host::now();
        if (!t.starts.empty() && host::now() - quiet_since >= kTail) break;
        if (host::now() >= limit) {
            t.errors.push_back("(job did not end)");
            break;
        }
    }
    t.cycles = host::now() - c0;
    for (size_t i = from_edge; i < host::edges().size(); ++i) {
        const host::Edge& e = host::edges()[i];
        const Kind k = e.kind == host::EdgeKind::Step
                           ? Kind::Step
                           : (e.kind == host::EdgeKind::Dir ? Kind::Dir : Kind::Enable);
        t.edges.push_back(PinEdge{e.cycle, k, e.axis, e.level});
    }
    t.starvations = g_starvations;
    d.take();
    d.send("?");
    const std::string out = d.run_for(2 * 16000);
    const size_t lt = out.find('<');
    if (lt != std::string::npos) t.final_status = out.substr(lt, out.find('>', lt) + 1 - lt);
    t.wall_seconds = seconds_since(t0);
    return t;
}

// ---- comparison ---------------------------------------------------------------------------

Comparison compare(const Trace& model, const Trace& chip, int64_t tolerance, int64_t enable_window,
                   int64_t disable_window) {
    Comparison c;
    auto problem = [&](const std::string& text) {
        if (c.problems.size() < 12) c.problems.push_back(text);
    };
    if (model.starts.empty() || chip.starts.empty()) {
        problem("the step timer never started");
        return c;
    }
    if (model.starts.size() != chip.starts.size()) {
        problem("timer starts: model " + std::to_string(model.starts.size()) + ", chip " +
                std::to_string(chip.starts.size()));
    }
    const int64_t m0 = static_cast<int64_t>(model.starts.front());
    const int64_t c0 = static_cast<int64_t>(chip.starts.front());
    auto model_start = [&](uint64_t cycle) {
        return std::find(model.starts.begin(), model.starts.end(), cycle) != model.starts.end();
    };

    std::map<int, std::vector<PinEdge>> me, ce;
    for (const PinEdge& e : model.edges) me[key_of(e)].push_back(e);
    for (const PinEdge& e : chip.edges) ce[key_of(e)].push_back(e);
    for (const auto& kv : ce)
        if (!me.count(kv.first))
            problem(describe(kv.second.front()) + ": " + std::to_string(kv.second.size()) +
                    " chip edges, none in the model");

    for (const auto& kv : me) {
        const std::vector<PinEdge>& m = kv.second;
        const std::vector<PinEdge> empty;
        const std::vector<PinEdge>& h = ce.count(kv.first) ? ce[kv.first] : empty;
        if (m.size() != h.size())
            problem(describe(m.front()) + ": model " + std::to_string(m.size()) + " edges, chip " +
                    std::to_string(h.size()));
        const size_t n = std::min(m.size(), h.size());
        for (size_t i = 0; i < n; ++i) {
            const PinEdge& a = m[i];
            const PinEdge& b = h[i];
            const int64_t tm = static_cast<int64_t>(a.cycle) - m0;
            const int64_t tc = static_cast<int64_t>(b.cycle) - c0;
            char where[160];
            snprintf(where, sizeof where, "%s #%zu at model +%lld, chip +%lld", describe(a).c_str(),
                     i, static_cast<long long>(tm), static_cast<long long>(tc));
            if (a.level != b.level) {
                problem(std::string(where) + ": chip level " + std::to_string(b.level));
                continue;
            }
            if (a.kind == Kind::Enable) {
                if (model_start(a.cycle)) {
                    // The firmware enables the drivers, then starts the timer: a path of main-
                    // loop code. An interrupt handler can run between the two (measured: Timer2's
                    // millis tick, 62 cycles, and the receive handler, 89), which delays the
                    // start but is no part of that path: its cycles are taken out of the lead.
                    const int64_t lead = tm - tc;
                    int64_t isr = 0;
                    for (const auto& span : chip.isr_before_start) {
                        const uint64_t from = std::max<uint64_t>(span.first, b.cycle);
                        const uint64_t to = std::min<uint64_t>(span.second, chip.starts.front());
                        if (to > from) isr += static_cast<int64_t>(to - from);
                    }
                    if (lead - isr > c.enable_lead) {
                        c.enable_lead = lead - isr;
                        c.enable_isr = isr;
                    }
                    if (lead < 0 || lead - isr > enable_window)
                        problem(std::string(where) + ": enable edge not just before the start (" +
                                std::to_string(lead - isr) + " cycles of main loop, " +
                                std::to_string(isr) + " in interrupts)");
                } else {
                    const int64_t dev = iabs(tc - tm);
                    c.disable_dev = std::max(c.disable_dev, dev);
                    if (dev > disable_window)
                        problem(std::string(where) + ": disable edge off by " +
                                std::to_string(dev));
                }
                ++c.compared;
                continue;
            }
            Category cat;
            int64_t offset;
            if (a.kind == Kind::Step) {
                // From rest, a step pin's edges alternate pulse start, pulse end.
                cat = (i % 2) == 0 ? kStepStart : kStepEnd;
                offset = cat == kStepStart ? step_edge_offset(a.axis) : pulse_end_offset(a.axis);
            } else if (model_start(a.cycle)) {
                cat = kDirAtStart;
                offset = start_dir_offset(a.axis);
            } else {
                cat = kDirAtRun;
                offset = pulse_end_offset(a.axis);
            }
            const int64_t dev = tc - tm - offset;
            c.dev[cat].add(dev);
            ++c.compared;
            if (iabs(dev) > tolerance)
                problem(std::string(where) + ": deviation " + std::to_string(dev) + " cycles");
        }
    }
    return c;
}

const char* category_name(uint8_t c) {
    switch (c) {
        case kStepStart:
            return "step start";
        case kStepEnd:
            return "step end";
        case kDirAtStart:
            return "dir at start";
        case kDirAtRun:
            return "dir at run change";
    }
    return "?";
}

std::string Comparison::ranges() const {
    std::string out;
    for (uint8_t k = 0; k < kCategories; ++k) {
        if (dev[k].n == 0) continue;
        char buf[96];
        snprintf(buf, sizeof buf, "%s%s %lld..%lld (%zu)", out.empty() ? "" : ", ",
                 category_name(k), static_cast<long long>(dev[k].min),
                 static_cast<long long>(dev[k].max), dev[k].n);
        out += buf;
    }
    return out;
}

// ---- pulse width and direction setup ------------------------------------------------------

PulseStats pulse_stats(const std::vector<PinEdge>& edges, uint8_t step_invert, uint8_t dir_invert,
                       uint8_t dir_levels0) {
    PulseStats s;
    uint64_t rise[4] = {0, 0, 0, 0};
    bool high[4] = {false, false, false, false};
    bool dir_pending[4] = {false, false, false, false};
    uint64_t dir_at[4] = {0, 0, 0, 0};
    uint8_t dir_level[4];
    for (uint8_t a = 0; a < 4; ++a) dir_level[a] = static_cast<uint8_t>((dir_levels0 >> a) & 1);
    std::vector<PinEdge> sorted = edges;
    std::stable_sort(sorted.begin(), sorted.end(),
                     [](const PinEdge& a, const PinEdge& b) { return a.cycle < b.cycle; });
    for (const PinEdge& e : sorted) {
        if (e.axis >= 4 || e.kind == Kind::Enable) continue;
        const uint8_t a = e.axis;
        if (e.kind == Kind::Dir) {
            dir_level[a] = e.level;
            dir_at[a] = e.cycle;
            dir_pending[a] = true;
            if (high[a]) ++s.dir_during_pulse;
            continue;
        }
        const uint8_t active = static_cast<uint8_t>(((step_invert >> a) & 1) ^ 1);
        if (e.level == active) {
            high[a] = true;
            rise[a] = e.cycle;
            if (dir_pending[a]) {
                s.min_dir_setup = std::min(s.min_dir_setup, e.cycle - dir_at[a]);
                ++s.dir_changes;
                dir_pending[a] = false;
            }
            const bool negative = ((dir_level[a] ^ (dir_invert >> a)) & 1) != 0;
            s.net[a] += negative ? -1 : 1;
        } else if (high[a]) {
            high[a] = false;
            ++s.pulses[a];
            const uint64_t w = e.cycle - rise[a];
            s.min_pulse = std::min(s.min_pulse, w);
            s.max_pulse = std::max(s.max_pulse, w);
        }
    }
    return s;
}

} // namespace fw
} // namespace sim
} // namespace ll
