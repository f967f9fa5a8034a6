#!/usr/bin/env bash
# Builds the recording fuzzer (tests/fuzz/recording_fuzz.cpp) and the mesh fuzzer
# (tests/fuzz/mesh_fuzz.cpp) with clang and runs them for ${PLIANT_FUZZ_SECONDS:-60} and
# ${PLIANT_MESH_FUZZ_SECONDS:-30} seconds from small seed corpora. Exits non-zero when the build
# fails or a fuzzer finds a crash, a sanitizer error, a leak, a timeout or an out-of-memory.
#
# The compression-test CSV fuzzer (tests/fuzz/compression_csv_fuzz.cpp) follows for
# ${PLIANT_CSV_FUZZ_SECONDS:-30} seconds.
#
# The telemetry decoder fuzzer (tests/fuzz/telemetry_fuzz.cpp) follows for
# ${PLIANT_TELEMETRY_FUZZ_SECONDS:-20} seconds.
#
# The HAL fault-script parser fuzzer (tests/fuzz/fault_script_fuzz.cpp) follows for
# ${PLIANT_FAULT_FUZZ_SECONDS:-15} seconds.
#
# Environment: PLIANT_FUZZ_SECONDS (default 60), PLIANT_MESH_FUZZ_SECONDS (default 30),
# PLIANT_CSV_FUZZ_SECONDS (default 30), PLIANT_TELEMETRY_FUZZ_SECONDS (default 20),
# PLIANT_FUZZ_BUILD_DIR (default build-fuzz), CXX_FUZZ (default clang++), CC_FUZZ (default
# clang: the telemetry codec is C).
#
# The fuzzers run in the background, ${PLIANT_FUZZ_JOBS:-$(nproc)} at a time (each is one process on
# one core), each into build-fuzz/fuzz/logs/<fuzzer>.log; a finished one prints its final stats,
# a failed one the end of its log. The script exits non-zero when any failed.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${PLIANT_FUZZ_BUILD_DIR:-$root/build-fuzz}"
seconds="${PLIANT_FUZZ_SECONDS:-60}"

fuzz_jobs="${PLIANT_FUZZ_JOBS:-$(nproc)}"
fuzz_logs="$build/fuzz/logs"
declare -A fuzz_running=()  # pid -> fuzzer name
fuzz_failed=()
trap 'kill "${!fuzz_running[@]}" 2> /dev/null || true' EXIT

# Waits for one running fuzzer and reports it.
fuzz_reap_one() {
  local pid status=0 name
  wait -n -p pid "${!fuzz_running[@]}" || status=$?
  name=${fuzz_running[$pid]}
  unset "fuzz_running[$pid]"
  if [ "$status" -eq 0 ]; then
    echo "== fuzz $name: passed ($(grep -E '^stat::number_of_executed_units' "$fuzz_logs/$name.log" | tr -d ' '))"
  else
    echo "== fuzz $name: FAILED (exit $status); end of $fuzz_logs/$name.log:"
    tail -n 80 "$fuzz_logs/$name.log"
    fuzz_failed+=("$name")
  fi
}

# fuzz_run FUZZER ARGS...: starts the fuzzer in the background once a slot is free.
fuzz_run() {
  local name
  name=$(basename "$1")
  while [ "${#fuzz_running[@]}" -ge "$fuzz_jobs" ]; do fuzz_reap_one; done
  echo "== fuzz $name: started"
  "$@" > "$fuzz_logs/$name.log" 2>&1 &
  fuzz_running[$!]=$name
}

# Waits for every fuzzer; fails when one did.
fuzz_wait_all() {
  while [ "${#fuzz_running[@]}" -gt 0 ]; do fuzz_reap_one; done
  if [ "${#fuzz_failed[@]}" -gt 0 ]; then
    echo "fuzz smoke: ${#fuzz_failed[@]} fuzzer(s) failed: ${fuzz_failed[*]}" >&2
    return 1
  fi
  echo "fuzz smoke: every fuzzer passed"
}

