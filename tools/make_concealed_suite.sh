#!/bin/sh
# Regenerates the concealed suite in examples/concealed/ with `pliant simulate`: recordings in
# which a physical effect may have been switched on in the generator, with nothing in the
# recording hinting at it. The answer for each case is only in its truth.json.
# Usage: tools/make_concealed_suite.sh [path/to/pliant]    (default: build/bin/pliant)
# Deterministic for a given simulator version: fixed seeds, no clock input. See
# examples/concealed/MANIFEST.md for how the suite is built and meant to be scored.
set -eu

pliant=${1:-build/bin/pliant}
if [ ! -x "$pliant" ]; then
  echo "make_concealed_suite.sh: $pliant is not an executable; build pliant first or pass its path" >&2
  exit 2
fi
suite=$(cd "$(dirname "$0")/.." && pwd)/examples/concealed
mkdir -p "$suite"
# Only the case directories are replaced; MANIFEST.md stays.
for old in "$suite"/case_[0-9][0-9]; do
  if [ -d "$old" ]; then rm -rf "$old"; fi
done

# The cases are listed in suite order, which is shuffled: neighbouring cases say nothing about
# each other. Each line: case number, then the `pliant simulate` arguments.
case_() {
  number=$1
  shift
  "$pliant" simulate "$@" -o "$suite/case_$number" >/dev/null
}

case_ 01 dome_press --rate 15 --beta 0.5 --noise 0.005 --cluster-radius 1.8 --seed 301
case_ 02 dome_press --rate 15 --beta 0.5 --noise 0.003 --occlusion 0.08 --cluster-radius 1.8 --effect viscosity:fraction=0.5,tau=0.5 --seed 302
case_ 03 ring_squeeze --beta 0.6 --noise 0.008 --effect heterogeneity:region=right,ratio=0.5 --seed 303
case_ 04 cantilever_strip --rate 30 --beta 0.4 --noise 0.004 --occlusion 0.05 --effect viscosity:fraction=0,damping=1.5 --seed 304
case_ 05 block_press --release --rate 15 --beta 0.6 --noise 0.002 --depth 0.6 --effect stiffening:k=10 --seed 305
case_ 06 dome_press --rate 15 --beta 0.5 --noise 0.004 --substeps 2 --effect gravity:g=0.08,tilt=20 --seed 306
case_ 07 cantilever_strip --rate 30 --beta 0.5 --noise 0.005 --effect friction --seed 307
case_ 08 cantilever_strip --rate 30 --beta 0.4 --noise 0.005 --seed 308
case_ 09 cantilever_strip --rate 30 --beta 0.4 --noise 0.005 --effect gravity --seed 309
case_ 10 ring_squeeze --beta 0.4 --noise 0.008 --occlusion 0.06 --effect plasticity:yield=0.03,creep=2 --seed 310
case_ 11 block_press --release --rate 15 --beta 0.6 --noise 0.002 --occlusion 0.12 --cluster-radius 1.8 --effect heterogeneity --seed 311
case_ 12 ring_squeeze --beta 0.5 --noise 0.003 --effect stiffening --seed 312
case_ 13 foam_press --depth 0.3 --beta 0.3 --noise 0.002 --substeps 2 --seed 313
case_ 14 foam_press --release --beta 0.5 --noise 0.002 --effect viscosity --seed 314
case_ 15 ring_squeeze --beta 0.5 --noise 0.004 --effect gravity:g=0.0015 --seed 315
case_ 16 block_press --release --rate 15 --beta 0.5 --noise 0.004 --occlusion 0.1 --seed 316
case_ 17 foam_press --release --beta 0.5 --noise 0.003 --occlusion 0.05 --effect gravity:g=150 --seed 317
case_ 18 block_press --release --rate 15 --beta 0.5 --noise 0.003 --occlusion 0.1 --cluster-radius 1.8 --effect plasticity --seed 318
case_ 19 dome_press --rate 15 --beta 0.6 --noise 0.004 --substeps 2 --effect plasticity:yield=0.02,creep=1 --seed 319
case_ 20 dome_press --rate 15 --beta 0.45 --noise 0.003 --depth 0.3 --effect heterogeneity:ratio=2 --seed 320
case_ 21 ring_squeeze --beta 0.5 --noise 0.003 --occlusion 0.15 --seed 321
case_ 22 dome_press --rate 15 --beta 0.6 --noise 0.004 --substeps 2 --occlusion 0.05 --seed 322
case_ 23 cantilever_strip --rate 30 --beta 0.6 --noise 0.003 --occlusion 0.08 --seed 323
case_ 24 ring_squeeze --beta 0.6 --noise 0.005 --effect viscosity:fraction=0.3,tau=1.5 --seed 324
case_ 25 foam_press --release --beta 0.6 --noise 0.005 --effect plasticity:yield=0.05,creep=0.3,max=0.2 --seed 325
case_ 26 foam_press --beta 0.7 --noise 0.002 --substeps 2 --effect friction:mu=0 --seed 326
case_ 27 ring_squeeze --beta 0.4 --noise 0.006 --seed 327
case_ 28 block_press --rate 15 --beta 0.7 --noise 0.008 --cluster-radius 1.8 --seed 328
case_ 29 foam_press --release --beta 0.5 --noise 0.005 --seed 329
case_ 30 dome_press --rate 15 --depth 0.8 --beta 0.7 --noise 0.002 --effect stiffening:k=5 --seed 330
case_ 31 block_press --release --rate 15 --beta 0.6 --noise 0.002 --depth 0.8 --effect friction:mu=0 --seed 331
case_ 32 ring_squeeze --beta 0.5 --noise 0.003 --occlusion 0.1 --effect friction:mu=0.1 --seed 332
case_ 33 foam_press --release --beta 0.5 --noise 0.003 --effect heterogeneity:region=left,ratio=0.3 --seed 333
case_ 34 foam_press --release --depth 0.4 --beta 0.6 --noise 0.003 --occlusion 0.1 --effect stiffening:k=10 --seed 334

count=$(ls -d "$suite"/case_[0-9][0-9] | wc -l)
echo "wrote $count recordings to $suite ($(du -sh "$suite" | cut -f1))"
