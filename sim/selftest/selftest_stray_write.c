/* A runaway program's store beyond RAMEND (GRBL 1.1h's step interrupts do this once they nest
 * until the stack wraps, from 50,000 steps/s). simavr 1.6 reports it and marks the core crashed,
 * then performs the store all the same (avr_core_watch_write), into its host buffer of RAMEND + 1
 * bytes: the harness must give that buffer the whole 64 KiB data space, so that the run ends
 * with the harness' "crashed" error instead of corrupting the host's heap. */
#include <stdint.h>

int main(void) {
    *(volatile uint8_t *)0xF000 = 0x5A;
    for (;;) {
    }
}
