# Fuzz smoke fragment for the device registry's typed parameters (hal::DeviceSpec), sourced by
# .ci/fuzz_smoke.sh ($root, $build, set -euo pipefail). Builds device_spec_fuzz and runs it for
# ${PLIANT_DEVICE_SPEC_FUZZ_SECONDS:-10} seconds from seeds written here: "name=value" lines.
cmake --build "$build" --target device_spec_fuzz -j "$(nproc)"
device_spec_fuzzer="$build/bin/device_spec_fuzz"
[ -x "$device_spec_fuzzer" ] || device_spec_fuzzer="$(find "$build" -type f -name device_spec_fuzz -perm -u+x | head -n 1)"
device_spec_corpus="$build/fuzz/device-spec-corpus"
device_spec_artifacts="$build/fuzz/device-spec-artifacts"
mkdir -p "$device_spec_corpus" "$device_spec_artifacts"
printf 'slave=9\nbase=0x20\nrate=100.5\nstream=yes\nformat=bgr8\n' > "$device_spec_corpus/seed-valid"
printf 'slave=0x-1\nbase=0x\nrate=nan\nstream=maybe\nformat=\n=\n' > "$device_spec_corpus/seed-malformed"
printf 'a=99999999999999999999\nb=1e999\nc=-0\nd=0X10\n' > "$device_spec_corpus/seed-ranges"
fuzz_run "$device_spec_fuzzer" "$device_spec_corpus" \
  -max_total_time="${PLIANT_DEVICE_SPEC_FUZZ_SECONDS:-10}" \
  -max_len=1024 \
  -timeout=10 \
  -rss_limit_mb=2048 \
  -artifact_prefix="$device_spec_artifacts/" \
  -print_final_stats=1
