// Output formatting. See print.h.
#include "lowlevel/print.h"

#include "lowlevel/hal.h"
#include "lowlevel/numparse.h"
#include "lowlevel/settings.h"

namespace ll {
namespace out {

namespace {
constexpr uint8_t kMinus = 0x80; // in digits()' `decimals`: a '-' first

// Digits of m, with at least `decimals + 1` of them and a point before the last `decimals`
// (after a '-' when kMinus is set in `decimals`). Cold (reports only): the library's division,
// which the image has anyway, takes 32 B less than a table of powers of ten (about 600 cycles
// a digit, 4 times the table's).
void digits(uint32_t m, uint8_t decimals) {
    if (decimals & kMinus) {
        ch('-');
        decimals = static_cast<uint8_t>(decimals & ~kMinus);
    }
    char buf[10]; // the last digit first (10 digits at most, decimals <= 9)
    uint8_t n = 0;
    do {
        buf[n++] = static_cast<char>('0' + m % 10u);
        m /= 10u;
    } while (m != 0 || n <= decimals);
    do {
        if (n == decimals) ch('.');
        ch(buf[--n]);
    } while (n != 0);
}

// value x mul / div, rounded half away from zero, printed with `decimals` decimals.
void scaled(int32_t v, uint8_t mul, uint16_t div, uint8_t decimals) {
    num::mul_div_round(v, mul, div, v); // div > 1 at every call
    fixed(v, decimals);
}
} // namespace

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

void line(const FlashChar* s) {
    str(s);
    eol();
}

void bracket_eol() {
    ch(']');
    eol();
}

void u32(uint32_t v) {
    digits(v, 0);
}

__attribute__((noinline)) void u8(uint8_t v) {
    digits(v, 0);
}

void word(char letter, uint8_t v) {
    ch(' ');
    ch(letter);
    u8(v); // not inlined: its widening is in one place
}

void fixed(int32_t v, uint8_t decimals) {
    // The sign goes to digits() with the count: v need not outlive a call here.
    uint32_t m = static_cast<uint32_t>(v);
    if (v < 0) {
        m = 0u - m;
        decimals = static_cast<uint8_t>(decimals | kMinus);
    }
    digits(m, decimals);
}

void coord(int32_t um) {
    // 1e-4 in = 2.54 um
    if (g_settings.report_inches) {
        scaled(um, 50, 127, 4);
    } else {
        fixed(um, 3);
    }
}

void coords(const int32_t* um) {
    for (uint8_t a = kAxes;;) {
        int32_t v = 0;
        if (um != nullptr) v = *um++;
        coord(v);
        if (--a == 0) return;
        ch(',');
    }
}

void rate(uint32_t milli_per_min) {
    int32_t m = static_cast<int32_t>(milli_per_min & 0x7FFFFFFFu);
    if (g_settings.report_inches) {
        scaled(m, 1, 2540, 1); // in/min x10
    } else {
        scaled(m, 1, 1000, 0);
    }
}

void status(uint8_t code) {
    if (code == 0) {
        // Every line's answer: two characters straight to the driver, not str()'s loop.
        ch('o');
        ch('k');
    } else {
        str(LL_PSTR("error:"));
        u8(code);
    }
    eol();
}

void msg(const FlashChar* text) {
    str(LL_PSTR("[MSG:"));
    str(text);
    bracket_eol();
}

} // namespace out
} // namespace ll
