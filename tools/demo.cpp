// lldemo: streams a G-code job to the real firmware running in simavr, as a sender would over
// USB, then shows what the machine did: GRBL's answers, a summary rebuilt from the step and
// direction pins, and a picture of the toolpath (SVG, plus PNG when rsvg-convert is there).
//
//   build/host/tools/lldemo jobs/demo.gcode [--elf FILE] [--out DIR]
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "grbl_client.h"
#include "harness.h"
#include "simjob.h"

using namespace ll::sim;
using namespace ll::tools;

#ifndef LLDEMO_FIRMWARE
#define LLDEMO_FIRMWARE "build/avr/firmware/lowlevel.elf"
#endif

namespace {

constexpr int kAxes3 = 3;
using Vec = std::array<double, kAxes3>;

std::string fmt(const char* f, ...) __attribute__((format(printf, 1, 2)));
std::string fmt(const char* f, ...) {
    char buf[512];
    va_list ap;
    va_start(ap, f);
    vsnprintf(buf, sizeof buf, f, ap);
    va_end(ap);
    return buf;
}

/// One programmed straight move, in steps (as the firmware rounds: half away from zero).
struct Move {
    std::array<int32_t, kAxes3> to;
    bool rapid;
    size_t line; ///< index in the job
};

int32_t round_steps(double mm, double per_mm) {
    const double v = mm * per_mm;
    return static_cast<int32_t>(v < 0 ? -std::floor(-v + 0.5) : std::floor(v + 0.5));
}

/// The moves a job programs: G0/G1 with X Y Z in G90/G91 and mm (G21), and $100-$102. That is
/// all the shipped jobs use; other words are ignored here (the firmware still gets them).
std::vector<Move> programmed_moves(const std::vector<std::string>& lines) {
    std::vector<Move> out;
    double per_mm[kAxes3] = {250, 250, 250}; // GRBL's defaults
    double pos[kAxes3] = {0, 0, 0};
    bool absolute = true, rapid = true;
    for (size_t i = 0; i < lines.size(); ++i) {
        const std::string& l = lines[i];
        if (l.size() > 4 && l[0] == '$' && l[1] == '1' && l[2] == '0' && l[3] >= '0' &&
            l[3] <= '2' && l[4] == '=') {
            per_mm[l[3] - '0'] = atof(l.c_str() + 5);
            continue;
        }
        if (!l.empty() && l[0] == '$') continue;
        bool has_axis = false;
        double target[kAxes3] = {pos[0], pos[1], pos[2]};
        for (size_t k = 0; k < l.size(); ++k) {
            const char c = static_cast<char>(toupper(static_cast<unsigned char>(l[k])));
            if (!isalpha(static_cast<unsigned char>(c))) continue;
            char* end = nullptr;
            const double v = strtod(l.c_str() + k + 1, &end);
            if (end == l.c_str() + k + 1) continue;
            k = static_cast<size_t>(end - l.c_str()) - 1;
            if (c == 'G') {
                if (v == 0) rapid = true;
                if (v == 1) rapid = false;
                if (v == 90) absolute = true;
                if (v == 91) absolute = false;
            } else if (c >= 'X' && c <= 'Z') {
                const int a = c - 'X';
                target[a] = absolute ? v : pos[a] + v;
                has_axis = true;
            }
        }
        if (!has_axis) continue;
        Move m;
        for (int a = 0; a < kAxes3; ++a) {
            pos[a] = target[a];
            m.to[static_cast<size_t>(a)] = round_steps(pos[a], per_mm[a]);
        }
        m.rapid = rapid;
        m.line = i;
        out.push_back(m);
    }
    return out;
}

double dist_to_segment(const Vec& p, const Vec& a, const Vec& b) {
    Vec ab, ap;
    double ab2 = 0, t = 0;
    for (int i = 0; i < kAxes3; ++i) {
        ab[static_cast<size_t>(i)] = b[static_cast<size_t>(i)] - a[static_cast<size_t>(i)];
        ap[static_cast<size_t>(i)] = p[static_cast<size_t>(i)] - a[static_cast<size_t>(i)];
        ab2 += ab[static_cast<size_t>(i)] * ab[static_cast<size_t>(i)];
        t += ab[static_cast<size_t>(i)] * ap[static_cast<size_t>(i)];
    }
    t = ab2 > 0 ? std::min(1.0, std::max(0.0, t / ab2)) : 0;
    double d2 = 0;
    for (int i = 0; i < kAxes3; ++i) {
        const double d = ap[static_cast<size_t>(i)] - t * ab[static_cast<size_t>(i)];
        d2 += d * d;
    }
    return std::sqrt(d2);
}

/// Follows the visited positions along the programmed moves: each move ends exactly on its
/// target, so a position equal to the current target moves on to the next move.
struct Follow {
    std::vector<int> move_of; ///< per trace position: index of the move it belongs to (-1: none)
    size_t reached = 0;       ///< targets reached, in order
    double worst = 0;         ///< ticks, largest distance from a position to its move's segment
};

Follow follow(const Trace& t, const std::vector<Move>& moves) {
    Follow f;
    Vec prev = {0, 0, 0};
    size_t k = 0;
    auto skip_empty = [&] {
        while (k < moves.size()) {
            const Move& m = moves[k];
            if (m.to[0] != prev[0] || m.to[1] != prev[1] || m.to[2] != prev[2]) break;
            ++k;
            ++f.reached;
        }
    };
    skip_empty();
    for (const auto& pos : t.pos) {
        const Vec p = {static_cast<double>(pos[0]), static_cast<double>(pos[1]),
                       static_cast<double>(pos[2])};
        if (k >= moves.size()) {
            f.move_of.push_back(-1);
            f.worst = std::max(f.worst, dist_to_segment(p, prev, prev));
            continue;
        }
        const Move& m = moves[k];
        const Vec to = {static_cast<double>(m.to[0]), static_cast<double>(m.to[1]),
                        static_cast<double>(m.to[2])};
        f.worst = std::max(f.worst, dist_to_segment(p, prev, to));
        f.move_of.push_back(static_cast<int>(k));
        if (p == to) {
            prev = to;
            ++k;
            ++f.reached;
            skip_empty();
        }
    }
    return f;
}

// ---- picture ----------------------------------------------------------------------------------

struct Picture {
    double per_mm[2];
    std::vector<Move> moves;
    std::vector<std::string> caption;
};

std::string svg_of(const Trace& t, const Follow& f, const Picture& pic) {
    // Bounding box in mm over the programmed and the visited positions.
    double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
    auto grow = [&](double x, double y) {
        x0 = std::min(x0, x);
        x1 = std::max(x1, x);
        y0 = std::min(y0, y);
        y1 = std::max(y1, y);
    };
    for (const Move& m : pic.moves) grow(m.to[0] / pic.per_mm[0], m.to[1] / pic.per_mm[1]);
    for (const auto& p : t.pos) grow(p[0] / pic.per_mm[0], p[1] / pic.per_mm[1]);
    x0 = std::floor(x0 / 5) * 5 - 2;
    y0 = std::floor(y0 / 5) * 5 - 2;
    x1 = std::ceil(x1 / 5) * 5 + 2;
    y1 = std::ceil(y1 / 5) * 5 + 2;
    const double scale = std::max(4.0, std::min(16.0, 900.0 / (x1 - x0)));
    const double margin = 20, text_h = 18.0 * static_cast<double>(pic.caption.size()) + 16;
    const double w = (x1 - x0) * scale + 2 * margin, h = (y1 - y0) * scale + 2 * margin + text_h;
    auto X = [&](double mm) { return margin + (mm - x0) * scale; };
    auto Y = [&](double mm) { return margin + (y1 - mm) * scale; };
    std::ostringstream s;
    s << fmt("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
             "viewBox=\"0 0 %.0f %.0f\" font-family=\"sans-serif\">\n",
             w, h, w, h);
    s << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n<g stroke=\"#eeeeee\">\n";
    for (double x = x0; x <= x1 + 1e-9; x += 1)
        s << fmt("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\"%s/>\n", X(x), Y(y0), X(x),
                 Y(y1), std::fmod(std::fabs(x), 5) < 1e-9 ? " stroke=\"#d0d0d0\"" : "");
    for (double y = y0; y <= y1 + 1e-9; y += 1)
        s << fmt("<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\"%s/>\n", X(x0), Y(y), X(x1),
                 Y(y), std::fmod(std::fabs(y), 5) < 1e-9 ? " stroke=\"#d0d0d0\"" : "");
    s << "</g>\n";
    // Programmed path: wide pale band (G1), thin dashes (G0).
    double px = 0, py = 0;
    for (const Move& m : pic.moves) {
        const double x = m.to[0] / pic.per_mm[0], y = m.to[1] / pic.per_mm[1];
        s << fmt("<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" %s/>\n", X(px), Y(py), X(x),
                 Y(y),
                 m.rapid ? "stroke=\"#bbbbbb\" stroke-width=\"1\" stroke-dasharray=\"4 3\""
                         : "stroke=\"#ffd27f\" stroke-width=\"7\" stroke-linecap=\"round\"");
        px = x;
        py = y;
    }
    // What the step pins did: one polyline per run of positions of the same kind of move.
    auto flush = [&](std::vector<std::pair<double, double>>& pts, bool rapid) {
        if (pts.size() < 2) return;
        s << "<polyline fill=\"none\" "
          << (rapid ? "stroke=\"#e8590c\" stroke-width=\"1.2\""
                    : "stroke=\"#1c4e9d\" stroke-width=\"1.6\" stroke-linejoin=\"round\"")
          << " points=\"";
        for (const auto& p : pts) s << fmt("%.2f,%.2f ", X(p.first), Y(p.second));
        s << "\"/>\n";
        const auto last = pts.back();
        pts.clear();
        pts.push_back(last);
    };
    std::vector<std::pair<double, double>> pts = {{0.0, 0.0}};
    bool rapid = !pic.moves.empty() && pic.moves.front().rapid;
    std::array<int32_t, kTraceAxes> last_delta{}, prev{};
    for (size_t i = 0; i < t.pos.size(); ++i) {
        const int k = f.move_of[i];
        const bool r = k >= 0 ? pic.moves[static_cast<size_t>(k)].rapid : rapid;
        const auto& p = t.pos[i];
        std::array<int32_t, kTraceAxes> delta;
        for (int a = 0; a < kTraceAxes; ++a)
            delta[static_cast<size_t>(a)] =
                p[static_cast<size_t>(a)] - prev[static_cast<size_t>(a)];
        if (r != rapid) {
            flush(pts, rapid);
            rapid = r;
        }
        // Keep the corners of the staircase only (and every 16th point on long straight runs).
        if (delta != last_delta || i % 16 == 0 || i + 1 == t.pos.size())
            pts.emplace_back(p[0] / pic.per_mm[0], p[1] / pic.per_mm[1]);
        last_delta = delta;
        prev = p;
    }
    flush(pts, rapid);
    double ty = h - text_h + 4;
    for (size_t i = 0; i < pic.caption.size(); ++i) {
        ty += 18;
        s << fmt("<text x=\"%.0f\" y=\"%.0f\" font-size=\"%d\" fill=\"%s\">", margin, ty,
                 i == 0 ? 15 : 13, i == 0 ? "#222" : "#444");
        for (char c : pic.caption[i]) {
            if (c == '<')
                s << "&lt;";
            else if (c == '>')
                s << "&gt;";
            else if (c == '&')
                s << "&amp;";
            else
                s << c;
        }
        s << "</text>\n";
    }
    s << "</svg>\n";
    return s.str();
}

bool have_program(const char* name) {
    const std::string cmd = std::string("command -v ") + name + " >/dev/null 2>&1";
    return system(cmd.c_str()) == 0;
}

void mkdirs(const std::string& path) {
    std::string cur;
    std::stringstream ss(path);
    std::string part;
    if (!path.empty() && path[0] == '/') cur = "/";
    while (std::getline(ss, part, '/')) {
        if (part.empty()) continue;
        cur += part + "/";
        mkdir(cur.c_str(), 0755);
    }
}

} // namespace

