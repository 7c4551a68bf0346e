// llmotion: the figures of docs/motion.md, measured by running the portable core on the host
// (no simavr): line positions and their deviation, the feed along lines, the speed of the first
// steps (ours against the seed's plain square-only scheme, §8.2), the peak and deceleration
// point, segment lengths and queue depth (compute windows), and the planner's speed handover.
//
//   build/host/tools/llmotion                       # every section
//   build/host/tools/llmotion --only speed          # line feed speed profile windows handover
//   build/host/tools/llmotion --svg docs/img        # also writes the two figures of the page
//
// Deterministic: fixed seeds, exact cycle arithmetic, the same output on every run.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "lowlevel/line.h"
#include "lowlevel/microstep.h"
#include "lowlevel/profile.h"
#include "motion_host.h"
#include "motion_util.h"

namespace {

constexpr double kF = 16e6;

std::vector<std::string> g_only;
bool want(const char* name) {
    return g_only.empty() || std::find(g_only.begin(), g_only.end(), name) != g_only.end();
}

// ---- line positions and deviation (seed §7.2, §2.2) -----------------------------------------

struct Dev {
    double worst = 0;       // max |x_j - s_j x_1| over every visited position
    double worst_macro = 0; // the same at macro positions only
    double margin = -1e9;   // max over positions of deviation minus its bound (< 0: holds)
    double worst_bound = 0; // the largest bound met
    uint64_t steps = 0;
};

// Walks a line micro step by micro step with segments of `len` ticks; `trace` (optional) gets
// (x_1, deviation of sorted position 1) after every micro step.
void walk(const int32_t delta[ll::kAxes], uint8_t len, Dev& d,
          std::vector<std::pair<double, double>>* trace = nullptr) {
    ll::LineGeometry g;
    if (!ll::line_setup(g, delta)) return;
    ll::LineCursor c;
    ll::line_start(g, c);
    double slope[ll::kAxes];
    for (uint8_t j = 0; j < g.m; ++j) slope[j] = static_cast<double>(g.dist[j]) / g.dist[0];
    uint32_t p[ll::kAxes] = {};
    if (trace) trace->push_back({0, 0});
    while (c.x1 < g.dist[0]) {
        uint32_t left = g.dist[0] - c.x1;
        uint8_t l = len > left ? static_cast<uint8_t>(left) : len;
        uint8_t e[ll::kAxes];
        ll::line_advance(g, c, l, e);
        ll::MicroRun runs[ll::kAxes];
        uint8_t n = ll::micro_split(e, g.m, runs);
        for (uint8_t r = 0; r < n; ++r) {
            for (uint8_t k = 0; k < runs[r].count; ++k) {
                for (uint8_t j = 0; j < g.m; ++j) {
                    if (runs[r].set & (1u << j)) ++p[j];
                }
                ++d.steps;
                for (uint8_t j = 1; j < g.m; ++j) {
                    double dev = p[j] - slope[j] * p[0];
                    double bound = 9.0 / 16 + l * slope[j] * (1 - slope[j]);
                    d.worst = std::max(d.worst, std::fabs(dev));
                    d.margin = std::max(d.margin, std::max(dev - bound, -9.0 / 16 - dev));
                    d.worst_bound = std::max(d.worst_bound, bound);
                }
                if (trace && g.m > 1) trace->push_back({double(p[0]), p[1] - slope[1] * p[0]});
            }
        }
        for (uint8_t j = 1; j < g.m; ++j) {
            d.worst_macro = std::max(d.worst_macro, std::fabs(c.pos[j] - slope[j] * c.x1));
        }
    }
}

void section_line() {
    std::printf("## Line positions (seed §7.2)\n\n");
    int32_t ex[ll::kAxes] = {1000, 500, 490, 0};
    ll::LineGeometry g{}; // (line_setup() is inline: gcc sees its refusal leave g unset)
    ll::line_setup(g, ex);
    std::printf("line (1000, 500, 490): k = %u, P = 2^k = %lu (>= 8 d_1 = %lu)\n", g.shift,
                1ul << g.shift, 8ul * g.dist[0]);
    for (uint8_t j = 0; j < g.m; ++j) {
        double s = static_cast<double>(g.dist[j]) / g.dist[0];
        std::printf("  sorted %u: axis %u, d = %lu, s = %.6f, S = %lu, S/P - s = %+.2e\n", j,
                    g.axis[j], static_cast<unsigned long>(g.dist[j]), s,
                    static_cast<unsigned long>(g.slope[j]),
                    static_cast<double>(g.slope[j]) / (1ul << g.shift) - s);
    }
    std::printf("\n## Deviation bound: 2000 random lines (1-4 axes, 1..100000 ticks) per segment "
                "length L\n\n");
    std::printf("| L | micro steps | worst at macro positions | worst anywhere | bound 9/16 + "
                "L s(1-s), largest met | worst (deviation - bound) |\n|---|---|---|---|---|---|\n");
    for (uint8_t len : {1, 2, 4, 8, 16}) {
        std::mt19937 rng(20261121);
        Dev d;
        for (int i = 0; i < 2000; ++i) {
            int32_t delta[ll::kAxes];
            lltest::random_delta(rng, delta);
            walk(delta, len, d);
        }
        std::printf("| %u | %llu | %.4f | %.4f | %.4f | %+.4f |\n", len,
                    static_cast<unsigned long long>(d.steps), d.worst_macro, d.worst, d.worst_bound,
                    d.margin);
    }
    std::printf("\n");
}

// ---- feed along the line --------------------------------------------------------------------

void section_feed() {
    std::printf("## Feed along the line: move time / (len / V) at cruise, 300 random lines per "
                "row\n\n");
    std::printf("| moving axes | steps/mm | reference rate | segment L | worst (its deltas, ticks) "
                "| mean |\n"
                "|---|---|---|---|---|---|\n");
    struct Row {
        uint8_t axes;
        bool mixed;
        double ref_rate; // reference-axis steps/s wanted
    };
    const Row rows[] = {{2, false, 2000},   {3, false, 2000},  {4, false, 2000},
                        {3, true, 2000},    {4, true, 2000},   {2, false, 120000},
                        {3, false, 120000}, {4, false, 120000}};
    for (const Row& r : rows) {
        std::mt19937 rng(17);
        double worst = 1, sum = 0;
        int32_t worst_d[ll::kAxes] = {};
        int n = 0;
        unsigned seg = 0;
        for (int i = 0; i < 300; ++i) {
            lltest::Machine m =
                r.mixed ? lltest::Machine{80, 100, 400, 250} : lltest::Machine{80, 80, 80, 80};
            int32_t d[ll::kAxes] = {};
            for (uint8_t a = 0; a < r.axes; ++a) {
                d[a] = static_cast<int32_t>(200 + rng() % 3000) * ((rng() & 1) ? -1 : 1);
            }
            // The feed that gives the reference axis (the most ticks) the wanted rate.
            uint8_t ref = 0;
            for (uint8_t a = 1; a < ll::kAxes; ++a) {
                if (std::abs(d[a]) > std::abs(d[ref])) ref = a;
            }
            double len = m.length_mm(d);
            double ref_mm = std::abs(d[ref]) / m.steps_per_mm[ref];
            double feed = r.ref_rate / m.steps_per_mm[ref] * len / ref_mm * 60; // mm/min
            ll::MoveSpec spec = m.move({d[0], d[1], d[2], d[3]}, feed, 1e6, feed, feed);
            ll::StepGen gen{};
            gen.configure(&m.lengths, 64);
            uint64_t t = 0;
            lltest::run_move(gen, spec, &t);
            seg = std::max<unsigned>(seg, gen.segment_ticks());
            double ratio = static_cast<double>(t) / (len / (feed / 60) * kF);
            if (std::fabs(ratio - 1) > std::fabs(worst - 1)) {
                worst = ratio;
                std::copy(d, d + ll::kAxes, worst_d);
            }
            sum += ratio;
            ++n;
        }
        std::printf("| %u | %s | %.0f steps/s | %u | %.5f (%ld, %ld, %ld, %ld) | %.5f |\n", r.axes,
                    r.mixed ? "80/100/400/250" : "80", r.ref_rate, seg, worst,
                    static_cast<long>(worst_d[0]), static_cast<long>(worst_d[1]),
                    static_cast<long>(worst_d[2]), static_cast<long>(worst_d[3]), sum / n);
    }
    std::printf("\nExamples on a mill with X, Y at 80 steps/mm and Z at 400 steps/mm (XYZ "
                "regulated):\n\n| G-code | ticks | F | segment L | time / (len / V) |\n"
                "|---|---|---|---|---|\n");
    struct Ex {
        const char* gcode;
        int32_t d[3];
        double feed;
    };
    const Ex exs[] = {
        {"G1 X10 Y10 Z3", {800, 800, 1200}, 1000}, {"G1 X10 Y9.8 Z3", {800, 784, 1200}, 1000},
        {"G1 X10 Y5 Z3", {800, 400, 1200}, 1000},  {"G1 X10 Y5 Z3", {800, 400, 1200}, 6000},
        {"G1 X10 Y5", {800, 400, 0}, 1000},        {"G1 X10 Y9.8 Z-6", {800, 784, -2400}, 3000},
    };
    const lltest::Machine mill{80, 80, 400, 80};
    for (const Ex& e : exs) {
        ll::MoveSpec spec = mill.move({e.d[0], e.d[1], e.d[2], 0}, e.feed, 1e6, e.feed, e.feed);
        ll::StepGen gen{};
        gen.configure(&mill.lengths, 64);
        uint64_t t = 0;
        lltest::run_move(gen, spec, &t);
        double ratio = static_cast<double>(t) / (mill.length_mm(spec.delta) / (e.feed / 60) * kF);
        std::printf("| %s | (%ld, %ld, %ld) | %.0f | %u | %.4f |\n", e.gcode,
                    static_cast<long>(e.d[0]), static_cast<long>(e.d[1]), static_cast<long>(e.d[2]),
                    e.feed, gen.segment_ticks(), ratio);
    }
    std::printf("\n");
}

// ---- speed of the first steps (seed §4.2, §8.2) ---------------------------------------------

struct Scheme {
    const char* name;
    std::vector<double> v; // speed of step k (index k - 1), ticks/s
};

// The seed's §8.2 as written: R = 1, C = 1 at the start; before each step, while x_1 > C:
// R += 1, C = R * R; the step then waits D / R (x_1 = ticks already travelled, one tick per
// macro position, which is the most favourable spacing for it). D / R is taken exactly.
std::vector<double> seed_plain(double a_t, int steps) {
    std::vector<double> v;
    double r = 1, c = 1;
    const double dnum = 1 / std::sqrt(2 * a_t); // s per tick at x = 1
    for (int k = 1; k <= steps; ++k) {
        double x = k - 1;
        while (x > c) {
            r += 1;
            c = r * r;
        }
        v.push_back(r / dnum);
    }
    return v;
}

// R = floor(sqrt(A)) with A = s x evaluated at the step's midpoint x = k - 1/2, D scaled by
// sqrt(s) (R = 0 is taken as 1, as the generator does).
std::vector<double> floor_mid(double a_t, int steps, double s) {
    std::vector<double> v;
    const double dnum = std::sqrt(s) / std::sqrt(2 * a_t);
    for (int k = 1; k <= steps; ++k) {
        double r = std::floor(std::sqrt(s * (k - 0.5)));
        if (r < 1) r = 1;
        v.push_back(r / dnum);
    }
    return v;
}

struct SvgSeries {
    std::string name, colour;
    std::vector<std::pair<double, double>> pts;
    bool dots;
};

void write_svg(const std::string& path, const std::string& title, const std::string& xlabel,
               const std::string& ylabel, const std::vector<SvgSeries>& series) {
    double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
    for (const auto& s : series) {
        for (auto p : s.pts) {
            x0 = std::min(x0, p.first);
            x1 = std::max(x1, p.first);
            y0 = std::min(y0, p.second);
            y1 = std::max(y1, p.second);
        }
    }
    double pad = 0.05 * (y1 - y0);
    y0 -= pad;
    y1 += pad;
    const double W = 720, H = 360, L = 60, R = 170, T = 30, B = 40;
    auto X = [&](double x) { return L + (x - x0) / (x1 - x0) * (W - L - R); };
    auto Y = [&](double y) { return H - B - (y - y0) / (y1 - y0) * (H - T - B); };
    FILE* f = std::fopen(path.c_str(), "w");
    if (!f) {
        std::fprintf(stderr, "cannot write %s\n", path.c_str());
        return;
    }
    std::fprintf(f,
                 "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
                 "font-family=\"sans-serif\" font-size=\"11\">\n",
                 W, H);
    std::fprintf(f, "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n");
    std::fprintf(f, "<text x=\"%.0f\" y=\"18\" font-size=\"13\">%s</text>\n", L, title.c_str());
    std::fprintf(f,
                 "<rect x=\"%.0f\" y=\"%.0f\" width=\"%.0f\" height=\"%.0f\" fill=\"none\" "
                 "stroke=\"#888\"/>\n",
                 L, T, W - L - R, H - T - B);
    for (int i = 0; i <= 4; ++i) {
        double yv = y0 + (y1 - y0) * i / 4, xv = x0 + (x1 - x0) * i / 4;
        std::fprintf(f, "<text x=\"%.0f\" y=\"%.1f\" text-anchor=\"end\">%.4g</text>\n", L - 4,
                     Y(yv) + 4, yv);
        std::fprintf(f, "<text x=\"%.1f\" y=\"%.0f\" text-anchor=\"middle\">%.4g</text>\n", X(xv),
                     H - B + 14, xv);
    }
    if (y0 < 0 && y1 > 0) {
        std::fprintf(f, "<line x1=\"%.0f\" x2=\"%.0f\" y1=\"%.1f\" y2=\"%.1f\" stroke=\"#ccc\"/>\n",
                     L, W - R, Y(0), Y(0));
    }
    std::fprintf(f, "<text x=\"%.0f\" y=\"%.0f\" text-anchor=\"middle\">%s</text>\n",
                 (L + W - R) / 2, H - 8, xlabel.c_str());
    std::fprintf(f,
                 "<text x=\"14\" y=\"%.0f\" transform=\"rotate(-90 14 %.0f)\" "
                 "text-anchor=\"middle\">%s</text>\n",
                 (T + H - B) / 2, (T + H - B) / 2, ylabel.c_str());
    int li = 0;
    for (const auto& s : series) {
        if (s.dots) {
            for (auto p : s.pts) {
                std::fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"2.2\" fill=\"%s\"/>\n",
                             X(p.first), Y(p.second), s.colour.c_str());
            }
        } else {
            std::fprintf(f,
                         "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.3\" "
                         "points=\"",
                         s.colour.c_str());
            for (auto p : s.pts) std::fprintf(f, "%.1f,%.1f ", X(p.first), Y(p.second));
            std::fprintf(f, "\"/>\n");
        }
        if (s.name.empty()) continue;
        double ly = T + 12 + 16 * li++;
        std::fprintf(f, "<rect x=\"%.0f\" y=\"%.0f\" width=\"12\" height=\"4\" fill=\"%s\"/>\n",
                     W - R + 10, ly - 4, s.colour.c_str());
        std::fprintf(f, "<text x=\"%.0f\" y=\"%.0f\">%s</text>\n", W - R + 26, ly + 1,
                     s.name.c_str());
    }
    std::fprintf(f, "</svg>\n");
    std::fclose(f);
    std::printf("wrote %s\n", path.c_str());
}

