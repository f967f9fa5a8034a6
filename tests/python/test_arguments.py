"""Malformed Python arguments: exceptions with clear messages, never a crash."""

import numpy as np
import pytest

import pliant


def arrays(frames=4, particles=6):
    times = np.arange(frames) / 10.0
    positions = np.zeros((frames, particles, 2))
    positions[:, :, 0] = np.arange(particles)
    return times, positions


def test_wrong_shapes_are_value_errors():
    times, positions = arrays()
    with pytest.raises(ValueError, match=r"positions must have shape \(n_frames, n_particles, dim\)"):
        pliant.make_recording(times, positions[0])
    with pytest.raises(ValueError, match=r"times must have shape \(n_frames,\) = \(4,\), not \(3,\)"):
        pliant.make_recording(times[:3], positions)
    with pytest.raises(ValueError, match="dim"):
        pliant.make_recording(times, np.zeros((4, 6, 4)))
    with pytest.raises(ValueError, match="observed must have shape"):
        pliant.make_recording(times, positions, observed=np.ones((4, 5), dtype=bool))
    with pytest.raises(ValueError, match="masses must have shape"):
        pliant.make_recording(times, positions, masses=np.ones(7))


def test_wrong_types_are_type_errors():
    times, positions = arrays()
    with pytest.raises(TypeError, match="must be an array, not None"):
        pliant.make_recording(None, positions)
    with pytest.raises(TypeError, match="real numbers"):
        pliant.make_recording(times, positions.astype(str))
    with pytest.raises(TypeError, match="real numbers"):
        pliant.make_recording(times, positions.astype(complex))
    with pytest.raises(TypeError, match="boolean"):
        pliant.make_recording(times, positions, observed=np.ones((4, 6)))
    with pytest.raises(TypeError, match="integer ids"):
        pliant.make_recording(times, positions, fixed=[0.5])
    with pytest.raises(TypeError, match="cannot be written as JSON"):
        pliant.make_recording(times, positions, meta={"when": object()})
    with pytest.raises(TypeError, match="unexpected keyword"):
        pliant.make_recording(times, positions, colour="red")
    for bad in (None, 42, 3.5):
        with pytest.raises(TypeError):
            pliant.estimate(bad)
        with pytest.raises(TypeError):
            pliant.read_recording(bad)
    with pytest.raises(TypeError):
        pliant.estimate("x", grid="many")


def test_ids_and_counts_out_of_range(examples):
    times, positions = arrays()
    with pytest.raises(pliant.InputError, match="out of range"):
        pliant.make_recording(times, positions, fixed=[-1])
    with pytest.raises(pliant.InputError, match="out of range"):
        pliant.make_recording(times, positions, driven=[{"id": 99}])
    with pytest.raises(ValueError, match=r"\(id, from_s, to_s\)"):
        pliant.make_recording(times, positions, driven=[(1, 2)])
    with pytest.raises(pliant.UsageError):
        pliant.estimate(examples / "foam_press_medium", grid=-5)
    with pytest.raises(pliant.UsageError):
        pliant.refine(examples / "foam_press_medium", threads=-3)


def test_online_estimator_checks_its_arguments(examples):
    rec = pliant.read_recording(examples / "foam_press_medium")
    with pytest.raises(pliant.UsageError, match="at least 3 candidates"):
        pliant.OnlineEstimator(rec, candidates=-1)
    with pytest.raises(pliant.UsageError, match="rows of steps per frame"):
        pliant.OnlineEstimator(rec, step_candidates=9)
    with pytest.raises(TypeError):
        pliant.OnlineEstimator(None)
    online = pliant.OnlineEstimator(rec)
    with pytest.raises(ValueError, match=r"positions must have shape \(n_particles, dim\) = \(32, 2\)"):
        online.update(0.1, 0.1, np.zeros((31, 2)))
    with pytest.raises(TypeError):
        online.update(0.1, 0.1, None)
    with pytest.raises(TypeError):
        online.update(0.1, 0.1, np.zeros((32, 2), dtype=object))
    assert online.update(0.1, -1.0, rec.positions[1])["status"] == "invalid_argument"
    assert online.rejected_frames == 1


def test_grasp_guard_checks_its_arguments():
    rest = np.array([[x, y] for y in range(3) for x in range(3)], dtype=float) * 0.01
    with pytest.raises(ValueError, match="squeeze_axis must have shape"):
        pliant.GraspGuard(rest, [1.0, 0.0, 0.0])
    with pytest.raises(ValueError, match="unknown option 'max_strian'"):
        pliant.GraspGuard(rest, [1.0, 0.0], max_strian=0.1)
    with pytest.raises(TypeError, match="max_force_n must be a number"):
        pliant.GraspGuard(rest, [1.0, 0.0], max_force_n="10")
    with pytest.raises(pliant.UsageError, match="grasp_guard_init"):
        pliant.GraspGuard(rest, [0.0, 0.0])
    guard = pliant.GraspGuard(rest, [1.0, 0.0])
    with pytest.raises(TypeError, match="gripper must be a dict"):
        guard.update(0.0, gripper=5)
    with pytest.raises(ValueError, match="unknown key 'widht'"):
        guard.update(0.0, gripper={"widht": 0.02})
    with pytest.raises(ValueError, match=r"wrench\['wrench'\] must have shape"):
        guard.update(0.0, wrench={"stamp": 0.0, "wrench": [0.0, 0.0, 1.0]})
    with pytest.raises(ValueError, match="positions must have shape"):
        guard.measure_strain(np.zeros((8, 2)))
