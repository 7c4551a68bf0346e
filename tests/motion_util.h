// Test helpers: run one move through the step generator and time its events exactly as the
// step interrupt would (each event: wait `period`, then step).
#pragma once

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "lowlevel/stepgen.h"

namespace lltest {

struct Event {
    uint64_t t;    ///< CPU cycle of the step, from the start of the move
    uint8_t steps; ///< axis bits
    uint8_t dirs;
    uint16_t period;
};

/// A random line: 1 to 4 moving axes (possibly the same one twice), the longest with a
/// log-uniform length of 1 to 100,000 ticks, the others up to it, random directions.
template <class Rng>
void random_delta(Rng& rng, int32_t delta[ll::kAxes]) {
    std::uniform_real_distribution<double> logd(0.0, std::log(100000.0));
    for (uint8_t a = 0; a < ll::kAxes; ++a) delta[a] = 0;
    uint8_t axes = static_cast<uint8_t>(1 + rng() % 4);
    int32_t longest = static_cast<int32_t>(std::lround(std::exp(logd(rng))));
    if (longest < 1) longest = 1;
    for (uint8_t k = 0; k < axes; ++k) {
        uint8_t a = static_cast<uint8_t>(rng() % ll::kAxes);
        int32_t d = k == 0 ? longest : static_cast<int32_t>(rng() % (longest + 1));
        delta[a] = (rng() & 1) ? -d : d;
    }
    bool any = false;
    for (uint8_t a = 0; a < ll::kAxes; ++a) any = any || delta[a] != 0;
    if (!any) delta[0] = 1;
}

/// Machine description for a test: steps per mm of each axis.
struct Machine {
    double steps_per_mm[ll::kAxes];
    ll::StepLengths lengths;

    explicit Machine(std::initializer_list<double> spm) {
        uint32_t milli[ll::kAxes];
        uint8_t i = 0;
        for (double v : spm) steps_per_mm[i++] = v;
        for (; i < ll::kAxes; ++i) steps_per_mm[i] = steps_per_mm[0];
        for (uint8_t a = 0; a < ll::kAxes; ++a) {
            milli[a] = static_cast<uint32_t>(std::lround(steps_per_mm[a] * 1000));
        }
        ll::step_lengths_build(lengths, milli);
    }

    /// Regulated length of a delta (ticks) over `group`, mm.
    double length_mm(const int32_t delta[ll::kAxes], uint8_t group = 0xFF) const {
        double s = 0;
        for (uint8_t a = 0; a < ll::kAxes; ++a) {
            if (!(group & (1u << a))) continue;
            double mm = delta[a] / steps_per_mm[a];
            s += mm * mm;
        }
        return std::sqrt(s);
    }

    /// A move at `feed` mm/min, acceleration `accel` mm/s^2, entry/exit speeds mm/min.
    ll::MoveSpec move(std::initializer_list<int32_t> delta, double feed, double accel,
                      double entry = 0, double exit = 0, uint8_t group = 0xFF) const {
        ll::MoveSpec m{};
        uint8_t i = 0;
        for (int32_t d : delta) m.delta[i++] = d;
        for (; i < ll::kAxes; ++i) m.delta[i] = 0;
        m.len_q8 = static_cast<uint32_t>(std::lround(length_mm(m.delta, group) * 256000));
        m.accel = static_cast<uint32_t>(std::lround(accel * 3600));
        m.feed = static_cast<uint32_t>(std::lround(feed * 1000));
        m.v_nominal2 = static_cast<uint32_t>(std::lround(feed * feed));
        m.v_entry2 = static_cast<uint32_t>(std::lround(entry * entry));
        m.v_exit2 = static_cast<uint32_t>(std::lround(exit * exit));
        m.group = group;
        return m;
    }
};

/// Runs the whole move, draining the queue as it fills. Idle waits add time only.
inline std::vector<Event> run_move(ll::StepGen& gen, const ll::MoveSpec& spec,
                                   uint64_t* end_time = nullptr) {
    std::vector<Event> out;
    ll::RunQueue q;
    q.clear();
    uint64_t t = end_time ? *end_time : 0;
    if (gen.begin(spec)) {
        while (gen.active() || !q.empty()) {
            gen.fill(q);
            while (!q.empty()) {
                ll::Run r = q.front();
                q.pop();
                for (uint8_t i = 0; i < r.count; ++i) {
                    t += r.period;
                    if (r.steps) out.push_back(Event{t, r.steps, r.dirs, r.period});
                }
            }
        }
    }
    if (end_time) *end_time = t;
    return out;
}

/// Runs the whole move one macro segment at a time and returns each segment's runs: before each
/// fill the queue is padded so that it has room for exactly one segment of an m-axis line (the
/// generator wants 2 m free slots), so each fill produces one. Lines only.
inline std::vector<std::vector<ll::Run>> run_segments(ll::StepGen& gen, const ll::MoveSpec& spec) {
    std::vector<std::vector<ll::Run>> out;
    uint8_t m = 0;
    for (uint8_t a = 0; a < ll::kAxes; ++a) m = static_cast<uint8_t>(m + (spec.delta[a] != 0));
    ll::RunQueue q;
    q.clear();
    if (!gen.begin(spec)) return out;
    while (gen.active()) {
        // An empty queue from slot 0, as after clear_queue_time(): the generator's horizon
        // accounting starts there (from any other head it would take the padding's slots for
        // its own runs, and stop after the first segment).
        q.clear();
        uint8_t pad = 0;
        while (q.free_slots() > 2 * m) {
            q.push(ll::Run{0, 0, 1, 1});
            ++pad;
        }
        gen.clear_queue_time();
        gen.fill(q);
        for (; pad > 0; --pad) q.pop();
        std::vector<ll::Run> seg;
        while (!q.empty()) {
            seg.push_back(q.front());
            q.pop();
        }
        if (seg.empty()) break;
        out.push_back(seg);
    }
    return out;
}

} // namespace lltest
