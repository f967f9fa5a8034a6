"""pliant.refine against `pliant refine --json -`: the material card."""

import pytest

import pliant
from conftest import assert_same_document, cli_error, cli_json


def test_refine_equals_the_command_line(examples, tmp_path):
    rec = examples / "phantom_compression" / "EF30_0T_A5"
    card = pliant.refine(rec, threads=1, quiet=True)
    assert card["format"] == "pliant-material" and card["estimator"] == "reaction"
    assert_same_document(card, cli_json("refine", rec, "--threads", "1"))


def test_refine_without_a_mesh_is_the_command_lines_usage_error(examples):
    message, status = cli_error("refine", examples / "foam_press_medium")
    assert status == 2
    with pytest.raises(pliant.UsageError) as error:
        pliant.refine(examples / "foam_press_medium")
    assert str(error.value) == message
