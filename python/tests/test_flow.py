"""Cells in a tube from Python: the same run folder as `bendlab flow`, resumable both ways."""
import filecmp

import pytest

import bendlab

# Two spheres of 42 vertices in a 5 um tube (a lattice of 10 x 14 x 14 nodes), 225 lattice steps.
SMALL = dict(diameter=5, length=5, dx=0.5, pseudo_shear_rate=200, cell="sphere", cell_radius=1.2, mesh="mt1:80",
             cells=2, sample_every=1e-6, snapshot_every=4e-6, t_end=8e-6)
CLI_ARGS = ["--diameter", 5, "--length", 5, "--dx", 0.5, "--pseudo-shear-rate", 200, "--cell", "sphere",
            "--cell-radius", 1.2, "--mesh", "mt1:80", "--cells", 2, "--sample-every", 1e-6, "--snapshot-every", 4e-6,
            "--t-end", 8e-6]


def test_a_python_run_equals_the_cli_run_and_resumes_from_it(tmp_path, cli):
    summary = bendlab.flow_run(tmp_path / "py", **SMALL)
    for key in ("apparent_viscosity", "tube_hematocrit", "discharge_hematocrit", "cell_free_layer_um",
                "mean_velocity_um_s"):
        assert set(summary[key]) == {"mean", "standard_error", "rows"}
    cli("flow", *CLI_ARGS, "--out", tmp_path / "cli")
    for name in ("timeseries.csv", "cells.csv", "profiles.csv"):
        assert filecmp.cmp(tmp_path / "py" / name, tmp_path / "cli" / name, shallow=False), name
    assert summary == bendlab.read_summary(tmp_path / "cli")
    # Stopped from Python, resumed by the command line.
    assert bendlab.flow_run(tmp_path / "parts", stop_after_steps=3, **SMALL) is None
    cli("flow", *CLI_ARGS, "--resume", "--out", tmp_path / "parts")
    assert bendlab.read_summary(tmp_path / "parts") == summary


def test_the_bending_net_force_is_removed_by_default_as_on_the_command_line(tmp_path):
    # The first test compares the defaults; here the two settings are part of the run's identity.
    assert bendlab.flow_run(tmp_path / "removed", **SMALL)["bending_without_net_force"] is True
    kept = bendlab.flow_run(tmp_path / "kept", bending_net_force="keep", **SMALL)
    assert "bending_without_net_force" not in kept
    with pytest.raises(ValueError, match="bending_net_force"):
        bendlab.flow_run(tmp_path / "r", bending_net_force="drop", **SMALL)


def test_bad_input_raises_value_error_naming_it(tmp_path):
    with pytest.raises(ValueError, match="tau"):
        bendlab.flow_run(tmp_path / "r", **dict(SMALL, tau=0.5))
    with pytest.raises(ValueError, match="geometry"):
        bendlab.flow_run(tmp_path / "r", **dict(SMALL, geometry="pipe"))
    assert not (tmp_path / "r").exists()


def test_progress_reports_the_recorders_measures(tmp_path):
    seen = []
    bendlab.flow_run(tmp_path / "r", progress=seen.append, progress_interval=0, **SMALL)
    assert seen and seen[-1]["final"]
    assert {"eta_app", "H_D", "CFL_um"} <= set(seen[-1])


def test_the_shear_box_without_cells_has_the_plasma_viscosity(tmp_path):
    summary = bendlab.flow_run(tmp_path / "r", geometry="shear", height=4, width=3, length=3, shear_rate=2000,
                               hematocrit=0, t_end=4e-6, sample_every=1e-6)
    assert summary["apparent_viscosity"]["mean"] == pytest.approx(1.0, abs=1e-12)
    assert summary["discharge_hematocrit"]["mean"] is None
    with pytest.raises(ValueError, match="shear-rate"):
        bendlab.flow_run(tmp_path / "q", geometry="shear", height=4, width=3, length=3, hematocrit=0, t_end=4e-6)
