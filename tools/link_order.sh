#!/bin/sh
# Regenerates cmake/text_order.ld: the order of lowlevel.elf's functions that --relax shrinks most
# (tools/link_order.cpp says how). Run it after a change that moves much code, then commit the
# script with the size it gives. Takes about a minute.
# Usage: tools/link_order.sh [build-dir]   (default /tmp/ll-link-order)
set -eu
cd "$(dirname "$0")/.."
src=$(pwd)
build=${1:-/tmp/ll-link-order}
# The image may be over the chip: link it into a larger text region; the order does not care.
cmake -B "$build" -S "$src" --toolchain cmake/avr-gcc.cmake -DCMAKE_BUILD_TYPE=MinSizeRel \
  -DLL_CHIP_FLASH=131072 -DLL_CHIP_RAM=4096 \
  "-DCMAKE_EXE_LINKER_FLAGS=-Wl,--defsym=__TEXT_REGION_LENGTH__=131072" >/dev/null
cmake --build "$build" --target lowlevel.elf -j2 >/dev/null
before=$(avr-size "$build/firmware/lowlevel.elf" | awk 'NR == 2 { print $1 + $2 }')
# The same link without relaxation, with a map: the model's input.
cd "$build/firmware"
link=$(sed -e 's/ -mrelax//g' -e 's/-o lowlevel\.elf/-o lowlevel_norelax.elf -Wl,-Map,lowlevel_norelax.map/' \
  CMakeFiles/lowlevel.elf.dir/link.txt)
sh -c "$link"
avr-objdump -d lowlevel_norelax.elf >lowlevel_norelax.dis
c++ -std=c++14 -O2 -Wall -Wextra -Werror -o link_order "$src/tools/link_order.cpp"
./link_order lowlevel_norelax.map lowlevel_norelax.dis "$src/cmake/text_order.ld" text_order.ld
cp text_order.ld "$src/cmake/text_order.ld"
cd "$src"
cmake -B "$build" -S "$src" >/dev/null
cmake --build "$build" --target lowlevel.elf -j2 >/dev/null
after=$(avr-size "$build/firmware/lowlevel.elf" | awk 'NR == 2 { print $1 + $2 }')
echo "lowlevel.elf: $before B -> $after B (cmake/text_order.ld rewritten)"