# -O1 with line tables: libFuzzer's recommended optimisation, file and line in every report, and
# less compile time than -O2 -g.
cmake -S "$root" -B "$build" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" \
  -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" \
  -DCMAKE_CXX_COMPILER="${CXX_FUZZ:-clang++}" \
  -DCMAKE_C_COMPILER="${CC_FUZZ:-clang}" \
  -DPLIANT_BUILD_FUZZERS=ON \
  -DPLIANT_BUILD_TESTS=ON \
  -DPLIANT_BUILD_HOST=OFF \
  -DPLIANT_BUILD_BENCHMARKS=OFF
cmake --build "$build" --target recording_fuzz mesh_fuzz compression_csv_fuzz telemetry_fuzz fault_script_fuzz -j "$(nproc)"
rm -rf "$fuzz_logs"
mkdir -p "$fuzz_logs"

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

fuzz_run "$fuzzer" "$corpus" \
  -dict="$root/tests/fuzz/recording_fuzz.dict" \
  -max_total_time="$seconds" \
  -max_len=8192 \
  -timeout=10 \
  -rss_limit_mb=2048 \
  -artifact_prefix="$artifacts/" \
  -print_final_stats=1

# Mesh readers. The first byte of an input picks the reader (tests/fuzz/mesh_fuzz.cpp): 0 MSH,
# 1 TetGen (.node NUL .ele), 2 OBJ, 3 PLY, 4 STL, 5 all. Seeds: a gmsh file from the examples, a
# binary MSH 4.1, TetGen, OBJ, ASCII and binary PLY, ASCII and binary STL.
mesh_fuzzer="$build/bin/mesh_fuzz"
[ -x "$mesh_fuzzer" ] || mesh_fuzzer="$(find "$build" -type f -name mesh_fuzz -perm -u+x | head -n 1)"
mesh_corpus="$build/fuzz/mesh-corpus"
mesh_artifacts="$build/fuzz/mesh-artifacts"
mkdir -p "$mesh_corpus" "$mesh_artifacts"
# Escape text for one little-endian value (bytes 0-255 only); the outer printf turns it into bytes.
u64() { printf '\\x%02x\\x00\\x00\\x00\\x00\\x00\\x00\\x00' "$1"; }
i32() { printf '\\x%02x\\x00\\x00\\x00' "$1"; }
f64() { if [ "$1" = 1 ]; then printf '\\x00\\x00\\x00\\x00\\x00\\x00\\xf0\\x3f'; else printf '\\x00%.0s' 1 2 3 4 5 6 7 8; fi; }
f32() { if [ "$1" = 1 ]; then printf '\\x00\\x00\\x80\\x3f'; else printf '\\x00%.0s' 1 2 3 4; fi; }
{ printf '\0'; cat "$root/examples/meshes/tetmesh_ipc/bar-6.msh"; } > "$mesh_corpus/seed-msh41"
printf '\0$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n$Elements\n2\n1 2 2 0 1 1 2 3\n2 4 2 0 1 1 2 3 4\n$EndElements\n' \
  > "$mesh_corpus/seed-msh22"
{
  printf '\0$MeshFormat\n4.1 1 8\n'; printf "$(i32 1)"; printf '\n$EndMeshFormat\n$Nodes\n'
  printf "$(u64 1)$(u64 4)$(u64 1)$(u64 4)$(i32 3)$(i32 1)$(i32 0)$(u64 4)"
  printf "$(u64 1)$(u64 2)$(u64 3)$(u64 4)"
  printf "$(f64 0)$(f64 0)$(f64 0)$(f64 1)$(f64 0)$(f64 0)$(f64 0)$(f64 1)$(f64 0)$(f64 0)$(f64 0)$(f64 1)"
  printf '\n$EndNodes\n$Elements\n'
  printf "$(u64 1)$(u64 1)$(u64 1)$(u64 1)$(i32 3)$(i32 1)$(i32 4)$(u64 1)$(u64 1)$(u64 1)$(u64 2)$(u64 3)$(u64 4)"
  printf '\n$EndElements\n'
} > "$mesh_corpus/seed-msh41-binary"
printf '\1# nodes\n5 3 1 1\n0 0 0 0 1.5 1\n1 1 0 0 1.5 1\n2 0 1 0 1.5 0\n3 0 0 1 1.5 1\n4 1 1 1 0 0\n\0# tets\n2 4 1\n0 0 1 2 3 1\n1 1 4 2 3 2\n' \
  > "$mesh_corpus/seed-tetgen"
