#!/usr/bin/env bash
# Installs the built pliant into a temporary prefix, builds tests/install_consumer against it
# with find_package(pliant), and runs it. Usage: run.sh <pliant build dir> <source dir>
set -euo pipefail
build=$1
source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" > /dev/null
cmake -S "$source_dir/tests/install_consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$work/prefix" > /dev/null
cmake --build "$work/consumer" > /dev/null
"$work/consumer/consumer"
