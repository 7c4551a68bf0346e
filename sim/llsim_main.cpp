// llsim: command-line front end of the simavr harness. See sim/README.md for examples.
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "grbl_client.h"
#include "harness.h"
#include "pty_bridge.h"

using namespace ll::sim;

namespace {

volatile sig_atomic_t g_stop = 0;
void on_signal(int) {
    g_stop = 1;
}

const char kUsage[] = R"(usage: llsim FIRMWARE.elf [options]
Runs the firmware on a simulated ATmega328P (Arduino Uno, 16 MHz) in simavr 1.6 with the
datasheet corrections of the harness, and records step/direction/enable pin edges.

Run length
  --ms N               simulated milliseconds to run (default 1000 without --gcode/--pty)
  --cycles N           simulated CPU cycles to run
Serial input (UART0, 115200 baud)
  --gcode FILE         wait for the banner, then stream FILE with GRBL character counting
  --sync               send --gcode lines one at a time, waiting for each ok/error
  --wait-idle          after --gcode, send '?' every 10 ms until the report says Idle
  --send TEXT          send TEXT at the start (escapes: \n \r \t \xNN)
  --rt CYCLE:BYTE      send one real-time byte at CYCLE: ? ! ~ or 0xNN (0x18 = soft reset)
  --status-every MS    send '?' every MS milliseconds
Pseudo-terminal (connect UGS, cncjs, bCNC or `screen PTY 115200`)
  --pty                expose UART0 on a pty (path printed), run until Ctrl-C or --ms
  --pty-link PATH      also make PATH a symlink to the pty
  --pty-fast           do not pace the simulation to wall-clock time
  --reset-on-open      reset the chip whenever a program opens the pty (as the Uno does)
Records
  --csv FILE           pin edges: cycle,time_us,signal,level
  --vcd FILE           pin edges as VCD (GTKWave, PulseView)
  --serial-log FILE    every serial byte: cycle,direction,hex,char
  --signal NAME=PXn    record another pin too (e.g. limit_x=PB1)
  --quiet              do not print the firmware's output
Chip
  --eeprom FILE        load the EEPROM from FILE if it exists, save it back at exit
  --input PXn=0|1      drive an input pin (e.g. PB1=0: X limit switch closed)
  --no-correction NAME switch one datasheet correction off (see --list-corrections)
  --no-corrections     stock simavr 1.6 behaviour
  --list-corrections
)";

[[noreturn]] void usage_error(const std::string& msg) {
    std::cerr << "llsim: " << msg << "\n\n" << kUsage;
    exit(2);
}

std::string unescape(const std::string& s) {
    std::string out;
    for (size_t i = 0; i < s.size(); ++i) {
        if (s[i] != '\\' || i + 1 == s.size()) {
            out += s[i];
            continue;
        }
        const char c = s[++i];
        if (c == 'n')
            out += '\n';
        else if (c == 'r')
            out += '\r';
        else if (c == 't')
            out += '\t';
        else if (c == 'x' && i + 2 < s.size() + 0) {
            out += static_cast<char>(strtol(s.substr(i + 1, 2).c_str(), nullptr, 16));
            i += 2;
        } else
            out += c;
    }
    return out;
}

uint8_t parse_byte(const std::string& s) {
    if (s.size() == 1) return static_cast<uint8_t>(s[0]);
    if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X'))
        return static_cast<uint8_t>(strtol(s.c_str() + 2, nullptr, 16));
    usage_error("not a byte: " + s);
}

bool file_exists(const std::string& path) {
    struct stat st;
    return stat(path.c_str(), &st) == 0;
}

} // namespace

