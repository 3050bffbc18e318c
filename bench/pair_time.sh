#!/usr/bin/env bash
# Times two commands as whole processes, in turn (A B A B ...), and prints
# each one's wall seconds and the ratio A/B as min / median / max over the
# pairs: pairing keeps the ratio meaningful while the machine's speed
# drifts.  Their output is thrown away.
#
#   bench/pair_time.sh RUNS 'COMMAND A' 'COMMAND B'
set -euo pipefail
runs=$1; a=$2; b=$3
now() { date +%s.%N; }
wall() { local t0; t0=$(now); bash -c "$1" >/dev/null 2>&1 || { echo "failed: $1" >&2; exit 1; }
         awk -v a="$(now)" -v b="$t0" 'BEGIN {printf "%.4f", a - b}'; }
wall "$a" >/dev/null; wall "$b" >/dev/null  # warm-up
as=(); bs=(); rs=()
for ((i = 0; i < runs; i++)); do
  ta=$(wall "$a"); tb=$(wall "$b")
  as+=("$ta"); bs+=("$tb"); rs+=("$(awk -v a="$ta" -v b="$tb" 'BEGIN {printf "%.4f", a / b}')")
done
stats() { printf '%s\n' "$@" | sort -g | awk '{v[NR] = $1} END {
  printf "%.3f / %.3f / %.3f", v[1], (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2), v[NR]}'; }
echo "A wall s (min / median / max): $(stats "${as[@]}")"
echo "B wall s (min / median / max): $(stats "${bs[@]}")"
echo "A/B      (min / median / max): $(stats "${rs[@]}")   over $runs pairs"
