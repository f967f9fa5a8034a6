"""pliant fleet: `diagnose`, `refine` and `estimate` over many recordings on Dask distributed.

    python3 -m pliant.fleet RECORDINGS... -o OUT [--jobs diagnose,refine] [--workers N | --scheduler ADDR]

(`pliant batch` runs this module.) Each (recording, job) is one Dask task; the task runs the
`pliant` command line in a child process (fleet_task.py) and returns one row. Rows are appended
to OUT/journal.jsonl as they arrive, keyed by the recording's content and the job
(fleet_inputs.py), so a batch that is stopped, killed or run again goes on where it was. At the
end the table of the batch (OUT/results.csv and OUT/results.jsonl, one row per recording and
job) and OUT/summary.json are written from the journal (fleet_table.py). docs/fleet.md.

Exit status: 0 the batch ran (rows may carry errors: see the summary), 1 the batch could not
finish (the scheduler was lost; what was done is kept), 2 bad arguments, Dask missing, or a
scheduler that cannot be reached.
"""

from __future__ import annotations

import argparse
import datetime
import importlib
import json
import logging
import os
import shlex
import shutil
import sys
import time

from . import fleet_task
from .fleet_inputs import UsageError, absolute_option_files, describe_recording, find_recordings, task_key
from .fleet_table import (Journal, JournalBusy, csv_text, is_final, json_line, normalized_row, summarize,
                          summary_text, write_atomically)

EXIT_OK, EXIT_FAILURE, EXIT_USAGE = 0, 1, 2
# Times the scheduler may lose a task's worker before the row gets an error instead: a worker
# rarely dies because of its task (the job runs in a child), so a few reruns are cheap, and a
# task that keeps killing workers stops doing so.
ALLOWED_FAILURES = 3
# Options the batch sets itself on every job.
RESERVED_OPTIONS = ("--json", "--report", "--vtk", "--rest-mesh", "-q", "--quiet")


class FleetFailure(Exception):
    """The batch could not finish (exit 1); the rows already written are kept."""


def program_name():
    return os.environ.get("PLIANT_FLEET_PROG", "python3 -m pliant.fleet")


def build_parser():
    parser = argparse.ArgumentParser(
        prog=program_name(),
        description="Run pliant diagnose, refine or estimate over many recordings on Dask distributed: an "
        "embedded local cluster, or a running scheduler. One row per recording and job in OUT/results.csv and "
        "OUT/results.jsonl, a fleet summary in OUT/summary.json. Results are kept by the recordings' content in "
        "OUT/journal.jsonl: run the same batch again and only what is not done runs.",
        epilog="Job options are the command line's own (pliant diagnose --help ...), given as one string, e.g. "
        "--diagnose-options='--model fem'. Exit status: 0 the batch ran (rows may hold errors), 1 it could not "
        "finish (rerun to go on), 2 bad arguments, Dask missing or no scheduler. docs/fleet.md",
    )
    parser.add_argument("sources", nargs="+", metavar="RECORDINGS",
                        help="a directory (every directory below it holding a recording.json) or a list file "
                        "(one recording directory per line, relative to the file)")
    parser.add_argument("-o", "--output", required=True, metavar="DIR",
                        help="results directory (created; a rerun into it skips what is done)")
    parser.add_argument("--jobs", default="diagnose", metavar="LIST",
                        help="comma-separated: diagnose, refine, estimate (default: diagnose)")
    for job in fleet_task.JOBS:
        parser.add_argument(f"--{job}-options", default="", metavar="OPTIONS",
                            help=f"options for every pliant {job}, as one shell-quoted string")
    parser.add_argument("--workers", type=int, default=None, metavar="N",
                        help="local cluster: worker processes, one job at a time each (default: the number of "
                        "cores)")
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help="use the Dask scheduler at ADDRESS (tcp://host:8786) instead of a local cluster")
    parser.add_argument("--connect-timeout", type=float, default=10.0, metavar="S",
                        help="seconds to wait for --scheduler (default: 10)")
    parser.add_argument("--timeout", type=float, default=1800.0, metavar="S",
                        help="seconds one job may run before it is killed and its row gets an error "
                        "(default: 1800)")
    parser.add_argument("--cli", metavar="PATH",
                        help="the pliant program the workers run (default: $PLIANT_CLI, else pliant on PATH)")
    parser.add_argument("--class-key", default="meta.object", metavar="PATH",
                        help="dotted path in recording.json naming the object class (default: meta.object)")
    parser.add_argument("--retry-errors", action="store_true",
                        help="run again the jobs whose rows hold an error (by default only those that did not "
                        "end: timeouts, crashes, lost workers)")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    return parser


