#!/bin/sh
# Seeds for the harnesses that read files the program writes: the forest
# of fuzz/forest_scene.json (depth 2, quality 0, as fuzz_forest.c loads it),
# a checkpoint of it (8 x 8, depth 2, 2 samples, as fuzz_checkpoint.c
# resumes it) and a small image in each format the readers know.
# usage: make_seeds.sh ZONETRACE OUTDIR
set -eu
zt=$1 out=$2
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out/forest" "$out/image" "$out/checkpoint"
"$zt" render "$here/forest_scene.json" --method zone --depth 2 --quality 0 --threads 1 \
    --save-forest "$out/forest/seed.ztf" -o "$out/image/seed.pfm" -q
"$zt" render "$here/forest_scene.json" --size 8x8 --spp 2 --depth 2 --threads 1 \
    --checkpoint "$out/checkpoint/seed.ckpt" -o "$out/image/seed8.pfm" -q
for ext in png ppm exr; do
    "$zt" render "$here/forest_scene.json" --size 6x4 --spp 1 -o "$out/image/seed.$ext" -q
done
