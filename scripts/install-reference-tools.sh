#!/usr/bin/env bash
# Installs what the independent-renderer checks need: Blender (its Cycles
# renders the references that tools/cycles_reference.py makes from scene
# files), from Debian 12's package (Blender 3.4.1).  Safe to run again: it
# only calls apt-get when blender is missing.
set -euo pipefail

packages=(
  blender   # Cycles, run headless: blender -b -P tools/cycles_reference.py -- ...
)

. "$(dirname "$0")/apt_missing.sh"
apt_install_missing install-reference-tools "${packages[@]}"
