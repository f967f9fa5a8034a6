#!/usr/bin/env bash
# Style and static checks; every finding is an error (exit 1).
#   format  clang-format (.clang-format) over every C and C++ source the repository tracks:
#           files that it would change are listed with the first lines of the diff.
#   tidy    clang-tidy (.clang-tidy) over the controller code, core/, firmware-bridge/ and hal/
#           (the real-time and safety path), with the compile commands of a Release configure.
#           Results are cached per translation unit, keyed by its preprocessed text, the tidy
#           configuration and the compile command, in ${PLIANT_LINT_CACHE:-~/.cache/pliant-lint}:
#           an unchanged unit is not analysed again.
# Usage: bash tools/lint.sh [--fix] [format] [tidy]   (no check named: both; --fix reformats)
# Needs clang-format-14 and clang-tidy-14 (Debian clang-format, clang-tidy; tools/setup-debian.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
fix=0
checks=()
for arg in "$@"; do
  case $arg in
    --fix) fix=1 ;;
    format | tidy) checks+=("$arg") ;;
    *) echo "usage: $0 [--fix] [format] [tidy]" >&2; exit 2 ;;
  esac
done
[ ${#checks[@]} -gt 0 ] || checks=(format tidy)

pick() {  # the first of the named programs that exists
  local name
  for name in "$@"; do
    if command -v "$name" > /dev/null; then echo "$name"; return 0; fi
  done
  echo "lint: none of $* is installed (bash tools/setup-debian.sh)" >&2
  return 1
}

# C and C++ sources under version control, test data excluded.
sources() {
  git ls-files -- '*.c' '*.h' '*.cpp' '*.hpp' | grep -v '^tests/data/' || true
}

format() {
  local clang_format bad_files file count
  clang_format=$(pick clang-format-14 clang-format)
  count=$(sources | wc -l)
  if [ "$fix" -eq 1 ]; then
    sources | xargs -d '\n' -r -P "$(nproc)" -n 40 "$clang_format" -i --style=file
    echo "lint format: $count files formatted"
    return 0
  fi
  # Batches of files on every core; clang-format names each file it would change in a
  # "FILE:LINE:COLUMN: error: code should be clang-formatted" line.
  local report status=0
  report=$(sources | xargs -d '\n' -r -P "$(nproc)" -n 40 "$clang_format" --style=file --dry-run --Werror 2>&1) ||
    status=$?
  bad_files=$(sed -n 's/^\(.*\):[0-9]*:[0-9]*: error: code should be clang-formatted.*/\1/p' <<< "$report" | sort -u)
  if [ "$status" -eq 0 ]; then
    echo "lint format: $count files formatted"
    return 0
  fi
  if [ -z "$bad_files" ]; then  # clang-format itself failed (configuration, unreadable file)
    echo "lint format: $clang_format failed:"
    head -n 20 <<< "$report"
    return 1
  fi
  while IFS= read -r file; do
    echo "lint format: $file is not formatted (bash tools/lint.sh --fix format):"
    "$clang_format" --style=file "$file" | diff -u "$file" - | sed -n '3,14p' || true
  done <<< "$bad_files"
  return 1
}

tidy() {
  local clang_tidy build=${PLIANT_LINT_BUILD_DIR:-build-lint}
  clang_tidy=$(pick clang-tidy-14 clang-tidy)
  # Only the compile commands are needed: the controller libraries and their tests, no host.
  cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_EXPORT_COMPILE_COMMANDS=ON \
    -DPLIANT_BUILD_HOST=OFF -DPLIANT_BUILD_DRIVERS=OFF -DPLIANT_BUILD_BENCHMARKS=OFF > /dev/null
  python3 tools/lint_tidy.py "$clang_tidy" "$build" \
    "${PLIANT_LINT_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/pliant-lint}" "$(nproc)" core firmware-bridge hal
}

status=0
for check in "${checks[@]}"; do
  "$check" || status=1
done
exit "$status"