class Config:
    """A checked batch request (see build_parser for the meaning of each field)."""

    def __init__(self, args):
        self.sources = args.sources
        self.output = args.output
        self.jobs = parse_jobs(args.jobs)
        self.options = {job: job_options(job, getattr(args, f"{job}_options")) for job in self.jobs}
        if args.workers is not None and args.workers < 1:
            raise UsageError("--workers must be at least 1")
        if args.workers is not None and args.scheduler:
            raise UsageError("--workers is for the local cluster; a --scheduler has its own workers")
        self.workers = args.workers or os.cpu_count() or 1
        self.scheduler = args.scheduler
        if not args.connect_timeout > 0:
            raise UsageError("--connect-timeout must be > 0")
        self.connect_timeout = args.connect_timeout
        if not args.timeout > 0:
            raise UsageError("--timeout must be > 0")
        self.timeout_s = args.timeout
        self.cli = resolve_cli(args.cli)
        if not args.class_key or any(not part for part in args.class_key.split(".")):
            raise UsageError(f"--class-key must be a dotted path such as meta.object, not '{args.class_key}'")
        self.class_key = args.class_key
        self.retry_errors = args.retry_errors
        self.quiet = args.quiet


def parse_jobs(text):
    jobs = []
    for job in (part.strip() for part in text.split(",")):
        if job not in fleet_task.JOBS:
            raise UsageError(f"--jobs: '{job}' is not one of " + ", ".join(fleet_task.JOBS))
        if job not in jobs:
            jobs.append(job)
    return jobs


def job_options(job, text):
    try:
        options = shlex.split(text)
    except ValueError as error:
        raise UsageError(f"--{job}-options: {error}") from None
    if options and not options[0].startswith("-"):
        raise UsageError(f"--{job}-options: '{options[0]}' is not an option (the batch gives the recording)")
    for option in options:
        if option.split("=", 1)[0] in RESERVED_OPTIONS:
            raise UsageError(f"--{job}-options: {option.split('=', 1)[0]} is set by the batch")
    return absolute_option_files(options)


def resolve_cli(argument):
    """The pliant program: the --cli argument, else $PLIANT_CLI, else pliant on PATH."""
    candidate = argument or os.environ.get("PLIANT_CLI") or shutil.which("pliant")
    if not candidate:
        raise UsageError("cannot find the pliant command line: pass --cli PATH, set PLIANT_CLI or put pliant on PATH")
    if os.sep not in candidate:
        found = shutil.which(candidate)
        candidate = found or candidate
    candidate = os.path.abspath(candidate)
    if not (os.path.isfile(candidate) and os.access(candidate, os.X_OK)):
        raise UsageError(f"{candidate} is not an executable pliant command line")
    return candidate


class Progress:
    """A progress bar on stderr (tqdm when installed), off when stderr is not a terminal or --quiet."""

    def __init__(self, total, skipped, enabled):
        self.enabled = enabled and sys.stderr.isatty()
        self.errors = 0
        self.bar = None
        self.done = 0
        self.total = total
        if not self.enabled:
            return
        try:
            from tqdm import tqdm
        except ImportError:
            tqdm = None
        description = f"{program_name()} ({skipped} done before)" if skipped else program_name()
        if tqdm is not None:
            self.bar = tqdm(total=total, desc=description, unit="job", file=sys.stderr, dynamic_ncols=True)
        else:
            self.description = description
            self._draw()

    def _draw(self):
        sys.stderr.write(f"\r{self.description}: {self.done}/{self.total} jobs, {self.errors} errors")
        sys.stderr.flush()

    def update(self, row):
        self.done += 1
        if row.get("status") != "ok":
            self.errors += 1
        if not self.enabled:
            return
        if self.bar is not None:
            self.bar.set_postfix(errors=self.errors, refresh=False)
            self.bar.update(1)
        else:
            self._draw()

    def close(self):
        if not self.enabled:
            return
        if self.bar is not None:
            self.bar.close()
        else:
            sys.stderr.write("\n")


def open_client(config):
    """A Dask client: on the scheduler at config.scheduler, or on a new local cluster."""
    import dask
    from distributed import Client, LocalCluster

    if config.scheduler:
        try:
            return Client(config.scheduler, timeout=config.connect_timeout), None
        except (OSError, ValueError, TypeError) as error:
            raise UsageError(f"cannot reach the Dask scheduler at {config.scheduler}: {error}") from None
    settings = {
        "distributed.scheduler.allowed-failures": ALLOWED_FAILURES,
        # One task per one-thread worker at a time: the rest wait on the scheduler, so a worker
        # that dies holds one task, and a new worker takes the next at once.
        "distributed.scheduler.worker-saturation": 1.0,
    }
    with dask.config.set(settings):
        cluster = LocalCluster(n_workers=config.workers, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.ERROR)
    return Client(cluster), cluster


