#!/usr/bin/env bash
# Installs what the independent-renderer checks need: Blender (its Cycles
# renders the references that tools/cycles_reference.py makes from scene
# files), from Debian 12's package (Blender 3.4.1), and numpy, which Blender's
# glTF importer needs.  Safe to run again: it only calls apt-get when one of
# them is missing.
set -euo pipefail

packages=(
  blender   # Cycles, run headless: blender -b -P tools/cycles_reference.py -- ...
  python3-numpy  # Blender's glTF importer (tools/cycles_reference.py with a glTF "mesh")
)

. "$(dirname "$0")/apt_missing.sh"
apt_install_missing install-reference-tools "${packages[@]}"
