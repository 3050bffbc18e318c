#!/bin/sh
# The path tracer against Blender Cycles on issue #40's second model: a glTF panel with an
# alpha-MASK cut-out pattern (16 square holes: light, the background and the panel's shadow go
# through them), metallic-roughness and normal textures, beside a lamp with an emissive texture
# times emissiveFactor and KHR_materials_emissive_strength 8 (tools/make_pbr_gltf.py
# alpha-emissive, bench/scenes/make_pbr_alpha_emissive.sh, run first: the committed model is its
# output), before a diffuse wall and floor, under a sphere light and a grey sky
# (bench/scenes/pbr_alpha_emissive.json).  Cycles reads the glTF file with Blender's own
# importer (tools/cycles_reference.py: the MASK made a step of the alpha at alphaCutoff, the
# importer's emissive factor relinked), three times: as imported ("spec"), with the Principled
# BSDFs' Specular at 0 ("nospec", --no-dielectric-specular: zonetrace renders no specular layer
# over non-metals, and its emissive triangles are lights that reflect nothing), and so with the
# sRGB textures made linear before filtering ("nospec_lin", --linear-filtering: Cycles filters
# 8-bit sRGB codes, zonetrace linear values, which parts between the emissive checker's texels).
# The blocks holding a pixel that sees a light (the lamp) are left out (--mask, zonetrace's
# --level 0 image); the lamp seen directly is compared on its own; then direct light alone.
#
#   bench/cycles_compare_pbr_alpha.sh OUTDIR
#
# Environment: ZT (zonetrace binary, default build/app/zonetrace), BLENDER (default blender),
# SIZE (128x128; square sizes that are multiples of 128 scale the rectangles below), CY_SPP and CY_SEEDS (Cycles: 256 spp for each
# of the seeds "11 ... 18"; "nospec" adds 10 to each, "nospec_lin" 20), ZT_SPP and ZT_SEEDS (1024
# spp for each of the seeds "0 ... 7"), VARIANTS (the Cycles variants, "spec nospec nospec_lin").
# Renders run under nice -n 10.
set -eu
OUT=${1:?usage: bench/cycles_compare_pbr_alpha.sh OUTDIR}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
ZT=${ZT:-$ROOT/build/app/zonetrace}
BLENDER=${BLENDER:-blender}
SIZE=${SIZE:-128x128}
CY_SPP=${CY_SPP:-256}
CY_SEEDS=${CY_SEEDS:-"11 12 13 14 15 16 17 18"}
ZT_SPP=${ZT_SPP:-1024}
ZT_SEEDS=${ZT_SEEDS:-"0 1 2 3 4 5 6 7"}
VARIANTS=${VARIANTS:-"spec nospec nospec_lin"}
SCENE=$ROOT/bench/scenes/pbr_alpha_emissive.json
CYC="nice -n 10 $BLENDER -b -P $ROOT/tools/cycles_reference.py --"
CMP="python3 $ROOT/tools/cycles_compare.py"
"$ROOT/bench/scenes/make_pbr_alpha_emissive.sh"
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
for v in $VARIANTS; do
    opts=""
    add=0
    case $v in
        nospec) opts="--no-dielectric-specular"; add=10 ;;
        nospec_lin) opts="--no-dielectric-specular --linear-filtering"; add=20 ;;
    esac
    cy=""
    for s in $CY_SEEDS; do
        s=$((s + add))
        $CYC "$SCENE" cy_${v}_s$s.pfm --spp "$CY_SPP" --seed $s --size "$SIZE" $opts |
            grep '^cycles_reference'
        cy="$cy cy_${v}_s$s.pfm"
    done
    three cy_$v "$cy"
done

# Regions (128 x 128 pixels): the panel's left half (metal, roughness 128/255, normal tilted 30
# degrees toward +u) and right half (metallic 0, roughness 153/255), holes included; their
# lower parts, where the wall's foot and the floor show through the holes; the back wall above
# the models; left of the panel (its shadow on the wall and floor; the panel's edge is at
# x = 10.8); between the panel and the lamp; the floor in front; below the lamp (the floor and
# wall it lights most); the metal half's top and bottom, and the right half's bottom (the
# holes there show the wall's foot and the floor in the panel's shadow).
R="--rect 12 36 40 92 --rect 40 36 68 92 --rect 12 64 68 92 --rect 0 0 128 28"
R="$R --rect 0 28 8 100 --rect 68 28 84 100 --rect 0 100 128 128 --rect 84 80 124 100"
R="$R --rect 16 36 36 64 --rect 16 64 36 92 --rect 44 64 64 92"
LAMP="--rect 88 48 120 76"
k=$((${SIZE%%x*} / 128))
scale() { # the rectangles' pixel coordinates times k
    for w in $1; do
        case $w in --*) printf '%s ' $w ;; *) printf '%s ' $((w * k)) ;; esac
    done
}
R=$(scale "$R")
LAMP=$(scale "$LAMP")
echo "== zonetrace's own noise: one half of the seeds against the other"
$CMP diff zt_a.pfm zt_b.pfm --mask zt_level0.pfm $R
for v in $VARIANTS; do
    echo "== Cycles' own noise ($v): one half of the seeds against the other"
    $CMP diff cy_${v}_a.pfm cy_${v}_b.pfm --mask zt_level0.pfm $R
    echo "== zonetrace against Cycles ($v; blocks holding a pixel that sees a light left out)"
    $CMP diff zt.pfm cy_$v.pfm --mask zt_level0.pfm $R --worst 10 --map zt_vs_cy_$v.ppm
    echo "== the lamp seen directly ($v; its pixels only, no mask)"
    $CMP diff zt.pfm cy_$v.pfm $LAMP | grep 'rect'
done

# Direct light alone at 64 x 64 (Cycles --bounces 0, 1,024 spp, without the dielectric layer,
# textures filtered linear, against zonetrace --level 1, 4,096 spp), on the scene and on a
# variant written to OUTDIR/diag/white whose panel is white (--color 1 1 1): the metal half's
# difference less its white share is what depends on the metal's colour.
R64="--rect 8 18 18 46 --rect 8 18 18 32 --rect 8 32 18 46 --rect 20 18 34 46"
R64="$R64 --rect 0 0 64 14 --rect 0 50 64 64 --rect 0 14 5 50"
mkdir -p diag/white/pbr_ae
cp "$SCENE" diag/white/
python3 "$ROOT/tools/make_pbr_gltf.py" alpha-emissive diag/white/pbr_ae/alpha_emissive.gltf \
    --color 1 1 1
for d in main white; do
    sc=diag/white/pbr_alpha_emissive.json
    [ $d = main ] && sc=$SCENE
    "$ZT" render "$sc" --size 64x64 --spp 16 --level 0 -o diag/${d}_level0.pfm -q
    nice -n 10 "$ZT" render "$sc" --size 64x64 --spp 4096 --level 1 -o diag/${d}_zt.pfm -q
    $CYC "$sc" diag/${d}_cy.pfm --spp 1024 --size 64x64 --bounces 0 --no-dielectric-specular \
        --linear-filtering | grep '^cycles_reference: wrote'
    echo "== direct light alone ($d), 64 x 64: zonetrace against Cycles (nospec_lin)"
    $CMP diff diag/${d}_zt.pfm diag/${d}_cy.pfm --mask diag/${d}_level0.pfm $R64
done
