"""`pliant batch`: the C++ command running the fleet, with the package directory and the program
it was built with; its errors when Python pieces are missing; and a batch on a running Dask
scheduler whose worker has no pliant Python package at all."""

import json
import os
import shutil
import subprocess
import sys
import time

from conftest import package_dir, read_summary, simulate
from pliant.fleet_table import read_csv



def clean_environment():
    """The environment of a user: no PYTHONPATH, no PLIANT_CLI (pliant batch sets both)."""
    return {name: value for name, value in os.environ.items()
            if name not in ("PYTHONPATH", "PLIANT_CLI", "PLIANT_PYTHONPATH")}


def pliant(cli, *arguments, env=None, timeout=180, cwd=None):
    return subprocess.run([cli, *map(str, arguments)], capture_output=True, text=True, timeout=timeout,
                          env=env if env is not None else clean_environment(), cwd=cwd)


def test_help_is_the_fleets(cli):
    result = pliant(cli, "batch", "--help")
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("usage: pliant batch")
    for option in ("--scheduler", "--workers", "--jobs", "--diagnose-options", "--retry-errors"):
        assert option in result.stdout
    listing = pliant(cli, "--help")
    assert "batch" in listing.stdout


def test_small_batches_through_the_command_line(tmp_path, cli, examples):
    """Three batches into one results directory: estimate on two presses; refine on a list of
    them and a real compression test; the first again, which finds everything done. The presses
    are in a directory named like a pliant command: it must reach the fleet as a directory."""
    for index in range(2):
        simulate(cli, tmp_path / "estimate" / f"p{index}", beta=0.2 + 0.3 * index, seed=index + 5)
    shutil.copytree(os.path.join(examples, "phantom_compression", "EF30_0T_A5"), tmp_path / "phantom")
    (tmp_path / "list.txt").write_text("estimate/p0\nestimate/p1\nphantom\n")
    out = tmp_path / "out"
    estimate = ["batch", "estimate", "-o", out, "--workers", 1, "--jobs", "estimate", "--quiet"]
    first = pliant(cli, *estimate, cwd=tmp_path)
    assert first.returncode == 0, first.stderr
    assert "2 recordings, 2 rows: estimate 2 (0 errors)" in first.stdout
    assert "this batch: 2 jobs ran, 0 done before" in first.stdout
    rows = {os.path.basename(row["recording"]): row for row in read_csv(out / "results.csv")}
    for name in ("p0", "p1"):
        assert rows[name]["status"] == "ok" and 0 <= rows[name]["msm_beta"] <= 1 and rows[name]["msm_beta_sd"] > 0
        assert rows[name]["verdict"] is None and rows[name]["attempts"] == 1 and rows[name]["job"] == "estimate"

    second = pliant(cli, "batch", tmp_path / "list.txt", "-o", out, "--workers", 1, "--jobs", "refine",
                    "--refine-options=--max-strain 0.1", "--quiet")
    assert second.returncode == 0, second.stderr
    rows = {os.path.basename(row["recording"]): row for row in read_csv(out / "results.csv")}
    assert sorted(rows) == ["p0", "p1", "phantom"]
    for name in ("p0", "p1"):  # 2D image-plane presses: no material card
        assert rows[name]["status"] == "error" and rows[name]["exit_status"] == 2
        assert rows[name]["error"].startswith("pliant refine: "), rows[name]
    card = rows["phantom"]
    assert card["status"] == "ok" and card["exit_status"] == 0 and card["job"] == "refine", card
    assert 5e4 < card["youngs_modulus"] < 5e5 and card["youngs_modulus_sd"] > 0
    assert card["parameters"]["youngs_modulus"] == card["youngs_modulus"]
    summary = read_summary(out)
    assert summary["batch"] == dict(summary["batch"], workers=1, ran=3, skipped=0, recordings=3)
    assert summary["jobs"] == {"refine": {"rows": 3, "ok": 1, "errors": 2, "pending": 0}}

    third = pliant(cli, *estimate, cwd=tmp_path)
    assert third.returncode == 0, third.stderr
    assert "this batch: 0 jobs ran, 2 done before" in third.stdout
    assert [row["job"] for row in read_csv(out / "results.csv")] == ["estimate", "estimate"]


def test_missing_python_pieces_exit_2(tmp_path, cli):
    env = clean_environment()
    env["PLIANT_PYTHONPATH"] = str(tmp_path / "nowhere")
    result = pliant(cli, "batch", tmp_path, "-o", tmp_path / "out", env=env)
    assert result.returncode == 2
    assert "pliant batch: the fleet's Python package (pliant/fleet.py) is in none of" in result.stderr
    assert "install python3-pliant or set PLIANT_PYTHONPATH" in result.stderr

    fake = tmp_path / "without_dask" / "distributed"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ImportError('this machine has no Dask')\n")
    env["PLIANT_PYTHONPATH"] = f"{fake.parent}:{package_dir()}"
    result = pliant(cli, "batch", tmp_path, "-o", tmp_path / "out", env=env)
    assert result.returncode == 2
    assert result.stderr == "pliant batch: Dask distributed is not installed: apt-get install python3-distributed\n"


def start(command, env):
    return subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)


def test_a_batch_on_a_running_scheduler(tmp_path, cli):
    """The workers of a real cluster: started apart, without this package on their path."""
    env = clean_environment()
    scheduler_file = tmp_path / "scheduler.json"
    scheduler = start([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", "0",
                       "--no-dashboard", "--scheduler-file", str(scheduler_file)], env)
    worker = None
    try:
        for _ in range(300):
            if scheduler_file.exists() and scheduler_file.stat().st_size > 0:
                break
            assert scheduler.poll() is None, scheduler.stderr.read().decode()
            time.sleep(0.1)
        address = json.loads(scheduler_file.read_text())["address"]
        worker = start([sys.executable, "-m", "distributed.cli.dask_worker", address, "--host", "127.0.0.1",
                        "--nthreads", "1", "--no-dashboard", "--local-directory", str(tmp_path / "worker")],
                       dict(env, PATH="/usr/bin:/bin"))
        for index in range(2):
            simulate(cli, tmp_path / "presses" / f"p{index}", seed=index + 20)
        out = tmp_path / "out"
        result = pliant(cli, "batch", tmp_path / "presses", "-o", out, "--scheduler", address, "--jobs", "estimate",
                        "--quiet")
        assert result.returncode == 0, result.stderr
        rows = read_csv(out / "results.csv")
        assert [row["status"] for row in rows] == ["ok", "ok"], rows
        assert all(row["worker"].startswith("tcp://127.0.0.1:") for row in rows), rows
        assert all(row["attempts"] == 1 for row in rows)
        assert read_summary(out)["batch"]["scheduler"] == address
    finally:
        for process in (worker, scheduler):
            if process is not None:
                process.terminate()
                try:
                    process.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    process.kill()
                    process.wait()
