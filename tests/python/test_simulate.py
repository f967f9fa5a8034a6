"""pliant.simulate against `pliant simulate`: the same files, the recording in memory."""

import json

import numpy as np
import pytest

import pliant
from conftest import cli_error, run_cli

OPTIONS = {"beta": 0.3, "noise": 0.005, "seed": 7, "effect": "plasticity:yield=0.02", "occlusion": 0.1}
CLI_OPTIONS = ["--beta", "0.3", "--noise", "0.005", "--seed", "7", "--effect", "plasticity:yield=0.02",
               "--occlusion", "0.1"]


def test_simulate_writes_what_the_command_line_writes(tmp_path):
    rec, truth = pliant.simulate("foam_press", output=tmp_path / "py", **OPTIONS)
    run_cli("simulate", "foam_press", "-o", tmp_path / "cli", *CLI_OPTIONS)
    for name in ("recording.json", "particles.csv", "truth.json"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    assert truth == json.loads((tmp_path / "cli" / "truth.json").read_text())
    back = pliant.read_recording(tmp_path / "cli")
    np.testing.assert_array_equal(rec.positions, back.positions)
    np.testing.assert_array_equal(rec.times, back.times)


def test_simulate_in_memory_writes_nothing(tmp_path):
    rec, truth = pliant.simulate("block_press", beta=0.6, seed=4)
    assert rec.dimension == 3 and rec.length_unit == "m"
    assert truth["parameters"]["msm_beta"] == 0.6
    assert list(tmp_path.iterdir()) == []


def test_simulate_refuses_what_the_command_line_refuses(tmp_path):
    message, status = cli_error("simulate", "no_such_scene", "-o", tmp_path / "a")
    assert status == 2
    with pytest.raises(pliant.UsageError) as error:
        pliant.simulate("no_such_scene", output=tmp_path / "a")
    assert str(error.value) == message
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "x").write_text("x")
    message, _ = cli_error("simulate", "foam_press", "-o", tmp_path / "full")
    with pytest.raises(pliant.UsageError) as error:
        pliant.simulate("foam_press", output=tmp_path / "full")
    assert str(error.value) == message
    with pytest.raises(pliant.UsageError, match="--seed must be >= 0"):
        pliant.simulate("foam_press", seed=-1)
