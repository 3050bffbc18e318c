#!/bin/sh
# The path tracer against Blender Cycles on the rough Cornell box (scenes/cornell_rough.json),
# and the check of tools/cycles_reference.py on the plain one against the shared reference.
#
#   bench/cycles_compare.sh OUTDIR
#
# Environment: ZT (zonetrace binary, default build/app/zonetrace), BLENDER (default blender),
# SIZE (256x256), CY_SPP and CY_SEEDS (Cycles: 2048 spp for each of the seeds "11 12 13 14 15
# 16"), ZT_SPP and ZT_SEEDS (8192, "0 1 2 3"), CORNELL_SPP (128, per seed 101 and 102),
# REFERENCE (the shared Cornell reference, shared/reference/cornell-cycles-2048spp.pfm).
# Renders run under nice -n 10: about an hour at the defaults on two quiet cores.
set -eu
OUT=${1:?usage: bench/cycles_compare.sh OUTDIR}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
ZT=${ZT:-$ROOT/build/app/zonetrace}
BLENDER=${BLENDER:-blender}
SIZE=${SIZE:-256x256}
CY_SPP=${CY_SPP:-2048}
CY_SEEDS=${CY_SEEDS:-"11 12 13 14 15 16"}
ZT_SPP=${ZT_SPP:-8192}
ZT_SEEDS=${ZT_SEEDS:-"0 1 2 3"}
CORNELL_SPP=${CORNELL_SPP:-128}
REFERENCE=${REFERENCE:-$ROOT/../shared/reference/cornell-cycles-2048spp.pfm}
CORNELL=$(dirname "$REFERENCE")/../scenes/retra/cornell.json
SCENE=$ROOT/scenes/cornell_rough.json
CYC="nice -n 10 $BLENDER -b -P $ROOT/tools/cycles_reference.py --"
CMP="python3 $ROOT/tools/cycles_compare.py"
mkdir -p "$OUT"
cd "$OUT"

# 1. The plain Cornell box, as the reference was made (Cycles' own light sampling), then with
#    the script's exact light sampling (the default).
for mode in asref exact; do
    opts=""
    [ $mode = asref ] && opts="--scale 1 --light-subdivisions 0"
    for s in 101 102; do
        $CYC "$CORNELL" cornell_${mode}_s$s.pfm --spp "$CORNELL_SPP" --seed $s $opts |
            grep '^cycles_reference'
    done
    $CMP mean cornell_$mode.pfm cornell_${mode}_s101.pfm cornell_${mode}_s102.pfm
    echo "== plain Cornell box ($mode) against the reference, and its two seeds"
    $CMP diff cornell_$mode.pfm "$REFERENCE"
    $CMP diff cornell_${mode}_s101.pfm cornell_${mode}_s102.pfm
done

# 2. The rough Cornell box.
"$ZT" render "$SCENE" --size "$SIZE" --spp 64 --level 0 -o zt_level0.pfm -q
cy=""
for s in $CY_SEEDS; do
    $CYC "$SCENE" cy_s$s.pfm --spp "$CY_SPP" --seed $s --size "$SIZE" | grep '^cycles_reference'
    cy="$cy cy_s$s.pfm"
done
zt=""
for s in $ZT_SEEDS; do
    nice -n 10 "$ZT" render "$SCENE" --size "$SIZE" --spp "$ZT_SPP" --seed $s -o zt_s$s.pfm
    zt="$zt zt_s$s.pfm"
done
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
$CMP mean cy.pfm $cy
$CMP mean cy_a.pfm $(half 1 "$cy")
$CMP mean cy_b.pfm $(half 2 "$cy")
$CMP mean zt.pfm $zt
$CMP mean zt_a.pfm $(half 1 "$zt")
$CMP mean zt_b.pfm $(half 2 "$zt")
# Regions (256 x 256 pixels): ceiling, back wall, left (red) wall, right (green) wall, glass
# sphere, mirror sphere, floor in front.
R="--rect 48 0 208 44 --rect 60 50 196 150 --rect 0 40 44 220 --rect 212 40 256 220"
R="$R --rect 57 160 114 216 --rect 130 166 196 232 --rect 0 230 256 256"
echo "== Cycles' own noise: one half of the seeds against the other"
$CMP diff cy_a.pfm cy_b.pfm --mask zt_level0.pfm
echo "== zonetrace's own noise: one half of the seeds against the other"
$CMP diff zt_a.pfm zt_b.pfm --mask zt_level0.pfm
echo "== zonetrace against Cycles (blocks holding a pixel that sees the light left out)"
$CMP diff zt.pfm cy.pfm --mask zt_level0.pfm $R --worst 10 --map zt_vs_cy.ppm