def plan_batch(config, recordings):
    """The batch's entries, one per (recording, job) in table order, each {"recording", "key",
    "job", "object"}; and {key: task spec} (copies of one recording share a key: one task)."""
    entries = []
    tasks = {}
    for recording in recordings:
        for job in config.jobs:
            key = task_key(recording, job, config.options[job])
            entries.append({"recording": recording.path, "key": key, "job": job, "object": recording.object})
            if key not in tasks:
                tasks[key] = {"recording": recording.abspath, "job": job, "options": config.options[job],
                              "cli": config.cli, "timeout_s": config.timeout_s}
    return entries, tasks


def run_batch(config, out=sys.stdout):
    """Runs the batch `config` describes; returns the summary (also written to OUT/summary.json).

    The table and the summary are written from the journal even when the batch is interrupted
    (KeyboardInterrupt is raised again after that).
    """
    recordings = [describe_recording(path, config.class_key) for path in find_recordings(config.sources)]
    entries, tasks = plan_batch(config, recordings)
    try:
        journal = Journal(config.output)
    except JournalBusy as error:
        raise UsageError(str(error)) from None
    except OSError as error:
        raise UsageError(f"cannot write into {config.output}: {error.strerror or error}") from None
    keys_to_run = [key for key in tasks if not _done(journal.rows.get(key), config.retry_errors)]
    stats = {"ran": 0, "lost": 0, "startup_s": 0.0, "run_s": 0.0}
    started = time.monotonic()
    try:
        if keys_to_run:
            first_entry = {}
            for entry in entries:
                first_entry.setdefault(entry["key"], entry)
            _run_tasks(config, tasks, keys_to_run, first_entry, journal, stats)
    except UsageError:  # no cluster to run on: nothing ran, nothing to write
        journal.close()
        raise
    except BaseException:
        _finish(config, journal, entries, tasks, keys_to_run, stats, time.monotonic() - started)
        raise
    summary = _finish(config, journal, entries, tasks, keys_to_run, stats, time.monotonic() - started)
    _report(summary, config.output, out)
    if stats["lost"]:
        raise FleetFailure(f"{stats['lost']} jobs were lost with the scheduler; run the batch again to finish them")
    return summary


def table_rows(entries, journal_rows):
    """The table: for each entry its journal row, under the entry's own path and class (a copy
    or a moved recording shows where it is now); an entry without one is "pending"."""
    rows = []
    for entry in entries:
        stored = journal_rows.get(entry["key"])
        if stored is None:
            rows.append(normalized_row(dict(entry, status="pending",
                                            error="not run: the batch stopped first; the next batch runs it")))
        else:
            rows.append(normalized_row(dict(stored, **entry)))
    return rows


def _finish(config, journal, entries, tasks, keys_to_run, stats, wall_s):
    """Writes results.csv, results.jsonl and summary.json from the journal, then compacts it."""
    try:
        rows = table_rows(entries, journal.rows)
        summary = summarize(rows, config.class_key)
        summary["batch"] = {
            "recordings": len({entry["recording"] for entry in entries}), "jobs": len(tasks),
            "ran": stats["ran"], "skipped": len(tasks) - len(keys_to_run), "lost": stats["lost"],
            "not_run": len(keys_to_run) - stats["ran"],
            "wall_s": round(wall_s, 3), "startup_s": round(stats["startup_s"], 3), "run_s": round(stats["run_s"], 3),
            "jobs_per_s": round(stats["ran"] / stats["run_s"], 4) if stats["ran"] and stats["run_s"] > 0 else None,
            "workers": None if config.scheduler else config.workers, "scheduler": config.scheduler,
        }
        write_atomically(os.path.join(config.output, "results.csv"), csv_text(rows))
        write_atomically(os.path.join(config.output, "results.jsonl"), "".join(json_line(row) for row in rows))
        write_atomically(os.path.join(config.output, "summary.json"), _json_text(summary))
        journal.compact()
    finally:
        journal.close()
    return summary


