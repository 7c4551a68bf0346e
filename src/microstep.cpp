#include "lowlevel/microstep.h"

namespace ll {

uint8_t micro_split(const uint8_t e[], uint8_t m, MicroRun out[]) {
    // Sorted positions 1..m-1 with a non-zero increment, ordered by increment, increasing.
    uint8_t order[kAxes];
    uint8_t n = 0;
    uint8_t set = 1;
    uint8_t bit = 1;
    for (uint8_t j = 1; j < m; ++j) {
        bit = static_cast<uint8_t>(bit << 1); // 1 << j
        if (e[j] == 0) continue;
        set = static_cast<uint8_t>(set | bit);
        uint8_t i = n;
        while (i > 0 && e[order[i - 1]] > e[j]) {
            order[i] = order[i - 1];
            --i;
        }
        order[i] = j;
        ++n;
    }
    MicroRun* o = out;
    uint8_t done = 0; // micro steps emitted so far
    for (uint8_t i = 0; i < n; ++i) {
        uint8_t j = order[i];
        if (e[j] > done) {
            o->set = set;
            o->count = static_cast<uint8_t>(e[j] - done);
            ++o;
            done = e[j];
        }
        set = static_cast<uint8_t>(set & ~(1u << j)); // axis j has reached its target
    }
    if (e[0] > done) {
        o->set = set;
        o->count = static_cast<uint8_t>(e[0] - done);
        ++o;
    }
    return static_cast<uint8_t>(o - out);
}

} // namespace ll
