#!/usr/bin/env bash
# Second command of the README (and what CI runs): install the dependencies,
# build and run the test suite, then build it again with AddressSanitizer and
# UndefinedBehaviorSanitizer and run it once more, then run each fuzz harness
# for a few seconds (fuzz/README.md; long runs: fuzz/run.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="$(nproc)"

scripts/install-deps.sh

echo "== release build and tests"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -j"$jobs"

echo "== sanitizer build (ASan + UBSan) and tests"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DZT_SANITIZE=ON -DZT_BUILD_BENCH=OFF >/dev/null
cmake --build build-asan -j"$jobs"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1"
export LSAN_OPTIONS="suppressions=$(pwd)/scripts/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export ZT_TEST_SANITIZER=1
ctest --test-dir build-asan --output-on-failure -j"$jobs"

echo "== fuzz harnesses (clang, libFuzzer, ASan + UBSan): a few seconds each"
CC=clang cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DZT_FUZZ=ON \
    -DZT_BUILD_BENCH=OFF -DZT_WITH_VIEWER=OFF >/dev/null
cmake --build build-fuzz -j"$jobs"
ctest --test-dir build-fuzz --output-on-failure -j"$jobs"
