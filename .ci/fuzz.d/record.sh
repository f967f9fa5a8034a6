# Fuzz smoke fragment for `pliant record`'s device specs, sourced by .ci/fuzz_smoke.sh ($root,
# $build, set -euo pipefail). Builds record_spec_fuzz when tests/fuzz/cli/record_spec.cmake
# defined it (included from tests/fuzz/CMakeLists.txt) and runs it for
# ${PLIANT_RECORD_FUZZ_SECONDS:-10} seconds from seeds written here. Byte 0 picks the option
# (0 --color, 1 --depth, 2 --ft, 3 --gripper), the rest is the spec.
if ! grep -q '^PLIANT_RECORD_SPEC_FUZZ_BUILT:INTERNAL=1' "$build/CMakeCache.txt"; then
  echo "record_spec_fuzz not configured (tests/fuzz/cli/record_spec.cmake not included): skipped"
else
  cmake --build "$build" --target record_spec_fuzz -j "$(nproc)"
  record_fuzzer="$build/bin/record_spec_fuzz"
  [ -x "$record_fuzzer" ] || record_fuzzer="$(find "$build" -type f -name record_spec_fuzz -perm -u+x | head -n 1)"
  record_corpus="$build/fuzz/record-spec-corpus"
  record_artifacts="$build/fuzz/record-spec-artifacts"
  mkdir -p "$record_corpus" "$record_artifacts"
  # One valid spec of every kind, and malformed ones (missing parts, out-of-range numbers).
  printf '\000v4l2:/dev/video0' > "$record_corpus/seed-v4l2"
  printf '\000video:take 1.avi' > "$record_corpus/seed-video"
  printf '\000images:frames/f_%%04d.png' > "$record_corpus/seed-images"
  printf '\000libcamera:any' > "$record_corpus/seed-libcamera"
  printf '\001openni2:any' > "$record_corpus/seed-openni2"
  printf '\001oni:room.oni' > "$record_corpus/seed-oni"
  printf '\002ati-can:can0@0x20' > "$record_corpus/seed-ati"
  printf '\002robotous-can:can0@0xF0,0xF1,0xF2' > "$record_corpus/seed-robotous"
  printf '\002ft300-rtu:/dev/ttyUSB1@9' > "$record_corpus/seed-ft300-rtu"
  printf '\002ft300-tcp:192.168.1.11:502' > "$record_corpus/seed-ft300-tcp"
  printf '\003robotiq-rtu:/dev/ttyUSB0@247' > "$record_corpus/seed-robotiq-rtu"
  printf '\003robotiq-tcp:127.0.0.1:65535@0' > "$record_corpus/seed-robotiq-tcp"
  printf '\002ati-can:can0@0x80' > "$record_corpus/seed-bad-base"
  printf '\003robotiq-tcp:localhost:0@300' > "$record_corpus/seed-bad-tcp"
  printf '\000v4l2:\n\377' > "$record_corpus/seed-bad-control"
  fuzz_run "$record_fuzzer" "$record_corpus" \
    -max_total_time="${PLIANT_RECORD_FUZZ_SECONDS:-10}" \
    -max_len=4200 \
    -timeout=10 \
    -rss_limit_mb=2048 \
    -artifact_prefix="$record_artifacts/" \
    -print_final_stats=1
fi
