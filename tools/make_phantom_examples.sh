#!/bin/sh
# Regenerates the phantom compression recordings in examples/phantom_compression/ from the lab's
# CSV files copied to examples/phantom_compression/source, with `pliant import compression`.
# Usage: tools/make_phantom_examples.sh [path/to/pliant]    (default: build/bin/pliant)
# The output is deterministic: the same CSV, options and pliant version give the same files.
set -eu

pliant=${1:-build/bin/pliant}
if [ ! -x "$pliant" ]; then
  echo "make_phantom_examples.sh: $pliant is not an executable; build pliant first or pass its path" >&2
  exit 2
fi
examples=$(cd "$(dirname "$0")/.." && pwd)/examples/phantom_compression

source_text="Dawood et al. 2026, Hyperelastic Characterisation of Silicone Tissue Phantoms (tissue phantom material database), github.com/abubakardawood/tissue-phantom-material-database @ 52b1271f0f8a966c168e5ddc0886190f12c6551f"

# One specimen per material (source/README.md says how they were chosen); density from the
# manufacturer's specific gravity (Ecoflex 00-10: 1.04, 00-30 and 00-50: 1.07).
convert_specimen() {
  name=$1
  density=$2
  "$pliant" import compression "$examples/source/$name.csv" -o "$examples/$name" --force \
    --frame-interval 1 --contact frictionless --expansion small-strain --poisson-ratio 0.49 \
    --density "$density" --mesh-divisions 2,24,5 \
    --source "$source_text" --license "CC BY 4.0"
}

convert_specimen EF10_0T_B5 1040
convert_specimen EF30_0T_A5 1070
convert_specimen EF50_0T_A4 1070