int main(int argc, char** argv) {
    std::vector<std::string> args(argv + 1, argv + argc);
    Options opt;
    uint64_t run_cycles = 0;
    bool have_length = false, pty = false, pty_fast = false, reset_on_open = false;
    bool sync = false, wait_idle = false, quiet = false;
    std::string gcode, csv, vcd, serial_log, eeprom, pty_link, send_text;
    std::vector<std::pair<uint64_t, uint8_t>> rt;
    std::vector<std::string> inputs;
    uint64_t status_every = 0;

    for (size_t i = 0; i < args.size(); ++i) {
        const std::string& a = args[i];
        auto value = [&]() -> const std::string& {
            if (i + 1 >= args.size()) usage_error(a + " needs a value");
            return args[++i];
        };
        if (a == "-h" || a == "--help") {
            std::cout << kUsage;
            return 0;
        } else if (a == "--list-corrections") {
            for (const std::string& n : Corrections::names()) std::cout << n << '\n';
            return 0;
        } else if (a == "--ms") {
            run_cycles = ms(std::stoull(value()));
            have_length = true;
        } else if (a == "--cycles") {
            run_cycles = std::stoull(value());
            have_length = true;
        } else if (a == "--gcode")
            gcode = value();
        else if (a == "--sync")
            sync = true;
        else if (a == "--wait-idle")
            wait_idle = true;
        else if (a == "--send")
            send_text = unescape(value());
        else if (a == "--rt") {
            const std::string& v = value();
            const size_t colon = v.find(':');
            if (colon == std::string::npos) usage_error("--rt wants CYCLE:BYTE");
            rt.emplace_back(std::stoull(v.substr(0, colon)), parse_byte(v.substr(colon + 1)));
        } else if (a == "--status-every")
            status_every = ms(std::stoull(value()));
        else if (a == "--pty")
            pty = true;
        else if (a == "--pty-link")
            pty_link = value();
        else if (a == "--pty-fast")
            pty_fast = true;
        else if (a == "--reset-on-open")
            reset_on_open = true;
        else if (a == "--csv")
            csv = value();
        else if (a == "--vcd")
            vcd = value();
        else if (a == "--serial-log")
            serial_log = value();
        else if (a == "--signal")
            opt.signals.push_back(parse_signal(value()));
        else if (a == "--quiet")
            quiet = true;
        else if (a == "--eeprom")
            eeprom = value();
        else if (a == "--input")
            inputs.push_back(value());
        else if (a == "--no-corrections")
            opt.corrections = Corrections::none();
        else if (a == "--no-correction") {
            const std::string& n = value();
            if (!opt.corrections.set(n, false)) usage_error("unknown correction " + n);
        } else if (!a.empty() && a[0] == '-')
            usage_error("unknown option " + a);
        else if (opt.elf.empty())
            opt.elf = a;
        else
            usage_error("one firmware only");
    }
    if (opt.elf.empty()) usage_error("no firmware given");
    if (!eeprom.empty() && file_exists(eeprom)) opt.eeprom_file = eeprom;

    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    try {
        Sim sim(opt);
        for (const std::string& in : inputs) {
            if (in.size() != 5 || in[0] != 'P' || in[3] != '=')
                usage_error("--input wants PXn=0|1, e.g. PB1=0");
            sim.set_input(in[1], static_cast<uint8_t>(in[2] - '0'), in[4] == '1');
        }
        if (!send_text.empty()) sim.send(send_text);
        for (const auto& r : rt) sim.send_at(r.first, std::string(1, static_cast<char>(r.second)));
        if (status_every) sim.send_every('?', status_every, status_every);

        int rc = 0;
        if (pty) {
            PtyBridge::Options po;
            po.link = pty_link;
            po.realtime = !pty_fast;
            po.reset_on_open = reset_on_open;
            PtyBridge bridge(sim, po);
            std::cout << "llsim: UART0 on " << bridge.path();
            if (!pty_link.empty()) std::cout << " (" << pty_link << ")";
            std::cout << " at 115200 baud; Ctrl-C to stop" << std::endl;
            bridge.run(g_stop, have_length ? sim.cycle() + run_cycles : kNever);
        } else if (!gcode.empty()) {
            Grbl grbl(sim);
            if (!grbl.wait_banner(ms(2000))) std::cerr << "llsim: no GRBL banner within 2 s\n";
            const std::vector<std::string> lines = read_gcode_file(gcode);
            const uint64_t budget = have_length ? run_cycles : ms(3600 * 1000);
            std::vector<Reply> replies;
            if (sync) {
                for (const std::string& l : lines) {
                    replies.push_back(grbl.send_line(l, budget));
                    if (replies.back().timeout || g_stop) break;
                }
            } else {
                replies = grbl.stream(lines, budget);
            }
            for (const Reply& r : replies) {
                if (r.timeout) {
                    std::cerr << "llsim: no answer to \"" << r.line << "\"\n";
                    rc = 1;
                    break;
                }
                if (!r.ok) {
                    std::cerr << "llsim: error:" << r.error << " for \"" << r.line << "\"\n";
                    rc = 1;
                }
            }
            if (wait_idle) {
                // At most about 10 minutes of simulated time (each try is 10-110 ms).
                for (int tries = 0; tries < 6000 && !g_stop; ++tries) {
                    const std::string s = grbl.status(ms(100));
                    if (s.compare(0, 5, "<Idle") == 0) break;
                    sim.run_for(ms(10));
                }
            }
        } else {
            sim.run_for(have_length ? run_cycles : ms(1000));
        }

        if (!quiet && !pty) std::cout << sim.output() << std::flush;
        if (!csv.empty()) sim.write_csv(csv);
        if (!vcd.empty()) sim.write_vcd(vcd);
        if (!serial_log.empty()) {
            std::ofstream f(serial_log);
            f << "cycle,direction,hex,char\n";
            std::vector<std::pair<SerialByte, char>> all;
            for (const SerialByte& b : sim.input_bytes()) all.emplace_back(b, '>');
            for (const SerialByte& b : sim.output_bytes()) all.emplace_back(b, '<');
            std::stable_sort(all.begin(), all.end(), [](const auto& x, const auto& y) {
                return x.first.cycle < y.first.cycle;
            });
            for (const auto& e : all) {
                char hex[8];
                snprintf(hex, sizeof hex, "%02x", e.first.byte);
                const char c = static_cast<char>(e.first.byte);
                f << e.first.cycle << ',' << (e.second == '>' ? "in" : "out") << ',' << hex << ','
                  << (c >= 32 && c < 127 && c != ',' ? std::string(1, c) : std::string()) << '\n';
            }
        }
        if (!eeprom.empty()) sim.save_eeprom(eeprom);

        std::cerr << "llsim: " << sim.cycle() << " cycles (" << Sim::to_us(sim.cycle()) / 1000.0
                  << " ms simulated), " << sim.edges().size() << " pin edges, " << sim.speed() / 1e6
                  << " M cycles/s";
        if (sim.overruns()) std::cerr << ", " << sim.overruns() << " receive overruns";
        std::cerr << '\n';
        return rc;
    } catch (const std::exception& e) {
        std::cerr << e.what() << '\n';
        return 1;
    }
}
