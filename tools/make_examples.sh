#!/bin/sh
# Regenerates the bundled example recordings in examples/ with `pliant simulate`.
# Usage: tools/make_examples.sh [path/to/pliant]    (default: build/bin/pliant)
# The recordings are deterministic for a given simulator version: fixed seeds, no clock input.
set -eu

pliant=${1:-build/bin/pliant}
if [ ! -x "$pliant" ]; then
  echo "make_examples.sh: $pliant is not an executable; build pliant first or pass its path" >&2
  exit 2
fi
examples=$(cd "$(dirname "$0")/.." && pwd)/examples

simulate() {
  name=$1
  shift
  "$pliant" simulate "$@" -o "$examples/$name" --force
}

simulate foam_press_soft   foam_press       --beta 0.8 --noise 0.005 --seed 1
simulate foam_press_medium foam_press       --beta 0.5 --noise 0.005 --seed 2
simulate foam_press_firm   foam_press       --beta 0.2 --noise 0.005 --seed 3
simulate block_press       block_press      --beta 0.6 --noise 0.005 --seed 4
simulate cantilever_strip  cantilever_strip --beta 0.4 --noise 0.005 --seed 5
