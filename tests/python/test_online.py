"""pliant.OnlineEstimator against `pliant replay --stepped`: frame by frame, the same estimates."""

import json
import math

import pliant
from conftest import run_cli

FIELDS = ("msm_beta", "msm_beta_std", "msm_alpha", "rms")


def replay_estimates(recording, *options):
    lines = run_cli("replay", "--stepped", *options, recording).stdout.splitlines()
    events = [json.loads(line) for line in lines]
    return [e["estimate"] for e in events if e.get("device") == "particles" and "estimate" in e]


def python_estimates(rec, **settings):
    online = pliant.OnlineEstimator(rec, **settings)
    t = rec.times
    out = []
    for k in range(1, rec.frame_count):
        dt = (t[k] - t[0]) - (t[k - 1] - t[0])  # the replay's stamps are recorded times from the start
        out.append(online.update(t[k], dt, rec.positions[k]))
    return online, out


def assert_same_estimates(python, replay):
    assert len(python) == len(replay) > 0
    for index, (p, r) in enumerate(zip(python, replay)):
        for field in FIELDS:
            if r[field] is None:
                assert not math.isfinite(p[field]), (index, field)
            else:
                assert math.isclose(p[field], r[field], rel_tol=1e-12, abs_tol=1e-15), (index, field, p[field], r[field])
        assert p["alpha_fitted"] == r["alpha_fitted"] and p["steps_per_frame"] == r["steps_per_frame"], index
        assert p["frames"] == r["frames"] and p["status"] == r["update"], index


def test_default_rows_follow_the_replay_frame_by_frame(examples):
    path = examples / "foam_press_medium"
    online, python = python_estimates(pliant.read_recording(path))
    assert_same_estimates(python, replay_estimates(path))
    assert abs(python[-1]["msm_beta"] - 0.5) < 0.15
    assert online.estimate()["frames"] == python[-1]["frames"]


def test_held_alpha_with_the_quasi_static_row(examples):
    path = examples / "block_press"
    _, python = python_estimates(pliant.read_recording(path), alpha_candidates=1, step_candidates=1, msm_alpha=1.0,
                                 settled_row=16)
    assert_same_estimates(python, replay_estimates(path, "--msm-alpha", "1", "--settled-row", "16"))


def test_reset_forgets_the_evidence(examples):
    rec = pliant.read_recording(examples / "foam_press_soft")
    online, python = python_estimates(rec, alpha_candidates=1, step_candidates=1)
    assert python[-1]["frames"] == rec.frame_count - 1
    online.reset()
    assert online.estimate()["frames"] == 0
