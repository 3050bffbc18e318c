#!/usr/bin/env bash
# Regenerates the glTF models with alpha coverage that tests/test_alpha.c
# renders (tools/make_pbr_gltf.py says what each option writes).  The test
# computes what it expects from the same stripes and factors, so change
# both together.
#
#   tests/data/make_alpha_models.sh
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
make="python3 $here/../../tools/make_pbr_gltf.py"
out="$here/alpha"
mkdir -p "$out"
rm -f "$out"/*.gltf "$out"/*.bin "$out"/*.png
plain="--metal 0 --rough 1 --no-normal --no-mr --specular 0"
# A white diffuse square whose 8 stripes along u are alternately covered
# (alpha 255) and holes (alpha 0): alphaMode MASK, the default cutoff.
$make "$out/stripes.gltf" $plain --size 8 --stripes --alpha-mode MASK
# A white diffuse square covering a quarter of itself: alphaMode BLEND
# with a base colour alpha of 0.25 and no texture.
$make "$out/quarter.gltf" $plain --alpha-mode BLEND --alpha 0.25
# Bad cutoffs: negative, above 1, and NaN (not JSON; Assimp's reader may
# take it or refuse the file).
$make "$out/cutoff_negative.gltf" $plain --size 8 --stripes --alpha-mode MASK --alpha-cutoff -0.5
$make "$out/cutoff_above.gltf" $plain --size 8 --stripes --alpha-mode MASK --alpha-cutoff 2
$make "$out/cutoff_nan.gltf" $plain --size 8 --stripes --alpha-mode MASK --alpha-cutoff nan
