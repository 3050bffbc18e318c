#!/usr/bin/env bash
# The zone tracer's growth with the number of triangles: the Cornell box
# with a UV sphere of N triangles (bench/gen_mesh --plain; radius 60, above
# the short block) at 64x64, default quality.  For each N: Phase One and
# Phase Two seconds, the zones, the process's peak memory, and the error
# against a path-traced reference of the same depth (whose own noise is
# given: two seeds differ by sqrt(2) times it).
#
#   bench/zone_nseries.sh [DEPTH] [REF_SPP] [N...]
#
# Defaults: depth 3, references at 16384 spp, N = 40 180 760 3000 12000
# 50000.  Run from the repository after scripts/setup.sh.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
zt="$here/../build/app/zonetrace"
gen="$here/../build/bench/gen_mesh"
depth=${1:-3}; ref_spp=${2:-16384}
shift $(( $# >= 2 ? 2 : $# ))
ns=("$@")
[ ${#ns[@]} -gt 0 ] || ns=(40 180 760 3000 12000 50000)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# The Cornell box with the sphere added as the scene list's last item (the
# file ends with the list's "]" and the top level's "}", one per line).
scene() {
  {
    sed '$d' "$here/../scenes/cornell.json" | sed '$d'
    printf '    ,{"mesh": {"file": "%s", "transform": {"scale": 60, "translate": [185, 250, 170]},\n' "$1"
    printf '       "material": {"character": {"diffuse": 1, "metallic": 0, "reflecting": 0,\n'
    printf '                                  "refractive": 0}, "color": [0.75, 0.75, 0.75]}}}\n'
    printf '    ]\n}\n'
  } > "$2"
}
err() { "$zt" compare "$1" "$2" | sed -n 's/^rel_rmse //p'; }

printf '%7s %6s %9s %9s %11s %9s %9s %9s\n' N depth phase1_s phase2_s zones peak_MB zone_err ref_noise
for n in "${ns[@]}"; do
  "$gen" --plain "$n" "$tmp/sphere.ply" > "$tmp/gen.log"
  tris=$(sed -n 's/.*: \([0-9]*\) triangles.*/\1/p' "$tmp/gen.log")
  scene "$tmp/sphere.ply" "$tmp/scene.json"
  common=(--size 64x64 --depth "$depth")
  "$zt" render "$tmp/scene.json" "${common[@]}" --spp "$ref_spp" --seed 1 -o "$tmp/ref.pfm" -q
  "$zt" render "$tmp/scene.json" "${common[@]}" --spp "$ref_spp" --seed 2 -o "$tmp/ref2.pfm" -q
  noise=$(awk -v e="$(err "$tmp/ref2.pfm" "$tmp/ref.pfm")" 'BEGIN { printf "%.5f", e / sqrt(2) }')
  /usr/bin/time -f "peak_kb %M" "$zt" render "$tmp/scene.json" "${common[@]}" --method zone \
      -o "$tmp/zone.pfm" -v 2> "$tmp/zone.log"
  p1=$(sed -n 's/^phase one: \([0-9.]*\) s.*/\1/p' "$tmp/zone.log")
  p2=$(sed -n 's/.*phase two: \([0-9.]*\) s.*/\1/p' "$tmp/zone.log")
  zones=$(sed -n 's/.*total \([0-9]*\);.*/\1/p' "$tmp/zone.log")
  peak=$(awk '/^peak_kb/ { printf "%.0f", $2 / 1024 }' "$tmp/zone.log")
  printf '%7s %6s %9s %9s %11s %9s %9.5f %9s\n' "$tris" "$depth" "$p1" "$p2" "${zones:-?}" \
      "$peak" "$(err "$tmp/zone.pfm" "$tmp/ref.pfm")" "$noise"
done