def _report(summary, output, out):
    batch = summary["batch"]
    out.write(summary_text(summary))
    line = f"this batch: {batch['ran']} jobs ran, {batch['skipped']} done before"
    if batch["ran"]:
        line += f", {batch['run_s']:.1f} s ({batch['jobs_per_s']:.3g} jobs/s) after {batch['startup_s']:.1f} s start-up"
    if batch["not_run"]:
        line += f"; {batch['not_run']} not run"
    out.write(line + "\n")
    out.write("wrote " + ", ".join(os.path.join(output, name)
                                   for name in ("results.csv", "results.jsonl", "summary.json")) + "\n")


def _json_text(document):
    return json.dumps(document, indent=2, allow_nan=False) + "\n"


def _done(row, retry_errors):
    if row is None:
        return False
    if row.get("status") == "ok":
        return True
    return is_final(row) and not retry_errors


def _run_tasks(config, tasks, keys_to_run, first_entry, journal, stats):
    """Runs the keys `keys_to_run` on the cluster, appending each row to `journal` as it arrives. Counts
    in `stats` the rows written ("ran"), the tasks lost with the scheduler ("lost": no row, the
    next batch runs them), the cluster's start-up and the time from submission to the last row."""
    try:
        from distributed import as_completed
    except ImportError:
        raise UsageError("Dask distributed is not installed: apt-get install python3-distributed") from None
    import cloudpickle

    # The workers and the scheduler get fleet_task's code by value: they need Dask and the pliant
    # program, not this package.
    cloudpickle.register_pickle_by_value(fleet_task)
    opened = time.monotonic()
    client, cluster = open_client(config)
    submitted = time.monotonic()
    stats["startup_s"] = submitted - opened
    written = set()
    progress = Progress(len(keys_to_run), len(tasks) - len(keys_to_run), not config.quiet)
    try:
        # One graph for the whole batch: the scheduler then sees a group of many like tasks and
        # queues them, handing each worker one at a time (submitted one by one, the first few
        # would each be sent to a worker at once).
        submitted_futures = client.map(fleet_task.run_job, [tasks[key] for key in keys_to_run],
                                       key=[f"pliant-{key}" for key in keys_to_run], pure=False)
        futures = dict(zip(submitted_futures, keys_to_run))
        for batch in as_completed(list(futures), with_results=False).batches():
            suspicious = _ask_suspicious(client, [future.key for future in batch])
            for future in batch:
                key = futures[future]
                if key in written:
                    continue  # one row per key, however the scheduler delivered it
                fields = _task_fields(future, suspicious.get(future.key))
                if fields is None:
                    stats["lost"] += 1
                    continue
                row = dict(first_entry[key], **fields)
                row["finished_utc"] = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
                journal.append(row)
                written.add(key)
                stats["ran"] += 1
                stats["run_s"] = time.monotonic() - submitted
                progress.update(row)
                future.release()
    finally:
        progress.close()
        client.close()
        if cluster is not None:
            cluster.close()


def _ask_suspicious(client, keys):
    try:
        return client.run_on_scheduler(fleet_task.suspicious_counts, keys)
    except Exception:  # a scheduler that refuses to run code: attempts stay unknown
        return {}


def _task_fields(future, suspicious):
    """The result fields of a finished future, or None for a task lost with the scheduler.

    suspicious: how often the task's worker died under it (None when the scheduler would not
    say); attempts = that + 1.
    """
    from distributed import KilledWorker

    if future.status == "cancelled":
        return None
    attempts = suspicious + 1 if suspicious is not None else None
    try:
        fields = future.result()
    except KilledWorker:
        return {"status": "error", "attempts": suspicious,
                "error": f"the worker running this job died {suspicious or 'too many'} times; the scheduler gave up "
                "on it (a new batch tries again)"}
    except Exception as error:  # the task failed on the worker, outside the job (that would be a row)
        if future.status == "cancelled":
            return None
        return {"status": "error", "attempts": attempts, "error": f"the task failed on its worker: {error!r}"}
    fields["attempts"] = attempts
    return fields


def main(argv=None):
    parser = build_parser()
    args = parser.parse_args(argv)
    prog = program_name()
    try:
        importlib.import_module("distributed")
    except ImportError:
        print(f"{prog}: Dask distributed is not installed: apt-get install python3-distributed", file=sys.stderr)
        return EXIT_USAGE
    try:
        run_batch(Config(args))
    except UsageError as error:
        print(f"{prog}: {error}", file=sys.stderr)
        return EXIT_USAGE
    except FleetFailure as error:
        print(f"{prog}: {error}", file=sys.stderr)
        return EXIT_FAILURE
    except KeyboardInterrupt:
        print(f"{prog}: interrupted; the rows written so far are kept, run the batch again to go on",
              file=sys.stderr)
        return 130
    return EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
