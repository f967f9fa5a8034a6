# Fuzz smoke fragment for host/vision/webcam, sourced by .ci/fuzz_smoke.sh ($root, $build, set
# -euo pipefail). Builds webcam_options_fuzz when tests/vision/webcam/fuzz.cmake defined it
# (included from tests/fuzz/CMakeLists.txt, OpenCV installed) and runs it for
# ${PLIANT_WEBCAM_FUZZ_SECONDS:-10} seconds from seeds written here: the option parsers (--roi,
# --grid, --support, --driven, --flow), grid seeding over a 40 x 30 frame or mask, the roles.
if ! grep -q '^PLIANT_WEBCAM_FUZZ_BUILT:INTERNAL=1' "$build/CMakeCache.txt"; then
  echo "webcam fuzzer not configured (fuzz.cmake not included, or OpenCV missing): skipped"
else
  cmake --build "$build" --target webcam_options_fuzz -j "$(nproc)"
  webcam_fuzzer="$build/bin/webcam_options_fuzz"
  [ -x "$webcam_fuzzer" ] || webcam_fuzzer="$(find "$build" -type f -name webcam_options_fuzz -perm -u+x | head -n 1)"
  webcam_corpus="$build/fuzz/webcam-options-corpus"
  webcam_artifacts="$build/fuzz/webcam-options-artifacts"
  mkdir -p "$webcam_corpus" "$webcam_artifacts"
  # Valid options with motions; a mask seed (1200 bytes of alternating inside/outside rows);
  # malformed text in every field.
  printf '2,3,36,24\n3x4\nauto\nauto\ndis\n\000\001\002\003\004\005\006\007\010\011\012\013\014\015\016\017\020' \
    > "$webcam_corpus/seed-roi"
  { printf '0,0,40,30\n2x2\nbottom\n10,5\nfarneback\n\050'; head -c 600 /dev/zero | tr '\0' '\1'; head -c 600 /dev/zero; \
    printf '\100\001\002\003'; } > "$webcam_corpus/seed-mask"
  printf '1,2,-3\n0x8\n1,,2\nnan,1\nlk\n' > "$webcam_corpus/seed-malformed"
  printf '0,0,40,30\n\n3,1\n7\ndis\n\010\377\377\377\377\377\377\377\377' > "$webcam_corpus/seed-ids"
  fuzz_run "$webcam_fuzzer" "$webcam_corpus" \
    -max_total_time="${PLIANT_WEBCAM_FUZZ_SECONDS:-10}" \
    -max_len=4096 \
    -timeout=10 \
    -rss_limit_mb=2048 \
    -artifact_prefix="$webcam_artifacts/" \
    -print_final_stats=1
fi
