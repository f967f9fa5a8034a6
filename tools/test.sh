#!/usr/bin/env bash
# Every test, in stages, each timed:
#   setup      install what is missing (tools/setup-debian.sh)
#   release    build everything (Release) and run every test: unit, integration, acceptance,
#              install consumers, the Python module's pytest files (label python)
#   package    tools/packages.sh: the Debian packages (CPack) from the release build, their
#              dependencies resolved by apt, the install consumer built against them unpacked,
#              and the Python module imported from the unpacked python3-pliant
#   sanitize   AddressSanitizer + UndefinedBehaviorSanitizer build of what parses outside input or
#              runs real-time code (PLIANT_SANITIZE_SCOPE=input, see tests/CMakeLists.txt), and
#              its tests except the slow acceptance runs and the wire HIL's 10-minute soak; never
#              the Python module (an ASan runtime and a Python interpreter do not mix)
#   cross      tools/cross.sh: the aarch64 tests under qemu, the Cortex-M7 firmware with its
#              no-allocator check
#   fuzz       a short libFuzzer smoke run of every parser and decoder (.ci/fuzz_smoke.sh)
#   lint       tools/lint.sh: formatting and static checks
# Every build goes through ccache (installed by the set-up script, cache in ~/.cache/ccache), so a
# rerun on the same machine recompiles only what changed.
# Usage: bash tools/test.sh [STAGE ...]      (no argument: every stage, in the order above;
#                                            package needs the release stage's build)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
jobs=$(nproc)
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$root}   # cache hits across clones in other folders
export CCACHE_MAXSIZE=${CCACHE_MAXSIZE:-12G}     # release, sanitizer, fuzz and cross objects
export CCACHE_COMPILERCHECK=${CCACHE_COMPILERCHECK:-content}
# Builds with debug information (sanitize: -g1, fuzz: line tables) would otherwise hash the
# working directory and miss the cache in every other clone.
export CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-1}
export CMAKE_GENERATOR=${CMAKE_GENERATOR:-Ninja}   # every configure below, the scripts' included

# Sends every compiler call of every configure below (cross.sh's and fuzz_smoke.sh's included)
# through ccache, once the set-up stage has installed it.
use_ccache() {
  if command -v ccache > /dev/null; then
    export CMAKE_C_COMPILER_LAUNCHER=ccache CMAKE_CXX_COMPILER_LAUNCHER=ccache
  fi
}
use_ccache

# A build folder configured earlier with another generator (make, before this script used Ninja)
# cannot be reconfigured in place: start it afresh.
forget_other_generator() {
  local dir
  for dir in build build-asan build-fuzz build-lint build-aarch64 build-cortex-m7; do
    if [ -f "$dir/CMakeCache.txt" ] && ! grep -qx "CMAKE_GENERATOR:INTERNAL=$CMAKE_GENERATOR" "$dir/CMakeCache.txt"; then
      echo "test.sh: $dir was configured with another generator; configuring it afresh"
      rm -rf "$dir/CMakeCache.txt" "$dir/CMakeFiles"
    fi
  done
}
forget_other_generator

setup() { bash tools/setup-debian.sh; }

# ctest -j starts the tests it knows to be longest first, from the build folder's cost file. A fresh
# clone has none, and the few tests of minutes would start wherever they fall; it gets the costs
# of an earlier run instead (tests/ctest_costs/README.md). ctest updates the file after every run.
seed_test_costs() {  # seed_test_costs BUILD_DIR COSTS_NAME
  local data="$1/Testing/Temporary/CTestCostData.txt"
  if [ ! -f "$data" ]; then
    mkdir -p "$(dirname "$data")"
    cp "tests/ctest_costs/$2.txt" "$data"
  fi
}

release() {
  # Tests and benchmarks named: tools/demo.sh configures the same folder without them.
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPLIANT_BUILD_TESTS=ON -DPLIANT_BUILD_BENCHMARKS=ON > /dev/null
  cmake --build build -j"$jobs"
  seed_test_costs build release
  ctest --test-dir build -j"$jobs" --output-on-failure
}

sanitize() {
  # -O1 and line tables only (-g1): what the sanitizers need for their reports with file and line,
  # at about half the compile time of -O2 -g on the Eigen-heavy units.
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPLIANT_SANITIZE=ON \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
    -DPLIANT_SANITIZE_SCOPE=input -DPLIANT_BUILD_BENCHMARKS=OFF -DPLIANT_BUILD_PYTHON=OFF > /dev/null
  cmake --build build-asan -j"$jobs"
  seed_test_costs build-asan asan
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build-asan -j"$jobs" --output-on-failure -LE 'acceptance|soak' -E install_consumer
}

package() { bash tools/packages.sh build; }

cross() { bash tools/cross.sh; }

fuzz() {
  # Shorter than the script's defaults, to keep the whole run within CI's time budget; run
  # .ci/fuzz_smoke.sh alone for the longer default durations.
  PLIANT_FUZZ_SECONDS=${PLIANT_FUZZ_SECONDS:-30} PLIANT_MESH_FUZZ_SECONDS=${PLIANT_MESH_FUZZ_SECONDS:-20} \
    PLIANT_CSV_FUZZ_SECONDS=${PLIANT_CSV_FUZZ_SECONDS:-20} bash .ci/fuzz_smoke.sh
}

lint() { bash tools/lint.sh; }

stages=("$@")
[ ${#stages[@]} -gt 0 ] || stages=(setup release package sanitize cross fuzz lint)
for stage in "${stages[@]}"; do
  case $stage in
    setup | release | package | sanitize | cross | fuzz | lint) ;;
    *) echo "usage: $0 [setup|release|package|sanitize|cross|fuzz|lint ...]" >&2; exit 2 ;;
  esac
done

timings=()
started_all=$SECONDS
for stage in "${stages[@]}"; do
  echo "== stage $stage"
  started=$SECONDS
  "$stage"
  timings+=("$(printf '%-9s %5d s' "$stage" $((SECONDS - started)))")
  echo "== stage $stage done in $((SECONDS - started)) s"
  use_ccache
done

echo "== stage durations"
printf '   %s\n' "${timings[@]}"
printf '   %-9s %5d s\n' total $((SECONDS - started_all))
if command -v ccache > /dev/null; then ccache --show-stats | sed -n '1,6p' | sed 's/^/   ccache: /'; fi
