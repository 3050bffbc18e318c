#!/usr/bin/env bash
# A walkthrough benchmark: a camera path through a still scene, rendered
# whole by the zone tracer (one Phase One, a Phase Two a frame) and by the
# path tracer at the zone tracer's error, both jobs timed as whole processes.
#
#   bench/walkthrough.sh [--size WxH] [--frames N] [--fps F] [--depth D]
#                        [--ref-spp N] [--probe-spp N] [--path-every K]
#                        [--threads T] [--scene FILE] [--motions FILE]
#                        [--out DIR]
#
# Defaults: 512x512, 50 frames at 24 fps, depth 3, references at 1024 spp,
# the path tracer probed at 32 spp, 2 threads, the engine room with
# bench/walkthrough/engine_walk.json, output in ./walkthrough_out.
# --path-every K times the path job on every K-th frame only (frames 0, K,
# 2K, ... at fps/K: the same camera times) and scales its time by K, for
# when the whole path job is too long to wait for.
#
# The error of a job is the mean, over three frames (the first, the middle
# and the last), of the per-pixel relative RMSE against a converged
# path-traced reference of that frame (bench_reference --motions --time,
# its own noise estimated and taken out: rel_rmse_own).  The path tracer's
# samples per pixel at the zone tracer's error come from a probe at
# --probe-spp, assuming error ~ 1/sqrt(spp); a render of the middle frame
# at that count checks it, and one correction follows the measured slope
# when it is off by more than 10%.  The path job's own three frames give
# its error in the table.  Each job is timed once, the zone job first.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
zt="$root/build/app/zonetrace"
ref_tool="$root/build/bench/bench_reference"
size=512x512; frames=50; fps=24; depth=3; ref_spp=1024; probe_spp=32; threads=2; every=1
scene="$root/scenes/engine_room.json"; motions="$root/bench/walkthrough/engine_walk.json"
out=walkthrough_out
while [ $# -gt 0 ]; do
  case $1 in
    --size) size=$2 ;; --frames) frames=$2 ;; --fps) fps=$2 ;; --depth) depth=$2 ;;
    --ref-spp) ref_spp=$2 ;; --probe-spp) probe_spp=$2 ;; --threads) threads=$2 ;;
    --path-every) every=$2 ;;
    --scene) scene=$2 ;; --motions) motions=$2 ;; --out) out=$2 ;;
    *) sed -n '2,16p' "$0" >&2; exit 1 ;;
  esac
  shift 2
done
[ -x "$zt" ] && [ -x "$ref_tool" ] || { echo "build zonetrace_cli and bench_reference first" >&2; exit 1; }
mkdir -p "$out/zone" "$out/path" "$out/ref" "$out/probe"
log="$out/walkthrough.log"
: > "$log"
say() { printf '%s\n' "$*" | tee -a "$log"; }
calc() { awk "BEGIN { printf \"%.6g\", $1 }"; }
# rel_rmse and rel_rmse_own of IMAGE against frame K's reference.
errs() { "$zt" compare "$1" "$out/ref/ref_$2.pfm" --noise "$out/ref/var_$2.pfm" |
         awk '$1 == "rel_rmse" {a = $2} $1 == "rel_rmse_own" {b = $2} END {print a, b}'; }
mean() { awk '{a += $1; b += $2; n++} END {printf "%.6g %.6g\n", a / n, b / n}'; }
# Times a whole process, its stderr kept in FILE, its wall and cpu seconds
# (user + sys) in FILE.time.
timed() { local f=$1; shift
          /usr/bin/time -f 'wall %e cpu %U %S maxrss_kb %M' -o "$f.time" "$@" 2> "$f" ||
            { cat "$f" >&2; echo "failed: $*" >&2; exit 1; }; }
wall_cpu() { awk '{printf "%s %.2f\n", $2, $4 + $5}' "$1.time"; }

