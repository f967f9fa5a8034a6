"""The fleet's parts without a cluster: keys, discovery, the journal, the table, the summary,
one task against stand-in programs, and the batch's argument errors."""

import json
import os
import signal
import statistics
import stat
import time

import pytest

from conftest import run_fleet
from pliant import fleet_task
from pliant.fleet import table_rows
from pliant.fleet_inputs import UsageError, describe_recording, find_recordings, task_key
from pliant.fleet_table import (COLUMNS, NO_CLASS, Journal, JournalBusy, csv_text, json_line, normalized_row,
                                read_csv, summarize, summary_text)


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as stream:
        stream.write(text)


def make_recording(directory, files=None, meta_object="foam"):
    files = files or {"particles": "particles.csv", "wrench": "wrench.csv"}
    document = {"format": "pliant-recording", "version": 1, "dimension": 2, "length_unit": "px",
                "particles": {"count": 2}, "files": files, "meta": {"object": meta_object}}
    write(os.path.join(directory, "recording.json"), json.dumps(document))
    for name in files.values():
        write(os.path.join(directory, name), f"contents of {name}\n")
    return str(directory)


def key_of(directory, job="diagnose", options=()):
    return task_key(describe_recording(directory), job, list(options))


# ------------------------------------------------------------------------------------------ keys

def test_key_follows_the_referenced_files_and_nothing_else(tmp_path):
    recording = make_recording(tmp_path / "a")
    write(os.path.join(recording, "notes.txt"), "not referenced\n")
    first = key_of(recording)
    assert len(first) == 64 and int(first, 16) >= 0

    write(os.path.join(recording, "notes.txt"), "changed, still not referenced\n")
    assert key_of(recording) == first
    os.makedirs(os.path.join(recording, "media"))
    assert key_of(recording) == first

    for name in ("particles.csv", "wrench.csv"):
        with open(os.path.join(recording, name), "a") as stream:
            stream.write("one more line\n")
        changed = key_of(recording)
        assert changed != first, name
        first = changed

    with open(os.path.join(recording, "recording.json")) as stream:
        document = json.load(stream)
    document["meta"]["camera"] = "another"
    write(os.path.join(recording, "recording.json"), json.dumps(document))
    assert key_of(recording) != first


def test_key_names_the_job_and_its_options(tmp_path):
    recording = make_recording(tmp_path / "a")
    keys = {key_of(recording), key_of(recording, "refine"), key_of(recording, "estimate"),
            key_of(recording, "diagnose", ["--model", "fem"]), key_of(recording, "diagnose", ["--model=fem"])}
    assert len(keys) == 5


def test_key_reads_option_files(tmp_path):
    recording = make_recording(tmp_path / "a")
    mesh = tmp_path / "part.msh"
    write(str(mesh), "mesh 1\n")
    before = key_of(recording, "refine", ["--mesh", str(mesh)])
    write(str(mesh), "mesh 2\n")
    assert key_of(recording, "refine", ["--mesh", str(mesh)]) != before


def test_key_is_the_content_not_the_place(tmp_path):
    recording = make_recording(tmp_path / "a")
    copy = make_recording(tmp_path / "elsewhere" / "b")
    assert key_of(recording) == key_of(copy)


def test_malformed_recordings_still_get_keys(tmp_path):
    broken = tmp_path / "broken"
    write(str(broken / "recording.json"), "{ this is not json")
    assert len(key_of(str(broken))) == 64
    assert describe_recording(str(broken)).object == ""

    recording = make_recording(tmp_path / "a")
    present = key_of(recording)
    os.unlink(os.path.join(recording, "wrench.csv"))
    missing = key_of(recording)
    assert missing != present
    assert dict(describe_recording(recording).digests)["wrench.csv"] == "missing"

    escaping = make_recording(tmp_path / "c", files={"particles": "../a/particles.csv"})
    assert dict(describe_recording(escaping).digests)["../a/particles.csv"] == "outside-the-recording"


def test_object_class_follows_the_class_key(tmp_path):
    recording = make_recording(tmp_path / "a", meta_object="silicone EF30")
    assert describe_recording(recording).object == "silicone EF30"
    assert describe_recording(recording, "meta.material").object == ""
    assert describe_recording(recording, "dimension").object == "2"


