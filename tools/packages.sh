#!/usr/bin/env bash
# Builds pliant's Debian packages with CPack (cmake/PliantPackaging.cmake, docs/packages.md) from a
# configured and built tree, then checks them as a user would meet them:
#   1. apt resolves every package's dependencies (a simulated install: nothing is installed);
#   2. no file is in two packages (dpkg would refuse the second);
#   3. libpliant-core-dev alone, unpacked into an empty root, is enough to build and run the
#      core consumer (tests/install_consumer) with find_package(pliant);
#   4. every package unpacked into another empty root: the consumer with every component the
#      build made, and the unpacked `pliant` program estimating a bundled recording;
#   5. python3-pliant alone, unpacked into an empty root: Debian's python3 imports the module from
#      its usr/lib/python3/dist-packages and estimates a bundled recording.
# Usage: bash tools/packages.sh [BUILD_DIR] [OUT_DIR]   (defaults: build, build/packages)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
build=$(cd "${1:-build}" && pwd)
out=${2:-$build/packages}
mkdir -p "$out"
out=$(cd "$out" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

rm -f "$out"/*.deb
(cd "$build" && cpack -G DEB -B "$out" > "$work/cpack.log" 2>&1) || { cat "$work/cpack.log" >&2; exit 1; }
debs=("$out"/*.deb)
[ -e "${debs[0]}" ] || { echo "packages: cpack made no .deb in $out" >&2; exit 1; }
for deb in "${debs[@]}"; do
  echo "packages: $(dpkg-deb -f "$deb" Package) $(dpkg-deb -f "$deb" Version): $(du -k "$deb" | cut -f1) KB"
  echo "          Depends: $(dpkg-deb -f "$deb" Depends)"
done

# 1. Dependencies resolvable from the machine's apt sources (and the packages themselves).
if ! apt-get install --simulate --no-install-recommends "${debs[@]}" > "$work/apt.log" 2>&1; then
  echo "packages: apt cannot install them:" >&2
  cat "$work/apt.log" >&2
  exit 1
fi

# 2. Each file in one package only.
for deb in "${debs[@]}"; do
  dpkg-deb --contents "$deb" | awk '$1 !~ /^d/ { print $NF }'
done | sort | uniq -d > "$work/shared_files"
if [ -s "$work/shared_files" ]; then
  echo "packages: files in more than one package:" >&2
  cat "$work/shared_files" >&2
  exit 1
fi

# The components the build installed (the consumer exercises each).
components=()
for deb in "${debs[@]}"; do
  [ "$(dpkg-deb -f "$deb" Package)" = libpliant-dev ] || continue
  dpkg-deb --contents "$deb" > "$work/host_dev_files"
  for component in host vision socketcan modbus opencv libcamera openni2 usb; do
    if grep -q "pliant-$component-targets.cmake" "$work/host_dev_files"; then components+=("$component"); fi
  done
done

consumer() {  # consumer <unpacked root> <name> [components...]
  local prefix=$1/usr name=$2
  shift 2
  local list
  list=$(IFS=';' && echo "$*")  # a CMake list
  cmake -S "$root/tests/install_consumer" -B "$work/$name" -DCMAKE_PREFIX_PATH="$prefix" \
    -DPLIANT_CONSUMER_COMPONENTS="$list" > "$work/$name.log" 2>&1 || { cat "$work/$name.log" >&2; return 1; }
  cmake --build "$work/$name" > "$work/$name.build.log" 2>&1 || { cat "$work/$name.build.log" >&2; return 1; }
  "$work/$name/consumer" > "$work/$name.run.log" 2>&1 || { cat "$work/$name.run.log" >&2; return 1; }
  if [ $# -gt 0 ]; then
    "$work/$name/components" "$root/examples/foam_press_medium" > "$work/$name.run.log" 2>&1 ||
      { cat "$work/$name.run.log" >&2; return 1; }
  fi
}

# 3. The controller package alone.
core_deb=$(ls "$out"/libpliant-core-dev_*.deb)
dpkg-deb -x "$core_deb" "$work/core-root"
consumer "$work/core-root" core-consumer
echo "packages: libpliant-core-dev alone builds and runs the core consumer"

# 4. Everything.
for deb in "${debs[@]}"; do dpkg-deb -x "$deb" "$work/all-root"; done
consumer "$work/all-root" all-consumer "${components[@]}"
echo "packages: all packages build and run the consumer with: core ${components[*]}"
if [ -x "$work/all-root/usr/bin/pliant" ]; then
  "$work/all-root/usr/bin/pliant" estimate "$root/examples/foam_press_medium" > "$work/estimate.txt"
  echo "packages: the packaged pliant estimates examples/foam_press_medium: $(grep -m1 msm_beta "$work/estimate.txt")"
fi

# 5. The Python module alone (the host libraries are linked into it).
python_deb=$(ls "$out"/python3-pliant_*.deb 2> /dev/null || true)
if [ -n "$python_deb" ]; then
  dpkg-deb -x "$python_deb" "$work/python-root"
  site=$work/python-root/usr/lib/python3/dist-packages
  [ -f "$site/pliant/__init__.py" ] || { echo "packages: python3-pliant has no usr/lib/python3/dist-packages/pliant" >&2; exit 1; }
  (cd "$work" && PYTHONPATH=$site PYTHONDONTWRITEBYTECODE=1 /usr/bin/python3 -c '
import sys

import pliant

site, recording = sys.argv[1], sys.argv[2]
assert pliant.__file__.startswith(site), pliant.__file__
document = pliant.estimate(recording, quiet=True)
print("msm_beta %.3f +- %.3f" % (document["parameters"]["msm_beta"], document["uncertainty"]["msm_beta"]))
' "$site" "$root/examples/foam_press_medium" > "$work/python.txt") || { cat "$work/python.txt" >&2; exit 1; }
  echo "packages: python3-pliant alone imports pliant and estimates examples/foam_press_medium: $(cat "$work/python.txt")"
else
  echo "packages: no python3-pliant (this build has no Python module)"
fi