int main(int argc, char** argv) {
    std::string job, elf = LLDEMO_FIRMWARE, out = "build/demo";
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if ((a == "--elf" || a == "--out") && i + 1 < argc) {
            (a == "--elf" ? elf : out) = argv[++i];
        } else if (a == "-h" || a == "--help") {
            std::cout << "usage: lldemo JOB.gcode [--elf FIRMWARE.elf] [--out DIR]\n";
            return 0;
        } else if (job.empty() && a[0] != '-') {
            job = a;
        } else {
            std::cerr << "lldemo: unexpected argument " << a << "\n";
            return 2;
        }
    }
    if (job.empty()) job = "jobs/demo.gcode";
    try {
        const std::vector<std::string> lines = read_gcode_file(job);
        const std::vector<Move> moves = programmed_moves(lines);
        std::cout << "== lldemo: " << job << " (" << lines.size() << " lines, " << moves.size()
                  << " moves) on " << elf << "\n   simulated ATmega328P at 16 MHz (simavr), "
                  << "115200 baud, GRBL character counting, '?' every 250 ms\n\n";
        Sim sim(elf);
        Host host(sim);
        if (!host.wait_banner(ms(3000))) {
            std::cerr << "lldemo: the firmware printed no banner\n";
            return 1;
        }
        StackProbe stack(sim);
        std::cout << "-- GRBL says\n   " << host.others().back().text << "\n";
        const uint64_t t0 = sim.cycle();
        const int status_id = sim.send_every('?', t0 + ms(250), ms(250));
        const int errors = host.stream(lines, false, ms(10000));
        const bool stalled = errors < 0;
        // Then until the machine has stopped: no edge for 100 ms and the step timer off.
        size_t edges = sim.edges().size();
        uint64_t quiet = sim.cycle();
        const uint64_t limit = sim.cycle() + ms(60000);
        while (sim.cycle() < limit) {
            sim.run_for(ms(10));
            if (sim.edges().size() != edges) {
                edges = sim.edges().size();
                quiet = sim.cycle();
            } else if (sim.cycle() - quiet >= ms(100) &&
                       peek_var(sim, "_ZN2ll6g_execE", 1, 3) == 0) {
                break;
            }
        }
        sim.stop_periodic(status_id);
        const std::string final_status = host.status(ms(100));
        const uint64_t t_end = sim.cycle();

        const std::vector<OutputLine>& answers = host.answers();
        size_t oks = 0;
        for (size_t i = 0; i < answers.size(); ++i) {
            if (answers[i].text == "ok") {
                ++oks;
                continue;
            }
            std::cout << fmt("   line %zu \"%s\": %s\n", i + 1,
                             i < lines.size() ? lines[i].c_str() : "?", answers[i].text.c_str());
        }
        std::cout << fmt("   %zu lines sent: %zu ok, %zu error%s\n", host.answered(), oks,
                         answers.size() - oks,
                         stalled ? " -- then the firmware stopped answering" : "");
        for (const OutputLine& o : host.others()) {
            if (o.cycle < t0) continue;
            std::cout << fmt("   %7.3f s  %s\n", static_cast<double>(o.cycle - t0) / 16e6,
                             o.text.c_str());
        }
        if (!final_status.empty()) std::cout << "   final: " << final_status << "\n";

        const Trace t = trace_steps(sim);
        const Follow f = follow(t, moves);
        double per_mm[3] = {250, 250, 250};
        for (const std::string& l : lines)
            if (l.size() > 5 && l.compare(0, 3, "$10") == 0 && l[3] >= '0' && l[3] <= '2')
                per_mm[l[3] - '0'] = atof(l.c_str() + 5);
        size_t rapids = 0;
        for (const Move& m : moves) rapids += m.rapid;
        const double motion =
            t.cycle.empty() ? 0 : static_cast<double>(t.last() - t.first()) / 16e6;
        const uint16_t starved = static_cast<uint16_t>(peek_var(sim, "_ZN2ll13g_starvationsE", 2));

        std::vector<std::string> summary;
        summary.push_back(fmt("moves: %zu (%zu G0, %zu G1), targets reached in order: %zu of %zu",
                              moves.size(), rapids, moves.size() - rapids, f.reached,
                              moves.size()));
        std::string steps = "steps:";
        for (int a = 0; a < 3; ++a)
            steps += fmt(" %c %zu (ends at %+d)", "XYZ"[a], static_cast<size_t>(t.steps(a)),
                         t.final_pos[static_cast<size_t>(a)]);
        summary.push_back(steps);
        summary.push_back(fmt("simulated time: %.3f s from the first line sent, motion %.3f s "
                              "(first to last step)",
                              static_cast<double>(t_end - t0) / 16e6, motion));
        summary.push_back(fmt("worst deviation of a visited position from the programmed path: "
                              "%.2f ticks (%.4f mm)",
                              f.worst, f.worst / per_mm[0]));
        summary.push_back(fmt("step queue ran dry mid-move: %u times; deepest stack %u B above "
                              "%u B of static RAM%s",
                              starved, stack.peak(), stack.static_end() - 0x100,
                              stack.overflowed() ? " -- IT REACHED THE STATIC VARIABLES" : ""));
        std::cout << "\n-- summary\n";
        for (const std::string& l : summary) std::cout << "   " << l << "\n";

        mkdirs(out);
        const std::string base = job.substr(job.find_last_of('/') + 1);
        const std::string name = out + "/" + base.substr(0, base.find_last_of('.'));
        Picture pic;
        pic.per_mm[0] = per_mm[0];
        pic.per_mm[1] = per_mm[1];
        pic.moves = moves;
        pic.caption.push_back("Low Level in simavr: " + job + " (toolpath from the step pins)");
        pic.caption.push_back("blue: G1 steps, orange: G0 steps, pale band: programmed G1 path, "
                              "dashes: programmed G0");
        for (const std::string& l : summary) pic.caption.push_back(l);
        {
            std::ofstream svg(name + ".svg");
            svg << svg_of(t, f, pic);
        }
        sim.write_csv(name + "-edges.csv");
        std::cout << "\n-- picture\n   " << name << ".svg\n";
        if (have_program("rsvg-convert")) {
            const std::string cmd =
                "rsvg-convert -b white -o '" + name + ".png' '" + name + ".svg' 2>/dev/null";
            if (system(cmd.c_str()) == 0) std::cout << "   " << name << ".png\n";
        }
        std::cout << "   " << name << "-edges.csv (every pin edge: cycle,time_us,signal,level)\n";
        return stalled || errors > 0 || f.reached != moves.size() ? 1 : 0;
    } catch (const std::exception& e) {
        std::cerr << "lldemo: " << e.what() << "\n";
        return 1;
    }
}
