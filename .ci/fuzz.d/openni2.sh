# Fuzz smoke fragment for drivers/openni2, sourced by .ci/fuzz_smoke.sh ($root, $build, set -euo
# pipefail). Builds openni2_oni_fuzz and openni2_depth_fuzz when tests/fuzz/drivers/openni2.cmake
# defined them (OpenNI2 installed) and runs each for ${PLIANT_OPENNI2_FUZZ_SECONDS:-10} seconds.
# Seeds for the .oni check: a two-frame recording written here (1.0.1.0 headers), the same with
# the older 24-byte record headers (version 1.0.0.9), and the room.oni fixture (libFuzzer keeps
# its first max_len bytes: the header and property records of a real recording). Seeds for the
# depth conversion: layouts as described in tests/fuzz/drivers/openni2_depth_fuzz.cpp.
if ! grep -q '^PLIANT_OPENNI2_LIBRARY_TARGET:INTERNAL=.' "$build/CMakeCache.txt"; then
  echo "openni2 fuzzers not configured (OpenNI2 missing?): skipped"
else
  cmake --build "$build" --target openni2_oni_fuzz openni2_depth_fuzz -j "$(nproc)"
  openni2_seconds="${PLIANT_OPENNI2_FUZZ_SECONDS:-10}"
  le32() { printf '\\x%02x\\x%02x\\x%02x\\x%02x' $(($1 & 255)) $((($1 >> 8) & 255)) $((($1 >> 16) & 255)) $((($1 >> 24) & 255)); }
  le64() { le32 "$1"; le32 0; }
  # record <wide 1|0> <type> <node> <fields bytes (escaped)> <fields length> <payload length>
  oni_record() {
    local header=28
    [ "$1" = 1 ] || header=24
    printf 'NIR\0'
    printf "$(le32 "$2")$(le32 "$3")$(le32 $((header + $5)))$(le32 "$6")"
    if [ "$1" = 1 ]; then printf "$(le64 0)"; else printf "$(le32 0)"; fi
    printf "$4"
    head -c "$6" /dev/zero | tr '\0' '\021'
  }
  oni_tiny() {
    local wide=$1
    printf 'NI10\x01\x00'
    if [ "$wide" = 1 ]; then printf '\x01\x00\x00\x00\x00\x00'; else printf '\x00\x00\x09\x00\x00\x00'; fi
    printf "$(le64 66000)$(le32 1)"
    oni_record "$wide" 12 1 "$(le32 7)Depth1\\x00$(le32 2)NONE$(le32 2)$(le64 0)$(le64 66000)" 39 0
    oni_record "$wide" 9 1 "" 0 0
    oni_record "$wide" 8 1 "$(le32 2)$(le64 66000)" 12 0
    oni_record "$wide" 10 1 "$(le64 33000)$(le32 1)" 12 8
    oni_record "$wide" 10 1 "$(le64 66000)$(le32 2)" 12 8
    oni_record "$wide" 7 1 "" 0 0
    oni_record "$wide" 11 4294967295 "" 0 0
  }
  oni_fuzzer="$build/bin/openni2_oni_fuzz"
  [ -x "$oni_fuzzer" ] || oni_fuzzer="$(find "$build" -type f -name openni2_oni_fuzz -perm -u+x | head -n 1)"
  oni_corpus="$build/fuzz/openni2-oni-corpus"
  oni_artifacts="$build/fuzz/openni2-oni-artifacts"
  mkdir -p "$oni_corpus" "$oni_artifacts"
  oni_tiny 1 > "$oni_corpus/seed-tiny"
  oni_tiny 0 > "$oni_corpus/seed-tiny-narrow"
  cp "$root/tests/data/oni_kinect/room.oni" "$oni_corpus/seed-room"
  fuzz_run "$oni_fuzzer" "$oni_corpus" \
    -max_total_time="$openni2_seconds" \
    -max_len=65536 \
    -timeout=10 \
    -rss_limit_mb=2048 \
    -artifact_prefix="$oni_artifacts/" \
    -print_final_stats=1

  # Layout: width, height (int16), stride (uint16), scale, fx, fy, cx, cy (float), flags (bit 0
  # and 1: intrinsics for the same size; bit 7: output one point short), hfov, vfov (float),
  # then pixels. A 4x3 frame with padding, a 2x2 frame with NaN intrinsics, an empty one.
  depth_fuzzer="$build/bin/openni2_depth_fuzz"
  [ -x "$depth_fuzzer" ] || depth_fuzzer="$(find "$build" -type f -name openni2_depth_fuzz -perm -u+x | head -n 1)"
  depth_corpus="$build/fuzz/openni2-depth-corpus"
  depth_artifacts="$build/fuzz/openni2-depth-artifacts"
  mkdir -p "$depth_corpus" "$depth_artifacts"
  # 0.001 = 0x3a83126f, 300 = 0x43960000, 1.5 = 0x3fc00000, 1.0 = 0x3f800000, 1.0145 ~ 0x3f81db23,
  # 0.7898 ~ 0x3f4a3088, NaN = 0x7fc00000
  printf "\\x04\\x00\\x03\\x00\\x0a\\x00$(le32 0x3a83126f)$(le32 0x43960000)$(le32 0x43960000)$(le32 0x3fc00000)$(le32 0x3f800000)\\x03$(le32 0x3f81db23)$(le32 0x3f4a3088)" > "$depth_corpus/seed-4x3"
  printf '\xe8\x03\x00\x00\xd0\x07\x00\x00\xff\xff\x00\x00\x01\x00\x02\x00\x03\x00\x00\x00\x00\x00\xff\xff\x10\x27\x00\x00\x00\x00\x00\x00' >> "$depth_corpus/seed-4x3"
  printf "\\x02\\x00\\x02\\x00\\x04\\x00$(le32 0x3a83126f)$(le32 0x7fc00000)$(le32 0x43960000)$(le32 0)$(le32 0)\\x83$(le32 0)$(le32 0)\\xe8\\x03\\x00\\x00\\x00\\x00\\xd0\\x07" > "$depth_corpus/seed-nan"
  printf '\x00\x00\x00\x00' > "$depth_corpus/seed-empty"
  fuzz_run "$depth_fuzzer" "$depth_corpus" \
    -max_total_time="$openni2_seconds" \
    -max_len=4096 \
    -timeout=10 \
    -rss_limit_mb=2048 \
    -artifact_prefix="$depth_artifacts/" \
    -print_final_stats=1
fi
