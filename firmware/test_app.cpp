// Bench application for the drivers (LL_FIRMWARE_TEST_APP): replaces ll::app so that the step
// interrupt, the UART and the EEPROM can be driven over the serial line without the protocol.
// Never part of the release image. One command per line, answered by "ok" (or "error"):
//
//   R s d c p      queue the run {steps s, dirs d, count c, period p} and start the timer
//   Q s d c p      queue it only (waits while the queue is full)
//   F n s d c p    feed n copies of the run, starting once the queue is full (long moves)
//   G              start the timer if stopped
//   X              stop at once (hal::stepper_stop)
//   C w s d e      stepper_configure(pulse_cycles w, step_invert s, dir_invert d, enable_inv e)
//   E b            stepper_enable(b)
//   S              "exec <remaining> <steps> <dirs> <running> <starved> q <used> ms <millis>
//                   lim <limits> free <rx free>"
//   W a v / V a    EEPROM write / read
// Real-time bytes are reported as "rt <bits>" when taken; a receive overflow as "overflow".
// Other lines are echoed as "echo <line>".
#include "fw.h"
#include "lowlevel/app.h"
#include "lowlevel/hal.h"
#include "lowlevel/realtime.h"
#include "lowlevel/run_queue.h"

namespace ll {
namespace {

char s_line[48];
uint8_t s_len;

void put(const char* s) {
    while (*s) hal::serial_put(static_cast<uint8_t>(*s++));
}

void put_u(uint32_t v) {
    char buf[11];
    uint8_t n = 0;
    do {
        buf[n++] = static_cast<char>('0' + v % 10);
        v /= 10;
    } while (v);
    while (n) hal::serial_put(static_cast<uint8_t>(buf[--n]));
}

void put_field(const char* name, uint32_t v) {
    put(name);
    put_u(v);
}

/// Parses up to `n` unsigned decimal numbers after the command letter.
uint8_t parse(const char* p, uint32_t* out, uint8_t n) {
    uint8_t got = 0;
    while (got < n) {
        while (*p == ' ') ++p;
        if (*p < '0' || *p > '9') break;
        uint32_t v = 0;
        while (*p >= '0' && *p <= '9') v = v * 10 + static_cast<uint32_t>(*p++ - '0');
        out[got++] = v;
    }
    return got;
}

Run make_run(const uint32_t* a) {
    return Run{static_cast<uint8_t>(a[0]), static_cast<uint8_t>(a[1]), static_cast<uint8_t>(a[2]),
               static_cast<uint16_t>(a[3])};
}

void push_waiting(const Run& r) {
    while (g_runs.full()) {
    }
    g_runs.push(r);
}

bool execute(const char* line) {
    uint32_t a[5];
    switch (line[0]) {
        case 'R':
        case 'Q':
            if (parse(line + 1, a, 4) != 4) return false;
            push_waiting(make_run(a));
            if (line[0] == 'R') hal::stepper_start();
            return true;
        case 'F': {
            if (parse(line + 1, a, 5) != 5) return false;
            Run r = make_run(a + 1);
            for (uint32_t i = 0; i < a[0]; ++i) {
                if (g_runs.full()) hal::stepper_start();
                push_waiting(r);
            }
            hal::stepper_start();
            return true;
        }
        case 'G':
            hal::stepper_start();
            return true;
        case 'X':
            hal::stepper_stop();
            return true;
        case 'C':
            if (parse(line + 1, a, 4) != 4) return false;
            hal::stepper_configure(
                hal::StepperConfig{static_cast<uint16_t>(a[0]), static_cast<uint8_t>(a[1]),
                                   static_cast<uint8_t>(a[2]), static_cast<uint8_t>(a[3])});
            return true;
        case 'E':
            if (parse(line + 1, a, 1) != 1) return false;
            hal::stepper_enable(a[0] != 0);
            return true;
        case 'S': {
            // A consistent snapshot in 3 loads + 2 cycles with interrupts off (fw::IrqGuard, not
            // hal::Critical: its two calls alone keep interrupts off for 13 cycles).
            uint8_t rem, steps, head;
            {
                fw::IrqGuard g;
                rem = g_exec.remaining;
                steps = g_exec.steps;
                head = g_runs.head;
            }
            uint8_t dirs = g_exec.dirs, running = g_exec.running, starved = g_exec.starved;
            uint8_t used = static_cast<uint8_t>((g_runs.tail - head) & (kRunQueueSize - 1));
            put_field("exec ", rem);
            put_field(" ", steps);
            put_field(" ", dirs);
            put_field(" ", running);
            put_field(" ", starved);
            put_field(" q ", used);
            put_field(" ms ", hal::millis());
            put_field(" lim ", hal::limits());
            put_field(" free ", hal::serial_rx_free());
            put("\r\n");
            return true;
        }
        case 'W':
            if (parse(line + 1, a, 2) != 2) return false;
            hal::eeprom_write(static_cast<uint16_t>(a[0]), static_cast<uint8_t>(a[1]));
            return true;
        case 'V':
            if (parse(line + 1, a, 1) != 1) return false;
            put_field("ee ", hal::eeprom_read(static_cast<uint16_t>(a[0])));
            put("\r\n");
            return true;
        default:
            put("echo ");
            put(line);
            put("\r\n");
            return true;
    }
}

} // namespace

namespace app {

void init() {
    g_runs.clear();
    put("\r\nLowLevel fw-test ['R s d c p' to step]\r\n");
}

void run_once() {
    // rt::take() runs a hal::Critical (two calls with interrupts off, ~14 cycles that delay a
    // step edge): only when a real-time byte is actually pending.
    uint8_t bits = rt::g_pending ? rt::take() : 0;
    if (bits) {
        put_field("rt ", bits);
        put("\r\n");
    }
    if (hal::serial_rx_overflowed()) put("overflow\r\n");
    uint8_t c;
    while (hal::serial_get(c)) {
        if (c == '\n' || c == '\r') {
            if (s_len == 0) continue;
            s_line[s_len] = 0;
            s_len = 0;
            put(execute(s_line) ? "ok\r\n" : "error\r\n");
            return;
        }
        if (s_len < sizeof(s_line) - 1) s_line[s_len++] = static_cast<char>(c);
    }
}

} // namespace app
} // namespace ll
