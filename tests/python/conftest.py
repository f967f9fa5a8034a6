"""Shared fixtures of the Python module's tests (run by ctest with the build tree's package on
PYTHONPATH; see CMakeLists.txt beside this file)."""

import json
import math
import os
import shutil
import subprocess
from pathlib import Path

import pytest

EXAMPLES = Path(os.environ["PLIANT_EXAMPLES_DIR"])
PLIANT_EXE = os.environ["PLIANT_EXE"]


@pytest.fixture
def examples():
    return EXAMPLES


def run_cli(*args, check=True):
    """Runs the built `pliant` with `args`; returns the CompletedProcess (text)."""
    result = subprocess.run([PLIANT_EXE, *map(str, args)], capture_output=True, text=True, check=False)
    if check and result.returncode != 0:
        raise AssertionError(f"pliant {' '.join(map(str, args))} exited {result.returncode}: {result.stderr}")
    return result


def cli_json(*args):
    """The document `pliant ARGS --json -` prints."""
    return json.loads(run_cli(*args, "--json", "-", "-q").stdout)


def cli_error(command, *args):
    """The message of a failing `pliant COMMAND ARGS`: its stderr line without the prefix, and the
    exit status."""
    result = run_cli(command, *args, check=False)
    prefix = f"pliant {command}: "
    lines = [line for line in result.stderr.splitlines() if line.startswith(prefix)]
    assert lines, f"no '{prefix}' line in: {result.stderr!r}"
    return lines[-1][len(prefix):], result.returncode


def assert_same_document(python, cli, path="", ignore=("runtime_s",)):
    """Deep equality of two JSON documents; numbers to 1e-9 relative, keys in `ignore` skipped."""
    if isinstance(cli, dict):
        assert isinstance(python, dict), path
        assert set(python) == set(cli), f"{path}: keys {sorted(set(python) ^ set(cli))} differ"
        for key in cli:
            if key not in ignore:
                assert_same_document(python[key], cli[key], f"{path}.{key}", ignore)
    elif isinstance(cli, list):
        assert isinstance(python, list) and len(python) == len(cli), path
        for index, (p, c) in enumerate(zip(python, cli)):
            assert_same_document(p, c, f"{path}[{index}]", ignore)
    elif isinstance(cli, float) and not isinstance(python, bool):
        assert isinstance(python, (int, float)), path
        assert math.isclose(python, cli, rel_tol=1e-9, abs_tol=1e-12), f"{path}: {python} != {cli}"
    else:
        assert python == cli, f"{path}: {python!r} != {cli!r}"


@pytest.fixture
def foam_copy(tmp_path):
    """A writable copy of examples/foam_press_medium."""
    target = tmp_path / "foam_press_medium"
    shutil.copytree(EXAMPLES / "foam_press_medium", target)
    return target
