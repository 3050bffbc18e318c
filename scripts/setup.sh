#!/usr/bin/env bash
# First command of the README: install the dependencies, build zonetrace in
# build/ and render the default scene (the Cornell box) to cornell.png.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$(nproc)"
build/app/zonetrace render scenes/cornell.json -o cornell.png -v
echo "setup: wrote $(pwd)/cornell.png"
