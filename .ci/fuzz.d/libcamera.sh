# Fuzz smoke fragment for drivers/libcamera, sourced by .ci/fuzz_smoke.sh ($root, $build, set -euo
# pipefail). Builds libcamera_conversion_fuzz when tests/fuzz/drivers/libcamera.cmake defined it
# (libcamera installed) and runs it for ${PLIANT_LIBCAMERA_FUZZ_SECONDS:-10} seconds from seeds
# written here. Input layout: tests/fuzz/drivers/libcamera_conversion_fuzz.cpp (8 header bytes:
# format, output, width-1, height-1, stride padding, flags, bytes used LE; then the buffer).
if ! grep -q '^PLIANT_DRIVER_LIBCAMERA_BUILT:INTERNAL=1' "$build/CMakeCache.txt"; then
  echo "libcamera fuzzer not configured (libcamera missing?): skipped"
else
  cmake --build "$build" --target libcamera_conversion_fuzz -j "$(nproc)"
  libcamera_fuzzer="$build/bin/libcamera_conversion_fuzz"
  [ -x "$libcamera_fuzzer" ] || libcamera_fuzzer="$(find "$build" -type f -name libcamera_conversion_fuzz -perm -u+x | head -n 1)"
  libcamera_corpus="$build/fuzz/libcamera-conversion-corpus"
  libcamera_artifacts="$build/fuzz/libcamera-conversion-artifacts"
  mkdir -p "$libcamera_corpus" "$libcamera_artifacts"
  # n deterministic bytes (a spread of values, so YUV and RGB paths see more than one level).
  libcamera_bytes() { local i; for ((i = 0; i < $1; ++i)); do printf "\\x$(printf %02x $(((i * 37 + 11) % 256)))"; done; }
  # YUYV 8x4 to RGB, stride 20, full range; NV12 4x2 in two planes to BGR (BT.709); RGB888 3x3 to
  # mono with padded rows; XBGR8888 2x2 in one plane with bytes-used one row short; NV21 4x2 in
  # one plane, a failed buffer.
  { printf '\x04\x00\x07\x03\x04\x01\x00\x00'; printf "$(libcamera_bytes 80)"; } > "$libcamera_corpus/seed-yuyv"
  { printf '\x06\x01\x03\x01\x00\x06\x00\x00'; printf '\x10\x20\x30\x40\x50\x60\x70\x80\x60\xa0\x90\x70'; } > "$libcamera_corpus/seed-nv12"
  { printf '\x00\x02\x02\x02\x03\x00\x00\x00'; printf "$(libcamera_bytes 36)"; } > "$libcamera_corpus/seed-rgb888"
  { printf '\x03\x00\x01\x01\x00\x00\x08\x00'; printf "$(libcamera_bytes 16)"; } > "$libcamera_corpus/seed-xbgr-short"
  { printf '\x07\x00\x03\x01\x00\x08\x00\x00'; printf "$(libcamera_bytes 12)"; } > "$libcamera_corpus/seed-nv21-error"
  fuzz_run "$libcamera_fuzzer" "$libcamera_corpus" \
    -max_total_time="${PLIANT_LIBCAMERA_FUZZ_SECONDS:-10}" \
    -max_len=20000 \
    -timeout=10 \
    -rss_limit_mb=2048 \
    -artifact_prefix="$libcamera_artifacts/" \
    -print_final_stats=1
fi