printf '\2v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvn 0 0 1\nf 1/1/1 3/1/1 2/1/1\nf 1//1 2//1 4//1\nf -4 -1 -2\nf 2 3 4 # quad\n' \
  > "$mesh_corpus/seed-obj"
printf '\3ply\nformat ascii 1.0\ncomment x\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n' \
  > "$mesh_corpus/seed-ply"
{
  printf '\3ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n'
  printf "$(f32 0)$(f32 0)$(f32 0)$(f32 1)$(f32 0)$(f32 0)$(f32 0)$(f32 1)$(f32 0)$(f32 0)$(f32 0)$(f32 1)"
  printf "\\x03$(i32 0)$(i32 2)$(i32 1)\\x03$(i32 0)$(i32 1)$(i32 3)\\x03$(i32 0)$(i32 3)$(i32 2)\\x03$(i32 1)$(i32 2)$(i32 3)"
} > "$mesh_corpus/seed-ply-binary"
printf '\4solid t\nfacet normal 0 0 -1\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid t\n' \
  > "$mesh_corpus/seed-stl"
{
  printf '\4'; printf ' %.0s' $(seq 80); printf "$(i32 1)"
  printf "$(f32 0)$(f32 0)$(f32 1)$(f32 0)$(f32 0)$(f32 0)$(f32 1)$(f32 0)$(f32 0)$(f32 0)$(f32 1)$(f32 0)"
  printf '\0\0'
} > "$mesh_corpus/seed-stl-binary"

fuzz_run "$mesh_fuzzer" "$mesh_corpus" \
  -dict="$root/tests/fuzz/mesh_fuzz.dict" \
  -max_total_time="${PLIANT_MESH_FUZZ_SECONDS:-30}" \
  -max_len=8192 \
  -timeout=10 \
  -rss_limit_mb=2048 \
  -artifact_prefix="$mesh_artifacts/" \
  -print_final_stats=1

# Compression-test CSV parser and converter. Seeds: the head of a phantom test file, and a file
# with other units, columns in another order, CRLF line endings and a byte-order mark.
csv_fuzzer="$build/bin/compression_csv_fuzz"
[ -x "$csv_fuzzer" ] || csv_fuzzer="$(find "$build" -type f -name compression_csv_fuzz -perm -u+x | head -n 1)"
csv_corpus="$build/fuzz/compression-csv-corpus"
csv_artifacts="$build/fuzz/compression-csv-artifacts"
mkdir -p "$csv_corpus" "$csv_artifacts"
head -n 40 "$root/examples/phantom_compression/source/EF10_0T_B5.csv" > "$csv_corpus/seed-phantom"
printf '\357\273\277Sample: cyl-7;\r\nDiameter (mm): 50\r\nheight: 0.03 m\r\nSpeed: 0.5 mm/s\r\nLoad cell: 1kN\r\nTime (ms),Load (kN),Compression (m),Note,True Stress (MPa)\r\n0,0,0,a,0\r\n500,0.002,0.001,b,0.1\r\n1000,0.004,0.002,c,0.2\r\n' \
  > "$csv_corpus/seed-units"

fuzz_run "$csv_fuzzer" "$csv_corpus" \
  -max_total_time="${PLIANT_CSV_FUZZ_SECONDS:-30}" \
  -max_len=8192 \
  -timeout=10 \
  -rss_limit_mb=2048 \
  -artifact_prefix="$csv_artifacts/" \
  -print_final_stats=1

