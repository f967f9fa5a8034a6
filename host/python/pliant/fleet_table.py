"""The fleet's results: the journal (JSON lines, appended as tasks finish), the table (CSV and
JSON lines) and the summary. Columns and files: docs/fleet.md. Pure Python.
"""

from __future__ import annotations

import csv
import fcntl
import io
import json
import math
import os
import tempfile

# (column, type): "str", "float", "int" or "json" (an object, written into the CSV as JSON text).
COLUMN_TYPES = (
    ("recording", "str"),
    ("key", "str"),
    ("job", "str"),
    ("object", "str"),
    ("status", "str"),
    ("verdict", "str"),
    ("effect", "str"),
    ("msm_beta", "float"),
    ("msm_beta_sd", "float"),
    ("msm_alpha", "float"),
    ("youngs_modulus", "float"),
    ("youngs_modulus_sd", "float"),
    ("effect_parameters", "json"),
    ("improvement", "float"),
    ("rms", "float"),
    ("noise_rms", "float"),
    ("parameters", "json"),
    ("uncertainty", "json"),
    ("runtime_s", "float"),
    ("worker", "str"),
    ("attempts", "int"),
    ("exit_status", "int"),
    ("error", "str"),
    ("finished_utc", "str"),
)
COLUMNS = tuple(name for name, _ in COLUMN_TYPES)
_TYPES = dict(COLUMN_TYPES)
# Exit statuses with which the command line ran the job to its end (host/cli/exit_status.hpp):
# the row is final. Any other failure (timeout, signal, lost worker, no program) is tried again.
FINAL_EXIT_STATUSES = (0, 1, 2)
# The parameters whose spread the summary gives per object class and job.
SUMMARY_PARAMETERS = ("msm_beta", "youngs_modulus")


class JournalBusy(Exception):
    """Another batch holds the output directory."""


def normalized_row(fields):
    """A row with every column, in column order; missing values and empty text are None (as an
    empty CSV cell reads back)."""
    return {name: (None if fields.get(name) == "" else fields.get(name)) for name in COLUMNS}


def is_final(row):
    """True when the row's job ran to its end (a result, or the command line's own error)."""
    return row.get("status") == "ok" or row.get("exit_status") in FINAL_EXIT_STATUSES


def row_order(row):
    return (row.get("recording") or "", row.get("job") or "", row.get("key") or "")


class Journal:
    """journal.jsonl in an output directory: every row any batch into it produced, one JSON
    object per line, keyed by "key" (the cache that lets a batch skip what is done).

    Opening takes an exclusive lock on DIR/.lock (a second batch on the same directory gets
    JournalBusy). Loading reads every row, the last line of a key winning (a retry supersedes an
    earlier failure); a torn last line (a batch killed mid-write) is counted and dropped.
    append() writes one row and fsyncs before returning, so a row acknowledged is on disk.
    """

    def __init__(self, directory):
        self.directory = directory
        self.path = os.path.join(directory, "journal.jsonl")
        self.rows = {}
        self.dropped_lines = 0
        self.superseded_lines = 0
        os.makedirs(directory, exist_ok=True)
        self._lock = open(os.path.join(directory, ".lock"), "w")
        try:
            fcntl.flock(self._lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            self._lock.close()
            raise JournalBusy(f"another batch is writing into {directory}") from None
        self._load()
        self._stream = open(self.path, "a", encoding="utf-8")
        if self._needs_newline:
            self._stream.write("\n")  # the torn line stays torn; the next row starts a line of its own

    def _load(self):
        self._needs_newline = False
        if not os.path.exists(self.path):
            return
        with open(self.path, encoding="utf-8", errors="replace") as stream:
            text = stream.read()
        self._needs_newline = bool(text) and not text.endswith("\n")
        for line in text.splitlines():
            if not line.strip():
                continue
            try:
                row = json.loads(line)
            except ValueError:
                self.dropped_lines += 1
                continue
            if not isinstance(row, dict) or not isinstance(row.get("key"), str):
                self.dropped_lines += 1
                continue
            if row["key"] in self.rows:
                self.superseded_lines += 1
            self.rows[row["key"]] = normalized_row(row)

    def append(self, row):
        """Stores `row` (replacing a stored row of the same key) and makes it durable."""
        row = normalized_row(row)
        if row["key"] in self.rows:
            self.superseded_lines += 1
        self.rows[row["key"]] = row
        self._stream.write(json_line(row))
        self._stream.flush()
        os.fsync(self._stream.fileno())

    def sorted_rows(self):
        return sorted(self.rows.values(), key=row_order)

    def compact(self):
        """Rewrites the journal atomically with one line per key (the last), ordered by recording."""
        self._stream.close()
        write_atomically(self.path, "".join(json_line(row) for row in self.sorted_rows()))
        self._stream = open(self.path, "a", encoding="utf-8")
        self.superseded_lines = 0
        self.dropped_lines = 0

    def close(self):
        self._stream.close()
        self._lock.close()


def json_line(row):
    return json.dumps(normalized_row(row), allow_nan=False, ensure_ascii=False) + "\n"


def write_atomically(path, text):
    """Writes `text` to a temporary file beside `path`, fsyncs it and renames it over `path`."""
    directory = os.path.dirname(path) or "."
    handle, temporary = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".", dir=directory)
    try:
        os.fchmod(handle, 0o666 & ~_umask())  # as open() would make it, not mkstemp's 0600
        with os.fdopen(handle, "w", encoding="utf-8", newline="") as stream:
            stream.write(text)
            stream.flush()
            os.fsync(stream.fileno())
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.unlink(temporary)
        raise


