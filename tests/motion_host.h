// Drives the motion side on the host model with an infinitely fast main loop: poll after every
// step event. Used by the whole-pipeline motion tests.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "host_hal.h"
#include "lowlevel/motion.h"
#include "lowlevel/settings.h"

namespace lltest {

/// A generic 4-axis machine: 80 steps/mm, 6000 mm/min, 1000 mm/s^2, $11 = 0.010 mm.
inline void default_settings(ll::Settings& s) {
    s = ll::Settings{};
    s.pulse_us = 2;
    s.idle_delay_ms = 25;
    s.junction_dev = 10;
    for (uint8_t a = 0; a < ll::kAxes; ++a) {
        s.axis[a].steps_per_unit = 80000;
        s.axis[a].max_rate = 6000000;
        s.axis[a].accel = 1000000;
        s.axis[a].max_travel = 200000;
        s.axis_group[a] = a < 3 ? 0 : 1;
    }
}

/// Fresh motion state: model reset, settings applied, position zero.
inline void reset_motion(const ll::Settings& s) {
    ll::host::reset_model(true);
    ll::motion::init();
    ll::g_settings = s;
    ll::motion::settings_changed();
}

/// Runs until motion is idle (or held); false after `limit` cycles.
inline bool run_until(ll::motion::State want, uint64_t limit = 16000000ull * 120) {
    uint64_t end = ll::host::now() + limit;
    while (ll::host::now() < end) {
        ll::motion::poll();
        if (ll::motion::state() == want) return true;
        uint64_t t = ll::host::next_event();
        if (t == std::numeric_limits<uint64_t>::max()) t = ll::host::now() + 1000;
        ll::host::advance_to(t);
    }
    return false;
}

/// Runs the main loop for `cycles` (polling after every step event).
inline void run_for(uint64_t cycles) {
    uint64_t end = ll::host::now() + cycles;
    while (ll::host::now() < end) {
        ll::motion::poll();
        uint64_t t = ll::host::next_event();
        if (t > end) t = end;
        if (t == ll::host::now()) t = ll::host::now() + 1;
        ll::host::advance_to(t);
    }
    ll::motion::poll();
}

/// Queues a move to `mm` (X, Y, Z, A) at `feed` mm/min, waiting for room.
inline void line_to(std::initializer_list<double> mm, double feed, bool rapid = false) {
    ll::motion::LineRequest r{};
    uint8_t i = 0;
    for (double v : mm) {
        r.target_um[i] = static_cast<int32_t>(std::lround(v * 1000));
        r.target_steps[i] = static_cast<int32_t>(std::lround(v * 80));
        ++i;
    }
    r.feed = static_cast<uint32_t>(std::lround(feed * 1000));
    r.rapid = rapid;
    while (!ll::motion::can_accept()) {
        ll::motion::poll();
        uint64_t t = ll::host::next_event();
        if (t == std::numeric_limits<uint64_t>::max()) t = ll::host::now() + 1000;
        ll::host::advance_to(t);
    }
    ll::motion::push_line(r);
}

/// Net steps per axis in the recorded edges (rising step edges, with the direction pin level).
inline void count_steps(int32_t out[ll::kAxes]) {
    uint8_t dir_level[ll::kAxes] = {};
    for (uint8_t a = 0; a < ll::kAxes; ++a) out[a] = 0;
    for (const auto& e : ll::host::edges()) {
        if (e.kind == ll::host::EdgeKind::Dir) dir_level[e.axis] = e.level;
        if (e.kind == ll::host::EdgeKind::Step && e.level == 1) {
            out[e.axis] += dir_level[e.axis] ? -1 : 1; // $3 = 0: high = negative
        }
    }
}

} // namespace lltest
