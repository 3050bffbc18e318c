#!/usr/bin/env bash
# Regenerates the glTF lamps with an emissive texture that
# tests/test_emissive.c renders (tools/make_pbr_gltf.py emissive says what
# each option writes).  The test computes what it expects from the same
# texel codes, factors and strength, so change both together.
#
#   tests/data/make_emissive_models.sh
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
make="python3 $here/../../tools/make_pbr_gltf.py emissive"
out="$here/emissive"
mkdir -p "$out"
rm -f "$out"/*
# Left half sRGB (255, 200, 100), right half black; factor (1, 0.8, 0.5)
# and KHR_materials_emissive_strength 6.
$make "$out/lamp.gltf" --size 8 --left 255 200 100 --factor 1 0.8 0.5 --strength 6
# The same texture without an emissiveFactor: glTF's default is black.
$make "$out/no_factor.gltf" --size 8 --left 255 200 100 --no-factor
