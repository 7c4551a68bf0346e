#!/usr/bin/env bash
# Builds the firmware and runs it on a shipped G-code job, showing what it did.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/deps.sh
cmake --preset avr >/dev/null
cmake --build --preset avr
cmake --preset host >/dev/null
cmake --build --preset host
job=${1:-jobs/demo.gcode}
if [ -x build/host/tools/lldry ]; then
  build/host/tools/lldry "$job"
else
  echo "demo: the host dry run is not built yet"
fi
