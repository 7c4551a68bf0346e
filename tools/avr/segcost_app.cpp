// llsegcost.elf: the step generator alone on the ATmega328P, for the compute-window figures of
// docs/motion.md (tools/segcost.cpp runs it in simavr and times every StepGen::fill call). It
// replaces ll::app: no protocol, no planner, no step timer. Each case prepares one straight move
// (1000 steps/mm, 2000 mm/s^2, from rest to rest, as llbench's producer profile) and produces
// it completely, emptying the run queue after every fill() as an infinitely fast interrupt
// would. GPIOR0 holds the number of the case being produced (0 before, 0xFF when done).
#include <avr/io.h>

#include "lowlevel/app.h"
#include "lowlevel/stepgen.h"

namespace ll {
namespace {

// Move specs in the step generator's units: lengths µm x 256, feeds mm/min x 1000, squared
// speeds (mm/min)^2, acceleration 2000 mm/s^2 = 7,200,000 mm/min^2.
struct Case {
    int32_t x, y, z; ///< ticks
    uint32_t len_q8; ///< µm x 256
    uint32_t feed;   ///< mm/min x 1000
    uint32_t v2;     ///< feed^2, (mm/min)^2
};
// 10 mm on X at 4,000 / 30,000 / 100,000 steps/s; 10 mm on X, Y and Z at 30,000 steps/s per axis
// (17.32 mm of path at 3117.69 mm/min).
const Case kCases[] = {
    {10000, 0, 0, 2560000ul, 240000ul, 57600ul},
    {10000, 0, 0, 2560000ul, 1800000ul, 3240000ul},
    {10000, 0, 0, 2560000ul, 6000000ul, 36000000ul},
    {10000, 10000, 10000, 4434050ul, 3117691ul, 9720000ul},
};

StepLengths g_lengths;
StepGen g_gen;
RunQueue g_q;

} // namespace

namespace app {

void init() {
    uint32_t spm[kAxes];
    for (uint8_t a = 0; a < kAxes; ++a) spm[a] = 1000000ul; // 1000 steps/mm
    step_lengths_build(g_lengths, spm);
    g_gen.configure(&g_lengths, 152); // the minimum period at $0 = 3 µs
    uint8_t n = 0;
    for (const Case& c : kCases) {
        MoveSpec s{};
        s.delta[0] = c.x;
        s.delta[1] = c.y;
        s.delta[2] = c.z;
        s.len_q8 = c.len_q8;
        s.accel = 7200000ul;
        s.feed = c.feed;
        s.v_nominal2 = c.v2;
        s.group = 0x07;
        g_q.clear();
        g_gen.clear_queue_time();
        GPIOR0 = ++n;
        g_gen.begin(s);
        while (g_gen.active()) {
            g_gen.fill(g_q);
            while (!g_q.empty()) g_q.pop(); // consumed at once, as by an infinitely fast interrupt
        }
    }
    GPIOR0 = 0xFF;
}

void run_once() {}

} // namespace app
} // namespace ll
