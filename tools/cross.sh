#!/usr/bin/env bash
# Cross builds (toolchains/README.md):
#   aarch64    core, bridge, hal and their tests built with aarch64-linux-gnu-g++ and run under
#              qemu-aarch64 by ctest (HIL tests: built, not run); fails unless every binary is an
#              aarch64 ELF.
#   cortex-m7  the example firmware (examples/firmware) with pliant_core and pliant_bridge for a
#              Cortex-M7 with newlib-nano; fails if any allocator (malloc, free, calloc, realloc,
#              operator new/delete in any variant, newlib's _malloc_r family) is linked; prints
#              flash and RAM use.
# Usage: bash tools/cross.sh [aarch64] [cortex-m7]      (no argument: both)
# Environment: PLIANT_CROSS_BUILD_PREFIX (default build-: build-aarch64, build-cortex-m7);
# PLIANT_CROSS_CTEST_ARGS (default "-LE hil"; "" runs every test under qemu).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
jobs=$(nproc)
prefix=${PLIANT_CROSS_BUILD_PREFIX:-build-}
launcher=()
if command -v ccache > /dev/null; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$root}
fi


aarch64() {
  local build=${prefix}aarch64
  echo "-- aarch64: configure, build, test under qemu-aarch64 ($build)"
  cmake -S . -B "$build" --toolchain "$root/toolchains/aarch64-linux-gnu.cmake" \
    -DCMAKE_BUILD_TYPE=Release -DPLIANT_BUILD_HOST=OFF -DPLIANT_BUILD_BENCHMARKS=OFF \
    "${launcher[@]}" > /dev/null
  cmake --build "$build" -j"$jobs"
  local binaries=("$build"/bin/*)
  [ -e "${binaries[0]}" ] || { echo "aarch64: no test binaries in $build/bin" >&2; return 1; }
  local binary wrong=0
  for binary in "${binaries[@]}"; do
    if ! file -b "$binary" | grep -q 'ELF 64-bit LSB .*ARM aarch64'; then
      echo "aarch64: $binary is not an aarch64 ELF: $(file -b "$binary")" >&2
      wrong=1
    fi
  done
  [ "$wrong" -eq 0 ] || return 1
  echo "-- aarch64: ${#binaries[@]} binaries, all ELF 64-bit ARM aarch64"
  # HIL tests (label hil) are built but not run: their simulated grasps are floating-point heavy,
  # qemu emulates floating point in software, and they take minutes there (seconds natively,
  # where the release and sanitizer stages run them).
  local ctest_args
  read -r -a ctest_args <<< "${PLIANT_CROSS_CTEST_ARGS--LE hil}"
  ctest --test-dir "$build" -j"$jobs" --output-on-failure "${ctest_args[@]}"
}

# Names of every allocator entry point: C, newlib's reentrant forms, and the Itanium-mangled
# operator new / new[] / delete / delete[] in all their overloads (_Znwj, _Znaj, _ZdlPv, ...).
allocator_pattern='^(malloc|free|calloc|realloc|reallocf|memalign|aligned_alloc|posix_memalign|valloc|pvalloc|_malloc_r|_free_r|_calloc_r|_realloc_r|_memalign_r)$|^_Zn[wa]|^_Zd[la]'

# Prints the allocator symbols linked into ELF $1 (nothing when clean).
allocators_in() {
  arm-none-eabi-nm "$1" | awk 'NF >= 2 { print $NF }' | { grep -E "$allocator_pattern" || true; } | sort -u |
    while read -r symbol; do
      echo "$symbol ($(echo "$symbol" | arm-none-eabi-c++filt))"
    done
}

kib() { awk -v bytes="$1" 'BEGIN { printf "%.1f", bytes / 1024 }'; }

# Sums the flash and RAM that objects of pliant's own libraries occupy, from the linker map.
pliant_share() {
  awk '
    function hex(s,   i, v) { s = tolower(substr(s, 3)); v = 0
      for (i = 1; i <= length(s); i++) v = v * 16 + index("0123456789abcdef", substr(s, i, 1)) - 1
      return v }
    /^Linker script and memory map/ { on = 1; next }
    on && $NF ~ /libpliant_(core|bridge)\.a\(/ && $(NF - 2) ~ /^0x/ && $(NF - 1) ~ /^0x/ {
      address = hex($(NF - 2)); size = hex($(NF - 1))
      if (address >= 134217728 && address < 268435456) flash += size   # 0x08000000..
      else if (address >= 536870912 && address < 805306368) ram += size  # 0x20000000..
    }
    END { printf "%d %d\n", flash, ram }' "$1"
}

cortex_m7() {
  local build=${prefix}cortex-m7
  echo "-- cortex-m7: example firmware with pliant_core and pliant_bridge ($build)"
  cmake -S examples/firmware -B "$build" --toolchain "$root/toolchains/arm-none-eabi-cortex-m7.cmake" \
    -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" > /dev/null
  cmake --build "$build" -j"$jobs"
  local elf=$build/pliant_firmware_example.elf
  file -b "$elf" | grep -q 'ELF 32-bit LSB executable, ARM' || { echo "cortex-m7: $elf is not an ARM ELF" >&2; return 1; }

  # The check must be able to fail: a probe image that calls malloc and new has to be caught.
  local probe caught
  probe=$(mktemp -d)
  printf '%s\n' '#include <cstdlib>' \
    'int main() { int* i = new int(1); void* p = std::malloc(4); std::free(p); delete i; return 0; }' \
    > "$probe/probe.cpp"
  arm-none-eabi-g++ -mcpu=cortex-m7 -mthumb -mfpu=fpv5-d16 -mfloat-abi=hard -fno-exceptions -fno-rtti \
    --specs=nano.specs --specs=nosys.specs -Wl,--gc-sections "$probe/probe.cpp" -o "$probe/probe.elf"
  caught=$(allocators_in "$probe/probe.elf")
  rm -rf "$probe"
  if ! grep -q '^malloc ' <<< "$caught" || ! grep -q '^_Znwj ' <<< "$caught"; then
    echo "cortex-m7: the allocator check missed malloc or operator new in a probe image" >&2
    return 1
  fi

  local found
  found=$(allocators_in "$elf")
  if [ -n "$found" ]; then
    echo "cortex-m7: allocator symbols linked into $elf:" >&2
    echo "$found" >&2
    echo "(who pulls them in: 'Archive member included' in ${elf%.elf}.map)" >&2
    return 1
  fi
  echo "-- cortex-m7: no malloc, free, calloc, realloc, operator new or operator delete linked"

  local text data bss flash ram share
  read -r text data bss < <(arm-none-eabi-size -B "$elf" | awk 'NR == 2 { print $1, $2, $3 }')
  flash=$((text + data))
  ram=$((data + bss))
  read -r -a share < <(pliant_share "${elf%.elf}.map")
  local workspace
  workspace=$(arm-none-eabi-nm -S -t d "$elf" | awk '$4 == "g_workspace" { print $2 + 0 }')
  printf -- '-- cortex-m7 memory: flash %d B (%s KiB; text %d + data %d), RAM %d B (%s KiB; data %d + bss %d)\n' \
    "$flash" "$(kib "$flash")" "$text" "$data" "$ram" "$(kib "$ram")" "$data" "$bss"
  printf -- '   of which pliant_core + pliant_bridge code and constants %d B, their static data %d B;\n' \
    "${share[0]}" "${share[1]}"
  printf -- '   RAM includes the 8 KiB stack and the example'"'"'s %d B pliant workspace (STM32F767xG-like part: 1 MiB flash, 512 KiB RAM)\n' \
    "${workspace:-0}"
}

if [ $# -eq 0 ]; then
  # Both, each in its own shell so that one failing still lets the other run and report.
  failed=()
  for target in aarch64 cortex-m7; do
    bash "$root/tools/cross.sh" "$target" || failed+=("$target")
  done
  if [ ${#failed[@]} -gt 0 ]; then
    echo "cross builds failed: ${failed[*]}" >&2
    exit 1
  fi
  exit 0
fi
for target in "$@"; do
  case $target in
    aarch64) aarch64 ;;
    cortex-m7) cortex_m7 ;;
    *) echo "usage: $0 [aarch64] [cortex-m7]" >&2; exit 2 ;;
  esac
done
