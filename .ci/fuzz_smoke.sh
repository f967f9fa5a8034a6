#!/usr/bin/env bash
# Builds the recording fuzzer (tests/fuzz/recording_fuzz.cpp) with clang and runs it for
# ${PLIANT_FUZZ_SECONDS:-60} seconds from a small seed corpus. Exits non-zero when the build
# fails or the fuzzer finds a crash, a sanitizer error, a leak, a timeout or an out-of-memory.
#
# Environment: PLIANT_FUZZ_SECONDS (default 60), PLIANT_FUZZ_BUILD_DIR (default build-fuzz),
# CXX_FUZZ (default clang++).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${PLIANT_FUZZ_BUILD_DIR:-$root/build-fuzz}"
seconds="${PLIANT_FUZZ_SECONDS:-60}"

cmake -S "$root" -B "$build" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_COMPILER="${CXX_FUZZ:-clang++}" \
  -DPLIANT_BUILD_FUZZERS=ON \
  -DPLIANT_BUILD_TESTS=ON \
  -DPLIANT_BUILD_HOST=OFF \
  -DPLIANT_BUILD_BENCHMARKS=OFF
cmake --build "$build" --target recording_fuzz -j "$(nproc)"

fuzzer="$build/bin/recording_fuzz"
[ -x "$fuzzer" ] || fuzzer="$(find "$build" -type f -name recording_fuzz -perm -u+x | head -n 1)"

# Seeds: recording.json, particles.csv, mesh.vtk, wrench.csv and gripper.csv joined by NULs.
corpus="$build/fuzz/recording-corpus"
artifacts="$build/fuzz/recording-artifacts"
mkdir -p "$corpus" "$artifacts"
json2d='{"format":"pliant-recording","version":1,"dimension":2,"length_unit":"m","particles":{"count":3},"files":{"particles":"particles.csv"}}'
json3d='{"format":"pliant-recording","version":1,"dimension":3,"length_unit":"m","gravity":[0,0,-9.81],"particles":{"count":4,"mass":[1,2,3,4],"fixed":[0],"driven":[3,{"id":2,"from":0.5,"to":1}]},"files":{"particles":"particles.csv","wrench":"wrench.csv","gripper":"gripper.csv","mesh":"mesh.vtk"},"wrench":{"applied_to":[3]},"material":{"poisson_ratio":0.45},"meta":{"object":"foam"},"extra":[1]}'
csv2d='t,id,x,y\n0,0,0,0\n0,1,1,0\n0,2,0,1\n0.1,0,0,0\n0.1,2,nan,1\n'
csv3d='t,id,x,y,z\r\n0,0,0,0,0\r\n0,1,1,0,0\r\n0,2,0,1,0\r\n0.5,3,0,0,1\r\n1,1,1e-3,2.5E2,.5\r\n'
classic='# vtk DataFile Version 3.0\nmesh\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 double\n0 0 0\n1 0 0\n0 1 0\n0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\nCELL_DATA 1\nSCALARS youngs_modulus double 1\nLOOKUP_TABLE default\n50000\n'
offsets='# vtk DataFile Version 5.1\nvtk output\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 float\n0 0 0 1 0 0 0 1 0 0 0 1\nMETADATA\nINFORMATION 0\n\nCELLS 2 4\nOFFSETS vtktypeint64\n0 4\nCONNECTIVITY vtktypeint64\n0 1 2 3\nCELL_TYPES 1\n10\nPOINT_DATA 4\nSCALARS t float\nLOOKUP_TABLE default\n1 2 3 4\n'
wrench='t,fx,fy,fz,tx,ty,tz\n0,1,2,3,0,0,0\n0.5,1,2,3,0,0,1e-9\n'
gripper='t,width,force\n0,0.08,0\n0.5,0.05,12.5\n'
printf '%s\0%b' "$json2d" "$csv2d" > "$corpus/seed-2d"
printf '%s\0%b\0%b\0%b\0%b' "$json3d" "$csv3d" "$classic" "$wrench" "$gripper" > "$corpus/seed-3d-classic"
printf '%s\0%b\0%b' "$json3d" "$csv3d" "$offsets" > "$corpus/seed-3d-offsets"

"$fuzzer" "$corpus" \
  -dict="$root/tests/fuzz/recording_fuzz.dict" \
  -max_total_time="$seconds" \
  -max_len=8192 \
  -timeout=10 \
  -rss_limit_mb=2048 \
  -artifact_prefix="$artifacts/" \
  -print_final_stats=1
