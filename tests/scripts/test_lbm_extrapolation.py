"""The resolution study's extrapolation (scripts/lbm_study.py): D(R) = D_inf + a / R^p fitted
through the radii, its spread under the runs' errors, and the block error of a steady mean.
Exact power laws must come back exactly; synthetic series with known statistics give their error."""
import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
import lbm_study  # noqa: E402
import study_runner  # noqa: E402


def power_law(R, d_inf, a, p):
    return d_inf + a * np.asarray(R, float) ** -p


@pytest.mark.parametrize("p", [0.5, 1.0, 1.7, 2.5])
def test_three_radii_recover_an_exact_power_law(p):
    R = [6.0, 8.0, 10.0]
    d_inf, a, p_fit, fitted, chi2 = lbm_study.fit_extrapolation(R, power_law(R, 0.21, 0.09, p))
    assert fitted
    assert p_fit == pytest.approx(p, rel=1e-6)
    assert d_inf == pytest.approx(0.21, abs=1e-9)
    assert a == pytest.approx(0.09, rel=1e-6)
    assert chi2 < 1e-20


def test_more_radii_weighted_fit_recovers_the_law_and_ignores_scaled_weights():
    R = [6.0, 7.0, 8.0, 10.0, 12.0]
    D = power_law(R, 0.5, -0.2, 1.3)
    sigma = [1e-4, 2e-4, 1e-4, 5e-5, 3e-5]
    f1 = lbm_study.fit_extrapolation(R, D, sigma)
    f2 = lbm_study.fit_extrapolation(R, D, [10 * s for s in sigma])
    assert f1[3] and f1[2] == pytest.approx(1.3, rel=1e-5)
    assert f1[0] == pytest.approx(0.5, abs=1e-8)
    assert f2[0] == pytest.approx(f1[0], abs=1e-10)


def test_chi2_counts_residuals_in_units_of_the_errors():
    # Four radii on a law, one point moved by 3 sigma: the least-squares chi^2 is positive and
    # below 9 (the fit absorbs part of the move).
    R = [6.0, 8.0, 10.0, 12.0]
    sigma = np.full(4, 1e-4)
    D = power_law(R, 0.2, 0.06, 1.0)
    D[1] += 3e-4
    chi2 = lbm_study.fit_extrapolation(R, D, sigma)[4]
    assert 0 < chi2 < 9


def test_two_radii_assume_first_order():
    R = [8.0, 10.0]
    d_inf, a, p, fitted, _ = lbm_study.fit_extrapolation(R, power_law(R, 0.3, 0.1, 1.0))
    assert not fitted and p == 1.0
    assert d_inf == pytest.approx(0.3, abs=1e-12)


def test_no_power_law_when_d_moves_the_same_amount_each_step():
    # Equal steps in R are no power law in R with p > 0: the fit falls back to p = 1.
    R = [6.0, 8.0, 10.0]
    assert not lbm_study.fit_extrapolation(R, [0.278, 0.276, 0.274])[3]


def test_spread_is_narrow_for_precise_points_and_brackets_the_fit():
    R = [6.0, 8.0, 10.0, 12.0]
    D = power_law(R, 0.2, 0.06, 1.0)
    lo, hi = lbm_study.extrapolation_spread(R, D, [1e-7] * 4)
    assert lo <= 0.2 <= hi and hi - lo < 1e-4
    wide = lbm_study.extrapolation_spread(R, D, [1e-4] * 4)
    assert wide[1] - wide[0] > hi - lo
    assert lbm_study.extrapolation_spread(R, D, None) is None