# ------------------------------------------------------------------------------------- discovery

def test_directories_are_searched_and_recordings_not_entered(tmp_path):
    make_recording(tmp_path / "day1" / "r2")
    make_recording(tmp_path / "day1" / "r1")
    make_recording(tmp_path / "day2" / "deep" / "r3")
    make_recording(tmp_path / "day1" / "r1" / "inner")  # inside a recording: not one of the batch
    write(str(tmp_path / "day2" / "readme.txt"), "no recording here\n")
    found = find_recordings([str(tmp_path)])
    assert found == [str(tmp_path / "day1" / "r1"), str(tmp_path / "day1" / "r2"), str(tmp_path / "day2/deep/r3")]
    assert find_recordings([str(tmp_path / "day1"), str(tmp_path / "day1" / "r1")]) == found[:2]


def test_list_files(tmp_path):
    make_recording(tmp_path / "data" / "r1")
    make_recording(tmp_path / "data" / "r2")
    write(str(tmp_path / "list.txt"), "# today\n\ndata/r2\n  data/r1  \n")
    assert find_recordings([str(tmp_path / "list.txt")]) == [str(tmp_path / "data/r2"), str(tmp_path / "data/r1")]
    write(str(tmp_path / "bad.txt"), "data/r1\ndata/none\n")
    with pytest.raises(UsageError, match=r"bad.txt:2: data/none is not a recording directory"):
        find_recordings([str(tmp_path / "bad.txt")])


def test_nothing_to_batch(tmp_path):
    with pytest.raises(UsageError, match="no such directory or list file"):
        find_recordings([str(tmp_path / "absent")])
    os.makedirs(tmp_path / "empty")
    with pytest.raises(UsageError, match="no recordings"):
        find_recordings([str(tmp_path / "empty")])


# -------------------------------------------------------------------------------------- journal

def row(key, recording="r", job="diagnose", **fields):
    return normalized_row({"key": key, "recording": recording, "job": job, "status": "ok", **fields})


def test_journal_keeps_one_row_per_key(tmp_path):
    out = str(tmp_path / "out")
    journal = Journal(out)
    journal.append(row("k1", error="first", status="error"))
    journal.append(row("k2", recording="q"))
    journal.append(row("k1", msm_beta=0.25))
    assert len(journal.rows) == 2 and journal.rows["k1"]["msm_beta"] == 0.25
    with pytest.raises(JournalBusy):
        Journal(out)  # the lock: one batch per output directory
    journal.close()

    with open(os.path.join(out, "journal.jsonl")) as stream:
        assert len(stream.readlines()) == 3  # appended as they came
    reopened = Journal(out)
    assert reopened.superseded_lines == 1
    assert reopened.rows["k1"]["msm_beta"] == 0.25 and reopened.rows["k1"]["error"] is None
    reopened.compact()
    reopened.close()
    with open(os.path.join(out, "journal.jsonl")) as stream:
        lines = [json.loads(line) for line in stream]
    assert [line["key"] for line in lines] == ["k2", "k1"]  # in table order: recording "q" before "r"


def test_journal_survives_a_torn_last_line(tmp_path):
    out = str(tmp_path / "out")
    journal = Journal(out)
    journal.append(row("k1"))
    journal.close()
    with open(os.path.join(out, "journal.jsonl"), "a") as stream:
        stream.write(json_line(row("k2"))[:25])  # a batch killed while writing
    journal = Journal(out)
    assert journal.dropped_lines == 1 and list(journal.rows) == ["k1"]
    journal.append(row("k3"))
    journal.close()
    journal = Journal(out)
    assert sorted(journal.rows) == ["k1", "k3"]
    journal.close()


# ------------------------------------------------------------------------------- table, summary

