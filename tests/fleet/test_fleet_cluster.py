"""A batch on a local cluster of 2 workers over 44 recordings, one worker killed in the middle.

The recordings are small simulated presses (some with a concealed effect, several object
classes) and three malformed ones. While the batch runs, one worker process is killed with
SIGKILL while its job's child process is running; the scheduler must rerun that job elsewhere,
the child must die with its worker, and the table must still hold exactly one row per recording.
A second run of the same batch must run nothing and leave the same table.
"""

import csv
import json
import os
import signal
import subprocess
import time

import psutil
import pytest

from conftest import fleet_command, read_summary, set_object, simulate, truncate_csv
from pliant.fleet_table import read_csv

GOOD = 41  # plus 3 malformed: 44 recordings
KILL_AFTER_ROWS = 10


def make_fleet(root, cli):
    """Writes the recordings; returns {path: expected} with expected "ok" or a piece of the error."""
    expected = {}
    classes = ("foam A", "foam B", "sponge")
    effects = {3: "plasticity", 11: "viscosity", 19: "plasticity", 27: "viscosity"}
    for index in range(GOOD):
        path = str(root / classes[index % 3].replace(" ", "_") / f"press_{index:02d}")
        simulate(cli, path, beta=0.15 + 0.5 * (index % 7) / 6, seed=index + 1, effect=effects.get(index))
        set_object(path, classes[index % 3])
        expected[path] = "ok"

    bad_json = str(root / "malformed" / "bad_json")
    simulate(cli, bad_json, seed=101)
    with open(os.path.join(bad_json, "recording.json"), "w") as stream:
        stream.write('{"format": "pliant-recording", "version": 1,, }\n')
    expected[bad_json] = "pliant diagnose: recording.json"

    no_particles = str(root / "malformed" / "no_particles")
    simulate(cli, no_particles, seed=102)
    set_object(no_particles, "broken")
    os.unlink(os.path.join(no_particles, "particles.csv"))
    expected[no_particles] = "pliant diagnose: particles.csv: no such file"

    truncated = str(root / "malformed" / "truncated_csv")
    simulate(cli, truncated, seed=103)
    set_object(truncated, "broken")
    truncate_csv(os.path.join(truncated, "particles.csv"))
    expected[truncated] = "pliant diagnose: particles.csv:"
    return expected


def running_jobs(batch_pid):
    """[(worker process, job process)] for each worker of the batch's cluster running a job."""
    pairs = []
    for worker in psutil.Process(batch_pid).children():
        try:
            if not any("spawn_main" in part for part in worker.cmdline()):
                continue  # not a worker (multiprocessing's resource tracker)
            jobs = [child for child in worker.children(recursive=True) if child.name() == "pliant"]
        except psutil.NoSuchProcess:
            continue
        if jobs:
            pairs.append((worker, jobs[0]))
    return pairs


def rows_written(out):
    try:
        with open(os.path.join(out, "journal.jsonl")) as stream:
            return sum(1 for line in stream if line.endswith("\n"))
    except FileNotFoundError:
        return 0


def kill_a_worker_mid_job(batch, out, deadline):
    """Once KILL_AFTER_ROWS rows are written, SIGKILLs a worker whose job is running; returns
    the job's process, which must not outlive its worker, the job's recording and the addresses
    the worker listened on."""
    while time.monotonic() < deadline:
        assert batch.poll() is None, "the batch ended before a worker could be killed"
        if rows_written(out) >= KILL_AFTER_ROWS:
            pairs = running_jobs(batch.pid)
            if pairs:
                worker, job = pairs[0]
                try:
                    recording = job.cmdline()[2]  # pliant diagnose RECORDING --json ...
                    ports = [c.laddr.port for c in worker.connections("tcp") if c.status == psutil.CONN_LISTEN]
                except psutil.NoSuchProcess:
                    continue  # the job ended meanwhile: take another
                os.kill(worker.pid, signal.SIGKILL)
                return job, recording, {f"tcp://127.0.0.1:{port}" for port in ports}
        time.sleep(0.05)
    pytest.fail("no worker ran a job in time")


