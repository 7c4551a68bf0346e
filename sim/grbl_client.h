// GRBL 1.1 host-side protocol on top of Sim's serial line: wait for the banner, send-and-wait,
// character-counting streaming, status queries. Only the protocol's framing is assumed: lines end
// with '\n'; each line gets exactly one "ok" or "error:N"; other lines ("<...>" status reports,
// "[...]" messages, "ALARM:N", the banner) are not acknowledgements.
#pragma once

#include <stddef.h>
#include <stdint.h>

#include <string>
#include <vector>

#include "harness.h"

namespace ll {
namespace sim {

/// The firmware's receive buffer in bytes (GRBL's RX_BUFFER_SIZE); the character-counting limit.
constexpr size_t kGrblRxBuffer = 128;

struct Reply {
    std::string line;      ///< the line sent, without its '\n'
    bool ok = false;       ///< answered "ok"
    int error = 0;         ///< N of "error:N"; 0 otherwise
    bool timeout = false;  ///< no answer within the time allowed
    uint64_t sent = 0;     ///< cycle the host wrote the line
    uint64_t answered = 0; ///< cycle of the answer's '\n' (0 on timeout)
};

class Grbl {
  public:
    explicit Grbl(Sim& sim) : sim_(sim) {}

    /// Runs until a line starting with "Grbl " (the banner) is output; false on timeout.
    bool wait_banner(uint64_t max_cycles);

    /// Send-and-wait ("simple send-response"): one line, then run until its ok / error:N.
    Reply send_line(const std::string& line, uint64_t max_cycles);

    /// Character counting: keeps at most `rx_buffer` bytes of unanswered lines (each counted with
    /// its '\n') in flight; each ok / error:N frees the oldest line's bytes. Returns one Reply per
    /// line, in order. Throws std::invalid_argument for a line that can never fit.
    std::vector<Reply> stream(const std::vector<std::string>& lines, uint64_t max_cycles,
                              size_t rx_buffer = kGrblRxBuffer);

    /// Sends '?' and runs until the next "<...>" status report; "" on timeout.
    std::string status(uint64_t max_cycles);

    /// Takes in the output lines received so far (acknowledgements nobody waits for are dropped).
    void collect() { take_acks(); }

    /// Largest number of unanswered bytes in flight during the last stream().
    size_t max_in_flight() const { return max_in_flight_; }
    /// Output lines that were not acknowledgements (status reports, messages, banner...), with
    /// their cycles, in the order received.
    const std::vector<OutputLine>& other_lines() const { return others_; }

  private:
    /// Consumes new output lines: acknowledgements are returned in order, others are kept.
    std::vector<OutputLine> take_acks();
    static bool is_ack(const std::string& text, int* error);

    Sim& sim_;
    size_t cursor_ = 0; ///< next unread index in sim_.output_lines()
    size_t max_in_flight_ = 0;
    std::vector<OutputLine> others_;
};

/// Reads a G-code file into lines: comments in parentheses or after ';' and blank lines dropped,
/// surrounding white space trimmed (as GRBL's stream.py does).
std::vector<std::string> read_gcode_file(const std::string& path);

} // namespace sim
} // namespace ll
