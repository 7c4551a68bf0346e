// fixmath_check.elf: computes tools/fixmath_check.h's hash on the chip, for the host test
// tools/test_fixmath_avr.cpp (simavr reads the result from RAM by symbol).
#include "fixmath_check.h"

volatile uint32_t g_fixmath_hash;
volatile uint32_t g_fixmath_edges;
volatile uint32_t g_parse_hash;
volatile uint8_t g_fixmath_done;

int main() {
    g_fixmath_hash = ll::check::fixmath_hash(LL_FIXMATH_CHECK_ROUNDS);
    g_fixmath_edges = ll::check::fixmath_edges();
    g_parse_hash = ll::check::parse_hash(LL_FIXMATH_CHECK_ROUNDS);
    g_fixmath_done = 1;
    for (;;) {
    }
}