common=(--size "$size" --depth "$depth" --threads "$threads" --motions "$motions")
last=$((frames - 1)); mid=$((last / 2))
keys=(0 "$mid" "$last")
t_of() { awk -v k="$1" -v f="$fps" 'BEGIN { printf "%.17g", k / f }'; }
say "walkthrough: $(basename "$scene") $size, $frames frames at $fps fps, depth $depth, threads $threads"
say "build: $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown), $(date -u '+%Y-%m-%d %H:%M UTC')"
say "load before: $(cut -d' ' -f1-3 /proc/loadavg)"

# 1. The zone job, timed whole; its frames are measured below.
zone_cmd=("$zt" render "$scene" --method zone "${common[@]}" --frames "$frames" --fps "$fps"
          -o "$out/zone/frame_%04d.pfm")
timed "$out/zone.log" "${zone_cmd[@]}"
read -r zone_wall zone_cpu < <(wall_cpu "$out/zone.log")
build_s=$(sed -n 's/.*forest built once for [0-9]* frames* (\([0-9.]*\) s).*/\1/p' "$out/zone.log")
# Frame 1's seconds include the forest; the others are Phase Two alone.
p2=$(sed -n 's/^frame [0-9]*\/[0-9]* .*, \([0-9.]*\) s$/\1/p' "$out/zone.log" |
     awk -v b="$build_s" 'NR == 1 {$1 -= b} {s += $1; if (NR == 1 || $1 < lo) lo = $1; if ($1 > hi) hi = $1}
                          END {printf "%.3f %.3f %.3f", s / NR, lo, hi}')
say "zone job: wall $zone_wall s, cpu $zone_cpu s; Phase One $build_s s; Phase Two per frame mean/min/max $p2 s"

# 2. References of the first, middle and last frames.
for k in "${keys[@]}"; do
  [ -f "$out/ref/ref_$k.pfm" ] && [ -f "$out/ref/var_$k.pfm" ] && continue
  "$ref_tool" "$scene" --motions "$motions" --time "$(t_of "$k")" --size "$size" --depth "$depth" \
      --spp "$ref_spp" --seed 7 --threads "$threads" \
      -o "$out/ref/ref_$k.pfm" --noise "$out/ref/var_$k.pfm" | tee -a "$log"
done

# 3. The zone tracer's error.
for k in "${keys[@]}"; do errs "$out/zone/$(printf 'frame_%04d' "$k").pfm" "$k"; done > "$out/zone.err"
read -r zone_e zone_own < <(mean < "$out/zone.err")
say "zone error per frame (rel_rmse rel_rmse_own): $(tr '\n' ';' < "$out/zone.err")"

# 4. The path tracer's error at the probe count, and the count at the zone error.
path_frame() {  # K SPP OUT [SEED]: frame K alone, as the job with SEED renders it
  "$zt" render "$scene" "${common[@]}" --time "$(t_of "$1")" --spp "$2" --seed "${4:-0}" -o "$3" -q; }
for k in "${keys[@]}"; do
  path_frame "$k" "$probe_spp" "$out/probe/probe_$k.pfm" 2
  errs "$out/probe/probe_$k.pfm" "$k"
done > "$out/probe.err"
read -r probe_e probe_own < <(mean < "$out/probe.err")
spp_eq=$(calc "int($probe_spp * ($probe_own / $zone_own) ^ 2 + 0.5)")
say "path at $probe_spp spp: error $probe_e (own $probe_own); spp_eq = $spp_eq by 1/sqrt(spp)"
mid_zone_own=$(sed -n 2p "$out/zone.err" | cut -d' ' -f2)
mid_probe_own=$(sed -n 2p "$out/probe.err" | cut -d' ' -f2)
check_spp=$spp_eq
t0=$(date +%s.%N)
path_frame "$mid" "$spp_eq" "$out/probe/check_$mid.pfm" 2
frame_s=$(calc "$(date +%s.%N) - $t0")
read -r _ check_own < <(errs "$out/probe/check_$mid.pfm" "$mid")
# The middle frame's error predicted at spp_eq by 1/sqrt(spp), against the measured.
predicted=$(calc "$mid_probe_own * sqrt($probe_spp / $spp_eq)")
off=$(calc "$check_own / $predicted - 1")
say "check, frame $mid at $spp_eq spp: own error $check_own, predicted $predicted ($off off), zone's $mid_zone_own; $frame_s s"
# (An error within the reference's noise reads 0 and leaves no slope.)
if awk -v o="$off" -v c="$check_own" -v p="$mid_probe_own" \
       'BEGIN { exit !((o > 0.1 || o < -0.1) && c > 0 && c < p) }'; then
  slope=$(calc "log($mid_probe_own / $check_own) / log($spp_eq / $probe_spp)")
  spp_eq=$(calc "int($spp_eq * ($check_own / $predicted) ^ (1 / $slope) + 0.5)")
  [ "$spp_eq" -ge 1 ] || spp_eq=1
  say "measured slope spp^-$slope: spp_eq corrected once to $spp_eq"
elif awk -v o="$off" 'BEGIN { exit !(o > 0.1 || o < -0.1) }'; then
  say "no slope to correct by (the check's error is within the reference's noise): spp_eq kept"
fi

# 5. The path job at spp_eq (the default seed), timed whole.
path_frames=$(( (frames + every - 1) / every ))
path_cmd=("$zt" render "$scene" "${common[@]}" --frames "$path_frames" --fps "$(calc "$fps / $every")"
          --spp "$spp_eq" -o "$out/path/frame_%04d.pfm")
say "path job estimated: $(calc "$frame_s * $spp_eq / $check_spp * $path_frames") s; load before it: $(cut -d' ' -f1-3 /proc/loadavg)"
timed "$out/path.log" "${path_cmd[@]}"
read -r path_wall path_cpu < <(wall_cpu "$out/path.log")
if [ "$every" -gt 1 ]; then
  say "path job: $path_frames frames (1 in $every) in wall $path_wall s, cpu $path_cpu s; times $every below"
  path_wall=$(calc "$path_wall * $every"); path_cpu=$(calc "$path_cpu * $every")
fi
# Its error on the reference frames; a frame the job skipped is rendered
# alone, the same bytes as the whole job's frame.
for k in "${keys[@]}"; do
  f="$out/path/$(printf 'frame_%04d' $((k / every))).pfm"
  if [ $((k % every)) -ne 0 ]; then f="$out/path/single_$k.pfm"; path_frame "$k" "$spp_eq" "$f"; fi
  errs "$f" "$k"
done > "$out/path.err"
read -r path_e path_own < <(mean < "$out/path.err")
say "path error per frame (rel_rmse rel_rmse_own): $(tr '\n' ';' < "$out/path.err")"
say "load after: $(cut -d' ' -f1-3 /proc/loadavg)"

# 6. Smoothness: the difference between consecutive zone frames.
for ((k = 1; k < frames; k++)); do
  "$zt" compare "$out/zone/$(printf 'frame_%04d' "$k").pfm" \
      "$out/zone/$(printf 'frame_%04d' $((k - 1))).pfm" | sed -n 's/^rel_rmse //p'
done > "$out/steps.txt"
steps=$(sort -g "$out/steps.txt" | awk '{v[NR] = $1} END {
  m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
  printf "min %.4f median %.4f max %.4f, max/median %.2f, min/median %.2f", v[1], m, v[NR], v[NR] / m, v[1] / m }')
say "consecutive zone frames, rel_rmse: $steps"

say ""
say "| job | wall s | cpu s | per-pixel error, own (mean of frames ${keys[*]}) | with the reference's noise |"
say "|---|---|---|---|---|"
say "| zone: one Phase One ($build_s s), $frames Phase Twos | $zone_wall | $zone_cpu | $(calc "100 * $zone_own")% | $(calc "100 * $zone_e")% |"
say "| path, $spp_eq spp$([ "$every" -gt 1 ] && echo ", $every x the time of 1 frame in $every") | $path_wall | $path_cpu | $(calc "100 * $path_own")% | $(calc "100 * $path_e")% |"
say "| path / zone | $(calc "$path_wall / $zone_wall") | $(calc "$path_cpu / $zone_cpu") | | |"
say ""
say "zone job: ${zone_cmd[*]}"
say "path job: ${path_cmd[*]}"
