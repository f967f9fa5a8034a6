#!/usr/bin/env bash
# The main job: install what is missing, build, estimate msm_beta on every bundled example,
# refine Young's modulus with the FEM on the three real silicone compression tests, and diagnose
# two presses made by a simulator that is not ours (one with an effect, one without), writing
# their HTML reports to build/diagnose/.
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
for recording in examples/diagnose/*/; do
  [ -f "${recording}recording.json" ] || continue
  name="$(basename "$recording")"
  echo
  build/bin/pliant diagnose "${recording%/}" -q --json "build/diagnose/${name}.json" --report "build/diagnose/${name}"
done
