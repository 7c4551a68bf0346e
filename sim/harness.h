// llsim: runs a real firmware .elf for the ATmega328P at 16 MHz in simavr 1.6, cycle by cycle, with
// the datasheet corrections of corrections.h, a serial line on UART0, a record of pin edges and
// EEPROM persistence. Deterministic: the same ELF, options and inputs give the same cycles.
//
//   ll::sim::Sim sim({"build/avr/firmware/lowlevel.elf"});
//   sim.run_until_output("['$' for help]", ll::sim::ms(100));
//   sim.send("G1 X10 F600\n");
//   sim.run_for(ll::sim::ms(50));
//   for (const auto& e : sim.edges()) ...
#pragma once

#include <stdint.h>

#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "corrections.h"
#include "io_hooks.h"
#include "recorder.h"

extern "C" {
#include <avr_eeprom.h>
#include <avr_uart.h>
#include <sim_avr.h>
#include <sim_elf.h>
}

namespace ll {
namespace sim {

constexpr uint32_t kCpuHz = 16000000; ///< Arduino Uno crystal
constexpr uint64_t kNever = UINT64_MAX;

/// Durations in CPU cycles at 16 MHz.
constexpr uint64_t us(uint64_t n) {
    return n * (kCpuHz / 1000000);
}
constexpr uint64_t ms(uint64_t n) {
    return n * (kCpuHz / 1000);
}

/// The simulated firmware stopped (crash, or SLEEP with interrupts off) or a file is missing.
struct SimError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

struct Options {
    std::string elf;                              ///< firmware image: ELF, or Intel hex (*.hex)
    Corrections corrections = Corrections::all(); ///< datasheet corrections, all on
    std::vector<Signal> signals = cnc_shield_signals(); ///< pins whose edges are recorded
    std::string eeprom_file; ///< raw 1024-byte image loaded at start ("" = blank 0xFF chip)
    /// simavr's own log messages printed to stderr up to this level (LOG_ERROR = 2, ...).
    int log_level = 2;
};

/// One byte on the serial line with the cycle it was put there.
struct SerialByte {
    uint64_t cycle; ///< firmware output: cycle of the UDR0 write; host input: start of its frame
    uint8_t byte;
};

/// One complete line the firmware sent (without "\r\n"), with the cycle of its '\n'.
struct OutputLine {
    uint64_t cycle;
    std::string text;
};

/// One run of an interrupt service routine.
struct IsrSpan {
    uint8_t vector;    ///< vector number (TIMER1_COMPA = 11 on the ATmega328P)
    uint64_t accepted; ///< cycle the CPU accepted the interrupt (start of the response)
    uint64_t returned; ///< cycle the RETI completed (0 while the ISR is still running)
};

/// One CPU write to a watched register.
struct RegWrite {
    uint64_t cycle;
    uint16_t addr; ///< data-space address
    uint8_t value;
};

class Sim {
  public:
    /// Loads `opt.elf` as an atmega328p at 16 MHz; the CPU is at cycle 0, nothing has run yet.
    explicit Sim(const Options& opt);
    explicit Sim(const std::string& elf) : Sim(options_for(elf)) {}
    ~Sim();
    Sim(const Sim&) = delete;
    Sim& operator=(const Sim&) = delete;

    // ---- time and running -----------------------------------------------------------------
    // Runs stop at instruction boundaries: at the first one at or after the requested cycle.

    uint64_t cycle() const { return avr_->cycle; }
    /// cycle() + cycles, saturating at kNever (so kNever means "no limit").
    uint64_t deadline(uint64_t cycles) const {
        return cycles >= kNever - avr_->cycle ? kNever : avr_->cycle + cycles;
    }
    static double to_us(uint64_t cycles) { return cycles * 1e6 / kCpuHz; }

    void run_for(uint64_t cycles);
    void run_until_cycle(uint64_t cycle);
    /// Runs until `done()` (checked after every instruction) or `max_cycles` elapsed.
    bool run_until(const std::function<bool()>& done, uint64_t max_cycles);
    /// Runs until the firmware output (from the current output length on) contains `text`.
    bool run_until_output(const std::string& text, uint64_t max_cycles);
    /// Runs until the next byte of firmware output arrives.
    bool run_until_any_output(uint64_t max_cycles);
    /// Runs until the program counter reaches `byte_address` (see symbol()).
    bool run_until_pc(uint32_t byte_address, uint64_t max_cycles);

