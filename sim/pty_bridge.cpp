#include "pty_bridge.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

namespace ll {
namespace sim {

namespace {

int64_t now_ns() {
    timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return int64_t(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

// A program has the slave open. Linux reports POLLHUP on the master once every slave descriptor
// is closed; the constructor opens and closes the slave once, so HUP also means "not yet opened".
bool slave_open(int master) {
    pollfd p{master, 0, 0};
    return poll(&p, 1, 0) >= 0 && !(p.revents & POLLHUP);
}

} // namespace

PtyBridge::PtyBridge(Sim& sim, const Options& opt) : sim_(sim), opt_(opt) {
    master_ = posix_openpt(O_RDWR | O_NOCTTY);
    if (master_ < 0 || grantpt(master_) != 0 || unlockpt(master_) != 0)
        throw SimError(std::string("llsim: cannot create a pty: ") + strerror(errno));
    path_ = ptsname(master_);
    fcntl(master_, F_SETFL, fcntl(master_, F_GETFL) | O_NONBLOCK);
    // Raw mode on the slave side (no echo, no line editing, no CR/LF translation): what a USB
    // serial port gives. The setting stays with the pty after this descriptor is closed.
    const int slave = open(path_.c_str(), O_RDWR | O_NOCTTY);
    if (slave >= 0) {
        termios t;
        if (tcgetattr(slave, &t) == 0) {
            cfmakeraw(&t);
            cfsetspeed(&t, B115200);
            tcsetattr(slave, TCSANOW, &t);
        }
        close(slave);
    }
    if (!opt_.link.empty()) {
        unlink(opt_.link.c_str());
        if (symlink(path_.c_str(), opt_.link.c_str()) != 0)
            throw SimError("llsim: cannot create the link " + opt_.link + ": " + strerror(errno));
    }
    sent_ = sim_.output_bytes().size();
}

PtyBridge::~PtyBridge() {
    if (!opt_.link.empty()) unlink(opt_.link.c_str());
    if (master_ >= 0) close(master_);
}

void PtyBridge::exchange() {
    const bool open_now = slave_open(master_);
    if (open_now && !connected_) {
        if (opt_.reset_on_open) sim_.reset(); // the Uno resets when the port is opened (DTR)
        sent_ = sim_.output_bytes().size();   // nothing from before the connection
        to_pty_.clear();
    }
    connected_ = open_now;

    if (connected_) {
        char buf[256];
        for (;;) {
            const ssize_t n = read(master_, buf, sizeof buf);
            if (n <= 0) break;
            sim_.send(std::string(buf, static_cast<size_t>(n)));
        }
    }

    const std::vector<SerialByte>& out = sim_.output_bytes();
    for (; sent_ < out.size(); ++sent_)
        if (connected_) to_pty_ += static_cast<char>(out[sent_].byte);
    while (connected_ && !to_pty_.empty()) {
        const ssize_t n = write(master_, to_pty_.data(), to_pty_.size());
        if (n <= 0) break; // the program is not reading: keep the rest for the next slice
        to_pty_.erase(0, static_cast<size_t>(n));
    }
}

void PtyBridge::step() {
    exchange();
    sim_.run_for(opt_.slice);
    if (!opt_.realtime) return;
    const int64_t now = now_ns();
    if (pace_wall_ns_ == 0) {
        pace_wall_ns_ = now;
        pace_cycle_ = sim_.cycle();
        return;
    }
    const int64_t due =
        pace_wall_ns_ + int64_t((sim_.cycle() - pace_cycle_) * 1000000000.0 / kCpuHz);
    if (due > now) {
        const int64_t wait = due - now;
        timespec ts{static_cast<time_t>(wait / 1000000000), static_cast<long>(wait % 1000000000)};
        nanosleep(&ts, nullptr);
    } else if (now - due > 100000000) {
        // More than 100 ms behind (the host was busy): do not try to catch up in a burst.
        pace_wall_ns_ = now;
        pace_cycle_ = sim_.cycle();
    }
}

void PtyBridge::run(const volatile sig_atomic_t& stop, uint64_t until_cycle) {
    while (!stop && sim_.cycle() < until_cycle) step();
    exchange();
}

} // namespace sim
} // namespace ll
