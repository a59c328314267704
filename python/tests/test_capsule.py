"""Capsule runs from Python: the same run folder as the command line, resumable both ways."""
import filecmp
import os
import signal

import numpy as np
import pytest

import bendlab

COMMON = dict(method="C", mesh="mt1:320", G=0.1, kappa_b_hat=0.05, t_end=0.3, snapshot_every=0.1)


def test_a_python_run_equals_the_cli_run(tmp_path, cli):
    summary = bendlab.shear_run(tmp_path / "py", **COMMON)
    cli("shear", "--method", "C", "--mesh", "mt1:320", "--G", "0.1", "--kappa-b-hat", "0.05", "--t-end", "0.3",
        "--snapshot-every", "0.1", "--no-plot", "--out", tmp_path / "cli")
    assert filecmp.cmp(tmp_path / "py" / "timeseries.csv", tmp_path / "cli" / "timeseries.csv", shallow=False)
    assert summary == bendlab.read_summary(tmp_path / "cli")
    ts = bendlab.read_time_series(tmp_path / "py")
    assert ts["gamma_t"][-1] == pytest.approx(0.3, abs=1e-12)
    assert np.all(np.diff(ts["gamma_t"]) > 0) and np.all(ts["D"] >= 0)
    assert summary["steps"] == len(ts["D"])


def test_stop_and_resume_equals_an_uninterrupted_run(tmp_path):
    full = bendlab.shear_run(tmp_path / "full", **COMMON)
    assert bendlab.shear_run(tmp_path / "parts", stop_after_steps=5, **COMMON) is None
    resumed = bendlab.shear_run(tmp_path / "parts", resume=True, **COMMON)
    assert resumed == full
    assert filecmp.cmp(tmp_path / "full" / "timeseries.csv", tmp_path / "parts" / "timeseries.csv", shallow=False)


def test_an_rkc_run_resumes_from_the_cli_and_equals_the_python_run(tmp_path, cli):
    rkc = dict(COMMON, integrator="rkc")
    full = bendlab.shear_run(tmp_path / "full", **rkc)
    assert full["integrator"] == "rkc" and full["integrator_stats"]["mean_stages"] >= 2
    assert bendlab.shear_run(tmp_path / "parts", stop_after_steps=3, **rkc) is None
    cli("shear", "--integrator", "rkc", "--method", "C", "--mesh", "mt1:320", "--G", "0.1", "--kappa-b-hat", "0.05",
        "--t-end", "0.3", "--snapshot-every", "0.1", "--no-plot", "--resume", "--out", tmp_path / "parts")
    assert bendlab.read_summary(tmp_path / "parts") == full
    assert filecmp.cmp(tmp_path / "full" / "timeseries.csv", tmp_path / "parts" / "timeseries.csv", shallow=False)
    with pytest.raises(Exception, match="integrator"):
        bendlab.shear_run(tmp_path / "bad", **dict(COMMON, integrator="euler"))


def test_a_skalak_run_from_python_resumes_from_the_cli_and_refuses_another_law(tmp_path, cli):
    sk = dict(COMMON, integrator="rkc", membrane="skalak", skalak_c=2.0)
    full = bendlab.shear_run(tmp_path / "full", **sk)
    assert full["membrane_law"] == "skalak" and full["skalak_c"] == 2.0
    assert bendlab.shear_run(tmp_path / "parts", stop_after_steps=3, **sk) is None
    with pytest.raises(Exception, match="membrane law skalak"):
        bendlab.shear_run(tmp_path / "parts", resume=True, **dict(sk, membrane="neo-hookean", skalak_c=1.0))
    cli("shear", "--integrator", "rkc", "--membrane", "skalak", "--skalak-c", "2", "--method", "C", "--mesh", "mt1:320",
        "--G", "0.1", "--kappa-b-hat", "0.05", "--t-end", "0.3", "--snapshot-every", "0.1", "--no-plot", "--resume",
        "--out", tmp_path / "parts")
    assert bendlab.read_summary(tmp_path / "parts") == full
    with pytest.raises(Exception, match="skalak-c"):
        bendlab.shear_run(tmp_path / "bad", **dict(sk, skalak_c=-0.5))