    // ---- serial line (host side of UART0) --------------------------------------------------
    // Bytes queue on a simulated wire: each occupies one UART frame (frame_cycles(), 10 bits at
    // 8N1), back to back, in the order sent. Bytes are fed to simavr's receiver only while it is
    // enabled and not in XOFF (SIMAVR-NOTES 4), so none is dropped by its 64-byte queue.

    /// Queues bytes at the current cycle.
    void send(const std::string& bytes);
    /// Queues bytes when the clock reaches `cycle` (after whatever is queued by then).
    void send_at(uint64_t cycle, const std::string& bytes);
    /// Queues `byte` at first, first + period, ... while <= until (e.g. '?' every 50 ms).
    /// Returns an id for stop_periodic().
    int send_every(uint8_t byte, uint64_t first, uint64_t period, uint64_t until = kNever);
    void stop_periodic(int id);
    /// Bytes queued or scheduled that have not started on the wire yet.
    size_t serial_pending() const;
    /// The UART0 frame time in cycles that simavr uses now (1360 at 115200 8N1 U2X, corrected).
    uint64_t frame_cycles() const;
    /// Bytes the hardware would have lost: their stop bit arrived while the 2-byte receive FIFO
    /// held two unread bytes (data overrun, DOR0). simavr itself queues 64 and never loses one
    /// (SIMAVR-NOTES 4), so a firmware reading too slowly shows up here.
    uint32_t overruns() const { return overruns_; }

    /// Every byte the firmware transmitted so far, with its cycle.
    const std::vector<SerialByte>& output_bytes() const { return out_bytes_; }
    /// The same bytes as text.
    const std::string& output() const { return out_text_; }
    /// Complete output lines so far ("\r" dropped).
    const std::vector<OutputLine>& output_lines() const { return out_lines_; }
    /// Every byte the host put on the wire, with the cycle its frame started.
    const std::vector<SerialByte>& input_bytes() const { return in_bytes_; }

    // ---- pins --------------------------------------------------------------------------------

    Recorder& recorder() { return *rec_; }
    const std::vector<Edge>& edges() const { return rec_->edges(); }
    const std::vector<Signal>& signals() const { return rec_->signals(); }
    /// Edges of the named signal; throws std::invalid_argument for an unknown name.
    std::vector<Edge> edges_of(const std::string& name) const;
    void write_csv(const std::string& path) const;
    void write_vcd(const std::string& path) const;

    /// Drives an input pin from outside (a switch, a probe). Kept across reset().
    void set_input(char port, uint8_t bit, bool level);
    /// PINx as the CPU would read it now.
    uint8_t pin_register(char port) const;

    // ---- memory, symbols, markers ------------------------------------------------------------

    /// A byte of the data space (registers, I/O, SRAM) without side effects.
    uint8_t peek(uint16_t data_addr) const { return avr_->data[data_addr]; }
    /// Address of an ELF symbol: flash byte address for code, data-space address for variables.
    /// Throws SimError when missing.
    uint32_t symbol(const std::string& name) const;
    bool has_symbol(const std::string& name) const;
    /// The first symbol whose name starts with `prefix` ("" when none).
    std::string symbol_with_prefix(const std::string& prefix) const;

    /// Records every CPU write to `data_addr` (e.g. GPIOR0 0x3E used as a code-region marker).
    void watch_register(uint16_t data_addr);
    const std::vector<RegWrite>& register_writes() const { return reg_writes_; }
    /// Cycles between the first write of `from_value` and the next write of `to_value` to the
    /// watched register `addr` at or after cycle `after`; kNever if not found.
    uint64_t marker_cycles(uint16_t addr, uint8_t from_value, uint8_t to_value,
                           uint64_t after = 0) const;

    /// Records every run of the ISR for `vector` (TIMER1_COMPA_vect_num = 11, ...).
    void record_isr(uint8_t vector);
    const std::vector<IsrSpan>& isr_spans() const { return isr_spans_; }

    // ---- EEPROM and reset ----------------------------------------------------------------------

    std::vector<uint8_t> eeprom() const;
    void set_eeprom(const std::vector<uint8_t>& image);
    void load_eeprom(const std::string& path); ///< raw image, at most 1024 bytes
    void save_eeprom(const std::string& path) const;

