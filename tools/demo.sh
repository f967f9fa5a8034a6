#!/usr/bin/env bash
# The main job: install what is missing, build, estimate msm_beta on every bundled example, and
# refine Young's modulus with the FEM on the three real silicone compression tests.
# Usage: bash tools/demo.sh
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup-debian.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPLIANT_BUILD_TESTS=OFF -DPLIANT_BUILD_BENCHMARKS=OFF > build-configure.log
cmake --build build -j"$(nproc)" --target pliant
rm -f build-configure.log
for recording in examples/*/; do
  [ -f "${recording}recording.json" ] || continue
  echo
  build/bin/pliant estimate "${recording%/}" --json "build/$(basename "$recording").estimate.json"
done
for recording in examples/phantom_compression/*/; do
  [ -f "${recording}recording.json" ] || continue
  echo
  build/bin/pliant refine "${recording%/}" --json "build/$(basename "$recording").material.json"
done
