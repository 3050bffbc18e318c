#!/bin/sh
# Regenerates the two glTF squares of bench/scenes/pbr_square.json with tools/make_pbr_gltf.py
# (standard-library Python: a square of side 2 with a metallic-roughness texture and a normal
# texture of 8 x 8 texels in halves along u).
#
#   bench/scenes/make_pbr_square.sh
#
# metal.gltf  left half: metal, roughness 128/255, its normal tilted 30 degrees toward +u (the
#             tangent); right half: white diffuse (metallic 0, roughness 0), normal untilted
# paint.gltf  base colour 0.8 0.6 0.4, metallic 0 everywhere; left half roughness 153/255, right
#             half roughness 0.  The generator tilts normals toward +u only, which leaves the
#             bitangent's sign untried, so its normal texture is then rewritten here: the left
#             half tilted 35 degrees toward the image's top (texel (0, sin 35, cos 35), green
#             up, glTF's convention: b = w (n x t), the direction of decreasing v), the right
#             half (0, 0, 1)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
tools=$(cd "$here/../../tools" && pwd)
make="python3 $tools/make_pbr_gltf.py"
mkdir -p "$here/pbr"
rm -f "$here"/pbr/*
$make "$here/pbr/metal.gltf" --rough 0.5 --metal 1 --metal-right 0 --tilt 30 --size 8
$make "$here/pbr/paint.gltf" --rough 0.6 --metal 0 --metal-right 0 --size 8 --color 0.8 0.6 0.4
PYTHONPATH=$tools python3 - "$here/pbr/paint_n.png" <<'PY'
import math, sys
import make_pbr_gltf as g
t = math.radians(35)
left = (g.code(0), g.code(math.sin(t)), g.code(math.cos(t)))
g.png(sys.argv[1], 8, 8, g.halves(8, left, (g.code(0), g.code(0), g.code(1))))
PY
