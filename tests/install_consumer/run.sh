#!/usr/bin/env bash
# Installs the built pliant into a temporary prefix, builds tests/install_consumer against it with
# find_package(pliant COMPONENTS ...), and runs it: the core consumer, then one use of each other
# component the build installed (host on RECORDING).
# Usage: run.sh <pliant build dir> <source dir> "<components>" [RECORDING]
set -euo pipefail
build=$1
source_dir=$2
components=${3:-}
recording=${4:-}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" > /dev/null
cmake -S "$source_dir/tests/install_consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DPLIANT_CONSUMER_COMPONENTS="$components" > /dev/null
cmake --build "$work/consumer" > /dev/null
"$work/consumer/consumer"
if [ -n "$components" ]; then
  "$work/consumer/components" $recording
fi
