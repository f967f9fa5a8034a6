"""Errors: Python exceptions with the command line's messages, in the documented hierarchy."""

import numpy as np
import pytest

import pliant
from conftest import cli_error


def test_the_exception_classes():
    assert issubclass(pliant.PliantError, RuntimeError)
    for cls in (pliant.UsageError, pliant.InputError):
        assert issubclass(cls, pliant.PliantError) and issubclass(cls, ValueError)
    assert issubclass(pliant.PliantWarning, UserWarning)


@pytest.mark.parametrize(
    "cli_options, python_options",
    [
        (["--grid", "2"], {"grid": 2}),
        (["--mode", "sideways"], {"mode": "sideways"}),
        (["--alpha", "bogus"], {"alpha": "bogus"}),
        (["--msm-alpha", "1.5"], {"msm_alpha": 1.5}),
        (["--steps-per-frame", "0"], {"steps_per_frame": "0"}),
        (["--cluster-radius", "9"], {"cluster_radius": 9}),
        (["--mode", "final", "--alpha", "fit"], {"mode": "final", "alpha": "fit"}),
    ],
)
def test_bad_estimate_options_are_usage_errors_in_the_command_lines_words(examples, cli_options, python_options):
    rec = examples / "foam_press_medium"
    message, status = cli_error("estimate", rec, *cli_options)
    assert status == 2
    with pytest.raises(pliant.UsageError) as error:
        pliant.estimate(rec, **python_options)
    assert str(error.value) == message


def test_bad_diagnose_options_are_usage_errors(examples):
    rec = examples / "foam_press_medium"
    for cli_options, python_options in ((["--model", "spline"], {"model": "spline"}),
                                        (["--model", "fem"], {"model": "fem"}),
                                        (["--model", "fem", "--alpha", "fit"], {"model": "fem", "alpha": "fit"})):
        message, status = cli_error("diagnose", rec, *cli_options)
        assert status == 2
        with pytest.raises(pliant.UsageError) as error:
            pliant.diagnose(rec, **python_options)
        assert str(error.value) == message


def test_bad_refine_options_are_usage_errors(examples):
    rec = examples / "phantom_compression" / "EF30_0T_A5"
    for cli_options, python_options in ((["--threads", "300"], {"threads": 300}),
                                        (["--max-strain", "2"], {"max_strain": 2.0}),
                                        (["--estimate", "colour"], {"estimate": "colour"}),
                                        (["--estimator", "guess"], {"estimator": "guess"}),
                                        (["--substeps", "0"], {"substeps": 0})):
        message, status = cli_error("refine", rec, *cli_options)
        assert status == 2
        with pytest.raises(pliant.UsageError) as error:
            pliant.refine(rec, **python_options)
        assert str(error.value) == message


def test_a_malformed_recording_is_an_input_error_naming_file_and_line(foam_copy):
    lines = (foam_copy / "particles.csv").read_text().splitlines()
    lines[118] = lines[118].split(",")[0] + ",40,1,2"
    (foam_copy / "particles.csv").write_text("\n".join(lines) + "\n")
    message, status = cli_error("estimate", foam_copy)
    assert status == 2 and message.startswith("particles.csv:119:")
    with pytest.raises(pliant.InputError) as error:
        pliant.estimate(foam_copy)
    assert str(error.value) == message
    with pytest.raises(pliant.InputError) as error:
        pliant.read_recording(foam_copy)
    assert str(error.value) == message


def test_a_missing_directory_is_an_input_error(tmp_path):
    message, status = cli_error("estimate", tmp_path / "missing")
    assert status == 2
    with pytest.raises(pliant.InputError) as error:
        pliant.estimate(tmp_path / "missing")
    assert str(error.value) == message


def test_a_recording_that_cannot_be_estimated_is_a_pliant_error(tmp_path):
    grid = np.array([[x, y] for y in range(2) for x in range(2)], dtype=float)
    positions = np.repeat(grid[None], 5, axis=0)
    pliant.write_recording(tmp_path / "pinned", np.arange(5) / 10.0, positions, fixed=[0, 1, 2, 3])
    message, status = cli_error("estimate", tmp_path / "pinned")
    assert status == 1
    with pytest.raises(pliant.PliantError) as error:
        pliant.estimate(tmp_path / "pinned")
    assert not isinstance(error.value, ValueError)
    assert str(error.value) == message
