#include "simjob.h"

#include <ctype.h>

#include <fcntl.h>
#include <gelf.h>
#include <libelf.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <stdexcept>

namespace ll {
namespace tools {

using sim::OutputLine;
using sim::Sim;

// ---- traces ---------------------------------------------------------------------------------

Trace trace_steps(const Sim& sim, uint8_t step_invert, uint8_t dir_invert) {
    static const char* const kStep[kTraceAxes] = {"step_x", "step_y", "step_z", "step_a"};
    static const char* const kDir[kTraceAxes] = {"dir_x", "dir_y", "dir_z", "dir_a"};
    const sim::Recorder& rec = const_cast<Sim&>(sim).recorder();
    std::vector<int> step_axis(rec.signals().size(), -1);
    int dir_signal[kTraceAxes];
    for (int a = 0; a < kTraceAxes; ++a) {
        const int s = rec.find(kStep[a]);
        if (s >= 0) step_axis[static_cast<size_t>(s)] = a;
        dir_signal[a] = rec.find(kDir[a]);
    }
    std::vector<uint8_t> level = rec.initial_levels();
    Trace t;
    std::array<int32_t, kTraceAxes> pos{};
    for (const sim::Edge& e : rec.edges()) {
        level[e.signal] = e.level;
        const int a = step_axis[e.signal];
        if (a < 0) continue;
        const uint8_t bit = static_cast<uint8_t>(1u << a);
        const bool idle_high = (step_invert & bit) != 0;
        if ((e.level != 0) == idle_high) continue; // pulse end
        const int d = dir_signal[a];
        const bool dir_level = d >= 0 && level[static_cast<size_t>(d)] != 0;
        const bool negative = dir_level != ((dir_invert & bit) != 0);
        pos[static_cast<size_t>(a)] += negative ? -1 : 1;
        t.edges[static_cast<size_t>(a)].push_back(e.cycle);
        if (!t.cycle.empty() && t.cycle.back() == e.cycle) {
            t.pos.back() = pos;
        } else {
            t.cycle.push_back(e.cycle);
            t.pos.push_back(pos);
        }
    }
    t.final_pos = pos;
    return t;
}

Stats stats_of(std::vector<uint64_t> v) {
    Stats s;
    s.n = v.size();
    if (v.empty()) return s;
    std::sort(v.begin(), v.end());
    s.min = v.front();
    s.max = v.back();
    s.median = v[v.size() / 2];
    double sum = 0;
    for (uint64_t x : v) sum += static_cast<double>(x);
    s.mean = sum / static_cast<double>(v.size());
    return s;
}

// ---- host protocol --------------------------------------------------------------------------

bool Host::run_until(const std::function<bool()>& done, uint64_t max_cycles) {
    if (!hook) return sim_.run_until(done, max_cycles);
    return sim_.run_until(
        [&] {
            hook();
            return done();
        },
        max_cycles);
}

void Host::run_for(uint64_t cycles) {
    if (!hook) {
        sim_.run_for(cycles);
        return;
    }
    const uint64_t end = sim_.deadline(cycles);
    run_until([&] { return sim_.cycle() >= end; }, cycles);
}

size_t Host::take() {
    size_t n = 0;
    const std::vector<OutputLine>& all = sim_.output_lines();
    for (; cursor_ < all.size(); ++cursor_) {
        const std::string& s = all[cursor_].text;
        if (s == "ok" || s.compare(0, 6, "error:") == 0) {
            answers_.push_back(all[cursor_]);
            ++n;
        } else {
            others_.push_back(all[cursor_]);
        }
    }
    return n;
}

bool Host::wait_banner(uint64_t max_cycles) {
    const uint64_t limit = sim_.deadline(max_cycles);
    for (;;) {
        // Everything up to the banner answers no line of ours (a blank EEPROM prints error:7).
        const std::vector<OutputLine>& all = sim_.output_lines();
        for (; cursor_ < all.size(); ++cursor_) {
            others_.push_back(all[cursor_]);
            if (all[cursor_].text.compare(0, 5, "Grbl ") == 0) {
                ++cursor_;
                return true;
            }
        }
        if (sim_.cycle() >= limit) return false;
        const size_t n = sim_.output_lines().size();
        run_until([&] { return sim_.output_lines().size() != n; }, limit - sim_.cycle());
    }
}

int Host::send_line(const std::string& line, uint64_t max_cycles) {
    const size_t before = answers_.size();
    if (stream({line}, true, max_cycles) < 0) return -1;
    const std::string& a = answers_[before].text;
    return a == "ok" ? 0 : atoi(a.c_str() + 6);
}

int Host::stream(const std::vector<std::string>& lines, bool send_and_wait, uint64_t max_wait) {
    uint64_t limit = sim_.deadline(max_wait);
    const size_t window = send_and_wait ? 0 : sim::kGrblRxBuffer;
    std::deque<size_t> flight; // bytes of each unanswered line
    size_t used = 0, next = 0, errors = 0, first_answer = answers_.size();
    take();
    first_answer = answers_.size();
    size_t done = 0;
    answered_ = 0;
    while (done < lines.size()) {
        while (next < lines.size() && (flight.empty() || used + lines[next].size() + 1 <= window)) {
            sim_.send(lines[next] + "\n");
            flight.push_back(lines[next].size() + 1);
            used += lines[next].size() + 1;
            ++next;
        }
        if (sim_.cycle() >= limit) return -1;
        const size_t n = sim_.output_lines().size();
        run_until([&] { return sim_.output_lines().size() != n; }, limit - sim_.cycle());
        for (size_t k = take(); k > 0 && !flight.empty(); --k) {
            used -= flight.front();
            flight.pop_front();
            answered_ = ++done;
            limit = sim_.deadline(max_wait);
        }
    }
    for (size_t i = first_answer; i < answers_.size(); ++i)
        if (answers_[i].text != "ok") ++errors;
    return static_cast<int>(errors);
}

std::string Host::status(uint64_t max_cycles) {
    const size_t seen = others_.size();
    sim_.send("?");
    const uint64_t limit = sim_.deadline(max_cycles);
    for (;;) {
        take();
        for (size_t i = seen; i < others_.size(); ++i)
            if (!others_[i].text.empty() && others_[i].text[0] == '<') return others_[i].text;
        if (sim_.cycle() >= limit) return "";
        const size_t n = sim_.output_lines().size();
        run_until([&] { return sim_.output_lines().size() != n; }, limit - sim_.cycle());
    }
}

// ---- profiler -------------------------------------------------------------------------------

namespace {
constexpr uint16_t kSpl = 0x5D; // data-space addresses of SPL / SPH on the ATmega328P
constexpr uint16_t kSph = 0x5E;
constexpr uint8_t kVectors = 26;
} // namespace

// A function's symbol, or when its signature changed since the name was written, the one with
// the same nested name (_ZN2ll7StepGen4fillE...: the part up to the E closing the name).
std::string resolve(const Sim& sim, const std::string& name) {
    if (sim.has_symbol(name)) return name;
    size_t i = name.compare(0, 4, "_ZNK") == 0 ? 4 : name.compare(0, 3, "_ZN") == 0 ? 3 : 0;
    if (i == 0) return "";
    while (i < name.size() && isdigit(static_cast<unsigned char>(name[i]))) {
        size_t len = 0;
        while (i < name.size() && isdigit(static_cast<unsigned char>(name[i])))
            len = len * 10 + static_cast<size_t>(name[i++] - '0');
        i += len;
    }
    if (i >= name.size() || name[i] != 'E') return "";
    return sim.symbol_with_prefix(name.substr(0, i + 1));
}

Profiler::Profiler(Sim& sim, const std::vector<std::string>& symbols)
    : sim_(sim), names_(symbols), fn_at_((sim.avr()->flashend + 1u) / 2, -1) {
    for (size_t i = 0; i < symbols.size(); ++i) {
        const std::string name = resolve(sim, symbols[i]);
        if (name.empty()) continue;
        const uint32_t addr = sim.symbol(name);
        if (addr / 2 < fn_at_.size()) fn_at_[addr / 2] = static_cast<int16_t>(i);
    }
    for (uint8_t v = 1; v < kVectors; ++v) sim.record_isr(v);
}

void Profiler::step() {
    avr_t* a = sim_.avr();
    const uint16_t sp = static_cast<uint16_t>(a->data[kSpl] | (a->data[kSph] << 8));
    // Returned: the stack pointer is above the frame and the CPU is at its return address. The
    // address matters: SP is written one byte at a time (SPH, then SPL), so while a frame is
    // released it can read above its final value for one instruction.
    while (!stack_.empty() && sp > stack_.back().sp && a->pc == stack_.back().ret) {
        calls_[static_cast<size_t>(stack_.back().call)].end = a->cycle;
        stack_.pop_back();
    }
    const uint32_t word = a->pc / 2;
    if (word < fn_at_.size() && fn_at_[word] >= 0) {
        // A tail call arrives with the caller's stack pointer and return address: it is nested
        // all the same and both end at the same return.
        const int parent = stack_.empty() ? -1 : stack_.back().call;
        const uint32_t ret = 2u * ((static_cast<uint32_t>(a->data[sp + 1]) << 8) | a->data[sp + 2]);
        calls_.push_back(Call{fn_at_[word], parent, a->cycle, 0});
        stack_.push_back(Frame{static_cast<int>(calls_.size() - 1), sp, ret});
    }
}

int Profiler::index_of(const std::string& symbol) const {
    for (size_t i = 0; i < names_.size(); ++i)
        if (names_[i] == symbol) return static_cast<int>(i);
    return -1;
}

uint64_t Profiler::isr_cycles_in(uint64_t from, uint64_t to) const {
    // Spans are in order of acceptance; nested ones (an interruptible handler) are counted once
    // by merging overlaps.
    uint64_t total = 0, covered_to = from;
    const std::vector<sim::IsrSpan>& spans = sim_.isr_spans();
    auto it = std::lower_bound(spans.begin(), spans.end(), from,
                               [](const sim::IsrSpan& s, uint64_t c) { return s.accepted < c; });
    // A handler accepted just before `from` may still be running.
    if (it != spans.begin()) --it;
    for (; it != spans.end() && it->accepted < to; ++it) {
        const uint64_t s = std::max(it->accepted, covered_to);
        const uint64_t e = std::min(it->returned ? it->returned : to, to);
        if (e > s) {
            total += e - s;
            covered_to = e;
        }
    }
    return total;
}

// ---- chip ---------------------------------------------------------------------------------

namespace {
constexpr uint8_t kPaint = 0xA5;
} // namespace

StackProbe::StackProbe(Sim& sim) : sim_(sim), bss_end_(sim.symbol("__bss_end")) {
    avr_t* a = sim.avr();
    const unsigned sp = static_cast<unsigned>(a->data[kSpl] | (a->data[kSph] << 8));
    painted_to_ = sp; // SP points at the next free byte: everything below it is free
    for (unsigned i = bss_end_; i < painted_to_; ++i) a->data[i] = kPaint;
}

unsigned StackProbe::peak() const {
    unsigned lowest = painted_to_;
    for (unsigned i = bss_end_; i < painted_to_; ++i) {
        if (sim_.peek(static_cast<uint16_t>(i)) != kPaint) {
            lowest = i;
            break;
        }
    }
    return sim_.avr()->ramend + 1u - lowest; // 0x8FF on the 328P (LLSIM_BIG_RAM: 0xFFF)
}

bool StackProbe::overflowed() const {
    return sim_.peek(static_cast<uint16_t>(bss_end_)) != kPaint;
}

CompareLog::CompareLog(Sim& sim, uint8_t vector, char timer) : sim_(sim) {
    avr_t* a = sim.avr();
    for (int i = 0; i < a->interrupts.vector_count; ++i) {
        avr_int_vector_t* v = a->interrupts.vector[i];
        if (v && v->vector == vector) irq_ = &v->irq[AVR_INT_IRQ_PENDING];
    }
    for (avr_io_t* io = a->io_port; io; io = io->next) {
        if (strcmp(io->kind, "timer") != 0) continue;
        avr_timer_t* t = reinterpret_cast<avr_timer_t*>(io);
        if (t->name == timer) timer_ = t;
    }
    if (!irq_ || !timer_) throw std::runtime_error("CompareLog: no such vector or timer");
    avr_irq_register_notify(irq_, &CompareLog::on_pending, this);
}

CompareLog::~CompareLog() {
    avr_irq_unregister_notify(irq_, &CompareLog::on_pending, this);
}

void CompareLog::on_pending(avr_irq_t*, uint32_t value, void* param) {
    if (!value) return; // cleared (served, or written one to clear)
    CompareLog* self = static_cast<CompareLog*>(param);
    const avr_t* a = self->sim_.avr();
    uint64_t at = a->cycle;
    // The flag is set at the period boundary; simavr notices it after the instruction under way
    // (at most 4 cycles later), with tov_base holding the boundary itself.
    const uint64_t base = self->timer_->tov_base;
    if (self->timer_->tov_cycles > 1 && base <= at && at - base <= 8) at = base;
    self->matches_.push_back(at);
}

bool CompareLog::latest_at(uint64_t cycle, uint64_t* match) const {
    auto it = std::upper_bound(matches_.begin(), matches_.end(), cycle);
    if (it == matches_.begin()) return false;
    *match = *(it - 1);
    return true;
}

uint32_t peek_var(const Sim& sim, const std::string& symbol, unsigned bytes, unsigned offset) {
    const uint32_t addr = sim.symbol(symbol) + offset;
    uint32_t v = 0;
    for (unsigned i = 0; i < bytes; ++i)
        v |= static_cast<uint32_t>(sim.peek(static_cast<uint16_t>(addr + i))) << (8 * i);
    return v;
}

ImageSize image_size(const std::string& elf) {
    ImageSize r;
    if (elf_version(EV_CURRENT) == EV_NONE) throw std::runtime_error("libelf too old");
    const int fd = open(elf.c_str(), O_RDONLY);
    if (fd < 0) throw std::runtime_error("cannot open " + elf);
    Elf* e = elf_begin(fd, ELF_C_READ, nullptr);
    size_t shstrndx = 0;
    if (!e || elf_getshdrstrndx(e, &shstrndx) != 0) {
        close(fd);
        throw std::runtime_error("not an ELF file: " + elf);
    }
    for (Elf_Scn* scn = elf_nextscn(e, nullptr); scn; scn = elf_nextscn(e, scn)) {
        GElf_Shdr sh;
        if (!gelf_getshdr(scn, &sh)) continue;
        const char* name = elf_strptr(e, shstrndx, sh.sh_name);
        if (!name) continue;
        const uint32_t size = static_cast<uint32_t>(sh.sh_size);
        if (!strcmp(name, ".text") || !strcmp(name, ".bootloader")) r.flash += size;
        if (!strcmp(name, ".data")) {
            r.flash += size;
            r.ram += size;
        }
        if (!strcmp(name, ".bss") || !strcmp(name, ".noinit")) r.ram += size;
    }
    elf_end(e);
    close(fd);
    return r;
}

// ---- jobs -----------------------------------------------------------------------------------

std::vector<std::string> circle_job(double radius, double segment, double feed) {
    const double kPi = 3.14159265358979323846;
    const int n = static_cast<int>(std::lround(2 * kPi * radius / segment));
    std::vector<std::string> lines;
    char buf[64];
    for (int k = 1; k <= n; ++k) {
        const double th = 2 * kPi * k / n;
        double x = -radius + radius * std::cos(th), y = radius * std::sin(th);
        if (k == n) x = y = 0; // exactly back at the start
        if (std::fabs(x) < 5e-4) x = 0;
        if (std::fabs(y) < 5e-4) y = 0;
        if (k == 1)
            snprintf(buf, sizeof buf, "G1X%.3fY%.3fF%.0f", x, y, feed);
        else
            snprintf(buf, sizeof buf, "G1X%.3fY%.3f", x, y);
        lines.push_back(buf);
    }
    return lines;
}

} // namespace tools
} // namespace ll
