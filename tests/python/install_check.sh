#!/usr/bin/env bash
# Installs the `python` component of a built tree into an empty prefix and imports pliant from
# <prefix>/lib/python3/dist-packages (not from the build tree), estimating a bundled recording.
# Usage: install_check.sh <build dir> <python> <recording>
set -euo pipefail
build=$1
python=$2
recording=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" --component python > /dev/null
site=$work/prefix/lib/python3/dist-packages
[ -f "$site/pliant/__init__.py" ] || { echo "install check: no pliant/__init__.py under $site" >&2; exit 1; }
ls "$site"/pliant/_pliant*.so > /dev/null || { echo "install check: no extension under $site/pliant" >&2; exit 1; }
cd "$work"
PYTHONPATH=$site PYTHONDONTWRITEBYTECODE=1 "$python" - "$site" "$recording" << 'PY'
import sys

import pliant

site, recording = sys.argv[1], sys.argv[2]
assert pliant.__file__.startswith(site), f"pliant imported from {pliant.__file__}, not {site}"
document = pliant.estimate(recording, quiet=True, alpha="fixed=1", steps_per_frame=1, cluster_radius=1.5)
beta = document["parameters"]["msm_beta"]
assert 0.35 < beta < 0.65, beta
print(f"install check: pliant {pliant.__version__} from {site}: msm_beta {beta:.3f}")
PY