std::string g_svg_dir;

void section_speed() {
    // tests/test_profile.cpp's "from rest" move: 80 steps/mm, 2000 ticks, F3000, 1000 mm/s^2.
    const lltest::Machine mach{80, 80, 80, 80};
    const double T = 80, accel = 1000, feed = 3000;
    const double a_t = accel * T; // ticks/s^2
    ll::StepGen gen{};
    gen.configure(&mach.lengths, 64);
    ll::MoveSpec spec = mach.move({2000}, feed, accel, 0, 0);
    auto ev = lltest::run_move(gen, spec);
    const ll::Profile& pr = gen.profile();
    const int n_acc = static_cast<int>(std::lround((feed / 60 * T) * (feed / 60 * T) / (2 * a_t)));
    std::printf("## Speed of the first steps (seed §4.2, §8.2)\n\n");
    std::printf("move: 1 axis, 80 steps/mm, 2000 ticks, F3000, 1000 mm/s^2 from rest: "
                "%d ticks of acceleration to 4000 steps/s\n",
                n_acc);
    std::printf("profile: log_s = %u (s = %lu), A_cruise = %lu, D = d_num = %lu (cycles x 256 "
                "x sqrt(tick)), cruise Delta_1 = %lu (cycles x 256), Delta_1 = D / R changes "
                "%lu times over %zu steps\n\n",
                pr.log_s, 1ul << pr.log_s, static_cast<unsigned long>(pr.a_cruise),
                static_cast<unsigned long>(pr.d_num), static_cast<unsigned long>(pr.cruise),
                static_cast<unsigned long>(gen.stats.divisions), ev.size());
    std::vector<double> ours;
    uint64_t prev = 0;
    for (const auto& e : ev) {
        ours.push_back(kF / static_cast<double>(e.t - prev));
        prev = e.t;
    }
    const double s = std::ldexp(1.0, pr.log_s);
    std::vector<Scheme> sch = {
        {"seed §8.2 as written (s = 1, R from the counter, at the step's start)",
         seed_plain(a_t, n_acc)},
        {"s = 1, R = floor(sqrt(A)) at the step's midpoint", floor_mid(a_t, n_acc, 1)},
        {"s = 512, R = floor(sqrt(A)) at the midpoint (model of ours)", floor_mid(a_t, n_acc, s)},
        {"StepGen (measured periods)", std::vector<double>(ours.begin(), ours.begin() + n_acc)},
    };
    auto mid = [&](int k) { return std::sqrt(2 * a_t * (k - 0.5)); };
    auto exact = [&](int k) {
        return 1 / (std::sqrt(2.0 * k / a_t) - std::sqrt(2.0 * (k - 1) / a_t));
    };
    std::printf("Relative speed error of step k, against the speed at the step's midpoint "
                "(sqrt(2 a (k - 1/2)), the reference of tests/test_profile.cpp):\n\n");
    std::printf("| k | exact kinematics | seed §8.2 | s = 1, midpoint | ours (model) | ours "
                "(StepGen) | test tolerance (L = 16) |\n|---|---|---|---|---|---|---|\n");
    const int ks[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 16, 17, 25, 26, 50, 75, 99};
    for (int k : ks) {
        if (k > n_acc) break;
        double want = mid(k);
        double A = s * (k - 0.5);
        double dt = kF / ours[k - 1];
        double tol = 1 / std::sqrt(A) + s * 16 / (4 * A) + 1 / dt + 1.0 / 4096;
        std::printf("| %d | %+.2f%% | %+.2f%% | %+.2f%% | %+.2f%% | %+.2f%% | %.1f%% |\n", k,
                    100 * (exact(k) / want - 1), 100 * (sch[0].v[k - 1] / want - 1),
                    100 * (sch[1].v[k - 1] / want - 1), 100 * (sch[2].v[k - 1] / want - 1),
                    100 * (sch[3].v[k - 1] / want - 1), 100 * tol);
    }
    std::printf("\nWorst |relative error| against the midpoint speed, by range of steps:\n\n");
    std::printf("| scheme | steps 1-3 | 4-10 | 11-30 | 31-%d |\n|---|---|---|---|---|\n", n_acc);
    for (const auto& c : sch) {
        double w[4] = {};
        for (int k = 1; k <= n_acc; ++k) {
            int b = k <= 3 ? 0 : k <= 10 ? 1 : k <= 30 ? 2 : 3;
            w[b] = std::max(w[b], std::fabs(c.v[k - 1] / mid(k) - 1));
        }
        std::printf("| %s | %.1f%% | %.1f%% | %.1f%% | %.1f%% |\n", c.name, 100 * w[0], 100 * w[1],
                    100 * w[2], 100 * w[3]);
    }
    // Against exact kinematics: when each step happens.
    std::printf("\nTime of step k against constant acceleration from rest (t_k = sqrt(2k/a)), "
                "in units of the first step's exact duration sqrt(2/a) = %.0f cycles:\n\n",
                std::sqrt(2 / a_t) * kF);
    std::printf("| scheme | step 1 | step 10 | step %d |\n|---|---|---|---|\n", n_acc);
    for (const auto& c : sch) {
        double t = 0, t1 = 0, t10 = 0;
        for (int k = 1; k <= n_acc; ++k) {
            t += 1 / c.v[k - 1];
            if (k == 1) t1 = t;
            if (k == 10) t10 = t;
        }
        const double u = std::sqrt(2 / a_t);
        std::printf("| %s | %+.3f | %+.3f | %+.3f |\n", c.name, (t1 - u) / u,
                    (t10 - std::sqrt(20 / a_t)) / u, (t - std::sqrt(2.0 * n_acc / a_t)) / u);
    }
    std::printf("\n");

    // test_profile's worst case (ToleranceHoldsAcrossResolutionsAndAccelerations): where it is.
    {
        const double t = 3200, acc = 5000, vc = 1500 / 60.0;
        const lltest::Machine m3{t};
        const int32_t ticks = static_cast<int32_t>(std::min(200000.0, t * (vc * vc / acc + 20)));
        ll::StepGen g3{};
        g3.configure(&m3.lengths, 64);
        auto e3 = lltest::run_move(g3, m3.move({ticks}, 1500, acc, 0, 0));
        const double at = acc * t, vt = vc * t;
        auto ideal = [&](double l) {
            return std::min(std::min(std::sqrt(2 * at * l), vt), std::sqrt(2 * at * (ticks - l)));
        };
        double worst = 0, worst_first_half = 0;
        size_t wk = 0;
        uint64_t p3 = 0;
        for (size_t k = 0; k < e3.size(); ++k) {
            double err = kF / static_cast<double>(e3[k].t - p3) / ideal(k + 0.5) - 1;
            p3 = e3[k].t;
            if (2 * k < e3.size()) worst_first_half = std::max(worst_first_half, std::fabs(err));
            if (std::fabs(err) > std::fabs(worst)) {
                worst = err;
                wk = k;
            }
        }
        std::printf("test_profile's worst case, 3200 steps/mm, 5000 mm/s^2, F1500, %d ticks: "
                    "%+.2f%% at step %zu; the last 12 steps (measured / ideal at the midpoint, "
                    "steps/s):\n",
                    ticks, 100 * worst, wk + 1);
        for (size_t k = e3.size() - 12; k < e3.size(); ++k) {
            std::printf("  step %zu: %.0f / %.0f\n", k + 1,
                        kF / static_cast<double>(e3[k].t - e3[k - 1].t), ideal(k + 0.5));
        }
        std::printf("worst |error| in the first half of the move (acceleration): %.2f%%\n\n",
                    100 * worst_first_half);
    }

    if (!g_svg_dir.empty()) {
        std::vector<SvgSeries> ser;
        SvgSeries ex{"exact kinematics", "#999999", {}, false};
        SvgSeries mi{"sqrt(2a(k-1/2))", "#000000", {}, false};
        for (int k = 1; k <= 40; ++k) {
            ex.pts.push_back({double(k), exact(k)});
            mi.pts.push_back({double(k), mid(k)});
        }
        SvgSeries se{"seed 8.2 as written", "#d62728", {}, true};
        SvgSeries ou{"StepGen (measured)", "#1f77b4", {}, true};
        for (int k = 1; k <= 40; ++k) {
            se.pts.push_back({double(k), sch[0].v[k - 1]});
            ou.pts.push_back({double(k), ours[k - 1]});
        }
        ser = {ex, mi, se, ou};
        write_svg(g_svg_dir + "/motion_first_steps.svg",
                  "First 40 steps from rest: 80 steps/mm, 1000 mm/s^2 (llmotion --svg)", "step k",
                  "speed of step k, steps/s", ser);
    }
}