def test_table_rows_follow_the_batch():
    entries = [{"recording": "a", "key": "k1", "job": "diagnose", "object": "foam"},
               {"recording": "copy of a", "key": "k1", "job": "diagnose", "object": "foam"},
               {"recording": "b", "key": "k2", "job": "diagnose", "object": ""}]
    stored = {"k1": row("k1", recording="where a was", object="old class", msm_beta=0.3), "k9": row("k9")}
    rows = table_rows(entries, stored)
    assert [(r["recording"], r["object"], r["msm_beta"], r["status"]) for r in rows] == \
        [("a", "foam", 0.3, "ok"), ("copy of a", "foam", 0.3, "ok"), ("b", None, None, "pending")]
    assert rows[2]["error"].startswith("not run")
    summary = summarize(rows)
    assert summary["jobs"]["diagnose"] == {"rows": 3, "ok": 2, "errors": 0, "pending": 1}
    assert "diagnose 3 (0 errors, 1 not run)" in summary_text(summary)


def test_csv_and_json_lines_round_trip(tmp_path):
    rows = [
        row("k1", recording="day 1/press, \"a\"", object="foam\nblock", msm_beta=0.1 + 0.2, msm_beta_sd=1e-300,
            youngs_modulus=123456.789, parameters={"msm_beta": 0.3, "nested": {"list": [1, 2.5]}},
            effect_parameters={"yield": 0.04}, attempts=2, exit_status=0, runtime_s=1.25),
        row("k2", status="error", exit_status=-11, error="pliant diagnose was killed by SIGSEGV: a, \"b\""),
        row("k3", uncertainty={}, improvement=0.0, noise_rms=-0.0),
    ]
    path = tmp_path / "t.csv"
    path.write_text(csv_text(rows))
    assert read_csv(str(path)) == rows
    assert path.read_text().splitlines()[0] == ",".join(COLUMNS)
    assert [json.loads(json_line(r)) for r in rows] == rows


def test_summary_statistics_on_a_known_table():
    betas = [0.4, 0.1, 0.3, 0.2]
    moduli = [1.0e5, 3.0e5, 2.0e5]
    rows = [row(f"a{i}", recording=f"a{i}", object="foam A", msm_beta=b, verdict="consistent", effect="none")
            for i, b in enumerate(betas)]
    rows[1]["verdict"], rows[1]["effect"] = "missing_physics", "plasticity"
    rows += [row(f"b{i}", recording=f"b{i}", job="refine", object="silicone", youngs_modulus=e)
             for i, e in enumerate(moduli)]
    rows.append(row("c", recording="c", object="", msm_beta=0.9, verdict="consistent", effect="none"))
    rows.append(row("d", recording="d", object="foam A", status="error", exit_status=2, msm_beta=5.0))
    summary = summarize(rows)

    assert summary["recordings"] == 9 and summary["rows"] == 9 and summary["errors"] == 1
    assert summary["jobs"] == {"diagnose": {"rows": 6, "ok": 5, "errors": 1, "pending": 0},
                               "refine": {"rows": 3, "ok": 3, "errors": 0, "pending": 0}}
    assert summary["verdicts"] == {"consistent": 4, "missing_physics": 1}
    assert summary["effects"] == {"none": 4, "plasticity": 1}
    assert summary["objects_per_class"] == {NO_CLASS: 1, "foam A": 5, "silicone": 3}
    spread = {(item["object"], item["job"], item["parameter"]): item for item in summary["spread"]}
    assert set(spread) == {(NO_CLASS, "diagnose", "msm_beta"), ("foam A", "diagnose", "msm_beta"),
                           ("silicone", "refine", "youngs_modulus")}
    for key, values in ((("foam A", "diagnose", "msm_beta"), betas),
                        (("silicone", "refine", "youngs_modulus"), moduli)):
        q1, median, q3 = statistics.quantiles(values, n=4, method="inclusive")  # the error row's 5.0 left out
        item = spread[key]
        assert item["n"] == len(values)
        assert item["median"] == pytest.approx(median) and item["q1"] == pytest.approx(q1)
        assert item["q3"] == pytest.approx(q3) and item["iqr"] == pytest.approx(q3 - q1)
        assert (item["min"], item["max"]) == (min(values), max(values))
    assert spread[("foam A", "diagnose", "msm_beta")]["median"] == pytest.approx(0.25)
    assert spread[("foam A", "diagnose", "msm_beta")]["q1"] == pytest.approx(0.175)
    text = summary_text(summary)
    assert "9 recordings, 9 rows" in text and "plasticity 1" in text and "silicone" in text


