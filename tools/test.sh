#!/usr/bin/env bash
# Every test: install what is missing, build, run the unit, integration, acceptance and install
# tests, then all but the slow acceptance runs (ctest label) under AddressSanitizer +
# UndefinedBehaviorSanitizer, then the cross builds (tools/cross.sh: the aarch64 tests under qemu,
# the Cortex-M7 firmware with its no-allocator check), then a short libFuzzer smoke run of every
# parser and decoder.
# Usage: bash tools/test.sh
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
bash tools/setup-debian.sh

echo "== release build and tests"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build build -j"$jobs"
ctest --test-dir build -j"$jobs" --output-on-failure

echo "== AddressSanitizer + UndefinedBehaviorSanitizer"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPLIANT_SANITIZE=ON -DPLIANT_BUILD_BENCHMARKS=OFF > /dev/null
cmake --build build-asan -j"$jobs"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan -j"$jobs" --output-on-failure -LE acceptance -E install_consumer

echo "== cross builds: aarch64 under qemu, Cortex-M7 firmware"
bash tools/cross.sh

echo "== libFuzzer smoke run"
# Shorter than the script's defaults, to keep the whole run within CI's time budget; run
# .ci/fuzz_smoke.sh alone for the longer default durations.
PLIANT_FUZZ_SECONDS=${PLIANT_FUZZ_SECONDS:-30} PLIANT_MESH_FUZZ_SECONDS=${PLIANT_MESH_FUZZ_SECONDS:-20} \
  PLIANT_CSV_FUZZ_SECONDS=${PLIANT_CSV_FUZZ_SECONDS:-20} bash .ci/fuzz_smoke.sh