// ---- peak and deceleration point -------------------------------------------------------------

void section_profile() {
    std::printf("## Peak and deceleration point (closed form)\n\n");
    const lltest::Machine m{80, 80, 80, 80};
    struct Case {
        const char* name;
        int32_t ticks;
        double feed, accel, entry, exit;
    };
    const Case cases[] = {
        {"triangle: 120 ticks, F3000, 1000 mm/s^2, rest to rest", 120, 3000, 1000, 0, 0},
        {"trapezoid: 3000 ticks, F6000, 500 mm/s^2, entry F1200, exit F1800", 3000, 6000, 500, 1200,
         1800},
        {"short, entry and exit: 200 ticks, F6000, 500 mm/s^2, entry F1200, exit F1800", 200, 6000,
         500, 1200, 1800},
    };
    for (const Case& c : cases) {
        ll::StepGen gen{};
        gen.configure(&m.lengths, 64);
        auto ev = lltest::run_move(gen, m.move({c.ticks}, c.feed, c.accel, c.entry, c.exit));
        const ll::Profile& p = gen.profile();
        uint32_t x2 = ll::profile_x2_decel(p);
        // Kinematics in steps/s and steps.
        const double a = c.accel * 80, v0 = c.entry / 60 * 80, v1 = c.exit / 60 * 80,
                     vc = c.feed / 60 * 80, L = c.ticks;
        double vp2 = (v0 * v0 + v1 * v1) / 2 + a * L;
        double x_meet = (v1 * v1 - v0 * v0 + 2 * a * L) / (4 * a);
        double x_dec = L - (vc * vc - v1 * v1) / (2 * a);
        bool cruise = vp2 >= vc * vc;
        double fastest = 0;
        size_t at = 0;
        uint64_t prev = 0;
        for (size_t k = 0; k < ev.size(); ++k) {
            double v = kF / static_cast<double>(ev[k].t - prev);
            prev = ev[k].t;
            if (v > fastest + 1e-9) {
                fastest = v;
                at = k + 1;
            }
        }
        std::printf("%s:\n  s = %lu, A_entry = %lu, A_cruise = %lu, A_exit = %lu\n", c.name,
                    1ul << p.log_s, static_cast<unsigned long>(p.a_entry),
                    static_cast<unsigned long>(p.a_cruise), static_cast<unsigned long>(p.a_exit));
        std::printf("  deceleration from x2 = %lu half ticks (x = %.1f ticks); kinematics: %s "
                    "x = %.2f ticks\n",
                    static_cast<unsigned long>(x2), x2 / 2.0,
                    cruise ? "cruise ends at" : "start and end lines meet at",
                    cruise ? x_dec : x_meet);
        if (cruise) {
            std::printf("  cruise reached: %.1f steps/s; fastest step measured %.1f steps/s\n", vc,
                        fastest);
        } else {
            std::printf("  peak v_p = sqrt((v0^2 + v1^2)/2 + a L) = %.1f steps/s; A_peak = "
                        "(A_entry + A_exit + s d)/2 = %lu = A(x2) %lu; fastest step measured "
                        "%.1f steps/s (step %zu of %zu)\n",
                        std::sqrt(vp2),
                        static_cast<unsigned long>((p.a_entry + p.a_exit + (p.d << p.log_s)) / 2),
                        static_cast<unsigned long>(ll::profile_a(p, x2)), fastest, at, ev.size());
        }
        // Entry and exit speeds as stepped: first and last step.
        double first = kF / static_cast<double>(ev[0].t);
        double last = kF / static_cast<double>(ev.back().t - ev[ev.size() - 2].t);
        std::printf("  first step %.1f steps/s (entry %.1f), last step %.1f steps/s (exit %.1f)\n",
                    first, v0, last, v1);
        if (!g_svg_dir.empty() && c.ticks == 200) {
            SvgSeries ideal{"kinematics", "#000000", {}, false};
            for (int i = 0; i <= 400; ++i) {
                double x = L * i / 400;
                ideal.pts.push_back({x, std::sqrt(std::min(std::min(v0 * v0 + 2 * a * x, vc * vc),
                                                           v1 * v1 + 2 * a * (L - x)))});
            }
            SvgSeries meas{"StepGen, step k", "#1f77b4", {}, true};
            prev = 0;
            for (size_t k = 0; k < ev.size(); ++k) {
                meas.pts.push_back({k + 0.5, kF / static_cast<double>(ev[k].t - prev)});
                prev = ev[k].t;
            }
            SvgSeries mark{"decel. point",
                           "#d62728",
                           {{x2 / 2.0, v0 * 0.9}, {x2 / 2.0, std::sqrt(vp2) * 1.02}},
                           false};
            write_svg(g_svg_dir + "/motion_profile.svg",
                      "200 ticks, 80 steps/mm, 500 mm/s^2, F1200 in, F1800 out, F6000 out of "
                      "reach (llmotion --svg)",
                      "x (reference ticks)", "steps/s", {ideal, meas, mark});
        }
    }
    std::printf("\n");
}

