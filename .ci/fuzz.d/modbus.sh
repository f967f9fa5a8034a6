# Fuzz smoke fragment for drivers/modbus, sourced by .ci/fuzz_smoke.sh ($root, $build, set -euo
# pipefail). Builds the two targets when tests/fuzz/drivers/modbus.cmake defined them (libmodbus
# installed) and runs each for ${PLIANT_MODBUS_FUZZ_SECONDS:-10} seconds from seeds written here.
#   modbus_robotiq_fuzz        Robotiq 2F status/command registers, scaling, FT 300 registers
#   modbus_ft300_stream_fuzz   FT 300 stream parser (byte 0 picks the piece size)
if ! grep -q '^PLIANT_LIBMODBUS_FOUND:INTERNAL=1' "$build/CMakeCache.txt"; then
  echo "modbus fuzzers not configured (libmodbus missing?): skipped"
else
  cmake --build "$build" --target modbus_robotiq_fuzz modbus_ft300_stream_fuzz -j "$(nproc)"
  modbus_seconds="${PLIANT_MODBUS_FUZZ_SECONDS:-10}"

  # Robotiq: the manual's example status "B9 00 00 FF BD 00", a move command, FT registers, a
  # 2F-85 scaling (doubles little-endian) with a width/speed/force, and open/closed bytes; plus
  # an all-ones input (faults, reserved bits, NaN doubles).
  robotiq_fuzzer="$build/bin/modbus_robotiq_fuzz"
  [ -x "$robotiq_fuzzer" ] || robotiq_fuzzer="$(find "$build" -type f -name modbus_robotiq_fuzz -perm -u+x | head -n 1)"
  robotiq_corpus="$build/fuzz/modbus-robotiq-corpus"
  robotiq_artifacts="$build/fuzz/modbus-robotiq-artifacts"
  mkdir -p "$robotiq_corpus" "$robotiq_artifacts"
  printf '\xb9\x00\x00\xff\xbd\x00\x09\x00\x00\x80\xff\x40\x00\x64\xff\x9c\x07\xd0\x03\xe8\xfc\x18\x7f\xff' > "$robotiq_corpus/seed-manual"
  # 0.085, 0.02, 0.15, 20, 235, width 0.04, speed 0.1, force 50, bytes 3 and 230
  printf '\xc3\xf5\x28\x5c\x8f\xc2\xb5\x3f\x7b\x14\xae\x47\xe1\x7a\x94\x3f\x33\x33\x33\x33\x33\x33\xc3\x3f' >> "$robotiq_corpus/seed-manual"
  printf '\x00\x00\x00\x00\x00\x00\x34\x40\x00\x00\x00\x00\x00\x60\x6d\x40\x7b\x14\xae\x47\xe1\x7a\xa4\x3f' >> "$robotiq_corpus/seed-manual"
  printf '\x9a\x99\x99\x99\x99\x99\xb9\x3f\x00\x00\x00\x00\x00\x00\x49\x40\x03\xe6' >> "$robotiq_corpus/seed-manual"
  head -c 90 /dev/zero | tr '\0' '\377' > "$robotiq_corpus/seed-ones"
  fuzz_run "$robotiq_fuzzer" "$robotiq_corpus" \
    -max_total_time="$modbus_seconds" \
    -max_len=256 \
    -timeout=10 \
    -rss_limit_mb=2048 \
    -artifact_prefix="$robotiq_artifacts/" \
    -print_final_stats=1

  # FT 300 stream: two clean frames in 5-byte pieces; garbage, a frame cut short, a damaged
  # frame and a clean one in one piece; the jam signal.
  stream_fuzzer="$build/bin/modbus_ft300_stream_fuzz"
  [ -x "$stream_fuzzer" ] || stream_fuzzer="$(find "$build" -type f -name modbus_ft300_stream_fuzz -perm -u+x | head -n 1)"
  stream_corpus="$build/fuzz/modbus-ft300-stream-corpus"
  stream_artifacts="$build/fuzz/modbus-ft300-stream-artifacts"
  mkdir -p "$stream_corpus" "$stream_artifacts"
  modbus_frame='\x20\x4e\x64\x00\x9c\xff\xd2\x04\xff\xff\x00\x00\xff\x7f\x59\x18'
  printf "\\x04${modbus_frame}${modbus_frame}" > "$stream_corpus/seed-clean"
  printf "\\x00\\x09\\x10\\x01\\x9a\\x00\\x01\\x20\\x4e\\x20\\x4e\\x64\\x00\\x9c${modbus_frame}\\x20\\x4e\\x65\\x00\\x9c\\xff\\xd2\\x04\\xff\\xff\\x00\\x00\\xff\\x7f\\x59\\x18${modbus_frame}" > "$stream_corpus/seed-damaged"
  { printf '\x10'; head -c 50 /dev/zero | tr '\0' '\377'; } > "$stream_corpus/seed-jam"
  fuzz_run "$stream_fuzzer" "$stream_corpus" \
    -max_total_time="$modbus_seconds" \
    -max_len=4096 \
    -timeout=10 \
    -rss_limit_mb=2048 \
    -artifact_prefix="$stream_artifacts/" \
    -print_final_stats=1
fi