# ------------------------------------------------------------------------------- one task alone

DIAGNOSIS = {
    "format": "pliant-diagnosis", "version": 1, "recording": "r",
    "baseline": {"model": "msm", "parameters": {"msm_alpha": 1.0, "msm_beta": 0.034}, "rms": 1.27e-3},
    "noise_rms": 2.1e-5, "verdict": "missing_physics", "effect": "plasticity", "explanation": "...",
    "augmented": {"model": "msm", "parameters": {"msm_alpha": 1.0, "msm_beta": 0.276, "yield": 0.04}, "rms": 2.5e-4},
    "improvement": 0.806, "candidates": [],
}


def test_result_fields_of_each_job():
    fields = fleet_task.result_fields("diagnose", DIAGNOSIS)
    assert (fields["verdict"], fields["effect"], fields["msm_beta"], fields["msm_alpha"]) == \
        ("missing_physics", "plasticity", 0.034, 1.0)
    assert fields["effect_parameters"] == {"msm_alpha": 1.0, "msm_beta": 0.276, "yield": 0.04}
    assert (fields["improvement"], fields["rms"], fields["noise_rms"], fields["msm_beta_sd"]) == \
        (0.806, 1.27e-3, 2.1e-5, None)

    consistent = dict(DIAGNOSIS, verdict="consistent", effect="none", improvement=0)
    assert fleet_task.result_fields("diagnose", consistent).get("effect_parameters") is None

    fem = dict(DIAGNOSIS, baseline={"model": "fem", "parameters": {"youngs_modulus": 1.1e5}, "rms": None},
               noise_rms=None, effect="stiffening")
    fields = fleet_task.result_fields("diagnose", fem)
    assert (fields["youngs_modulus"], fields["rms"], fields["noise_rms"], fields["msm_beta"]) == \
        (1.1e5, None, None, None)

    estimate = {"format": "pliant-estimate", "parameters": {"msm_beta": 0.58, "msm_alpha": 1.0},
                "uncertainty": {"msm_beta": 0.012}, "rms": 4.1e-4}
    fields = fleet_task.result_fields("estimate", estimate)
    assert (fields["msm_beta"], fields["msm_beta_sd"], fields["rms"]) == (0.58, 0.012, 4.1e-4)
    assert "verdict" not in fields

    card = {"format": "pliant-material", "parameters": {"youngs_modulus": 6.79e5, "poisson_ratio": 0.45,
            "rayleigh_alpha": 0.021}, "uncertainty": {"youngs_modulus": 4.0e3, "rayleigh_alpha": 0.004}, "rms": 2.3e-4}
    fields = fleet_task.result_fields("refine", card)
    assert (fields["youngs_modulus"], fields["youngs_modulus_sd"]) == (6.79e5, 4.0e3)
    assert fields["uncertainty"] == {"youngs_modulus": 4.0e3, "rayleigh_alpha": 0.004}
    assert fields["parameters"]["poisson_ratio"] == 0.45


def stand_in(tmp_path, body):
    """A program in place of pliant: $1 job, $2 recording, $3 --json, $4 OUT, $5 --quiet."""
    path = tmp_path / "pliant"
    path.write_text("#!/bin/sh\n" + body)
    path.chmod(path.stat().st_mode | stat.S_IXUSR)
    return str(path)


def run_with(cli, timeout_s=30.0, options=()):
    return fleet_task.run_job({"recording": "/rec", "job": "diagnose", "options": list(options), "cli": cli,
                               "timeout_s": timeout_s})


def test_task_reads_the_json_the_program_wrote(tmp_path):
    cli = stand_in(tmp_path, f"[ \"$1 $3 $5 $6\" = 'diagnose --json --quiet --model' ] || exit 7\n"
                   f"cat > \"$4\" <<'END'\n{json.dumps(DIAGNOSIS)}\nEND\n")
    fields = run_with(cli, options=["--model", "msm"])
    assert fields["status"] == "ok" and fields["exit_status"] == 0 and fields["error"] is None
    assert fields["effect"] == "plasticity" and fields["runtime_s"] >= 0 and fields["worker"]