# Telemetry streaming decoder. Byte 0 of an input picks how the rest is split into pieces
# (tests/fuzz/telemetry_fuzz.cpp). Seeds (made with the codec's encoder): every message type in
# one piece; two 3D particle chunks after a short garbage frame, an unknown type and a version-2
# packet, in 1..64-byte pieces; a counters message, a verdict with a flipped bit and a cut
# estimate.
telemetry_fuzzer="$build/bin/telemetry_fuzz"
[ -x "$telemetry_fuzzer" ] || telemetry_fuzzer="$(find "$build" -type f -name telemetry_fuzz -perm -u+x | head -n 1)"
telemetry_corpus="$build/fuzz/telemetry-corpus"
telemetry_artifacts="$build/fuzz/telemetry-artifacts"
mkdir -p "$telemetry_corpus" "$telemetry_artifacts"
printf '\x00\x03\x01\x01\x01\x03\xe8\x03\x01\x01\x01\x01\x01\x01\x01\x01\x01\x01\x01\x03\xd8\x3f\x01\x01\x01\x01\x01\x0e\xb0\x3f\x61\x32\x55\x30\x2a\xa9\x23\x3f\x40\xe2\x01\x04\x03\x2f\xdb\x00\x04\x01\x02\x01\x03\xd0\x07\x01\x01\x01\x01\x01\x05\x01\x0e\x01\x04\x02\x50\x01\x02\x01\x01\x01\x05\x6f\x12\x83\x3b\x01\x07\xf0\x40\xcd\xcc\x4c\x3d\x01\x13\xe0\x40\x8f\xc2\x75\x3d\x42\x60\x65\x3b\xe7\xfb\x29\x3d\xcd\xcc\xdc\x40\x01\x03\x80\x3e\x01\x01\x04\x3f\xe2\xd9\x00\x04\x01\x03\x02\x03\xb8\x0b\x01\x01\x01\x01\x01\x01\x01\x01\x01\x02\x02\x02\x06\x01\x01\x02\x06\x01\x01\x01\x01\x05\x6f\x12\x83\x3a\x09\x0a\xd7\x23\x3c\x58\x39\x34\x3c\x09\x0a\xd7\xa3\x3c\x31\x08\xac\x3c\x12\x8f\xc2\xf5\x3c\xb6\xf3\xfd\x3c\x01\x0a\xd7\x23\x3d\x9d\xef\x27\x3d\x0c\xcc\xcc\x4c\x3d\x5f\xe5\x50\x3d\x02\xeb\xc4\x00\x04\x01\x04\x03\x03\xa0\x0f\x01\x01\x01\x01\x01\x02\x02\x02\x08\x03\xe8\x03\x01\x04\x92\x10\x07\x01\x01\x03\xc0\xe0\x00' > "$telemetry_corpus/seed-all-types"
printf '\x07\x03\x41\x42\x00\x04\x01\x03\x04\x03\x88\x13\x01\x01\x01\x01\x01\x02\x01\x01\x01\x02\x03\x02\x0c\x01\x01\x02\x04\x0d\x6f\x12\x03\xba\x6f\x12\x03\x3a\xa6\x9b\xc4\x3a\x0d\xe3\xa5\x1b\x3c\x31\x08\x2c\x3c\x7f\x6a\x3c\x3c\x0d\x77\xbe\x9f\x3c\x9e\xef\xa7\x3c\xc5\x20\xb0\x3c\x10\xfc\xa9\xf1\x3c\x23\xdb\xf9\x3c\x24\x06\x01\x3d\x01\x3d\x9c\x00\x04\x01\x03\x05\x03\x88\x13\x01\x01\x01\x01\x01\x02\x01\x01\x01\x02\x03\x02\x0c\x02\x04\x02\x04\x0d\xc0\xca\x21\x3d\x53\xe3\x25\x3d\xe7\xfb\x29\x3d\x1a\x82\xc0\x4a\x3d\x15\xd9\x4e\x3d\xa9\xf1\x52\x3d\x02\x45\xb6\x73\x3d\xd8\xce\x77\x3d\x6c\xe7\x7b\x3d\x0d\x04\x56\x8e\x3d\x4e\x62\x90\x3d\x97\x6e\x92\x3d\x03\x44\x4d\x00\x04\x01\x03\x06\x03\x88\x13\x01\x01\x01\x01\x01\x02\x01\x01\x01\x02\x03\x02\x0c\x02\x08\x02\x04\x0d\xe5\xd0\xa2\x3d\x2f\xdd\xa4\x3d\x78\xe9\xa6\x3d\x0d\xc6\x4b\xb7\x3d\x10\x58\xb9\x3d\x59\x64\xbb\x3d\x1a\xa7\xc6\xcb\x3d\xf1\xd2\xcd\x3d\x3a\xdf\xcf\x3d\x01\x89\x41\xe0\x3d\xd3\x4d\xe2\x3d\x1c\x5a\xe4\x3d\x03\xbe\xfe\x00\x04\x01\x09\x28\x03\xe8\x03\x01\x01\x01\x01\x01\x06\x01\x02\x03\x72\x43\x00\x04\x02\x01\x29\x03\xe8\x03\x01\x01\x01\x01\x01\x20\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\x22\xf2\x4e\x00' > "$telemetry_corpus/seed-chunks-garbage"
printf '\x01\x04\x01\x04\x07\x03\x70\x17\x01\x01\x01\x01\x01\x02\x03\x02\x01\x02\x01\x01\x01\x02\x02\x02\x02\x01\x01\x02\x03\x02\x03\x01\x01\x03\x71\x27\x00\x04\x01\x02\x08\x03\x58\x1b\x01\x01\x01\x01\x01\x05\x01\x0e\x01\x04\x02\x50\x01\x01\x01\x01\x01\x05\x6f\x12\x83\x3b\x01\x07\xf0\x40\xcd\xcc\x4c\x3d\x01\x13\xe0\x40\x8f\xc2\x75\x3d\x42\x60\x65\x3b\xe7\xfb\x29\x3d\xcd\xcc\xdc\x40\x01\x03\x80\x3e\x01\x01\x04\x3f\x7d\xd1\x00\x04\x01\x01\x09\x03\x40\x1f\x01\x01\x01\x01\x01\x01\x01\x01\x01\x01\x01\x03\xd8\x3f\x01\x01\x01\x01\x01\x0e\xb0\x3f\x61\x32\x55\x30\x2a\xa9\x23\x3f\x40' > "$telemetry_corpus/seed-damaged"

