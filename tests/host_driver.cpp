#include "host_driver.h"

#include "host_hal.h"
#include "lowlevel/app.h"
#include "lowlevel/motion.h"
#include "lowlevel/protocol.h"

namespace ll {
namespace test {

unsigned count_responses(const std::string& text) {
    unsigned n = 0;
    size_t pos = 0;
    while (pos < text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string::npos) break;
        std::string line = text.substr(pos, end - pos);
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line == "ok" || line.compare(0, 6, "error:") == 0) ++n;
        pos = end + 1;
    }
    return n;
}

std::string HostDriver::boot(bool erase_eeprom) {
    host::reset_model(erase_eeprom);
    pending.clear();
    app::init();
    return take();
}

void HostDriver::send(const std::string& bytes) {
    host::send(bytes);
}

void HostDriver::step() {
    app::run_once();
    pending += host::take_output();
    uint64_t next = host::now() + quantum;
    uint64_t ev = host::next_event();
    if (ev < next && ev > host::now()) next = ev;
    host::advance_to(next);
}

std::string HostDriver::take() {
    pending += host::take_output();
    std::string out;
    out.swap(pending);
    return out;
}

std::string HostDriver::run_until_responses(unsigned n) {
    std::string out;
    uint64_t end = host::now() + limit;
    while (count_responses(out) < n && host::now() < end) {
        step();
        out += take();
    }
    return out;
}

std::string HostDriver::run_until_idle() {
    std::string out;
    uint64_t end = host::now() + limit;
    for (;;) {
        step();
        out += take();
        bool rx_empty =
            hal::serial_rx_free() == host::kRxCapacity && host::next_arrival() == UINT64_MAX;
        if (rx_empty && protocol::idle() && motion::state() == motion::State::Idle) break;
        if (host::now() >= end) break;
    }
    return out;
}

std::string HostDriver::command(const std::string& line) {
    send(line + "\n");
    return run_until_responses(1);
}

std::string HostDriver::run_for(uint64_t cycles) {
    std::string out;
    uint64_t end = host::now() + cycles;
    while (host::now() < end) {
        step();
        out += take();
    }
    return out;
}

} // namespace test
} // namespace ll
