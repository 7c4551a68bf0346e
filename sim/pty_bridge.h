// UART0 of the simulated board on a pseudo-terminal, so that a real G-code sender (UGS, cncjs,
// bCNC, screen) can connect to it like to an Uno's /dev/ttyACM0.
//
// Why not simavr's uart_pty part (SIMAVR-NOTES 9): it always uses /tmp/simavr-uart0 (one board at
// a time), feeds the UART from its own thread (so the byte timing is not reproducible) and can hang
// when stopped. This bridge runs in the simulation thread: it moves bytes between the pty and the
// harness's serial line between slices of simulated time, and paces the simulation to wall-clock
// time so that the sender's timeouts behave as with a real board.
#pragma once

#include <signal.h>
#include <stdint.h>

#include <string>

#include "harness.h"

namespace ll {
namespace sim {

class PtyBridge {
  public:
    struct Options {
        std::string link;           ///< optional symlink to the pty (e.g. /tmp/ttyLowLevel)
        bool realtime = true;       ///< pace simulated time to wall-clock time
        bool reset_on_open = false; ///< reset the chip when a program opens the pty (Uno DTR)
        uint64_t slice = ms(1);     ///< simulated cycles between two exchanges with the pty
    };

    PtyBridge(Sim& sim, const Options& opt);
    ~PtyBridge(); ///< closes the pty and removes the link
    PtyBridge(const PtyBridge&) = delete;
    PtyBridge& operator=(const PtyBridge&) = delete;

    /// The slave side a sender opens, e.g. /dev/pts/3.
    const std::string& path() const { return path_; }
    /// True while a program has the pty open.
    bool connected() const { return connected_; }

    /// One slice: bytes from the pty go on the serial line, the simulation runs `slice` cycles,
    /// new firmware output goes to the pty (dropped while nobody has it open, as on a real port).
    void step();
    /// Repeats step() until `stop` becomes non-zero (e.g. from a SIGINT handler) or the
    /// simulated time reaches `until_cycle`.
    void run(const volatile sig_atomic_t& stop, uint64_t until_cycle = kNever);

  private:
    void exchange();

    Sim& sim_;
    Options opt_;
    int master_ = -1;
    std::string path_;
    bool connected_ = false;
    size_t sent_ = 0;         ///< firmware output bytes already handled
    std::string to_pty_;      ///< output waiting for the pty to accept it
    uint64_t pace_cycle_ = 0; ///< simulated cycle at pace_wall_ns_
    int64_t pace_wall_ns_ = 0;
};

} // namespace sim
} // namespace ll
