#!/bin/sh
# The path tracer against Blender Cycles on a glTF model made by a script: issue #40's check
# that a model with metallic-roughness and normal textures renders as Cycles renders it
# (within 2% over 4 x 4 blocks).  bench/scenes/pbr_square.json holds two squares written by
# tools/make_pbr_gltf.py (bench/scenes/make_pbr_square.sh, run first: the committed models are
# its output) before a diffuse wall and floor, under a sphere light and a grey sky.  Cycles
# reads the glTF files with Blender's own importer (tools/cycles_reference.py), twice: as
# imported, and with the Principled BSDFs' Specular at 0 (--no-dielectric-specular), since
# zonetrace renders no specular layer over non-metals.
#
#   bench/cycles_compare_pbr.sh OUTDIR
#
# Environment: ZT (zonetrace binary, default build/app/zonetrace), BLENDER (default blender),
# SIZE (256x256), CY_SPP and CY_SEEDS (Cycles: 256 spp for each of the seeds "11 ... 30" as
# imported, each seed plus 10 without the dielectric layer), ZT_SPP and ZT_SEEDS (1024 spp for
# each of the seeds "0 ... 15").  Renders run under nice -n 10.
#
# Then direct light alone at 64 x 64 (Cycles --bounces 0, 1024 spp, against zonetrace --level 1,
# 4096 spp; Cycles without the dielectric layer), on the scene and on two variants written to
# OUTDIR/diag: the painted square's normal texture flat ("flat"), and the scene without its
# sky ("nosky"), to tell the normal map's share of a difference from the rest.
set -eu
OUT=${1:?usage: bench/cycles_compare_pbr.sh OUTDIR}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
ZT=${ZT:-$ROOT/build/app/zonetrace}
BLENDER=${BLENDER:-blender}
SIZE=${SIZE:-256x256}
CY_SPP=${CY_SPP:-256}
CY_SEEDS=${CY_SEEDS:-"11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30"}
ZT_SPP=${ZT_SPP:-1024}
ZT_SEEDS=${ZT_SEEDS:-"0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15"}
SCENE=$ROOT/bench/scenes/pbr_square.json
CYC="nice -n 10 $BLENDER -b -P $ROOT/tools/cycles_reference.py --"
CMP="python3 $ROOT/tools/cycles_compare.py"
"$ROOT/bench/scenes/make_pbr_square.sh"
mkdir -p "$OUT"
cd "$OUT"

half() { # half 1 LIST: the first half of the words of LIST; half 2 LIST: the rest
    n=$(echo $2 | wc -w); i=0
    for f in $2; do
        i=$((i + 1))
        if [ $1 = 1 ]; then
            [ $i -le $((n / 2)) ] && printf '%s ' $f
        else
            [ $i -gt $((n / 2)) ] && printf '%s ' $f
        fi
    done
    return 0
}
three() { # three NAME LIST: NAME.pfm, NAME_a.pfm and NAME_b.pfm, the means of LIST and halves
    $CMP mean $1.pfm $2
    $CMP mean $1_a.pfm $(half 1 "$2")
    $CMP mean $1_b.pfm $(half 2 "$2")
}

"$ZT" render "$SCENE" --size "$SIZE" --spp 64 --level 0 -o zt_level0.pfm -q
zt=""
for s in $ZT_SEEDS; do
    nice -n 10 "$ZT" render "$SCENE" --size "$SIZE" --spp "$ZT_SPP" --seed $s -o zt_s$s.pfm -q
    zt="$zt zt_s$s.pfm"
done
three zt "$zt"
for v in spec nospec; do
    opts=""
    [ $v = nospec ] && opts="--no-dielectric-specular"
    cy=""
    for s in $CY_SEEDS; do
        [ $v = nospec ] && s=$((s + 10))
        $CYC "$SCENE" cy_${v}_s$s.pfm --spp "$CY_SPP" --seed $s --size "$SIZE" $opts |
            grep '^cycles_reference'
        cy="$cy cy_${v}_s$s.pfm"
    done
    three cy_$v "$cy"
done

# Regions (256 x 256 pixels, away from the squares' edges and from the texture halves' border,
# where both renderers blend the maps bilinearly): the metal square's left half (metal,
# roughness 128/255, normal tilted 30 degrees toward +u), its right half (white diffuse,
# roughness 0), the painted square's left half (roughness 153/255, normal tilted 35 degrees
# toward the image's top), its right half (roughness 0), the back wall above, the floor below;
# then the metal half's left and right parts and its top and bottom parts, and the floor just
# below each square.
R="--rect 16 76 56 180 --rect 76 76 120 180 --rect 136 76 180 180 --rect 200 76 240 180"
R="$R --rect 0 0 256 64 --rect 0 196 256 256 --rect 16 76 36 180 --rect 36 76 56 180"
R="$R --rect 16 76 56 128 --rect 16 128 56 180 --rect 4 184 124 196 --rect 132 184 252 196"
echo "== zonetrace's own noise: one half of the seeds against the other"
$CMP diff zt_a.pfm zt_b.pfm --mask zt_level0.pfm $R
for v in spec nospec; do
    echo "== Cycles' own noise ($v): one half of the seeds against the other"
    $CMP diff cy_${v}_a.pfm cy_${v}_b.pfm --mask zt_level0.pfm $R
    echo "== zonetrace against Cycles ($v; blocks holding a pixel that sees the light left out)"
    $CMP diff zt.pfm cy_$v.pfm --mask zt_level0.pfm $R --worst 10 --map zt_vs_cy_$v.ppm
done

# Direct light alone, 64 x 64: the scene, the painted square untilted, the scene without sky.
R64="--rect 4 19 14 45 --rect 19 19 30 45 --rect 34 19 45 45 --rect 50 19 60 45"
R64="$R64 --rect 0 0 64 16 --rect 0 49 64 64"
mkdir -p diag/flat/pbr diag/nosky/pbr
cp "$ROOT"/bench/scenes/pbr/* diag/flat/pbr/
cp "$ROOT"/bench/scenes/pbr/* diag/nosky/pbr/
cp "$SCENE" diag/flat/
python3 "$ROOT/tools/make_pbr_gltf.py" diag/flat/pbr/paint.gltf --rough 0.6 --metal 0 \
    --metal-right 0 --size 8 --color 0.8 0.6 0.4
python3 - "$SCENE" diag/nosky/pbr_square.json <<'PY'
import json, sys
doc = json.load(open(sys.argv[1]))
doc["scene"] = [item for item in doc["scene"] if "sky" not in item]
json.dump(doc, open(sys.argv[2], "w"), indent=1)
PY
for d in main flat nosky; do
    sc=diag/$d/pbr_square.json
    [ $d = main ] && sc=$SCENE
    "$ZT" render "$sc" --size 64x64 --spp 16 --level 0 -o diag/${d}_level0.pfm -q
    nice -n 10 "$ZT" render "$sc" --size 64x64 --spp 4096 --level 1 -o diag/${d}_zt.pfm -q
    $CYC "$sc" diag/${d}_cy.pfm --spp 1024 --size 64x64 --bounces 0 --no-dielectric-specular |
        grep '^cycles_reference'
    echo "== direct light alone ($d), 64 x 64: zonetrace against Cycles without the dielectric layer"
    $CMP diff diag/${d}_zt.pfm diag/${d}_cy.pfm --mask diag/${d}_level0.pfm $R64
done