def test_progress_reaches_the_callback_and_ctrl_c_stops_cleanly(tmp_path):
    seen = []

    def progress(p):
        seen.append(p)
        if len(seen) == 3:
            os.kill(os.getpid(), signal.SIGINT)  # as a user pressing Ctrl-C

    with pytest.raises(KeyboardInterrupt):
        bendlab.shear_run(tmp_path / "run", progress=progress, progress_interval=0.0, **dict(COMMON, t_end=100.0))
    assert len(seen) == 3 and seen[-1]["steps"] == 3 and 0 < seen[-1]["time"] < 100
    # The folder is consistent: its checkpoint resumes (here to a short end time).
    summary = bendlab.shear_run(tmp_path / "run", resume=True, **dict(COMMON, t_end=0.15))
    assert summary["t_end"] == 0.15


def test_an_exception_in_the_callback_stops_the_run_and_is_raised(tmp_path):
    def progress(p):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        bendlab.shear_run(tmp_path / "run", progress=progress, progress_interval=0.0, **COMMON)


def test_bad_parameters_raise_value_error_before_any_file(tmp_path):
    with pytest.raises(ValueError, match="G"):
        bendlab.shear_run(tmp_path / "a", **dict(COMMON, G=-1.0))
    with pytest.raises(ValueError, match="kappa"):
        bendlab.shear_run(tmp_path / "b", **dict(COMMON, kappa_b=1.0))  # both moduli
    with pytest.raises(ValueError, match="no checkpoint"):
        bendlab.shear_run(tmp_path / "c", resume=True, **COMMON)
    with pytest.raises(ValueError, match="rings"):
        bendlab.shear_run(tmp_path / "d", **dict(COMMON, method="E"), method_options={"rings": 9})
    assert not any((tmp_path / n).exists() for n in "abcd")


def test_a_new_run_into_a_folder_holding_a_run_needs_overwrite(tmp_path):
    quick = dict(COMMON, t_end=0.02, snapshot_every=0.01)
    first = bendlab.shear_run(tmp_path / "run", **quick)
    with pytest.raises(ValueError, match="overwrite"):
        bendlab.shear_run(tmp_path / "run", **dict(quick, G=0.2))
    assert bendlab.read_summary(tmp_path / "run") == first
    second = bendlab.shear_run(tmp_path / "run", overwrite=True, **dict(quick, G=0.2))
    assert second["G"] == 0.2


def test_a_red_blood_cell_from_python_resumes_from_the_cli_with_the_same_angles(tmp_path, cli):
    rbc = dict(COMMON, shape="rbc", tilt=60.0, membrane="skalak", skalak_c=10.0, t_end=0.2)
    full = bendlab.shear_run(tmp_path / "full", **rbc)
    assert full["capsule_shape"]["shape"] == "rbc" and full["tilt"] == 60.0
    assert 0.6 < full["capsule_shape"]["reduced_volume"] < 0.7
    ts = bendlab.read_time_series(tmp_path / "full")
    # The axis starts at the tilt and turns with the flow; the marked rim node is a quarter turn ahead.
    assert ts["axis_angle"][0] == pytest.approx(np.radians(60.0), abs=0.01)
    assert ts["axis_angle"][-1] > ts["axis_angle"][0]
    assert ts["node_phase"][0] == pytest.approx(np.radians(150.0), abs=0.01)
    assert bendlab.shear_run(tmp_path / "parts", stop_after_steps=3, **rbc) is None
    cli("shear", "--shape", "rbc", "--tilt", "60", "--membrane", "skalak", "--skalak-c", "10", "--method", "C",
        "--mesh", "mt1:320", "--G", "0.1", "--kappa-b-hat", "0.05", "--t-end", "0.2", "--snapshot-every", "0.1",
        "--no-plot", "--resume", "--out", tmp_path / "parts")
    assert bendlab.read_summary(tmp_path / "parts") == full
    assert filecmp.cmp(tmp_path / "full" / "timeseries.csv", tmp_path / "parts" / "timeseries.csv", shallow=False)
    with pytest.raises(Exception, match="--tilt"):
        bendlab.shear_run(tmp_path / "bad", **dict(rbc, tilt=500.0))
