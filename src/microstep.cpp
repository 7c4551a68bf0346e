#include "lowlevel/microstep.h"

namespace ll {

uint8_t micro_split(const uint8_t e[], uint8_t m, MicroRun out[]) {
    // Each run takes every axis with steps left and ends at the smallest increment still ahead
    // (where the axes that reach it drop out); the last one ends at e[0].
    MicroRun* o = out;
    uint8_t done = 0; // micro steps emitted so far
    do {
        uint8_t next = e[0], set = 0, bit = 1;
        for (uint8_t j = 0; j < m; ++j, bit = static_cast<uint8_t>(bit << 1)) {
            if (e[j] > done) {
                set = static_cast<uint8_t>(set | bit);
                if (e[j] < next) next = e[j];
            }
        }
        o->set = set;
        o->count = static_cast<uint8_t>(next - done);
        ++o;
        done = next;
    } while (done != e[0]);
    return static_cast<uint8_t>(o - out);
}

} // namespace ll
