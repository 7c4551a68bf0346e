// TEMPORARY stand-in for the planner and step generator so that the protocol can be built and
// tested before they land: every move completes instantly. Replaced by planner.cpp/stepgen.cpp.
#include "lowlevel/motion.h"

namespace ll {
namespace motion {
namespace {
int32_t g_pos[kAxes];
State g_state = State::Idle;
} // namespace

bool can_accept() {
    return true;
}
void push_line(const LineRequest& req) {
    for (uint8_t a = 0; a < kAxes; ++a) g_pos[a] = req.target_steps[a];
}
uint8_t blocks_free() {
    return kPlannerSize - 1;
}
void poll() {}
State state() {
    return g_state;
}
void feed_hold() {
    if (g_state == State::Cycle) g_state = State::Held;
}
void cycle_start() {
    if (g_state == State::Held) g_state = State::Idle;
}
bool abort() {
    return false;
}
void position(int32_t steps[kAxes]) {
    for (uint8_t a = 0; a < kAxes; ++a) steps[a] = g_pos[a];
}
uint32_t current_feed() {
    return 0;
}
void settings_changed() {}

} // namespace motion
} // namespace ll
