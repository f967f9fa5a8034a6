"""pliant.diagnose against `pliant diagnose --json -`; the report only on request."""

import pliant
from conftest import assert_same_document, cli_json, run_cli


def test_diagnose_equals_the_command_line_and_writes_the_report_when_asked(tmp_path):
    recording = tmp_path / "press"
    run_cli("simulate", "foam_press", "-o", recording, "--beta", "0.4", "--noise", "0.005", "--seed", "3")
    report = tmp_path / "report"
    document = pliant.diagnose(recording, report=report, quiet=True)
    assert document["format"] == "pliant-diagnosis" and document["verdict"] == "consistent"
    assert (report / "index.html").is_file()
    assert_same_document(document, cli_json("diagnose", recording))


def test_no_report_without_a_path(tmp_path, examples):
    rec = pliant.read_recording(examples / "foam_press_firm")
    before = set(tmp_path.iterdir())
    document = pliant.diagnose(rec, quiet=True, alpha="fixed=1", steps_per_frame=1, cluster_radius=1.5)
    assert document["baseline"]["model"] == "msm"
    assert set(tmp_path.iterdir()) == before
