#!/usr/bin/env bash
# The README's demo: builds the firmware and the host tools, runs the real lowlevel.elf in simavr
# on a shipped G-code job (default jobs/demo.gcode), and shows what the machine did: GRBL's
# answers, a summary rebuilt from the step pins, and a picture of the toolpath in build/demo/.
#
#   tools/demo.sh [JOB.gcode]
#
# If the firmware misses its size budget (firmware/CMakeLists.txt), the build says so and the
# demo goes on with the same image built without that check (build/avr-nobudget).
set -euo pipefail
cd "$(dirname "$0")/.."
tools/deps.sh demo
job=${1:-jobs/demo.gcode}
mkdir -p build/demo
logs=build/demo

step() { printf '== %s\n' "$*"; }
# Runs a build command quietly; on failure shows the end of its log and returns non-zero.
quiet() {
  local log=$1
  shift
  if ! "$@" >"$log" 2>&1; then
    return 1
  fi
}

step "building the firmware (cmake --preset avr)"
elf=build/avr/firmware/lowlevel.elf
cmake --preset avr >"$logs/avr-configure.log" 2>&1 || { tail -20 "$logs/avr-configure.log"; exit 1; }
if ! quiet "$logs/avr-build.log" cmake --build --preset avr; then
  tail -30 "$logs/avr-build.log"
  echo "demo: the firmware build failed (log: $logs/avr-build.log)"
  exit 1
fi
if grep -q "over budget" "$logs/avr-build.log"; then
  echo "   !! over the size budget of issue 3 (the image still fits the chip and runs):"
  grep -h -o "lowlevel.elf:.*over budget[^;]*;.*" "$logs/avr-build.log" | head -1 | sed 's/^/   !! /'
fi

avr-size --format=avr --mcu=atmega328p "$elf" | grep -E "^(Program|Data):" | sed 's/^/   /'

step "building the simulator tools (cmake --preset host, target lldemo)"
cmake --preset host >"$logs/host-configure.log" 2>&1 || { tail -20 "$logs/host-configure.log"; exit 1; }
quiet "$logs/host-build.log" cmake --build --preset host --target lldemo ||
  { tail -30 "$logs/host-build.log"; echo "demo: host build failed"; exit 1; }

step "running $elf on $job"
echo
rc=0
build/host/tools/lldemo "$job" --elf "$elf" --out build/demo || rc=$?
if [ "$rc" -ne 0 ]; then
  echo
  echo "demo: the job did not run as programmed (see above); the picture shows what the pins did."
fi
exit "$rc"
