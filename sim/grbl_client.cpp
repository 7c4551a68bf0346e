#include "grbl_client.h"

#include <stdlib.h>

#include <deque>
#include <fstream>
#include <stdexcept>

namespace ll {
namespace sim {

bool Grbl::is_ack(const std::string& text, int* error) {
    if (text == "ok") {
        *error = 0;
        return true;
    }
    if (text.compare(0, 6, "error:") == 0) {
        *error = atoi(text.c_str() + 6);
        return true;
    }
    return false;
}

std::vector<OutputLine> Grbl::take_acks() {
    std::vector<OutputLine> acks;
    const std::vector<OutputLine>& all = sim_.output_lines();
    for (; cursor_ < all.size(); ++cursor_) {
        int err = 0;
        if (is_ack(all[cursor_].text, &err))
            acks.push_back(all[cursor_]);
        else
            others_.push_back(all[cursor_]);
    }
    return acks;
}

bool Grbl::wait_banner(uint64_t max_cycles) {
    const uint64_t limit = sim_.deadline(max_cycles);
    for (;;) {
        const std::vector<OutputLine>& all = sim_.output_lines();
        for (; cursor_ < all.size(); ++cursor_) {
            others_.push_back(all[cursor_]);
            if (all[cursor_].text.compare(0, 5, "Grbl ") == 0) {
                ++cursor_;
                return true;
            }
        }
        if (sim_.cycle() >= limit || !sim_.run_until_any_output(limit - sim_.cycle())) return false;
    }
}

Reply Grbl::send_line(const std::string& line, uint64_t max_cycles) {
    std::vector<Reply> r = stream({line}, max_cycles, kNever);
    return r.front();
}

std::vector<Reply> Grbl::stream(const std::vector<std::string>& lines, uint64_t max_cycles,
                                size_t rx_buffer) {
    struct InFlight {
        size_t index;
        size_t bytes;
    };
    std::vector<Reply> replies(lines.size());
    std::deque<InFlight> flight;
    size_t used = 0, next = 0, done = 0;
    max_in_flight_ = 0;
    take_acks(); // answers to earlier traffic are not ours
    const uint64_t limit = sim_.deadline(max_cycles);
    while (done < lines.size()) {
        while (next < lines.size() && used + lines[next].size() + 1 <= rx_buffer) {
            const size_t bytes = lines[next].size() + 1;
            replies[next].line = lines[next];
            replies[next].sent = sim_.cycle();
            sim_.send(lines[next] + "\n");
            flight.push_back(InFlight{next, bytes});
            used += bytes;
            max_in_flight_ = std::max(max_in_flight_, used);
            ++next;
        }
        if (flight.empty()) {
            if (next < lines.size())
                throw std::invalid_argument("llsim: line longer than the receive buffer: " +
                                            lines[next]);
            break;
        }
        if (sim_.cycle() >= limit || !sim_.run_until_any_output(limit - sim_.cycle())) break;
        for (const OutputLine& ack : take_acks()) {
            if (flight.empty()) continue; // an answer nobody asked for (e.g. after a reset)
            Reply& r = replies[flight.front().index];
            r.ok = is_ack(ack.text, &r.error) && r.error == 0;
            r.answered = ack.cycle;
            used -= flight.front().bytes;
            flight.pop_front();
            ++done;
        }
    }
    for (size_t i = done; i < lines.size(); ++i) {
        replies[i].line = lines[i];
        replies[i].timeout = true;
    }
    return replies;
}

std::string Grbl::status(uint64_t max_cycles) {
    take_acks(); // reports already received (an earlier '?') are not the answer to this one
    const size_t seen = others_.size();
    sim_.send("?");
    const uint64_t limit = sim_.deadline(max_cycles);
    for (;;) {
        take_acks();
        for (size_t i = seen; i < others_.size(); ++i)
            if (!others_[i].text.empty() && others_[i].text[0] == '<') return others_[i].text;
        if (sim_.cycle() >= limit || !sim_.run_until_any_output(limit - sim_.cycle())) return "";
    }
}

std::vector<std::string> read_gcode_file(const std::string& path) {
    std::ifstream f(path);
    if (!f) throw std::runtime_error("llsim: cannot read " + path);
    std::vector<std::string> out;
    std::string raw;
    while (std::getline(f, raw)) {
        std::string line;
        bool in_paren = false;
        for (char c : raw) {
            if (c == ';') break;
            if (c == '(') in_paren = true;
            if (!in_paren && c != '\r') line += c;
            if (c == ')') in_paren = false;
        }
        const size_t a = line.find_first_not_of(" \t");
        if (a == std::string::npos) continue;
        const size_t b = line.find_last_not_of(" \t");
        out.push_back(line.substr(a, b - a + 1));
    }
    return out;
}

} // namespace sim
} // namespace ll
