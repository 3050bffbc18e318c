#!/usr/bin/env bash
# Zone tracer benchmark: for each scene, Phase One and Phase Two times of the
# zone tracer, its error against a converged path-traced reference of the
# same depth, and the equal-error speedup: the time the path tracer needs
# to reach the zone image's error (same reference, another seed), divided by
# the zone tracer's time.
#
#   bench/bench_zone.sh [SIZE] [DEPTH] [REF_SPP] SCENE...
#
# Defaults: 128 pixels square, depth 3, reference at 4096 spp.  Run from the
# repository after scripts/setup.sh; figures go to stdout.
set -euo pipefail
zt="$(dirname "$0")/../build/app/zonetrace"
size=${1:-128}; depth=${2:-3}; ref_spp=${3:-4096}
shift $(( $# >= 3 ? 3 : $# ))
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=("$(dirname "$0")/../scenes/cornell.json")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

secs() { sed -n 's/.* in \([0-9.]*\) s[ :].*/\1/p' "$1"; }
err() { "$zt" compare "$1" "$2" | sed -n 's/^rel_rmse //p'; }

printf '%-28s %9s %9s %9s %10s %10s %9s\n' scene phase1_s phase2_s zone_s zone_err path_s speedup
for scene in "${scenes[@]}"; do
  name=$(basename "$scene" .json)
  "$zt" render "$scene" --size "${size}x$size" --depth "$depth" --spp "$ref_spp" \
      --seed 1 -o "$tmp/ref.pfm" -q
  "$zt" render "$scene" --method zone --size "${size}x$size" --depth "$depth" \
      -o "$tmp/zone.pfm" -v 2> "$tmp/zone.log"
  p1=$(sed -n 's/^phase one: \([0-9.]*\) s.*/\1/p' "$tmp/zone.log")
  p2=$(sed -n 's/.*phase two: \([0-9.]*\) s.*/\1/p' "$tmp/zone.log")
  zt_s=$(secs "$tmp/zone.log")
  zerr=$(err "$tmp/zone.pfm" "$tmp/ref.pfm")
  # The path tracer's error against the same reference, doubling the
  # samples until it is at or below the zone tracer's.
  path_s=""
  for spp in 1 2 4 8 16 32 64 128 256 512 1024 2048 4096; do
    "$zt" render "$scene" --size "${size}x$size" --depth "$depth" --spp "$spp" \
        --seed 2 -o "$tmp/path.pfm" 2> "$tmp/path.log"
    perr=$(err "$tmp/path.pfm" "$tmp/ref.pfm")
    if awk -v a="$perr" -v b="$zerr" 'BEGIN { exit !(a <= b) }'; then
      path_s=$(secs "$tmp/path.log"); break
    fi
  done
  if [ -z "$path_s" ]; then path_s=">$(secs "$tmp/path.log")"; speed="-"
  else speed=$(awk -v a="$path_s" -v b="$zt_s" 'BEGIN { printf "%.2f", a / b }'); fi
  printf '%-28s %9s %9s %9s %10.5f %10s %9s\n' "$name" "$p1" "$p2" "$zt_s" "$zerr" "$path_s" "$speed"
done
