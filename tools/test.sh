#!/usr/bin/env bash
# Runs every test: builds the firmware (avr preset) and the host suites (host preset), then ctest
# runs the GoogleTest suites and the simavr checks on the real lowlevel.elf.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/deps.sh
cmake --preset avr >/dev/null
cmake --build --preset avr
cmake --preset host >/dev/null
cmake --build --preset host
ctest --preset host
