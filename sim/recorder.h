// Pin edge record: every level change of the watched pins with the CPU cycle at which it happened,
// and its CSV and VCD renderings (VCD opens in GTKWave and PulseView).
//
// Cycle convention: an edge carries the cycle at which the instruction that wrote the port
// register (PORTx, PINx, DDRx) started, as simavr raises the pin during that instruction. All
// edges use the same convention, so differences between edges are exact.
#pragma once

#include <stdint.h>

#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

extern "C" {
#include <sim_avr.h>
}

namespace ll {
namespace sim {

struct Signal {
    std::string name; ///< CSV / VCD name, e.g. "step_x"
    char port;        ///< 'B', 'C' or 'D'
    uint8_t bit;      ///< 0..7
};

/// The Arduino CNC shield map as GRBL uses it on the Uno: step X/Y/Z = PD2/PD3/PD4, direction
/// X/Y/Z = PD5/PD6/PD7, stepper enable = PB0, 4th axis A step = PB4, A direction = PB5.
std::vector<Signal> cnc_shield_signals();

/// Parses "name=PD2" (port letter after 'P', bit digit); throws std::invalid_argument.
Signal parse_signal(const std::string& spec);

struct Edge {
    uint64_t cycle;  ///< CPU cycles since power-up (see the convention above)
    uint16_t signal; ///< index into the recorder's signals
    uint8_t level;   ///< electrical level after the edge: 0 or 1
};

class Recorder {
  public:
    /// Watches `signals` on `avr` from now on. Levels start from the pins' current state.
    Recorder(avr_t* avr, std::vector<Signal> signals);
    ~Recorder(); ///< stops watching (the avr_t may outlive the recorder)
    Recorder(const Recorder&) = delete;
    Recorder& operator=(const Recorder&) = delete;

    /// Adds a signal (its edges are recorded from now on); returns its index.
    uint16_t add(const Signal& s);
    const std::vector<Signal>& signals() const { return signals_; }
    /// Index of a signal by name, or -1.
    int find(const std::string& name) const;

    const std::vector<Edge>& edges() const { return edges_; }
    /// Forgets the edges so far; the current levels become the initial levels of the record.
    void clear();
    uint8_t level(uint16_t signal) const { return levels_[signal]; }
    const std::vector<uint8_t>& initial_levels() const { return initial_; }

    /// Edges of one signal only (cycles in order).
    std::vector<Edge> edges_of(uint16_t signal) const;

    /// Re-reads every pin from the port state and records an edge where it changed (after a reset
    /// simavr may change port registers without raising the pin IRQs).
    void resync();

    /// CSV: header "cycle,time_us,signal,level", one row per edge in time order.
    void write_csv(std::ostream& out, uint32_t cpu_hz) const;
    /// VCD: $timescale 100ps (a 16 MHz cycle is exactly 625 units), one wire per signal.
    void write_vcd(std::ostream& out, uint32_t cpu_hz) const;

  private:
    struct Hook {
        Recorder* self;
        uint16_t signal;
    };
    static void on_pin(avr_irq_t* irq, uint32_t value, void* param);
    uint8_t read_level(const Signal& s) const;

    avr_t* avr_;
    std::vector<Signal> signals_;
    std::vector<std::unique_ptr<Hook>> hooks_; ///< addresses given to simavr as notify params
    std::vector<uint8_t> levels_;
    std::vector<uint8_t> initial_;
    std::vector<Edge> edges_;
};

/// "12.3456": microseconds with the cycle's exact decimal expansion at 16 MHz (4 decimals).
std::string cycles_to_us_string(uint64_t cycle, uint32_t cpu_hz);

} // namespace sim
} // namespace ll
