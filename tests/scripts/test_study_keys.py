"""The runs kept in studies/ (studies/README.md) are found by the keys the study scripts give
their runs, so that regenerating a document reruns nothing: every finished run of studies/lbm,
studies/small_g and studies/rbc_shear is 'done' for its study's runner, and a run of other
arguments is not."""
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import lbm_study  # noqa: E402
import rbc_shear_study  # noqa: E402
import small_g_study  # noqa: E402
import study_runner  # noqa: E402

STUDIES = ROOT / "studies"


def state(work, run):
    return study_runner.Runner("bendlab", work).state(run)[0]


def lbm_runs():
    """The LBM study's runs of the README's command (radii 6-12, the 5120 series, placements, checks)."""
    box, t = lbm_study.BOX, 10.0
    runs = [lbm_study.LbmRun(m, G, kb if m != "none" else 0.0, R, 1280, box, t)
            for (G, kb) in lbm_study.PAIRS for R in (6.0, 8.0, 10.0) for m in ("A", "B", "none")]
    runs += [lbm_study.LbmRun(m, 0.2, 0.15, R, 5120, box, t) for m in ("A", "B") for R in (6.0, 8.0, 10.0, 12.0)]
    runs += [lbm_study.LbmRun("B", 0.2, 0.15, R, 5120, box, t, offset=0.5) for R in (8.0, 10.0)]
    runs += [lbm_study.LbmRun("A", 0.2, 0.15, 6.0, 1280, box, t, lbm_study.REYNOLDS / 2),
             lbm_study.LbmRun("A", 0.2, 0.15, 6.0, 1280, (8.0, 8.0, 16.0), t, lbm_study.REYNOLDS * 1.6),
             lbm_study.LbmRun("A", 0.2, 0.15, 6.0, 1280, box, t, kernel="phi4"),
             lbm_study.LbmRun("A", 0.2, 0.15, 6.0, 5120, box, t, lbm_study.REYNOLDS / 2),
             lbm_study.LbmRun("A", 0.2, 0.15, 6.0, 5120, box, t, kernel="phi4")]
    return runs


@pytest.mark.parametrize("run", lbm_runs(), ids=lambda r: r.name)
def test_the_lbm_study_finds_its_runs(run):
    assert state(STUDIES / "lbm", run) == "done"


def test_the_lbm_study_finds_its_bim_runs_in_the_shear_study():
    for triangles in (1280, 5120):
        assert state(STUDIES / "shear", lbm_study.BimRun("B", 0.2, 0.15, 10.0, triangles)) == "done"


def test_an_lbm_run_of_other_arguments_in_a_kept_folder_is_not_done():
    kept = lbm_study.LbmRun("B", 0.2, 0.15, 8.0, 5120, lbm_study.BOX, 10.0)
    other = lbm_study.LbmRun("B", 0.2, 0.15, 8.0, 5120, lbm_study.BOX, 10.0, reynolds=0.3)
    folder = STUDIES / "lbm" / kept.name
    assert study_runner.finished(folder, kept) is not None
    assert study_runner.finished(folder, other) is None


@pytest.mark.parametrize("run", small_g_study.RUNS, ids=lambda r: r.name)
def test_the_small_g_study_finds_its_runs(run):
    assert state(small_g_study.WORK, run) == "done"


def test_the_small_g_reference_is_part_e_s_run():
    assert state(small_g_study.SHEAR, small_g_study.REFERENCE) == "done"


def rbc_runs():
    sweep = rbc_shear_study.sweep_runs(rbc_shear_study.DEFAULT_G, [1280], 100.0)
    fine = rbc_shear_study.sweep_runs([0.03, 0.04, 0.05], [5120], 100.0)
    return ([rbc_shear_study.jeffery_run(), rbc_shear_study.lbm_run(0.01, 30.0, 8)] + sweep + fine
            + rbc_shear_study.reference_runs([0.05, 0.1], 100.0))


@pytest.mark.parametrize("run", rbc_runs(), ids=lambda r: r.name)
def test_the_rbc_shear_study_finds_its_runs(run):
    assert state(STUDIES / "rbc_shear", run) == "done"


def test_an_rbc_run_to_another_end_is_not_done():
    run = rbc_shear_study.sweep_runs([0.05], [1280], 50.0)[0]
    assert state(STUDIES / "rbc_shear", run) == "run"