def _umask():
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _cell(name, value):
    if value is None:
        return ""
    if _TYPES[name] == "json":
        return json.dumps(value, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return str(value)  # floats as their shortest repr: they read back exactly


def csv_text(rows):
    """The table as CSV: a header of COLUMNS, then one line per row; empty cells are None."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(COLUMNS)
    for row in rows:
        writer.writerow([_cell(name, row.get(name)) for name in COLUMNS])
    return buffer.getvalue()


def read_csv(path):
    """Reads a table written by csv_text back into typed rows."""
    with open(path, encoding="utf-8", newline="") as stream:
        reader = csv.DictReader(stream)
        if tuple(reader.fieldnames or ()) != COLUMNS:
            raise ValueError(f"{path}: not a pliant fleet table (its header differs)")
        return [{name: _parse_cell(name, text) for name, text in record.items()} for record in reader]


def _parse_cell(name, text):
    if text == "":
        return None
    kind = _TYPES[name]
    if kind == "float":
        return float(text)
    if kind == "int":
        return int(text)
    if kind == "json":
        return json.loads(text)
    return text


def quantile(sorted_values, p):
    """Linear interpolation between closest ranks (numpy's default) of ascending values."""
    position = p * (len(sorted_values) - 1)
    low = math.floor(position)
    high = min(low + 1, len(sorted_values) - 1)
    return sorted_values[low] + (sorted_values[high] - sorted_values[low]) * (position - low)


def spread(values):
    """n, median, q1, q3, iqr, min and max of `values` (which must not be empty)."""
    ordered = sorted(values)
    q1, median, q3 = (quantile(ordered, p) for p in (0.25, 0.5, 0.75))
    return {"n": len(ordered), "median": median, "q1": q1, "q3": q3, "iqr": q3 - q1,
            "min": ordered[0], "max": ordered[-1]}


NO_CLASS = "(no class)"


def summarize(rows, class_key="meta.object"):
    """The fleet summary of a table (format pliant-fleet-summary, docs/fleet.md)."""
    jobs = {}
    verdicts = {}
    effects = {}
    errors = 0
    recordings = set()
    classes = {}
    for row in rows:
        job = row.get("job") or ""
        counts = jobs.setdefault(job, {"rows": 0, "ok": 0, "errors": 0, "pending": 0})
        counts["rows"] += 1
        recordings.add(row.get("recording"))
        label = row.get("object") or NO_CLASS
        entry = classes.setdefault(label, {"recordings": set(), "values": {}})
        entry["recordings"].add(row.get("recording"))
        if row.get("status") == "pending":
            counts["pending"] += 1
            continue
        if row.get("status") != "ok":
            counts["errors"] += 1
            errors += 1
            continue
        counts["ok"] += 1
        if job == "diagnose":
            verdicts[row.get("verdict")] = verdicts.get(row.get("verdict"), 0) + 1
            effects[row.get("effect")] = effects.get(row.get("effect"), 0) + 1
        for parameter in SUMMARY_PARAMETERS:
            value = row.get(parameter)
            if isinstance(value, (int, float)) and math.isfinite(value):
                entry["values"].setdefault((job, parameter), []).append(float(value))
    objects = []
    for label in sorted(classes):
        entry = classes[label]
        for (job, parameter) in sorted(entry["values"]):
            objects.append({"object": label, "job": job, "parameter": parameter,
                            **spread(entry["values"][(job, parameter)])})
    return {
        "format": "pliant-fleet-summary",
        "version": 1,
        "class_key": class_key,
        "recordings": len(recordings),
        "rows": len(rows),
        "errors": errors,
        "jobs": dict(sorted(jobs.items())),
        "verdicts": dict(sorted(verdicts.items(), key=lambda item: str(item[0]))),
        "effects": dict(sorted(effects.items(), key=lambda item: str(item[0]))),
        "objects_per_class": {label: len(classes[label]["recordings"]) for label in sorted(classes)},
        "spread": objects,
    }


def _g(value):
    return f"{value:.4g}"


def summary_text(summary):
    """The summary as the few lines the batch prints."""
    jobs = ", ".join(f"{job} {counts['rows']} ({counts['errors']} errors"
                     + (f", {counts['pending']} not run)" if counts["pending"] else ")")
                     for job, counts in summary["jobs"].items())
    lines = [f"{summary['recordings']} recordings, {summary['rows']} rows: {jobs or 'none'}"]
    if summary["verdicts"]:
        lines.append("verdicts: " + ", ".join(f"{name} {count}" for name, count in summary["verdicts"].items()))
        lines.append("effects: " + ", ".join(f"{name} {count}" for name, count in summary["effects"].items()))
    if summary["spread"]:
        width = max(len("object"), *(len(item["object"]) for item in summary["spread"]))
        width = min(width, 48)
        lines.append(f"{'object':<{width}}  {'job':<8}  {'parameter':<14}  {'n':>4}  {'median':>10}  "
                     f"{'q1':>10}  {'q3':>10}  {'min':>10}  {'max':>10}")
        for item in summary["spread"]:
            name = item["object"] if len(item["object"]) <= width else item["object"][: width - 3] + "..."
            lines.append(f"{name:<{width}}  {item['job']:<8}  {item['parameter']:<14}  {item['n']:>4}  "
                         f"{_g(item['median']):>10}  {_g(item['q1']):>10}  {_g(item['q3']):>10}  "
                         f"{_g(item['min']):>10}  {_g(item['max']):>10}")
    return "\n".join(lines) + "\n"