// ---- compute windows ---------------------------------------------------------------------------

void section_windows() {
    std::printf("## Compute windows: segment length, runs and queue depth at cruise (1 axis, "
                "1000 steps/mm)\n\n");
    std::printf("kSegmentCycles = %u, kHorizonCycles = %lu, kMaxSegmentTicks = %u, "
                "kRunQueueSize = %u, kMaxPeriodCycles = %lu\n\n",
                ll::kSegmentCycles, static_cast<unsigned long>(ll::kHorizonCycles),
                ll::kMaxSegmentTicks, ll::kRunQueueSize,
                static_cast<unsigned long>(ll::kMaxPeriodCycles));
    std::printf("| steps/s | period (cycles) | segment L | segment (cycles) | runs per step | "
                "queued when full (cycles) | runs queued |\n|---|---|---|---|---|---|---|\n");
    const lltest::Machine m{1000, 1000, 1000, 1000};
    for (double rate :
         {100.0, 240.0, 1000.0, 4000.0, 7800.0, 8000.0, 16000.0, 30000.0, 60000.0, 100000.0}) {
        double feed = rate / 1000 * 60;
        ll::MoveSpec spec = m.move({200000}, feed, 1e6, feed, feed);
        ll::StepGen gen{};
        gen.configure(&m.lengths, 152);
        ll::RunQueue q;
        q.clear();
        gen.begin(spec);
        gen.fill(q); // as far as the horizon and the queue allow
        uint32_t queued = gen.queued_cycles(q);
        uint8_t used = q.used();
        // Exact queued time from the runs themselves.
        uint64_t exact = 0;
        uint32_t steps = 0, runs = 0;
        for (uint8_t i = q.head; i != q.tail;
             i = static_cast<uint8_t>((i + 1) & (ll::kRunQueueSize - 1))) {
            exact += static_cast<uint64_t>(q.buf[i].period) * q.buf[i].count;
            if (q.buf[i].steps) steps += q.buf[i].count;
            ++runs;
        }
        double period = kF / rate;
        unsigned L = gen.segment_ticks();
        std::printf("| %.0f | %.0f | %u | %.0f | %.2f | %llu (counted %lu) | %u |\n", rate, period,
                    L, period * L, steps ? double(runs) / steps : 0.0,
                    static_cast<unsigned long long>(exact), static_cast<unsigned long>(queued),
                    used);
    }
    std::printf("\n");
}

