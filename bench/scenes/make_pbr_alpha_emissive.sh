#!/bin/sh
# Regenerates the glTF model of bench/scenes/pbr_alpha_emissive.json with tools/make_pbr_gltf.py
# alpha-emissive (standard-library Python), into bench/scenes/pbr_ae/:
#
#   bench/scenes/make_pbr_alpha_emissive.sh
#
# alpha_emissive.gltf  one mesh of two parts in the plane y = 0 (front up):
#   panel  a square of side 2 centred on x = -1.2, alphaMode MASK (alphaCutoff 0.5): a white
#          base-colour texture of 16 x 16 texels whose alpha is 0 in 16 square holes of 2 x 2
#          texels (4 x 4 of them, on a pitch of 4 texels), times baseColorFactor 0.8 0.6 0.4;
#          metallic-roughness and normal textures in halves along u: the left half metal,
#          roughness 128/255, its normal tilted 30 degrees toward +u; the right half
#          metallic 0, roughness 153/255, normal untilted
#   lamp   a square of side 1.2 centred on x = 1, cut into 8 x 8 squares, base colour black,
#          an emissive texture of 8 x 8 texels (a checker of 2 x 2 texel squares, white and
#          orange 255 140 0) times emissiveFactor 1 0.9 0.8, KHR_materials_emissive_strength 8
set -eu
here=$(cd "$(dirname "$0")" && pwd)
tools=$(cd "$here/../../tools" && pwd)
mkdir -p "$here/pbr_ae"
rm -f "$here"/pbr_ae/*
python3 "$tools/make_pbr_gltf.py" alpha-emissive "$here/pbr_ae/alpha_emissive.gltf"
