"""pliant.estimate against `pliant estimate --json -` on the same input, and the GIL."""

import json
import sys
import threading
import time

import pliant
from conftest import assert_same_document, cli_json


def test_estimate_of_a_path_equals_the_command_line(examples):
    rec = examples / "foam_press_medium"
    assert_same_document(pliant.estimate(rec, quiet=True), cli_json("estimate", rec))


def test_estimate_of_a_recording_in_memory_equals_the_command_line(examples):
    rec = pliant.read_recording(examples / "block_press")
    options = ["--mode", "final", "--alpha", "fixed=1", "--grid", "21"]
    document = pliant.estimate(rec, mode="final", alpha="fixed=1", grid=21, quiet=True)
    assert document["format"] == "pliant-estimate" and document["mode"] == "final"
    assert_same_document(document, cli_json("estimate", examples / "block_press", *options))


def test_numbers_stand_for_the_options_text(examples, tmp_path):
    rec = examples / "foam_press_soft"
    out = tmp_path / "estimate.json"
    document = pliant.estimate(rec, json=out, steps_per_frame=1, cluster_radius=1.5, msm_alpha=1, quiet=True)
    cli = cli_json("estimate", rec, "--steps-per-frame", "1", "--cluster-radius", "1.5", "--msm-alpha", "1")
    assert_same_document(document, cli)
    assert_same_document(json.loads(out.read_text()), cli)


def test_another_thread_runs_during_an_estimate(examples):
    """The estimate releases the GIL: a Python loop keeps running beside it, with no long stall."""
    rec = pliant.read_recording(examples / "block_press")
    sys.setswitchinterval(0.001)
    worker = threading.Thread(target=pliant.estimate, args=(rec,), kwargs={"quiet": True})
    started = time.perf_counter()
    worker.start()
    iterations, longest_stall, last = 0, 0.0, time.perf_counter()
    while worker.is_alive():
        now = time.perf_counter()
        longest_stall = max(longest_stall, now - last)
        last = now
        iterations += 1
    duration = time.perf_counter() - started
    worker.join()
    assert duration > 0.05, f"the estimate took {duration:.3f} s: too short to tell"
    assert iterations > 1000
    assert longest_stall < 0.5 * duration, f"the loop stalled {longest_stall:.3f} s of {duration:.3f} s"
