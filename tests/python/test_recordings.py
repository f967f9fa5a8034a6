"""Recordings: read as NumPy views, made from arrays, written and read back, masks."""

import numpy as np
import pytest

import pliant
from conftest import run_cli


def test_read_gives_read_only_views_of_the_recording(examples):
    rec = pliant.read_recording(examples / "foam_press_medium")
    assert (rec.dimension, rec.particle_count, rec.length_unit) == (2, 32, "px")
    assert rec.times.shape == (rec.frame_count,)
    assert rec.positions.shape == (rec.frame_count, 32, 2)
    assert rec.positions.dtype == np.float64
    assert rec.observed.shape == (rec.frame_count, 32) and rec.observed.dtype == np.bool_
    assert rec.rest_positions.shape == (32, 2)
    # Views: no copy, owned by the recording, not writable.
    assert rec.positions.base is rec
    assert np.shares_memory(rec.positions, rec.positions)
    assert not rec.positions.flags.writeable
    with pytest.raises(ValueError):
        rec.positions[0, 0, 0] = 1.0
    assert list(rec.fixed) == list(range(8))
    assert [d["id"] for d in rec.driven] == [28]
    assert rec.wrench is None and rec.gripper is None and rec.mesh is None


def test_a_view_keeps_the_recording_alive(examples):
    positions = pliant.read_recording(examples / "foam_press_medium").positions
    assert np.isfinite(positions[0]).all()  # the Recording object is gone; its memory is not
    assert positions.base.particle_count == 32


def test_round_trip_through_a_directory_is_exact(examples, tmp_path):
    rec = pliant.read_recording(examples / "foam_press_medium")
    pliant.write_recording(tmp_path / "copy", rec)
    back = pliant.read_recording(tmp_path / "copy")
    np.testing.assert_array_equal(back.times, rec.times)
    np.testing.assert_array_equal(back.positions, rec.positions)
    np.testing.assert_array_equal(back.masses, rec.masses)
    assert back.driven == rec.driven
    assert list(back.fixed) == list(rec.fixed)


def test_wrench_and_mesh_round_trip(examples, tmp_path):
    rec = pliant.read_recording(examples / "phantom_compression" / "EF30_0T_A5")
    assert rec.wrench["force"].shape == (rec.wrench["times"].shape[0], 3)
    assert rec.mesh["tetrahedra"].shape[1] == 4
    rec.write(tmp_path / "copy")
    back = pliant.read_recording(tmp_path / "copy")
    for key in ("times", "force", "torque", "applied_to"):
        np.testing.assert_array_equal(back.wrench[key], rec.wrench[key])
    np.testing.assert_array_equal(back.mesh["points"], rec.mesh["points"])
    np.testing.assert_array_equal(back.mesh["tetrahedra"], rec.mesh["tetrahedra"])
    assert back.material == rec.material


def press_arrays(frames=20, seed=3):
    """A small 2D press: 3 x 4 particles, bottom row fixed, the top-right one driven down."""
    grid = np.array([[x, y] for y in range(4) for x in range(3)], dtype=float)
    times = np.arange(frames) / 30.0
    positions = np.repeat(grid[None], frames, axis=0)
    positions[:, 11, 1] -= np.linspace(0.0, 0.4, frames)
    positions += np.random.default_rng(seed).normal(0.0, 1e-3, positions.shape) * (np.arange(frames) > 0)[:, None, None]
    return times, positions


def test_made_recording_round_trips_with_its_mask(tmp_path):
    times, positions = press_arrays()
    observed = np.ones(positions.shape[:2], dtype=bool)
    observed[5:9, 4] = False
    rec = pliant.make_recording(times, positions, observed=observed, fixed=[0, 1, 2], driven=[(11, 0.0, None)],
                                length_unit="m", meta={"source": "test", "frames": 20}, name="made")
    assert np.isnan(rec.positions[5:9, 4]).all()
    np.testing.assert_array_equal(rec.observed, observed)
    assert rec.driven == [{"id": 11, "from": 0.0, "to": float("inf")}]
    pliant.write_recording(tmp_path / "made", rec)
    back = pliant.read_recording(tmp_path / "made")
    np.testing.assert_array_equal(back.observed, observed)
    np.testing.assert_array_equal(back.positions[observed], positions[observed])
    assert back.meta == {"source": "test", "frames": 20}


def test_nan_marks_unobserved_as_the_mask_does(tmp_path):
    times, positions = press_arrays()
    positions[3, 7] = np.nan
    pliant.write_recording(tmp_path / "nan", times, positions, fixed=[0, 1, 2], driven=[11])
    back = pliant.read_recording(tmp_path / "nan")
    assert not back.observed[3, 7] and back.observed.sum() == back.observed.size - 1


def test_a_recording_written_from_python_is_one_the_command_line_reads(tmp_path):
    times, positions = press_arrays(frames=40)
    pliant.write_recording(tmp_path / "py", times, positions, fixed=[0, 1, 2], driven=[11])
    summary = run_cli("estimate", tmp_path / "py", "-q", "--alpha", "fixed=1", "--steps-per-frame", "1",
                      "--cluster-radius", "1.5").stdout
    assert "msm_beta" in summary


def test_make_recording_applies_the_readers_rules():
    times, positions = press_arrays()
    with pytest.raises(pliant.InputError, match="particles.fixed: id 12 out of range 0..11"):
        pliant.make_recording(times, positions, fixed=[12])
    with pytest.raises(pliant.InputError, match="strictly increasing"):
        pliant.make_recording(times[::-1].copy(), positions)
    positions[0, 2] = np.nan
    with pytest.raises(pliant.InputError, match="does not observe particle 2"):
        pliant.make_recording(times, positions)
