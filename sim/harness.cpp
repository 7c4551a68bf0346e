#include "harness.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <fstream>

extern "C" {
#include <avr_eeprom.h>
#include <avr_ioport.h>
#include <avr_uart.h>
#include <sim_hex.h>
#include <sim_regbit.h>
}

namespace ll {
namespace sim {

namespace {

constexpr const char* kMcu = "atmega328p";
// The AVR data space that 16-bit addresses reach (simavr indexes avr->data with them).
constexpr size_t kDataSpace = 0x10000;
// While the receiver cannot take a byte (disabled, XOFF), the line is checked again this often:
// 256 cycles = 16 us, a fifth of a frame, so a byte starts at most that late once it can.
constexpr uint64_t kBlockedRetryCycles = 256;

int g_log_level = LOG_ERROR;

void logger(avr_t*, const int level, const char* format, va_list ap) {
    // LOG_OUTPUT carries simavr's console echo of UART lines; the harness records those itself.
    if (level < LOG_ERROR || level > g_log_level) return;
    vfprintf(stderr, format, ap);
}

template <class T>
T* find_module(avr_t* avr, const char* kind) {
    for (avr_io_t* io = avr->io_port; io; io = io->next)
        if (strcmp(io->kind, kind) == 0) return reinterpret_cast<T*>(io);
    return nullptr;
}

bool file_exists(const std::string& path) {
    struct stat st;
    return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

bool is_hex_image(const std::string& path) {
    return path.size() > 4 && (path.compare(path.size() - 4, 4, ".hex") == 0 ||
                               path.compare(path.size() - 4, 4, ".HEX") == 0);
}

/// An Intel hex image (what avrdude flashes, e.g. a released GRBL build): its data records into
/// fw->flash from address 0, gaps erased (0xFF). No symbols, no EEPROM.
void read_hex_image(const std::string& path, elf_firmware_t* fw) {
    ihex_chunk_p chunks = nullptr;
    const int n = read_ihex_chunks(path.c_str(), &chunks);
    if (n <= 0) throw SimError("llsim: cannot read Intel hex " + path);
    uint32_t end = 0;
    for (int i = 0; i < n; ++i) end = std::max(end, chunks[i].baseaddr + chunks[i].size);
    fw->flash = static_cast<uint8_t*>(malloc(end));
    memset(fw->flash, 0xFF, end);
    for (int i = 0; i < n; ++i)
        memcpy(fw->flash + chunks[i].baseaddr, chunks[i].data, chunks[i].size);
    fw->flashsize = end;
    fw->flashbase = 0;
    free_ihex_chunks(chunks);
}

} // namespace

Sim::Sim(const Options& opt) : opt_(opt) {
    memset(&fw_, 0, sizeof fw_);
    if (!file_exists(opt_.elf)) throw SimError("llsim: firmware not found: " + opt_.elf);
    g_log_level = opt_.log_level;
    avr_global_logger_set(&logger);
    if (is_hex_image(opt_.elf))
        read_hex_image(opt_.elf, &fw_);
    else if (elf_read_firmware(opt_.elf.c_str(), &fw_) != 0)
        throw SimError("llsim: cannot read ELF " + opt_.elf);
    // The board is fixed: an Uno. An .mmcu section in the ELF cannot change that.
    snprintf(fw_.mmcu, sizeof fw_.mmcu, "%s", kMcu);
    fw_.frequency = kCpuHz;

    avr_ = avr_make_mcu_by_name(kMcu);
    if (!avr_) throw SimError("llsim: simavr has no atmega328p core");
    // Diagnostic only: LLSIM_BIG_FLASH=1 gives the simulated chip 64 KiB of flash, so that an
    // image over the 328P's 32 KiB can still be run and measured (stack, timing) while it is
    // being made smaller; LLSIM_BIG_RAM=1 gives it 4 KiB of RAM (for an image linked with
    // -Wl,--defsym=__stack=0x800FFF). Everything else stays the 328P's.
    const char* big = getenv("LLSIM_BIG_FLASH");
    if (big && big[0] == '1') avr_->flashend = 0xFFFF;
    const char* big_ram = getenv("LLSIM_BIG_RAM");
    if (big_ram && big_ram[0] == '1') avr_->ramend = 0x0FFF;
    avr_init(avr_);
    // simavr 1.6 performs a store beyond RAMEND after reporting it and marking the core crashed
    // (avr_core_watch_write; loads alike): a runaway firmware, such as GRBL 1.1h once its step
    // interrupts nest, wrote past the RAMEND + 1 bytes avr_init() allocated and corrupted the
    // host's heap. The buffer covers the whole 16-bit data space; the run still ends with the
    // crash (selftest_stray_write).
    const size_t ram = static_cast<size_t>(avr_->ramend) + 1;
    uint8_t* data = static_cast<uint8_t*>(realloc(avr_->data, kDataSpace));
    if (!data) throw SimError("llsim: out of memory");
    memset(data + ram, 0, kDataSpace - ram);
    avr_->data = data;
    avr_->log = static_cast<uint8_t>(opt_.log_level) & 0xF;
    avr_->frequency = kCpuHz;
    avr_load_firmware(avr_, &fw_);
    avr_->frequency = kCpuHz;
    // avr_t has no user pointer for its callbacks; custom.data is free while custom.init and
    // custom.deinit are unused, which is the case here.
    avr_->custom.data = this;
    avr_->sleep = &Sim::sleep_cb;

    hooks_.reset(new IoHooks(avr_));
    corr_.reset(new Corrector(avr_, *hooks_, opt_.corrections));

    uart_ = find_module<avr_uart_t>(avr_, "uart");
    eeprom_ = find_module<avr_eeprom_t>(avr_, "eeprom");
    uart_in_ = avr_io_getirq(avr_, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_INPUT);
    avr_irq_register_notify(avr_io_getirq(avr_, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT),
                            &Sim::uart_out_cb, this);
    avr_irq_register_notify(avr_io_getirq(avr_, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUT_XON),
                            &Sim::uart_xon_cb, this);
    avr_irq_register_notify(avr_io_getirq(avr_, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUT_XOFF),
                            &Sim::uart_xoff_cb, this);

    for (int i = 0; i < avr_->interrupts.vector_count; ++i) {
        avr_int_vector_t* v = avr_->interrupts.vector[i];
        if (!v || !v->vector) continue;
        vector_hooks_.push_back(std::unique_ptr<VectorHook>(new VectorHook{this, v->vector}));
        // RUNNING rises when the CPU accepts this vector and falls at its RETI.
        avr_irq_register_notify(&v->irq[AVR_INT_IRQ_RUNNING], &Sim::vector_cb,
                                vector_hooks_.back().get());
    }

    rec_.reset(new Recorder(avr_, opt_.signals));
    if (!opt_.eeprom_file.empty()) load_eeprom(opt_.eeprom_file);
}

Sim::~Sim() {
    rec_.reset();
    hooks_.reset(); // hands simavr its own register callbacks back
    if (avr_) {
        avr_->custom.data = nullptr;
        avr_terminate(avr_);
        free(avr_);
    }
    free(fw_.flash);
    free(fw_.eeprom);
    free(fw_.fuse);
    free(fw_.lockbits);
#if ELF_SYMBOLS
    for (uint32_t i = 0; i < fw_.symbolcount; ++i) free(fw_.symbol[i]);
    free(fw_.symbol);
#endif
}

// ---- running ----------------------------------------------------------------------------

template <class Done>
bool Sim::run_loop(uint64_t limit, Done done) {
    avr_t* const a = avr_;
    if (a->cycle >= limit) return done();
    // A sleeping CPU jumps to the next cycle timer; this one keeps it from jumping past `limit`.
    if (limit != kNever) avr_cycle_timer_register(a, limit - a->cycle, &Sim::limit_timer_cb, this);
    const auto t0 = std::chrono::steady_clock::now();
    const uint64_t c0 = a->cycle;
    bool hit = false;
    while (a->cycle < limit) {
        a->run(a);
        corr_->after_step();
        if (a->state == cpu_Done || a->state == cpu_Crashed) {
            char msg[128];
            snprintf(msg, sizeof msg, "llsim: firmware %s at pc 0x%04x, cycle %llu",
                     a->state == cpu_Done ? "stopped (sleep with interrupts off)" : "crashed",
                     static_cast<unsigned>(a->pc), static_cast<unsigned long long>(a->cycle));
            throw SimError(msg);
        }
        if (done()) {
            hit = true;
            break;
        }
    }
    if (limit != kNever) avr_cycle_timer_cancel(a, &Sim::limit_timer_cb, this);
    wall_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    wall_cycles_ += a->cycle - c0;
    return hit;
}

void Sim::run_for(uint64_t cycles) {
    run_until_cycle(avr_->cycle + cycles);
}

void Sim::run_until_cycle(uint64_t c) {
    run_loop(c, [] { return false; });
}

bool Sim::run_until(const std::function<bool()>& done, uint64_t max_cycles) {
    if (done()) return true;
    return run_loop(deadline(max_cycles), [&] { return done(); });
}

bool Sim::run_until_any_output(uint64_t max_cycles) {
    const size_t n = out_bytes_.size();
    return run_loop(deadline(max_cycles), [&] { return out_bytes_.size() != n; });
}

bool Sim::run_until_output(const std::string& text, uint64_t max_cycles) {
    const size_t from = out_text_.size();
    const uint64_t limit = deadline(max_cycles);
    while (avr_->cycle < limit) {
        if (!run_until_any_output(limit - avr_->cycle)) return false;
        if (out_text_.find(text, from) != std::string::npos) return true;
    }
    return false;
}

bool Sim::run_until_pc(uint32_t byte_address, uint64_t max_cycles) {
    return run_loop(deadline(max_cycles), [&] { return avr_->pc == byte_address; });
}

avr_cycle_count_t Sim::limit_timer_cb(avr_t*, avr_cycle_count_t, void*) {
    return 0;
}

void Sim::sleep_cb(avr_t* avr, avr_cycle_count_t how_long) {
    Sim* self = static_cast<Sim*>(avr->custom.data);
    if (!self) return;
    self->corr_->on_sleep();
    // simavr's raw loop would usleep() the simulated sleep time on the host.
    if (!self->opt_.corrections.no_wallclock_sleep) avr_callback_sleep_raw(avr, how_long);
}

double Sim::speed() const {
    return wall_seconds_ > 0 ? wall_cycles_ / wall_seconds_ : 0.0;
}

// ---- interrupts -------------------------------------------------------------------------

void Sim::vector_cb(avr_irq_t*, uint32_t value, void* param) {
    VectorHook* h = static_cast<VectorHook*>(param);
    h->self->on_vector(h->vector, value);
}

void Sim::on_vector(uint8_t vector, uint32_t running) {
    if (running) {
        const uint64_t accepted = avr_->cycle;
        corr_->on_irq_entry();
        if (isr_watch_[vector]) {
            isr_open_.push_back(isr_spans_.size());
            isr_spans_.push_back(IsrSpan{vector, accepted, 0});
        }
        return;
    }
    // RETI of `vector`: the callback runs while RETI executes (4 cycles on the ATmega328P).
    constexpr uint64_t kRetiCycles = 4;
    for (size_t i = isr_open_.size(); i-- > 0;) {
        IsrSpan& s = isr_spans_[isr_open_[i]];
        if (s.vector != vector) continue;
        s.returned = avr_->cycle + kRetiCycles;
        isr_open_.erase(isr_open_.begin() + static_cast<long>(i));
        break;
    }
}

void Sim::record_isr(uint8_t vector) {
    if (vector >= isr_watch_.size()) throw std::invalid_argument("llsim: no such vector");
    isr_watch_[vector] = true;
}

// ---- serial line ------------------------------------------------------------------------

void Sim::uart_out_cb(avr_irq_t*, uint32_t value, void* param) {
    static_cast<Sim*>(param)->on_output(static_cast<uint8_t>(value));
}

void Sim::on_output(uint8_t byte) {
    out_bytes_.push_back(SerialByte{avr_->cycle, byte});
    out_text_ += static_cast<char>(byte);
    if (byte == '\n') {
        out_lines_.push_back(OutputLine{avr_->cycle, partial_line_});
        partial_line_.clear();
    } else if (byte != '\r') {
        partial_line_ += static_cast<char>(byte);
    }
}

void Sim::uart_xon_cb(avr_irq_t*, uint32_t value, void* param) {
    Sim* self = static_cast<Sim*>(param);
    if (!value) return;
    self->xoff_ = false;
    if (self->line_head_ < self->line_.size()) self->arm_host_timer(self->avr_->cycle);
}

void Sim::uart_xoff_cb(avr_irq_t*, uint32_t value, void* param) {
    static_cast<Sim*>(param)->xoff_ = value != 0;
}

void Sim::send(const std::string& bytes) {
    for (char ch : bytes) line_.push_back(HostByte{static_cast<uint8_t>(ch), avr_->cycle});
    if (!bytes.empty()) arm_host_timer(std::max(avr_->cycle, wire_free_at_));
}

void Sim::send_at(uint64_t at, const std::string& bytes) {
    if (at <= avr_->cycle) {
        send(bytes);
        return;
    }
    scheduled_.emplace(at, bytes);
    arm_host_timer(at);
}

int Sim::send_every(uint8_t byte, uint64_t first, uint64_t period, uint64_t until) {
    if (period == 0) throw std::invalid_argument("llsim: send_every needs a period");
    const int id = next_periodic_id_++;
    periodic_.push_back(Periodic{id, byte, std::max(first, avr_->cycle), period, until});
    arm_host_timer(periodic_.back().next);
    return id;
}

void Sim::stop_periodic(int id) {
    periodic_.erase(std::remove_if(periodic_.begin(), periodic_.end(),
                                   [id](const Periodic& p) { return p.id == id; }),
                    periodic_.end());
}

size_t Sim::serial_pending() const {
    size_t n = line_.size() - line_head_;
    for (const auto& s : scheduled_) n += s.second.size();
    return n;
}

uint64_t Sim::frame_cycles() const {
    return uart_ ? uart_->cycles_per_byte : 0;
}

unsigned Sim::receiver_fill() const {
    return (uart_->input.write + uart_fifo_fifo_size - uart_->input.read) &
           (uart_fifo_fifo_size - 1);
}

bool Sim::receiver_ready() const {
    if (!uart_ || xoff_ || !avr_regbit_get(avr_, uart_->rxen)) return false;
    return receiver_fill() + 1 < uart_fifo_fifo_size;
}

void Sim::arm_host_timer(uint64_t at) {
    if (host_armed_ && host_armed_at_ <= at) return;
    const uint64_t now = avr_->cycle;
    avr_cycle_timer_register(avr_, at > now ? at - now : 0, &Sim::host_timer_cb, this);
    host_armed_ = true;
    host_armed_at_ = std::max(at, now);
}

avr_cycle_count_t Sim::host_timer_cb(avr_t* avr, avr_cycle_count_t when, void* param) {
    Sim* self = static_cast<Sim*>(param);
    const uint64_t next = self->host_service(when, avr->cycle);
    self->host_armed_ = next != 0;
    self->host_armed_at_ = next;
    return next;
}

// `when` is the cycle this service was scheduled for; `now` >= when is the end of the instruction
// after which simavr ran it.
uint64_t Sim::host_service(uint64_t when, uint64_t now) {
    // 0. Stop bits that have arrived: on hardware the byte is lost when the receive FIFO (2 bytes)
    //    is still full of unread ones. simavr's queue holds the arrived bytes and the ones still
    //    on the wire, which are exactly those with a later arrival.
    while (arrivals_head_ < arrivals_.size() && arrivals_[arrivals_head_] <= now) {
        ++arrivals_head_;
        const unsigned on_wire = static_cast<unsigned>(arrivals_.size() - arrivals_head_);
        const unsigned fill = receiver_fill();
        if (fill > on_wire && fill - on_wire > 2) ++overruns_;
    }
    if (arrivals_head_ == arrivals_.size()) {
        arrivals_.clear();
        arrivals_head_ = 0;
    }

    // 1. Bytes whose time has come join the wire queue, in time order.
    while (!scheduled_.empty() && scheduled_.begin()->first <= now) {
        const auto it = scheduled_.begin();
        for (char ch : it->second) line_.push_back(HostByte{static_cast<uint8_t>(ch), it->first});
        scheduled_.erase(it);
    }
    for (Periodic& p : periodic_) {
        while (p.next <= now && p.next <= p.until) {
            line_.push_back(HostByte{p.byte, p.next});
            p.next += p.period;
        }
    }
    periodic_.erase(std::remove_if(periodic_.begin(), periodic_.end(),
                                   [](const Periodic& p) { return p.next > p.until; }),
                    periodic_.end());

    // 2. At most one byte starts per frame: its start bit begins when the previous stop bit ends.
    uint64_t next = kNever;
    if (line_head_ < line_.size()) {
        const HostByte& b = line_[line_head_];
        const uint64_t ideal = std::max(b.not_before, wire_free_at_);
        if (ideal > now) {
            next = ideal;
        } else if (!receiver_ready()) {
            next = now + kBlockedRetryCycles;
        } else {
            // A byte held back (receiver off, XOFF) starts when it is let through.
            const uint64_t start = std::max(ideal, when);
            // simavr delivers it one frame after this call (its RX pump), i.e. at start + frame.
            avr_raise_irq(uart_in_, b.byte);
            in_bytes_.push_back(SerialByte{start, b.byte});
            wire_free_at_ = start + uart_->cycles_per_byte;
            arrivals_.push_back(wire_free_at_);
            ++line_head_;
            if (line_head_ == line_.size()) {
                line_.clear();
                line_head_ = 0;
            } else {
                next = std::max(wire_free_at_, line_[line_head_].not_before);
            }
        }
    }
    if (!scheduled_.empty()) next = std::min<uint64_t>(next, scheduled_.begin()->first);
    for (const Periodic& p : periodic_) next = std::min(next, p.next);
    if (arrivals_head_ < arrivals_.size()) next = std::min(next, arrivals_[arrivals_head_]);
    if (next == kNever) return 0;
    return std::max(next, now + 1);
}

// ---- pins -------------------------------------------------------------------------------

std::vector<Edge> Sim::edges_of(const std::string& name) const {
    const int i = rec_->find(name);
    if (i < 0) throw std::invalid_argument("llsim: unknown signal " + name);
    return rec_->edges_of(static_cast<uint16_t>(i));
}

void Sim::write_csv(const std::string& path) const {
    std::ofstream f(path);
    if (!f) throw SimError("llsim: cannot write " + path);
    rec_->write_csv(f, kCpuHz);
}

void Sim::write_vcd(const std::string& path) const {
    std::ofstream f(path);
    if (!f) throw SimError("llsim: cannot write " + path);
    rec_->write_vcd(f, kCpuHz);
}

void Sim::set_input(char port, uint8_t bit, bool level) {
    if (port < 'B' || port > 'D' || bit > 7) throw std::invalid_argument("llsim: no such pin");
    bool found = false;
    for (Input& in : inputs_) {
        if (in.port == port && in.bit == bit) {
            in.level = level;
            found = true;
        }
    }
    if (!found) inputs_.push_back(Input{port, bit, level});
    apply_input(port, bit, level);
}

void Sim::apply_input(char port, uint8_t bit, bool level) {
    // The external drive is kept by the port model (it survives DDR changes); the pin IRQ makes
    // the new level visible in PINx and to pin-change / external interrupts at once.
    avr_ioport_external_t ext;
    memset(&ext, 0, sizeof ext);
    unsigned mask = 0, value = 0;
    for (const Input& in : inputs_) {
        if (in.port != port) continue;
        mask |= 1u << in.bit;
        if (in.level) value |= 1u << in.bit;
    }
    ext.name = static_cast<unsigned>(port) & 0x7F;
    ext.mask = mask & 0xFF;
    ext.value = value & 0xFF;
    avr_ioctl(avr_, AVR_IOCTL_IOPORT_SET_EXTERNAL(port), &ext);
    avr_raise_irq(avr_io_getirq(avr_, AVR_IOCTL_IOPORT_GETIRQ(port), bit), level ? 1 : 0);
}

uint8_t Sim::pin_register(char port) const {
    avr_ioport_state_t st;
    if (avr_ioctl(avr_, AVR_IOCTL_IOPORT_GETSTATE(port), &st) < 0) return 0;
    const unsigned ddr = st.ddr, out = st.port, pin = st.pin;
    return static_cast<uint8_t>((pin & ~ddr) | (out & ddr));
}

// ---- memory, symbols, markers -----------------------------------------------------------

bool Sim::has_symbol(const std::string& name) const {
#if ELF_SYMBOLS
    for (uint32_t i = 0; i < fw_.symbolcount; ++i)
        if (fw_.symbol[i] && name == fw_.symbol[i]->symbol) return true;
#endif
    (void)name;
    return false;
}

std::string Sim::symbol_with_prefix(const std::string& prefix) const {
#if ELF_SYMBOLS
    for (uint32_t i = 0; i < fw_.symbolcount; ++i) {
        if (fw_.symbol[i] && strncmp(fw_.symbol[i]->symbol, prefix.c_str(), prefix.size()) == 0)
            return fw_.symbol[i]->symbol;
    }
#endif
    (void)prefix;
    return "";
}

uint32_t Sim::symbol(const std::string& name) const {
#if ELF_SYMBOLS
    constexpr uint32_t kDataSpace = 0x800000; // avr-gcc's offset of SRAM addresses in the ELF
    for (uint32_t i = 0; i < fw_.symbolcount; ++i) {
        if (!fw_.symbol[i] || name != fw_.symbol[i]->symbol) continue;
        const uint32_t a = fw_.symbol[i]->addr;
        return a >= kDataSpace ? a - kDataSpace : a;
    }
#endif
    throw SimError("llsim: no symbol " + name + " in " + opt_.elf);
}

void Sim::watch_register(uint16_t addr) {
    if (std::find(watched_.begin(), watched_.end(), addr) != watched_.end()) return;
    watched_.push_back(addr);
    hooks_->on_write(addr, [this](uint16_t a, uint8_t v, const IoHooks::WriteNext& next) {
        reg_writes_.push_back(RegWrite{avr_->cycle, a, v});
        next(v);
    });
}

uint64_t Sim::marker_cycles(uint16_t addr, uint8_t from_value, uint8_t to_value,
                            uint64_t after) const {
    uint64_t start = kNever;
    for (const RegWrite& w : reg_writes_) {
        if (w.addr != addr || w.cycle < after) continue;
        if (start == kNever) {
            if (w.value == from_value) start = w.cycle;
        } else if (w.value == to_value) {
            return w.cycle - start;
        }
    }
    return kNever;
}

// ---- EEPROM and reset -------------------------------------------------------------------

std::vector<uint8_t> Sim::eeprom() const {
    if (!eeprom_ || !eeprom_->eeprom) return {};
    return std::vector<uint8_t>(eeprom_->eeprom, eeprom_->eeprom + eeprom_->size);
}

void Sim::set_eeprom(const std::vector<uint8_t>& image) {
    if (!eeprom_ || !eeprom_->eeprom) throw SimError("llsim: no EEPROM in this core");
    if (image.size() > eeprom_->size) throw SimError("llsim: EEPROM image larger than 1 KiB");
    memset(eeprom_->eeprom, 0xFF, eeprom_->size); // erased cells read 0xFF
    memcpy(eeprom_->eeprom, image.data(), image.size());
}

void Sim::load_eeprom(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw SimError("llsim: cannot read EEPROM image " + path);
    std::vector<uint8_t> image((std::istreambuf_iterator<char>(f)),
                               std::istreambuf_iterator<char>());
    set_eeprom(image);
}

void Sim::save_eeprom(const std::string& path) const {
    const std::vector<uint8_t> image = eeprom();
    std::ofstream f(path, std::ios::binary);
    if (!f) throw SimError("llsim: cannot write EEPROM image " + path);
    f.write(reinterpret_cast<const char*>(image.data()), static_cast<long>(image.size()));
}

void Sim::reset() {
    avr_reset(avr_); // keeps avr->cycle running and the EEPROM array; empties the cycle timers
    corr_->after_reset();
    host_armed_ = false;
    xoff_ = false;
    arrivals_.clear(); // simavr's reset empties its receive queue
    arrivals_head_ = 0;
    isr_open_.clear();
    // SIMAVR-NOTES 8: avr_reset() zeroes PINx but leaves each pin IRQ at its old level, so when
    // the firmware enables a pull-up again simavr sees "no change" and PINx keeps reading 0 (a
    // closed switch). Put every pin back to its reset level (tri-stated, reads 0), then re-drive
    // the inputs the harness holds.
    for (char port : {'B', 'C', 'D'}) {
        for (uint8_t bit = 0; bit < 8; ++bit) {
            const bool driven = std::any_of(inputs_.begin(), inputs_.end(), [&](const Input& in) {
                return in.port == port && in.bit == bit;
            });
            if (!driven) avr_raise_irq(avr_io_getirq(avr_, AVR_IOCTL_IOPORT_GETIRQ(port), bit), 0);
        }
    }
    for (const Input& in : inputs_) apply_input(in.port, in.bit, in.level);
    rec_->resync();
    ++resets_;
    uint64_t next = kNever;
    if (line_head_ < line_.size()) next = std::max(wire_free_at_, line_[line_head_].not_before);
    if (!scheduled_.empty()) next = std::min<uint64_t>(next, scheduled_.begin()->first);
    for (const Periodic& p : periodic_) next = std::min(next, p.next);
    if (next != kNever) arm_host_timer(next);
}

} // namespace sim
} // namespace ll
