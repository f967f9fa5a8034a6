# Fuzz smoke fragment for drivers/opencv, sourced by .ci/fuzz_smoke.sh ($root, $build, set -euo
# pipefail). Builds opencv_sequence_fuzz when tests/fuzz/drivers/opencv.cmake defined it (OpenCV
# installed) and runs it for ${PLIANT_OPENCV_FUZZ_SECONDS:-10} seconds from seeds written here.
# Input layout: tests/fuzz/drivers/opencv_sequence_fuzz.cpp (byte 0 cuts the rest into a pattern
# and a second name).
if ! grep -q '^PLIANT_DRIVER_OPENCV_BUILT:INTERNAL=1' "$build/CMakeCache.txt"; then
  echo "opencv fuzzer not configured (OpenCV missing?): skipped"
else
  cmake --build "$build" --target opencv_sequence_fuzz -j "$(nproc)"
  opencv_fuzzer="$build/bin/opencv_sequence_fuzz"
  [ -x "$opencv_fuzzer" ] || opencv_fuzzer="$(find "$build" -type f -name opencv_sequence_fuzz -perm -u+x | head -n 1)"
  opencv_corpus="$build/fuzz/opencv-sequence-corpus"
  opencv_artifacts="$build/fuzz/opencv-sequence-artifacts"
  mkdir -p "$opencv_corpus" "$opencv_artifacts"
  # Pattern | second name: frame_%04d.png | frame_10.png; 100%%_%3i.jpg (an escape and space
  # padding) | img_2.JPG; %d_%d.png (two conversions, refused) | notes.txt.
  printf '\x0eframe_%%04d.pngframe_10.png' > "$opencv_corpus/seed-pattern"
  printf '\x0d100%%%%_%%3i.jpgimg_2.JPG' > "$opencv_corpus/seed-escape"
  printf '\x09%%d_%%d.pngnotes.txt' > "$opencv_corpus/seed-two"
  fuzz_run "$opencv_fuzzer" "$opencv_corpus" \
    -max_total_time="${PLIANT_OPENCV_FUZZ_SECONDS:-10}" \
    -max_len=512 \
    -timeout=10 \
    -rss_limit_mb=2048 \
    -artifact_prefix="$opencv_artifacts/" \
    -print_final_stats=1
fi
