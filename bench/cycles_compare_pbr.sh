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
# SIZE (256x256), CY_SPP and CY_SEEDS (Cycles, each variant: 1024 spp for each of the seeds
# "11 12"), ZT_SPP and ZT_SEEDS (2048, "0 1 2 3").  Renders run under nice -n 10.
set -eu
OUT=${1:?usage: bench/cycles_compare_pbr.sh OUTDIR}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
ZT=${ZT:-$ROOT/build/app/zonetrace}
BLENDER=${BLENDER:-blender}
SIZE=${SIZE:-256x256}
CY_SPP=${CY_SPP:-1024}
CY_SEEDS=${CY_SEEDS:-"11 12"}
ZT_SPP=${ZT_SPP:-2048}
ZT_SEEDS=${ZT_SEEDS:-"0 1 2 3"}
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
# toward the image's top), its right half (roughness 0), the back wall above, the floor below.
R="--rect 16 76 56 180 --rect 76 76 120 180 --rect 136 76 180 180 --rect 200 76 240 180"
R="$R --rect 0 0 256 64 --rect 0 196 256 256"
echo "== zonetrace's own noise: one half of the seeds against the other"
$CMP diff zt_a.pfm zt_b.pfm --mask zt_level0.pfm $R
for v in spec nospec; do
    echo "== Cycles' own noise ($v): one half of the seeds against the other"
    $CMP diff cy_${v}_a.pfm cy_${v}_b.pfm --mask zt_level0.pfm $R
    echo "== zonetrace against Cycles ($v; blocks holding a pixel that sees the light left out)"
    $CMP diff zt.pfm cy_$v.pfm --mask zt_level0.pfm $R --worst 10 --map zt_vs_cy_$v.ppm
done
