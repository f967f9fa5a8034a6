"""One fleet task, on a Dask worker: the `pliant` command line in a child process, its JSON read back.

The job runs in a child process, never in the worker itself, so a crash or a hang in native code
costs one row: a crash is the child's exit status, a hang is killed at the task's timeout, and
the worker goes on with the next task. The child asks the kernel for SIGKILL when the worker
that started it dies (setpriv --pdeathsig), so a worker killed mid-task leaves no orphan behind.

Only the standard library: the batch sends this module's code to the workers and the scheduler
by value, so they need Dask and the `pliant` program, not this package.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import signal
import socket
import subprocess
import tempfile
import time

JOBS = ("diagnose", "refine", "estimate")
# Exit statuses of the command line (host/cli/exit_status.hpp): the job ran to its end.
EXIT_OK, EXIT_FAILURE, EXIT_USAGE = 0, 1, 2


def run_job(spec):
    """Runs one job and returns its result fields (fleet_table.COLUMNS less those the batch fills).

    spec: {"recording": absolute directory, "job": one of JOBS, "options": [str],
    "cli": path of pliant, "timeout_s": float}. Never raises for a failure of the job: the
    returned fields say it in "status", "exit_status" and "error".
    """
    fields = {"status": "error", "exit_status": None, "error": None, "worker": _worker_name(), "runtime_s": None}
    cli = spec["cli"]
    if not (os.path.isfile(cli) and os.access(cli, os.X_OK)):
        fields["error"] = f"the pliant command line {cli} is missing or not executable on this worker"
        return fields
    with tempfile.TemporaryDirectory(prefix="pliant-fleet-") as scratch:
        output = os.path.join(scratch, "result.json")
        command = [cli, spec["job"], spec["recording"], "--json", output, "--quiet", *spec["options"]]
        setpriv = shutil.which("setpriv")
        if setpriv:
            command = [setpriv, "--pdeathsig", "KILL", *command]
        started = time.monotonic()
        try:
            child = subprocess.Popen(command, cwd=scratch, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                     stderr=subprocess.PIPE, start_new_session=True)
        except OSError as error:
            fields["error"] = f"cannot run {cli}: {error.strerror or error}"
            return fields
        try:
            _, stderr = child.communicate(timeout=spec["timeout_s"])
        except subprocess.TimeoutExpired:
            _kill_group(child)
            fields["runtime_s"] = round(time.monotonic() - started, 3)
            fields["error"] = f"pliant {spec['job']} timed out after {spec['timeout_s']:g} s and was killed"
            return fields
        fields["runtime_s"] = round(time.monotonic() - started, 3)
        fields["exit_status"] = child.returncode
        message = cli_message(stderr.decode("utf-8", "replace"))
        if child.returncode != EXIT_OK:
            fields["error"] = failure_message(spec["job"], child.returncode, message)
            return fields
        try:
            with open(output, encoding="utf-8") as stream:
                document = json.load(stream)
        except (OSError, ValueError) as error:
            fields["error"] = f"pliant {spec['job']} exited 0 but its JSON could not be read: {error}"
            return fields
    fields.update(result_fields(spec["job"], document))
    fields["status"] = "ok"
    return fields


def suspicious_counts(keys, dask_scheduler=None):
    """Run on the scheduler (Client.run_on_scheduler): for each task key it still knows, how
    many times a worker died while the task was assigned to it."""
    counts = {}
    for key in keys:
        state = dask_scheduler.tasks.get(key)
        if state is not None:
            counts[key] = state.suspicious
    return counts


def _kill_group(child):
    try:
        os.killpg(child.pid, signal.SIGKILL)  # the child leads its own session: it and its children
    except ProcessLookupError:
        pass
    child.communicate()


def _worker_name():
    try:
        from distributed import get_worker

        return get_worker().address
    except (ImportError, ValueError):
        return f"{socket.gethostname()}:{os.getpid()}"


def cli_message(stderr):
    """The command line's own error lines ("pliant diagnose: recording.json: ..."), warnings left out."""
    lines = [line.strip() for line in stderr.splitlines()]
    errors = [line for line in lines if line and not line.startswith("pliant: warning:")]
    return " ".join(errors)


def failure_message(job, status, message):
    """The row's error for a job that ended with `status` (negative: killed by that signal)."""
    if status < 0:
        try:
            name = signal.Signals(-status).name
        except ValueError:
            name = f"signal {-status}"
        text = f"pliant {job} was killed by {name}"
        return text + (": " + message if message else "")
    if message:
        return message
    return f"pliant {job} exited with status {status}"


def _number(value):
    """A finite float, else None (JSON null, or a value the command line did not give)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def _object(value):
    return value if isinstance(value, dict) else {}


def result_fields(job, document):
    """The table's fields from one command's JSON: diagnosis-v1 (diagnose), pliant-estimate
    (estimate) or the pliant-material card (refine), docs/spec/."""
    fields = {}
    if job == "diagnose":
        baseline = _object(document.get("baseline"))
        parameters = _object(baseline.get("parameters"))
        fields["verdict"] = document.get("verdict")
        fields["effect"] = document.get("effect")
        fields["improvement"] = _number(document.get("improvement"))
        fields["rms"] = _number(baseline.get("rms"))
        fields["noise_rms"] = _number(document.get("noise_rms"))
        fields["parameters"] = parameters or None
        if document.get("effect") not in (None, "none", "unknown"):
            fields["effect_parameters"] = _object(_object(document.get("augmented")).get("parameters")) or None
        uncertainty = {}
    else:
        parameters = _object(document.get("parameters"))
        uncertainty = _object(document.get("uncertainty"))
        fields["rms"] = _number(document.get("rms"))
        fields["parameters"] = parameters or None
        fields["uncertainty"] = uncertainty or None
    fields["msm_beta"] = _number(parameters.get("msm_beta"))
    fields["msm_beta_sd"] = _number(uncertainty.get("msm_beta"))
    fields["msm_alpha"] = _number(parameters.get("msm_alpha"))
    fields["youngs_modulus"] = _number(parameters.get("youngs_modulus"))
    fields["youngs_modulus_sd"] = _number(uncertainty.get("youngs_modulus"))
    return fields