def test_block_error_of_a_steady_mean(tmp_path):
    # D = c + alternating +-e per block of the window [5, 10]: the block means are c +- e, so the
    # standard error is std([c+e, c-e, c+e, c-e, c+e], ddof=1) / sqrt(5).
    t = np.linspace(0.0, 10.0, 10001)
    block = np.clip(np.floor(t - 5.0), 0, 4).astype(int)
    e, c = 1e-3, 0.25
    D = c + np.where(block % 2 == 0, e, -e)
    with open(tmp_path / "timeseries.csv", "w") as f:
        f.write("gamma_t,D\n")
        for ti, di in zip(t, D):
            f.write(f"{ti:.6f},{di:.12f}\n")
    means = [c + e, c - e, c + e, c - e, c + e]
    expected = np.std(means, ddof=1) / math.sqrt(5)
    got = lbm_study.steady_uncertainty(tmp_path, (5.0, 10.0))
    assert got == pytest.approx(expected, rel=2e-3)
    with open(tmp_path / "timeseries.csv", "w") as f:  # a run stopped at gamma t = 8: no full window
        f.write("gamma_t,D\n" + "".join(f"{ti:.6f},{di:.12f}\n" for ti, di in zip(t, D) if ti <= 8.0))
    assert lbm_study.steady_uncertainty(tmp_path, (5.0, 10.0)) is None


def test_placement_sigma_recovers_the_spread_of_one_placement():
    # Each D = D_true + e with e ~ N(0, s), two placements per radius: the estimate is s.
    rng = np.random.default_rng(7)
    s = 3e-4
    pairs = [(0.21 + rng.normal(0, s), 0.21 + rng.normal(0, s)) for _ in range(4000)]
    assert lbm_study.placement_sigma(pairs) == pytest.approx(s, rel=0.05)
    assert lbm_study.placement_sigma([(0.2, 0.2)]) == 0.0
    assert lbm_study.placement_sigma([(0.2, 0.2 + 2e-4)]) == pytest.approx(2e-4 / math.sqrt(2), rel=1e-12)
    assert lbm_study.placement_sigma([]) is None


def matches(record, run):
    """Whether a summary's or checkpoint's arguments are those of `run` (the study's cache key)."""
    return study_runner.matches(record, run.resume_key(), run.assumed())


def summary_of(run):
    """The identity fields of a finished run's summary.json for `run` (default placement and kernel)."""
    return {"solver": "lbm", "method": run.method, "mesh": f"mt1:{run.triangles}", "G": run.G,
            "kappa_b_hat": run.kappa_b, "radius_lu": run.radius, "reynolds": run.reynolds, "box": list(run.box)}


def test_placement_runs_are_named_and_started_apart_from_the_study():
    centred = lbm_study.LbmRun("B", 0.2, 0.15, 8.0, 5120, lbm_study.BOX, 10.0)
    moved = lbm_study.LbmRun("B", 0.2, 0.15, 8.0, 5120, lbm_study.BOX, 10.0, offset=0.5)
    assert moved.name == centred.name + "_offset0.5"
    args = moved.arguments("out")
    assert args[args.index("--offset") + 1] == "0.5,0.5,0.5"
    assert "--offset" not in centred.arguments("out")
    assert lbm_study.is_placement(moved) and not lbm_study.is_placement(centred)
    assert not lbm_study.is_check(moved)
    # A finished run's summary is matched with its own placement only.
    summary = summary_of(centred)
    assert matches(summary, centred) and not matches(summary, moved)
    summary["offset"] = [0.5, 0.5, 0.5]
    assert matches(summary, moved) and not matches(summary, centred)


def test_kernel_check_runs_are_named_matched_and_kept_out_of_the_fit():
    study = lbm_study.LbmRun("A", 0.2, 0.15, 6.0, 1280, lbm_study.BOX, 10.0)
    wide = lbm_study.LbmRun("A", 0.2, 0.15, 6.0, 1280, lbm_study.BOX, 10.0, kernel="phi4")
    assert wide.name == study.name + "_phi4"
    args = wide.arguments("out")
    assert args[args.index("--kernel") + 1] == "phi4"
    assert "--kernel" not in study.arguments("out")
    assert lbm_study.is_check(wide) and not lbm_study.is_check(study)
    assert not lbm_study.is_placement(wide)
    # A summary names its kernel; one without the field is the default kernel's (older runs).
    summary = summary_of(study)
    assert matches(summary, study) and not matches(summary, wide)
    summary["kernel"] = "phi4"
    assert matches(summary, wide) and not matches(summary, study)
