// Output formatting. See print.h.
#include "lowlevel/print.h"

#include "lowlevel/hal.h"
#include "lowlevel/numparse.h"
#include "lowlevel/settings.h"

namespace ll {
namespace out {

namespace {
const uint32_t kPow10[10] LL_PROGMEM = {1u,      10u,      100u,      1000u,      10000u,
                                        100000u, 1000000u, 10000000u, 100000000u, 1000000000u};

// Digits of m, with at least `decimals + 1` of them and a point before the last `decimals`.
void digits(uint32_t m, uint8_t decimals) {
    bool started = false;
    for (int8_t p = 9; p >= 0; --p) {
        uint32_t pw = flash_read_u32(&kPow10[p]);
        char d = '0';
        while (m >= pw) {
            m -= pw;
            ++d;
        }
        if (d != '0' || p <= static_cast<int8_t>(decimals)) started = true;
        if (!started) continue;
        if (decimals != 0 && p == static_cast<int8_t>(decimals) - 1) ch('.');
        ch(d);
    }
}
} // namespace

void ch(char c) {
    hal::serial_put(static_cast<uint8_t>(c));
}

void str(const FlashChar* s) {
    for (;;) {
        char c = static_cast<char>(flash_read_byte(s));
        if (c == 0) return;
        ch(c);
        s = reinterpret_cast<const FlashChar*>(reinterpret_cast<const char*>(s) + 1);
    }
}

void eol() {
    ch('\r');
    ch('\n');
}

void u32(uint32_t v) {
    digits(v, 0);
}

void fixed(int32_t v, uint8_t decimals) {
    uint32_t m = static_cast<uint32_t>(v);
    if (v < 0) {
        ch('-');
        m = 0u - m;
    }
    digits(m, decimals);
}

void coords(const int32_t* um) {
    for (uint8_t a = 0; a < kAxes; ++a) {
        if (a != 0) ch(',');
        if (g_settings.report_inches) {
            int32_t in; // 1e-4 in = 2.54 um
            num::mul_div_round(um[a], 50u, 127u, in);
            fixed(in, 4);
        } else {
            fixed(um[a], 3);
        }
    }
}

void rate(uint32_t milli_per_min) {
    int32_t v;
    int32_t m = static_cast<int32_t>(milli_per_min & 0x7FFFFFFFu);
    if (g_settings.report_inches) {
        num::mul_div_round(m, 1u, 2540u, v); // in/min x10
        fixed(v, 1);
    } else {
        num::mul_div_round(m, 1u, 1000u, v);
        fixed(v, 0);
    }
}

void status(uint8_t code) {
    if (code == 0) {
        str(LL_PSTR("ok"));
    } else {
        str(LL_PSTR("error:"));
        u32(code);
    }
    eol();
}

void msg(const FlashChar* text) {
    str(LL_PSTR("[MSG:"));
    str(text);
    ch(']');
    eol();
}

} // namespace out
} // namespace ll
