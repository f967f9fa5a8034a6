"""Shared helpers of the fleet tests: the pliant program, simulated recordings, running a batch.

ctest sets PLIANT_CLI (the built pliant), PLIANT_EXAMPLES_DIR and PYTHONPATH (the package
directory); by hand: PLIANT_CLI=build/bin/pliant PLIANT_EXAMPLES_DIR=examples PYTHONPATH=build/python
/usr/bin/python3 -m pytest tests/fleet
"""

import json
import os
import shutil
import subprocess
import sys

import pytest

# Small, quick presses: 2D foam_press at a low frame rate, so diagnose takes about a second.
PRESS_RATE_HZ = "8"


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("PLIANT_CLI")
    if not path or not os.access(path, os.X_OK):
        pytest.fail("PLIANT_CLI must name the built pliant program (ctest sets it)")
    return os.path.abspath(path)


@pytest.fixture(scope="session")
def examples():
    path = os.environ.get("PLIANT_EXAMPLES_DIR")
    if not path or not os.path.isdir(path):
        pytest.fail("PLIANT_EXAMPLES_DIR must name the repository's examples/ (ctest sets it)")
    return path


def package_dir():
    """The directory holding the pliant package these tests import."""
    import pliant.fleet

    return os.path.dirname(os.path.dirname(os.path.abspath(pliant.fleet.__file__)))


def simulate(cli, directory, beta=0.3, seed=1, effect=None, scenario="foam_press", rate=PRESS_RATE_HZ):
    command = [cli, "simulate", scenario, "-o", str(directory), "--beta", str(beta), "--seed", str(seed),
               "--noise", "0.004"]
    if rate:
        command += ["--rate", rate]
    if effect:
        command += ["--effect", effect]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return directory


def set_object(directory, name):
    """Gives the recording the object class `name` (recording.json meta.object)."""
    path = os.path.join(directory, "recording.json")
    with open(path) as stream:
        document = json.load(stream)
    document.setdefault("meta", {})["object"] = name
    with open(path, "w") as stream:
        json.dump(document, stream, indent=2)


def truncate_csv(path):
    """Cuts particles.csv inside a row, just after a comma: the reader must name the line."""
    with open(path, "rb") as stream:
        data = stream.read()
    middle = data.index(b"\n", len(data) // 2) + 1
    cut = data.index(b",", middle) + 1
    with open(path, "wb") as stream:
        stream.write(data[:cut])


def fleet_command(*arguments):
    return [sys.executable, "-m", "pliant.fleet", *map(str, arguments)]


def run_fleet(*arguments, timeout=180, env=None):
    return subprocess.run(fleet_command(*arguments), capture_output=True, text=True, timeout=timeout, env=env)


def read_summary(out):
    with open(os.path.join(out, "summary.json")) as stream:
        return json.load(stream)


def copy_recording(source, target):
    shutil.copytree(source, target)
    return target
