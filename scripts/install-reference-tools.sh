#!/usr/bin/env bash
# Installs what the independent-renderer checks need: Blender (its Cycles
# renders the references that tools/cycles_reference.py makes from scene
# files), from Debian 12's package (Blender 3.4.1).  Safe to run again: it
# only calls apt-get when blender is missing.
set -euo pipefail

packages=(
  blender   # Cycles, run headless: blender -b -P tools/cycles_reference.py -- ...
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-reference-tools: everything is installed"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-reference-tools: run as root or install sudo" >&2; exit 1; }
  sudo="sudo"
fi
echo "install-reference-tools: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