def test_a_worker_killed_mid_batch_loses_and_doubles_nothing(tmp_path, cli):
    expected = make_fleet(tmp_path / "recordings", cli)
    assert len(expected) == 44
    out = str(tmp_path / "out")
    command = fleet_command(tmp_path / "recordings", "-o", out, "--workers", "2", "--timeout", "120", "--quiet")
    started = time.monotonic()
    batch = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        orphan, killed_recording, killed_worker = kill_a_worker_mid_job(batch, out, started + 120)
        stdout, stderr = batch.communicate(timeout=180)
    finally:
        if batch.poll() is None:
            batch.kill()
    assert batch.returncode == 0, stderr
    try:
        orphan.wait(timeout=10)  # the job's child died with its worker (parent-death signal)
    except psutil.TimeoutExpired:
        pytest.fail(f"the job of the killed worker (pid {orphan.pid}) is still running")

    rows = read_csv(os.path.join(out, "results.csv"))
    by_recording = {}
    for row in rows:
        by_recording.setdefault(row["recording"], []).append(row)
    assert sorted(by_recording) == sorted(expected)
    assert all(len(found) == 1 for found in by_recording.values()), "a recording with more than one row"
    assert len({row["key"] for row in rows}) == len(rows)
    with open(os.path.join(out, "results.jsonl")) as stream:
        assert [json.loads(line) for line in stream] == rows  # the same table in JSON lines
    with open(os.path.join(out, "journal.jsonl")) as stream:
        assert sorted(json.loads(line)["key"] for line in stream) == sorted(row["key"] for row in rows)

    for path, outcome in expected.items():
        row = by_recording[path][0]
        assert row["job"] == "diagnose"
        if outcome == "ok":
            assert row["status"] == "ok", row
            assert row["verdict"] in ("consistent", "missing_physics"), row
            assert row["effect"] and 0 <= row["msm_beta"] <= 1 and row["runtime_s"] > 0, row
            assert row["object"] in ("foam A", "foam B", "sponge")
            assert row["error"] is None and row["exit_status"] == 0
        else:
            assert row["status"] == "error" and row["exit_status"] == 2, row
            assert row["error"].startswith(outcome), row
            assert row["verdict"] is None and row["msm_beta"] is None
    # The killed worker's job ran again, once, elsewhere: its row counts two attempts.
    rerun = by_recording[killed_recording][0]
    assert rerun["attempts"] == 2, rerun
    assert killed_worker and rerun["worker"] not in killed_worker, (rerun, killed_worker)
    assert {row["attempts"] for row in rows} <= {1, 2}

    summary = read_summary(out)
    assert summary["batch"]["ran"] == 44 and summary["batch"]["skipped"] == 0 and summary["batch"]["lost"] == 0
    assert summary["errors"] == 3 and summary["recordings"] == 44
    ok_rows = [row for row in rows if row["status"] == "ok"]
    assert sum(summary["effects"].values()) == len(ok_rows) == 41
    for effect, count in summary["effects"].items():
        assert count == sum(1 for row in ok_rows if row["effect"] == effect)
    assert summary["objects_per_class"] == {"(no class)": 1, "broken": 2, "foam A": 14, "foam B": 14, "sponge": 13}
    spread = {item["object"]: item for item in summary["spread"]}
    assert spread["foam A"]["n"] == 14 and spread["sponge"]["n"] == 13
    assert "44 recordings, 44 rows: diagnose 44 (3 errors)" in stdout

    with open(os.path.join(out, "results.csv"), "rb") as stream:
        table = stream.read()
    again = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert again.returncode == 0, again.stderr
    assert "this batch: 0 jobs ran, 44 done before" in again.stdout
    summary = read_summary(out)
    assert summary["batch"]["ran"] == 0 and summary["batch"]["skipped"] == 44
    with open(os.path.join(out, "results.csv"), "rb") as stream:
        assert stream.read() == table
    with open(os.path.join(out, "results.csv")) as stream:
        assert len(list(csv.reader(stream))) == 45
