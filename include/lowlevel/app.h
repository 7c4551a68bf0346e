// The firmware's main loop, portable: the AVR main() and the host driver both call these.
#pragma once

namespace ll {
namespace app {

/// After the hardware is initialised: loads the settings (restoring defaults from a blank or
/// corrupt EEPROM), configures motion and prints the GRBL banner.
void init();
/// One iteration of the main loop: real-time commands, received bytes, motion background work.
/// Never blocks for long: a line that must wait (M0, G4, full planner) keeps its `ok` pending.
void run_once();

} // namespace app
} // namespace ll
