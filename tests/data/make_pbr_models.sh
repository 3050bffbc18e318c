#!/usr/bin/env bash
# Regenerates the glTF models with metallic-roughness and normal textures
# that tests/test_model_maps.c renders (tools/make_pbr_gltf.py says what
# each option writes).  The test computes what it expects from the same
# texel codes, so change both together.
#
#   tests/data/make_pbr_models.sh
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
make="python3 $here/../../tools/make_pbr_gltf.py"
out="$here/pbr"
mkdir -p "$out"
rm -f "$out"/*
# A metal whose left half has roughness 128/255, its right half 0.
$make "$out/rough.gltf" --rough 0.5 --metal 1 --size 8 --no-normal
# A white diffuse surface whose normal map tilts the left half by 30
# degrees toward +u: tangents made by the reader, then given by the file
# (with a normal scale of 0.5).
$make "$out/tilt.gltf" --metal 0 --rough 0 --tilt 30 --size 8 --specular 0
$make "$out/tilt_tangents.gltf" --metal 0 --rough 0 --tilt 30 --size 8 --specular 0 --tangents --scale 0.5
# Maps of 8 x 8 texels over a base texture of 16 x 16: left out.
$make "$out/sizes.gltf" --metal 0 --rough 0 --tilt 30 --size 8 --specular 0 --base-size 16