// ---- handover between planned moves ------------------------------------------------------------

void section_handover() {
    std::printf("## Planner/step generator handover (look-ahead arriving during an end "
                "deceleration)\n\n");
    // X10 then X10.5 queued at once; X20.5 arrives after 0.215 s, while the first move is
    // already decelerating towards the short second move's entry.
    ll::Settings s;
    lltest::default_settings(s);
    lltest::reset_motion(s);
    lltest::line_to({10, 0, 0, 0}, 3000);
    lltest::line_to({10.5, 0, 0, 0}, 3000);
    lltest::run_for(static_cast<uint64_t>(0.215 * kF));
    lltest::line_to({20.5, 0, 0, 0}, 3000);
    lltest::run_until(ll::motion::State::Idle);
    std::vector<uint64_t> t;
    for (const auto& e : ll::host::edges()) {
        if (e.kind == ll::host::EdgeKind::Step && e.level == 1 && e.axis == 0) t.push_back(e.cycle);
    }
    double worst = 0;
    size_t wk = 0;
    for (size_t k = 2; k < t.size(); ++k) {
        double r1 = kF / static_cast<double>(t[k] - t[k - 1]);
        double r0 = kF / static_cast<double>(t[k - 1] - t[k - 2]);
        if (std::fabs(r1 - r0) > std::fabs(worst)) {
            worst = r1 - r0;
            wk = k;
        }
    }
    std::printf("G1 X10 F3000, G1 X10.5, then G1 X20.5 0.215 s later (80 steps/mm, 1000 mm/s^2): "
                "%zu X steps\n",
                t.size());
    std::printf("largest change of step rate between two consecutive steps: %+.1f steps/s at "
                "step %zu (tick %.3f mm)\n",
                worst, wk, wk / 80.0);
    for (size_t k = wk - 3; k < wk + 3 && k < t.size(); ++k) {
        std::printf("  step %zu: %.1f steps/s\n", k, kF / static_cast<double>(t[k] - t[k - 1]));
    }
    std::printf("at 1000 mm/s^2 the rate may change by a / v = %.1f steps/s per step at "
                "4000 steps/s\n\n",
                80000.0 / 4000.0);
}

