#!/usr/bin/env bash
# Installs the Debian packages Low Level needs, only those that are missing.
# Usage: tools/deps.sh [test|demo]   (sourced or run; needs root or sudo when something is missing)
set -euo pipefail
pkgs=(cmake make g++ gcc-avr avr-libc binutils-avr avrdude simavr libsimavr-dev libelf-dev
      libgtest-dev pkg-config)
# The demo also renders its SVG picture to PNG.
[ "${1:-}" = demo ] && pkgs+=(librsvg2-bin)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "== installing: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO=sudo
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
