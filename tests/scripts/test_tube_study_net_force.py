"""The tube study's net force of each bending method on a run's cells (scripts/tube_study.py):
on a red blood cell and a sheared copy of it, Method A's net force vanishes to round-off (the exact
gradient of a translation-invariant energy) while the other methods' does not on the sheared cell;
the driving force per cell is the body force times the tube's volume over the cells; the record
is kept in net_force.json and read back once the snapshot is gone; and a failed run's message is
cleaned of its checkpoint path, with its time read from it."""
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import tube_study  # noqa: E402

BENDLAB = ROOT / "build" / "release" / "bendlab"


def read_off(path):
    lines = [l for l in Path(path).read_text().split("\n") if l.strip()]
    n, m = map(int, lines[1].split()[:2])
    pts = np.array([[float(v) for v in l.split()] for l in lines[2:2 + n]])
    tris = np.array([[int(v) for v in l.split()[1:4]] for l in lines[2 + n:2 + n + m]])
    return pts, tris


def write_vtp(path, pts, tris, body):
    def arr(name, values, kind):
        return (f'<DataArray type="{kind}" Name="{name}" format="ascii">\n'
                + "\n".join(str(v) for v in values) + "\n</DataArray>\n")
    Path(path).write_text(
        '<?xml version="1.0"?>\n<VTKFile type="PolyData"><PolyData><Piece>\n<PointData>'
        + arr("body", body, "Float64") + "</PointData><Points>"
        + arr("Points", [f"{x!r} {y!r} {z!r}" for x, y, z in pts], "Float64") + "</Points><Polys>"
        + arr("connectivity", [f"{a} {b} {c}" for a, b, c in tris], "Int64")
        + arr("offsets", [3 * (i + 1) for i in range(len(tris))], "Int64")
        + "</Polys></Piece></PolyData></VTKFile>\n")


@pytest.mark.skipif(not BENDLAB.exists(), reason="needs the built bendlab (build/release/bendlab)")
def test_net_force_record(tmp_path):
    off = tmp_path / "rbc.off"
    subprocess.run([str(BENDLAB), "mesh", "--family", "mt1", "--level", "2", "--shape", "rbc", "--radius", "3.91",
                    "--out", str(off)], check=True, capture_output=True)
    x, t = read_off(off)
    sheared = x.copy()
    sheared[:, 0] += 0.3 * x[:, 2] + 0.05 * x[:, 2] ** 2  # bent: no symmetry left to cancel the errors
    pts = np.vstack([x + [5.0, 0.0, 0.0], sheared])
    tris = np.vstack([t, t + len(x)])
    body = [0] * len(x) + [1] * len(x)
    run = tube_study.run(10, 0.3, "C")
    folder = tmp_path / run.name
    folder.mkdir()
    write_vtp(folder / "snapshot_00003.vtp", pts, tris, body)
    (folder / "shapes.pvd").write_text('<DataSet timestep="0.03" group="" part="0" file="snapshot_00003.vtp"/>\n')
    (folder / "run.log").write_text(
        "driving: pseudo-shear rate 100 1/s, body force 3.84e+05 N/m^3 (6.6e-06 lattice), mean velocity 1000 um/s\n"
        "cells: 2 x rbc (mt1:320, skalak; G_s = 5.3e-06 N/m, kappa_B = 2e-19 J, Method C), tube hematocrit 0.1\n")
    rec = tube_study.net_force_record(BENDLAB, tmp_path, run)
    assert rec["t_s"] == pytest.approx(0.03)
    assert rec["kappa_pN_um"] == pytest.approx(0.2)
    # 3.84e5 N/m^3 x pi (5 um)^2 x 20 um / 2 cells, in pN.
    assert rec["driving_per_cell_pN"] == pytest.approx(3.84e5 * math.pi * 25e-12 * 20e-6 / 2 * 1e12)
    for m in tube_study.NET_FORCE_METHODS:
        e = rec["methods"][m]
        assert not e["errors"] and len(e["net_pN"]) == 2 and min(e["rms_node_pN"]) > 0
    a = np.array(rec["methods"]["A"]["net_pN"])
    assert np.abs(a).max() < 1e-10 * min(rec["methods"]["A"]["rms_node_pN"])
    c = np.array(rec["methods"]["C"]["net_pN"])
    assert np.linalg.norm(c[1]) > 1e-3 * rec["methods"]["C"]["rms_node_pN"][1]
    # Kept: a checkout without the snapshot reads the same record, without the program.
    (folder / "snapshot_00003.vtp").unlink()
    assert tube_study.net_force_record(None, tmp_path, run) == rec
    lines = tube_study.net_force_section(None, tmp_path, [run])
    assert any(l.startswith("| A | ") for l in lines) and any("0.03 s" in l for l in lines)


def test_failure_message(tmp_path):
    run = tube_study.run(10, 0.3, "M")
    (tmp_path / run.name).mkdir()
    (tmp_path / run.name / "failed.json").write_text(
        '{"arguments": [], "error": "bendlab: error: the run failed after step 111 (t (s) = 0.0110969): cell 0: '
        "singular fit; the last checkpoint, at t (s) = 0.0100971, is whole in '/x/checkpoint.json'\"}")
    err = tube_study.failure(run, tmp_path)
    assert err == "the run failed after step 111 (t (s) = 0.0110969): cell 0: singular fit"
    assert tube_study.failed_at(err) == pytest.approx(0.0110969)
    assert tube_study.failed_at("the run failed after step 3 (gamma t = 0.5): x") == pytest.approx(0.5)
    assert tube_study.failed_at("no time here") is None


def test_pries_hematocrit_inverts_the_law():
    # The hematocrit found gives back the viscosity it was asked for, at several diameters, and a
    # viscosity beyond the law's range has none.
    for D in (10.0, 15.0, 20.0):
        for H in (0.1, 0.3, 0.45, 0.6):
            eta = tube_study.pries_in_vitro(D, H)
            h = tube_study.pries_hematocrit(D, eta)
            assert h == pytest.approx(H, abs=1e-9)
    assert tube_study.pries_hematocrit(10.0, 0.5) is None


def test_net_force_removed_runs_are_runs_of_their_own():
    # The twin of a methods run without its bending force's net force: its own folder, the flow
    # option on its command (the plain runs say keep: the flow command removes it by default), and
    # the key in its identity only where it is set (so the plain runs made before the option still
    # match their summaries).
    plain, removed = tube_study.run(10, 0.3, "C"), tube_study.run(10, 0.3, "C", net_force="remove")
    assert removed.name != plain.name and removed.name.endswith("_noNF")
    args = removed.arguments("out")
    assert args[args.index("--bending-net-force") + 1] == "remove"
    plain_args = plain.arguments("out")
    assert plain_args[plain_args.index("--bending-net-force") + 1] == "keep"
    assert removed.key()["bending_without_net_force"] is True
    assert "bending_without_net_force" not in plain.key()
