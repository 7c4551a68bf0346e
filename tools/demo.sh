#!/usr/bin/env bash
# The README's demo: builds the firmware and the host tools, runs the real lowlevel.elf in simavr
# on a shipped G-code job (default jobs/demo.gcode), and shows what the machine did: GRBL's
# answers, a summary rebuilt from the step pins, and a picture of the toolpath in build/demo/.
#
#   tools/demo.sh [JOB.gcode]
#
# If the firmware is over its size budget, the build says so and the demo goes on; if it does not
# fit the chip at all, the demo says so and runs the same sources on simavr's diagnostic chip
# with 64 KiB of flash and 4 KiB of RAM (docs/verification.md).
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
if ! quiet "$logs/avr-build.log" cmake --build --preset avr -- -k; then
  if grep -q -e "will not fit in region" -e "overflowed by" "$logs/avr-build.log" &&
    [ ! -f "$elf" ]; then
    # The image is over the chip's flash (docs/benchmarks.md): run the same sources on the
    # diagnostic chip of the simavr checks, and say so.
    big=build/avr-big
    cmake -B "$big" -S . --toolchain cmake/avr-gcc.cmake -DCMAKE_BUILD_TYPE=MinSizeRel \
      -DLL_CHIP_FLASH=131072 -DLL_CHIP_RAM=4096 \
      "-DCMAKE_EXE_LINKER_FLAGS=-Wl,--defsym=__TEXT_REGION_LENGTH__=65536 -Wl,--defsym=__stack=0x800FFF -Wl,--defsym=__DATA_REGION_LENGTH__=4096" \
      >"$logs/avr-big-configure.log" 2>&1 || { tail -20 "$logs/avr-big-configure.log"; exit 1; }
    quiet "$logs/avr-big-build.log" cmake --build "$big" --target lowlevel.elf ||
      { tail -30 "$logs/avr-big-build.log"; echo "demo: the firmware build failed"; exit 1; }
    elf=$big/firmware/lowlevel.elf
    export LLSIM_BIG_FLASH=1 LLSIM_BIG_RAM=1
    flash=$(avr-size -A "$elf" | awk '/^\.text/{t=$2} /^\.data/{d=$2} END{print t+d}')
    echo "   !! lowlevel.elf does not fit the ATmega328P yet: $flash bytes of flash for 32,256"
    echo "   !! running the same sources on a simulated 328P with 64 KiB of flash and 4 KiB of RAM"
    echo "   !! (the diagnostic chip of docs/verification.md; nothing else differs)"
  else
    tail -30 "$logs/avr-build.log"
    echo "demo: the firmware build failed (log: $logs/avr-build.log)"
    exit 1
  fi
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