void deviation_svg() {
    if (g_svg_dir.empty()) return;
    int32_t d[ll::kAxes] = {200, 93, 0, 0};
    std::vector<SvgSeries> ser;
    const char* colours[] = {"#1f77b4", "#d62728"};
    int i = 0;
    for (uint8_t len : {1, 16}) {
        Dev dv;
        std::vector<std::pair<double, double>> tr;
        walk(d, len, dv, &tr);
        ser.push_back({"L = " + std::to_string(len), colours[i++], tr, false});
    }
    double s = 93.0 / 200;
    ser.push_back({"+-9/16", "#999999", {{0, 9.0 / 16}, {200, 9.0 / 16}}, false});
    ser.push_back({"", "#999999", {{0, -9.0 / 16}, {200, -9.0 / 16}}, false});
    ser.push_back({"9/16 + 16 s(1-s)",
                   "#ff9896",
                   {{0, 9.0 / 16 + 16 * s * (1 - s)}, {200, 9.0 / 16 + 16 * s * (1 - s)}},
                   false});
    write_svg(g_svg_dir + "/motion_deviation.svg",
              "Line (200, 93): deviation of Y from the ideal line (llmotion --svg)",
              "x_1 (reference ticks)", "y - s x_1 (ticks)", ser);
}

} // namespace

int main(int argc, char** argv) {
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--only") && i + 1 < argc) {
            g_only.push_back(argv[++i]);
        } else if (!std::strcmp(argv[i], "--svg") && i + 1 < argc) {
            g_svg_dir = argv[++i];
        } else {
            std::fprintf(stderr, "usage: llmotion [--only line|feed|speed|profile|windows|"
                                 "handover]... [--svg DIR]\n");
            return 2;
        }
    }
    if (want("line")) section_line();
    if (want("feed")) section_feed();
    if (want("speed")) section_speed();
    if (want("profile")) section_profile();
    if (want("windows")) section_windows();
    if (want("handover")) section_handover();
    deviation_svg();
    return 0;
}
