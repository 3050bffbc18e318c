#!/usr/bin/env bash
# Installs what zonetrace needs to build, test and run, from Debian 12's
# packages.  Safe to run again: it only calls apt-get for missing packages.
set -euo pipefail

packages=(
  build-essential cmake pkg-config   # compiler and build
  libjansson-dev                     # JSON parsing of scene files
  libembree-dev                      # ray traversal (Intel Embree 3)
  libopenexr-dev                     # OpenEXR output (its C API, OpenEXRCore)
  libpng-dev                         # PNG output and textures
  libjpeg62-turbo-dev                # JPEG textures
  libassimp-dev                      # model files (OBJ, glTF, PLY, STL, ...)
  assimp-testmodels                  # real and broken models for tests and examples
  libsdl2-dev                        # the interactive viewer's window
  libcmocka-dev                      # the test framework
  xvfb xauth                         # an X server for the viewer's tests
  time                               # /usr/bin/time: peak memory in bench/zone_nseries.sh
  clang libclang-rt-dev libomp-dev   # the fuzz harnesses (libFuzzer, OpenMP for clang)
  libopenmpi-dev openmpi-bin         # rendering across processes and machines (mpirun)
)

. "$(dirname "$0")/apt_missing.sh"
apt_install_missing install-deps "${packages[@]}"