    /// Resets the chip as the Uno's DTR reset does (without the bootloader's delay): registers to
    /// their reset values, EEPROM kept, pins driven by set_input() restored (SIMAVR-NOTES 8). The
    /// cycle count keeps running and the records keep growing. Bytes already in the receiver are
    /// lost, as on the chip; bytes not yet sent wait until the firmware enables it again.
    void reset();
    uint32_t resets() const { return resets_; }

    // ---- the simulator ----------------------------------------------------------------------

    avr_t* avr() { return avr_; }
    const avr_t* avr() const { return avr_; }
    const Corrector& corrector() const { return *corr_; }
    /// CPU cycles simulated per wall-clock second, over every run so far.
    double speed() const;

  private:
    static Options options_for(const std::string& elf) {
        Options o;
        o.elf = elf;
        return o;
    }
    template <class Done>
    bool run_loop(uint64_t limit, Done done);
    void arm_host_timer(uint64_t at);
    uint64_t host_service(uint64_t when, uint64_t now);
    bool receiver_ready() const;
    unsigned receiver_fill() const; ///< bytes in simavr's receive queue
    void on_output(uint8_t byte);
    void on_vector(uint8_t vector, uint32_t running);
    void apply_input(char port, uint8_t bit, bool level);

    static avr_cycle_count_t host_timer_cb(avr_t*, avr_cycle_count_t when, void* param);
    static avr_cycle_count_t limit_timer_cb(avr_t*, avr_cycle_count_t when, void* param);
    static void sleep_cb(avr_t* avr, avr_cycle_count_t how_long);
    static void uart_out_cb(avr_irq_t*, uint32_t value, void* param);
    static void uart_xon_cb(avr_irq_t*, uint32_t value, void* param);
    static void uart_xoff_cb(avr_irq_t*, uint32_t value, void* param);
    static void vector_cb(avr_irq_t* irq, uint32_t value, void* param);

    struct VectorHook {
        Sim* self;
        uint8_t vector;
    };
    struct HostByte {
        uint8_t byte;
        uint64_t not_before; ///< cycle at which the host wrote it
    };
    struct Periodic {
        int id;
        uint8_t byte;
        uint64_t next;
        uint64_t period;
        uint64_t until;
    };
    struct Input {
        char port;
        uint8_t bit;
        bool level;
    };

    Options opt_;
    elf_firmware_t fw_;
    avr_t* avr_ = nullptr;
    std::unique_ptr<IoHooks> hooks_;
    std::unique_ptr<Corrector> corr_;
    std::unique_ptr<Recorder> rec_;
    std::vector<std::unique_ptr<VectorHook>> vector_hooks_;
    avr_irq_t* uart_in_ = nullptr;
    avr_uart_t* uart_ = nullptr;
    avr_eeprom_t* eeprom_ = nullptr;

    // serial line, host -> firmware
    std::vector<HostByte> line_; ///< queued bytes not yet on the wire (front = index line_head_)
    size_t line_head_ = 0;
    std::multimap<uint64_t, std::string> scheduled_;
    std::vector<Periodic> periodic_;
    int next_periodic_id_ = 1;
    uint64_t wire_free_at_ = 0; ///< cycle at which the last byte's stop bit ends
    bool host_armed_ = false;
    uint64_t host_armed_at_ = 0;
    bool xoff_ = false;
    uint32_t overruns_ = 0;
    std::vector<uint64_t> arrivals_; ///< stop-bit cycles of bytes given to simavr, not yet due
    size_t arrivals_head_ = 0;
    std::vector<SerialByte> in_bytes_;

    // serial line, firmware -> host
    std::vector<SerialByte> out_bytes_;
    std::string out_text_;
    std::vector<OutputLine> out_lines_;
    std::string partial_line_;

    // run control
    bool stop_ = false;
    bool stop_on_output_ = false;
    double wall_seconds_ = 0;
    uint64_t wall_cycles_ = 0;

    std::vector<Input> inputs_;
    std::vector<uint16_t> watched_;
    std::vector<RegWrite> reg_writes_;
    std::vector<bool> isr_watch_ = std::vector<bool>(64, false);
    std::vector<IsrSpan> isr_spans_;
    std::vector<size_t> isr_open_; ///< indices into isr_spans_ of ISRs still running (nesting)
    uint32_t resets_ = 0;
};

} // namespace sim
} // namespace ll
