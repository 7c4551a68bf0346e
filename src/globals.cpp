// Storage shared between the main loop and the step / receive interrupts.
#include "lowlevel/hal.h"
#include "lowlevel/realtime.h"
#include "lowlevel/run_queue.h"
#include "lowlevel/settings.h"

namespace ll {

RunQueue g_runs;
StepExec g_exec;
volatile uint16_t g_starvations;
Settings g_settings;

namespace rt {

volatile uint8_t g_pending;

uint8_t take() {
    // Called at every main-loop iteration and almost always with nothing pending: a byte read
    // is atomic, so only a non-zero value needs the critical section (and its interrupts-off
    // window, which delays the step interrupt).
    if (g_pending == 0) return 0;
    hal::Critical cs;
    uint8_t p = g_pending;
    g_pending = 0;
    return p;
}

} // namespace rt
} // namespace ll
