"""The shear study's record of a run that spent its step budget (scripts/shear_study.py,
failed.json): read back for exactly the run that wrote it, and for no other run, budget or
damaged record, so that a changed run is run again and an unchanged one is not."""
import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
import shear_study  # noqa: E402
from shear_study import Run, read_failure, write_failure  # noqa: E402


def run(method="M", G=0.2):
    return Run(method, 320, G, 0.15, 10.0)


def test_a_recorded_failure_is_read_back_for_the_same_run(tmp_path):
    write_failure(tmp_path, run(), "bendlab: error: more than 200000 accepted steps (the budget of --max-steps)")
    assert "--max-steps" in read_failure(tmp_path, run())
    assert not (tmp_path / "failed.json.tmp").exists()


def test_another_run_or_budget_does_not_see_it(tmp_path, monkeypatch):
    write_failure(tmp_path, run(), "budget spent")
    assert read_failure(tmp_path, run(G=0.05)) is None
    assert read_failure(tmp_path, run(method="C")) is None
    monkeypatch.setattr(shear_study, "MAX_STEPS", shear_study.MAX_STEPS * 2)
    assert read_failure(tmp_path, run()) is None


@pytest.mark.parametrize("text", ["", "{", "[]", json.dumps({"error": 3})])
def test_a_damaged_record_is_no_failure(tmp_path, text):
    (tmp_path / "failed.json").write_text(text)
    assert read_failure(tmp_path, run()) is None


def test_no_record_is_no_failure(tmp_path):
    assert read_failure(tmp_path, run()) is None


def test_the_document_shows_the_reason_without_the_prefix_and_path():
    error = ("bendlab: error: the run failed after step 100000 (gamma t = 3.87163): more than 100000 accepted "
             "steps (the budget of --max-steps) to reach gamma t = 10 (mean gamma dt 3.87e-05; the last step "
             "4.04e-08); the last checkpoint, at gamma t = 3.5102, is whole in '/x/y/checkpoint.json'")
    reason = shear_study.failure_reason(error)
    assert reason.startswith("the run failed after step 100000")
    assert reason.endswith("(last checkpoint at gamma t = 3.5102)")
    assert "/x/y" not in reason and "bendlab: error" not in reason
    assert shear_study.failure_reason("exit status 3") == "exit status 3"
    assert shear_study.failure_reason(None) == ""


def test_only_failures_of_the_steps_are_recorded():
    assert shear_study.failed_while_stepping(
        "bendlab: error: the run failed after step 51807 (gamma t = 4.23): method M: the jet at vertex 101 is singular")
    assert not shear_study.failed_while_stepping("bendlab: error: --resume: no checkpoint in 'x' to resume from")
    assert not shear_study.failed_while_stepping("exit status -9")
    assert not shear_study.failed_while_stepping(None)
