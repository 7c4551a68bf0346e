#!/usr/bin/env bash
# Runs every test: builds the firmware (avr preset) and the host suites (host preset), then ctest
# runs the GoogleTest suites and the simavr checks on the real lowlevel.elf.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/deps.sh
cmake --preset avr >/dev/null
# A firmware that fails to build (e.g. too large for the chip) must not hide the host results:
# its simavr checks then fail on the missing image, and the run fails.
avr=0
cmake --build --preset avr -- -k || avr=$? # -k: the other images (check images, bench) still build
cmake --preset host >/dev/null
cmake --build --preset host
ctest --preset host
if [ "$avr" -ne 0 ]; then
  echo "test.sh: the firmware build failed (see above)" >&2
  exit "$avr"
fi
