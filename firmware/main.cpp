// Firmware entry point: hardware first (interrupts off), then the portable main loop. main() runs
// right after a reset (Optiboot starts the application after a watchdog reset, or at once after
// any reset but an external one), so the drivers write only registers whose reset value they do
// not want.
#include <avr/interrupt.h>

#include "fw.h"
#include "lowlevel/app.h"

int main() {
    ll::fw::board_init();
    ll::fw::stepper_init();
    ll::fw::clock_init();
    ll::fw::serial_init();
    sei();
    ll::app::init();
    for (;;) ll::app::run_once();
}