def test_task_keeps_the_command_lines_message(tmp_path):
    cli = stand_in(tmp_path, "echo 'pliant: warning: recording.json: unknown key \"x\"' >&2\n"
                   "echo 'pliant diagnose: particles.csv:12: expected 4 fields, got 2' >&2\nexit 2\n")
    fields = run_with(cli)
    assert (fields["status"], fields["exit_status"]) == ("error", 2)
    assert fields["error"] == "pliant diagnose: particles.csv:12: expected 4 fields, got 2"


def test_task_reports_a_crash(tmp_path):
    fields = run_with(stand_in(tmp_path, "echo 'half a line' >&2\nkill -SEGV $$\n"))
    assert fields["exit_status"] == -signal.SIGSEGV
    assert fields["error"] == "pliant diagnose was killed by SIGSEGV: half a line"


def test_task_kills_a_hang_at_its_timeout(tmp_path):
    pid_file = tmp_path / "pid"
    cli = stand_in(tmp_path, f"sleep 60 &\necho $! > {pid_file}\nwait\n")
    started = time.monotonic()
    fields = run_with(cli, timeout_s=1.0)
    assert time.monotonic() - started < 10
    assert fields["status"] == "error" and fields["exit_status"] is None
    assert fields["error"] == "pliant diagnose timed out after 1 s and was killed"
    sleeper = int(pid_file.read_text())
    for _ in range(50):  # the whole process group goes, the program's own children too
        if not os.path.exists(f"/proc/{sleeper}") or open(f"/proc/{sleeper}/stat").read().split()[2] == "Z":
            break
        time.sleep(0.1)
    else:
        pytest.fail("the timed-out program's child is still running")


def test_task_without_usable_output(tmp_path):
    fields = run_with(stand_in(tmp_path, "echo '{ truncated' > \"$4\"\n"))
    assert fields["status"] == "error" and fields["exit_status"] == 0
    assert fields["error"].startswith("pliant diagnose exited 0 but its JSON could not be read")
    fields = run_with(str(tmp_path / "no-such-pliant"))
    assert fields["status"] == "error" and "missing or not executable" in fields["error"]


# --------------------------------------------------------------------------------- bad arguments

def test_bad_arguments_exit_2_with_a_reason(tmp_path, cli):
    recording = make_recording(tmp_path / "recs" / "r1")
    out = tmp_path / "out"
    os.makedirs(tmp_path / "nothing-here" / "empty")
    cases = [
        ([tmp_path / "absent", "-o", out], "absent: no such directory or list file"),
        ([tmp_path / "nothing-here", "-o", out], "no recordings (directories holding a recording.json)"),
        ([recording, "-o", out, "--jobs", "diagnose,squeeze"], "'squeeze' is not one of diagnose, refine, estimate"),
        ([recording, "-o", out, "--diagnose-options=--json x.json"], "--json is set by the batch"),
        ([recording, "-o", out, "--workers", "0"], "--workers must be at least 1"),
        ([recording, "-o", out, "--cli", tmp_path / "nothing"], "is not an executable pliant command line"),
        ([recording, "-o", out, "--scheduler", "tcp://127.0.0.1:9", "--connect-timeout", "1"],
         "cannot reach the Dask scheduler at tcp://127.0.0.1:9"),
    ]
    for arguments, message in cases:
        result = run_fleet(*arguments, "--cli", cli) if "--cli" not in arguments else run_fleet(*arguments)
        assert result.returncode == 2, (arguments, result.stderr)
        assert message in result.stderr, (arguments, result.stderr)
        assert result.stderr.startswith("python3 -m pliant.fleet: "), result.stderr
    assert not os.path.exists(out / "results.csv")


def test_without_a_pliant_program(tmp_path):
    recording = make_recording(tmp_path / "recs" / "r1")
    env = {name: value for name, value in os.environ.items() if name != "PLIANT_CLI"}
    env["PATH"] = "/usr/bin:/bin"
    result = run_fleet(recording, "-o", tmp_path / "out", env=env)
    assert result.returncode == 2
    assert "cannot find the pliant command line: pass --cli PATH, set PLIANT_CLI or put pliant on PATH" in result.stderr