fuzz_run "$telemetry_fuzzer" "$telemetry_corpus" \
  -dict="$root/tests/fuzz/telemetry_fuzz.dict" \
  -max_total_time="${PLIANT_TELEMETRY_FUZZ_SECONDS:-20}" \
  -max_len=8192 \
  -timeout=10 \
  -rss_limit_mb=2048 \
  -artifact_prefix="$telemetry_artifacts/" \
  -print_final_stats=1

# HAL fault scripts (one event per line: t_s kind device duration_s [value]). Seeds: every kind
# on a device that has it, comments, CRLF, hex fault bits; and a malformed script.
fault_fuzzer="$build/bin/fault_script_fuzz"
[ -x "$fault_fuzzer" ] || fault_fuzzer="$(find "$build" -type f -name fault_script_fuzz -perm -u+x | head -n 1)"
fault_corpus="$build/fuzz/fault-script-corpus"
fault_artifacts="$build/fuzz/fault-script-artifacts"
mkdir -p "$fault_corpus" "$fault_artifacts"
printf '# faults\n1.2 timeout gripper 0.05\r\n1.5\tbus_off ft 0.02 # CAN\n2 fault_bits gripper 0.1 0x0e00\n2.5 fault_bits ft 0.1 32\n3 stamp_jump observer 0.2 -0.25\n3.5 occlude observer 1e-1 0.5\n4 nan depth 0.1\n4 drop color 0.1\n5 freeze_data observer 0.1\n5 freeze_stamp ft 0.1\n6 disconnect gripper 1\n' \
  > "$fault_corpus/seed-kinds"
printf '1 drop gripper\nx nan ft 1\n1 bus_off gripper 1\n1 occlude observer 0.1 2\n' > "$fault_corpus/seed-malformed"

fuzz_run "$fault_fuzzer" "$fault_corpus" \
  -max_total_time="${PLIANT_FAULT_FUZZ_SECONDS:-15}" \
  -max_len=4096 \
  -timeout=10 \
  -rss_limit_mb=2048 \
  -artifact_prefix="$fault_artifacts/" \
  -print_final_stats=1

# Driver decoder fuzzers: each .ci/fuzz.d/<driver>.sh builds its targets in "$build" (when the
# driver's library is installed, i.e. tests/fuzz/drivers/<driver>.cmake defined them) and runs them
# from seeds it writes, with the same failure rules. They see $root, $build and this shell's
# options (set -euo pipefail).
shopt -s nullglob
for fragment in "$root"/.ci/fuzz.d/*.sh; do
  echo "== fuzz smoke: $(basename "$fragment")"
  # shellcheck source=/dev/null
  source "$fragment"
done
fuzz_wait_all
