"""The shear study's record of a run that spent its step budget (scripts/shear_study.py,
failed.json, kept by scripts/study_runner.py): read back for exactly the run and budget that wrote
it, and for no other, so that a changed run is run again and an unchanged one is not; and the runs
kept in studies/ are found under the keys the study gives its runs."""
import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
import shear_study  # noqa: E402
import study_runner  # noqa: E402
from shear_study import Run  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


def run(method="M", G=0.2):
    return Run(method, 320, G, 0.15, 10.0)


def state(work, r):
    return shear_study.runner("bendlab", work).state(r)


def record(work, r, error):
    (work / r.name).mkdir(parents=True, exist_ok=True)
    study_runner.write_failure(work / r.name, shear_study.runner("bendlab", work).identity(r), error)


def test_a_recorded_failure_is_read_back_for_the_same_run(tmp_path):
    record(tmp_path, run(), "bendlab: error: more than 200000 accepted steps (the budget of --max-steps)")
    assert state(tmp_path, run())[0] == "failed"
    assert "--max-steps" in state(tmp_path, run())[1]
    assert not (tmp_path / run().name / "failed.json.tmp").exists()


def test_another_budget_does_not_see_it(tmp_path, monkeypatch):
    record(tmp_path, run(), "budget spent")
    monkeypatch.setattr(shear_study, "MAX_STEPS", shear_study.MAX_STEPS * 2)
    assert state(tmp_path, run()) == ("run", None)


def test_the_kept_failure_and_finished_runs_of_studies_shear_are_found():
    work = ROOT / "studies" / "shear"
    # The failure kept in git (Method M at 320 triangles, G = 0.2): not run again.
    assert state(work, run())[0] == "failed"
    # Finished runs of parts (a)-(c) (Cash-Karp) and of part (e) (RKC, tree-mixed), with 2/15 spelled
    # out in full on the command line.
    assert state(work, Run("C", 1280, 0.05, 0.0375, 10.0))[0] == "done"
    assert state(work, Run("none", 1280, 0.0125, 0.0, 10.0))[0] == "done"
    try:
        shear_study.E_QUADRATURE = "tree-mixed"
        assert state(work, Run("A", 5120, 0.2, 2.0 / 15.0, 10.0, "rkc"))[0] == "done"
        assert state(work, Run("S", 5120, 0.05, 0.0375, 10.0, "rkc"))[0] == "done"
        shear_study.E_QUADRATURE = "tree"
        assert state(work, Run("C", 5120, 0.2, 0.15, 10.0, "rkc"))[0] == "done"
    finally:
        shear_study.E_QUADRATURE = "all7"


@pytest.mark.parametrize("text", ["", "{", "[]", json.dumps({"error": 3})])
def test_a_damaged_record_is_no_failure(tmp_path, text):
    (tmp_path / run().name).mkdir()
    (tmp_path / run().name / "failed.json").write_text(text)
    assert state(tmp_path, run()) == ("run", None)


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
