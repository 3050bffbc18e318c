#!/usr/bin/env bash
# Long fuzzing runs: builds the libFuzzer harnesses (clang, ASan + UBSan) in
# build-fuzz, makes the seeds, and runs each harness named (default: all)
# for SECONDS (default 1800), keeping what it learns in
# build-fuzz/fuzz/corpus/HARNESS.  A crash, leak, timeout or undefined
# behaviour stops that harness and leaves its input in
# build-fuzz/fuzz/findings/; after the fix, copy it into
# fuzz/regressions/HARNESS/ so every test build replays it.
# usage: fuzz/run.sh [SECONDS] [HARNESS...]
# ZT_FUZZ_RUNS=N also stops each harness after N executions.  An input that
# takes more than 30 s (ZT_FUZZ_TIMEOUT) counts as a finding: on a loaded
# machine libFuzzer's usual 10 s took inputs of under a second for hangs.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-1800}
shift || true
harnesses=("$@")
[ ${#harnesses[@]} -gt 0 ] || harnesses=(scene motions image forest checkpoint)

CC=clang cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DZT_FUZZ=ON \
    -DZT_BUILD_BENCH=OFF -DZT_WITH_VIEWER=OFF >/dev/null
cmake --build build-fuzz -j"$(nproc)" >/dev/null
fz=build-fuzz/fuzz
sh fuzz/make_seeds.sh build-fuzz/app/zonetrace "$fz/seeds"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"

status=0
for h in "${harnesses[@]}"; do
    case $h in
    scene) seeds=(scenes fuzz/seeds/scene); [ -d ../shared/scenes ] && seeds+=(../shared/scenes) ;;
    motions) seeds=(fuzz/seeds/motions) ;;
    image|forest|checkpoint) seeds=("$fz/seeds/$h") ;;
    *) echo "run.sh: no harness '$h' (scene, motions, image, forest, checkpoint)" >&2; exit 1 ;;
    esac
    [ -d "fuzz/regressions/$h" ] && seeds+=("fuzz/regressions/$h")
    mkdir -p "$fz/corpus/$h" "$fz/findings"
    log="$fz/$h.log"
    echo "== fuzz_$h for ${seconds}s (log: $log)"
    if (cd "$fz" && ./fuzz_"$h" -max_total_time="$seconds" -runs="${ZT_FUZZ_RUNS:--1}" -rss_limit_mb=2048 -timeout="${ZT_FUZZ_TIMEOUT:-30}" \
            -print_final_stats=1 -artifact_prefix=findings/"$h"- corpus/"$h" \
            $(for s in "${seeds[@]}"; do printf '%s ' "$OLDPWD/$s"; done)) >"$log" 2>&1; then
        :
    else
        status=1
        echo "fuzz_$h found a problem: see $log and $fz/findings/"
    fi
    grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$log" || true
    grep -E "DONE" "$log" | tail -1 || true
done
exit $status
