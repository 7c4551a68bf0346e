// The GRBL 1.1 line protocol (app::init / app::run_once in app.h), and what other modules and
// test drivers may ask of it.
#pragma once

#include <stdint.h>

namespace ll {
namespace protocol {

/// Longest line kept after dropping spaces and comments (GRBL's LINE_BUFFER_SIZE 80 with its
/// terminator): a longer line is answered error:11 and never runs.
constexpr uint8_t kLineMax = 79;

/// Enters the alarm state now (e.g. a hard limit): prints `ALARM:code`, answers `error:9` to any
/// G-code line pending or to come, until `$X` or a soft reset.
void raise_alarm(uint8_t code);
/// True while an alarm locks G-code.
bool alarmed();
/// True when nothing is being assembled, executed or waited for: every received line has been
/// answered. (Motion may still be running: see motion::state().)
bool idle();

} // namespace protocol
} // namespace ll
