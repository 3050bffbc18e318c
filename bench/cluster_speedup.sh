#!/usr/bin/env bash
# Speed-up of a render split over MPI processes (docs/cluster.md), on this
# machine, one thread per process: 2 processes against 1, timed in turn
# (bench/pair_time.sh), for
#   the path tracer: the Cornell box, 512x512, 64 spp;
#   the zone tracer's Phase One: the Cornell box at depth 4, quality 3,
#     128x128, where Phase One is 95% of the work (its seconds as rank 0
#     reports them, and the whole job's wall time).
# Each job's image is compared with one process's: the same bytes.
#
#   bench/cluster_speedup.sh [RUNS]      (default 5)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
zt="$here/../build/app/zonetrace"
scene="$here/../scenes/cornell.json"
runs=${1:-5}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none
# mpirun's default binding: each process on a core of its own (unbound,
# two processes here waited over a second of five for each other).
mpi="mpirun --oversubscribe"

path="render $scene --spp 64 --threads 1 -q"
echo "== path tracer, 512x512, 64 spp: A = 2 processes, B = 1 process (mpirun -n 1)"
"$here/pair_time.sh" "$runs" "$mpi -n 2 $zt $path -o $tmp/p2.pfm" "$mpi -n 1 $zt $path -o $tmp/p1.pfm"
cmp "$tmp/p1.pfm" "$tmp/p2.pfm" && echo "images: the same bytes"
echo "   B' = 1 process without mpirun: A/B'"
"$here/pair_time.sh" "$runs" "$mpi -n 2 $zt $path -o $tmp/p2.pfm" "$zt $path -o $tmp/p0.pfm" | tail -1

zone="render $scene --method zone --depth 4 --quality 3 --size 128x128 --threads 1 -v"
echo "== zone tracer, depth 4, quality 3, 128x128: Phase One seconds (rank 0), $runs runs each, in turn"
for ((i = 0; i < runs; i++)); do
  for n in 1 2; do
    $mpi -n $n "$zt" $zone -o "$tmp/z$n.pfm" 2> "$tmp/log"
    sed -n "s/^phase one: \([0-9.]*\) s.*/\1/p" "$tmp/log" >> "$tmp/phase1_$n"
    sed -n "s/^exchanges between the \([0-9]*\) processes: .*, \([0-9.]*\) MiB, \([0-9.]*\) s in them.*/\2 \3/p" \
      "$tmp/log" >> "$tmp/exchanges_$n"
  done
done
cmp "$tmp/z1.pfm" "$tmp/z2.pfm" && echo "images: the same bytes"
for n in 1 2; do
  printf '%d process(es): Phase One s (min / median / max): ' $n
  sort -g "$tmp/phase1_$n" | awk '{v[NR] = $1} END {printf "%.3f / %.3f / %.3f\n", v[1], v[int((NR + 1) / 2)], v[NR]}'
done
echo "2 processes' exchanges (MiB, seconds in them on process 0): $(head -1 "$tmp/exchanges_2")"
echo "   whole job, A = 2 processes, B = 1 process:"
"$here/pair_time.sh" "$runs" "$mpi -n 2 $zt ${zone/ -v/ -q} -o $tmp/z2.pfm" "$mpi -n 1 $zt ${zone/ -v/ -q} -o $tmp/z1.pfm"
