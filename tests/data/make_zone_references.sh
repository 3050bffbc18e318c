#!/usr/bin/env bash
# Regenerates the path-traced references that tests/test_zone_accuracy.c
# holds the zone tracer to: the project's Cornell box at 48x48, one image
# per level 0..3 and one for depth 3, converged far below the tolerances
# (the sample counts below; each reference's own noise is printed at the
# end, measured against a second render with another seed).
#
#   tests/data/make_zone_references.sh [BUILD_DIR]
#
# Takes about 15 minutes on two cores.  Run it after a change to the light
# transport model, and commit the images with the figures it prints.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
zt="${1:-$here/../../build}/app/zonetrace"
scene="$here/../../scenes/cornell.json"
out="$here/zone_references"
mkdir -p "$out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
render() { # name, spp, range options
  local name=$1 spp=$2; shift 2
  "$zt" render "$scene" --size 48x48 --spp "$spp" --seed 1 "$@" -o "$out/$name.pfm" -q
  "$zt" render "$scene" --size 48x48 --spp "$((spp / 4))" --seed 2 "$@" -o "$tmp/$name.pfm" -q
  # A render with a quarter of the samples has twice the noise: the
  # reference's own noise is about that difference / sqrt(5).
  local d
  d=$("$zt" compare "$tmp/$name.pfm" "$out/$name.pfm" | sed -n 's/^rel_rmse //p')
  awk -v n="$name" -v s="$spp" -v d="$d" 'BEGIN { printf "%-8s %7d spp  own noise about %.3f%%\n", n, s, 100 * d / sqrt(5) }'
}
render level0 65536 --level 0
render level1 65536 --level 1
render level2 131072 --level 2
render level3 262144 --level 3
render depth3 65536 --depth 3
