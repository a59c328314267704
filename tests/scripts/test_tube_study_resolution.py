"""The tube study's resolution verdict (scripts/tube_study.py): each figure of the finest run
against the coarsest, in standard errors of the difference (the root sum of squares of the two
standard errors) and relative, with each run's departure from Pries' law at its own H_D; nothing
until two runs are done."""
import json
import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import tube_study  # noqa: E402


def write_summary(work, run, eta, hd, cfl):
    folder = work / run.name
    folder.mkdir(parents=True)
    summary = dict(run.key())
    for key, (mean, se) in (("apparent_viscosity", eta), ("discharge_hematocrit", hd), ("cell_free_layer_um", cfl)):
        summary[key] = {"mean": mean, "standard_error": se, "rows": 100}
    (folder / "summary.json").write_text(json.dumps(summary))


def test_resolution_verdict(tmp_path):
    coarse, fine = tube_study.run(10, 0.3), tube_study.run(10, 0.3, "C", "mt1:5120")
    assert tube_study.resolution_verdict(tmp_path, [coarse, fine]) == []  # nothing done yet
    write_summary(tmp_path, coarse, (1.5, 0.003), (0.38, 0.001), (1.3, 0.01))
    assert tube_study.resolution_verdict(tmp_path, [coarse, fine]) == []  # one run is not a comparison
    write_summary(tmp_path, fine, (1.54, 0.004), (0.38, 0.001), (1.2, 0.01))
    text = tube_study.resolution_verdict(tmp_path, [coarse, fine])[0]
    assert text.startswith("From mt1:1280 to mt1:5120: ")
    # eta: +0.04 over hypot(0.003, 0.004) = 0.005, 8 standard errors, +2.7 %.
    assert "eta_app / eta 1.5 -> 1.54 (+2.7%, +8.0 standard errors of the difference)" in text
    assert "H_D 0.38 -> 0.38 (+0.0%, +0.0 standard errors" in text
    assert f"the cell-free layer 1.3 -> 1.2 ({-0.1 / 1.3:+.1%}, {-0.1 / math.hypot(0.01, 0.01):+.1f} standard" in text
    law = tube_study.pries_in_vitro(10, 0.38)
    assert f"from {(1.5 - law) / law:+.1%} to {(1.54 - law) / law:+.1%}" in text


def test_unfinished_run_reports_how_far_it_got(tmp_path):
    run = tube_study.run(20, 0.3)
    assert tube_study.unfinished(run, tmp_path) == "not run yet"
    folder = tmp_path / run.name
    folder.mkdir()
    (folder / "run.log").write_text("$ bendlab flow ...\nplaced 40 cells\n")
    assert tube_study.unfinished(run, tmp_path) == "not run yet"  # started, no progress line
    (folder / "run.log").write_text(
        "$ bendlab flow ...\n"
        "t = 0.01 / 0.1 s ( 10%)  eta_app 1.9  H_D 0.35  CFL_um 1.0  elapsed 1800 s  ETA 16200 s  5.3 MLUPS\n"
        "t = 0.02 / 0.1 s ( 20%)  eta_app 1.97  H_D 0.35  CFL_um 1.1  elapsed 3600 s  ETA 14400 s  5.3 MLUPS\n")
    # The last line: 3600 s for a fifth of the run, so 5 h for all of it.
    assert tube_study.unfinished(run, tmp_path) == (
        "unfinished: t = 0.02 s of 0.1 s reached in 3600 s of wall time (about 5.0 h for the whole run at that rate)")


def test_threads_note_names_a_count_other_than_one(tmp_path):
    run = tube_study.run(10, 0.3, "C", "mt1:5120")
    assert tube_study.threads_note(tmp_path, run) == ""  # no log: the study's one thread
    folder = tmp_path / run.name
    folder.mkdir()
    (folder / "run.log").write_text("$ /tmp/bendlab flow --out x\nt = 1\n$ OMP_NUM_THREADS=1 /tmp/bendlab flow --resume\n")
    assert tube_study.threads_note(tmp_path, run) == ""
    with open(folder / "run.log", "a") as log:
        log.write("$ OMP_NUM_THREADS=2 /tmp/bendlab flow --resume\n")
    assert tube_study.threads_note(tmp_path, run) == " on 2 threads"
