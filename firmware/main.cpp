// Firmware entry point: hardware first (interrupts off), then the portable main loop.
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
