#!/usr/bin/python3
"""`mpirun -np N bendlab shear --solver lbm` and `mpirun -np N bendlab flow` (a tube with two red
blood cells) against the serial command (ctest parallel.cli): the same files in the run folder
(for flow every file byte for byte: time series, per-cell rows, profiles, fluid slices and
snapshots), the same time series and summary to the last digit, stdout's summary only once; a
checkpoint of N ranks resumed by the serial command, and the serial one by N ranks; an error on
the ranks ends the run with status != 0 and a line naming the rank and the problem.
Usage: cli_mpi_check.py BENDLAB MPIEXEC N
"""
import json
import os
import pathlib
import subprocess
import sys
import tempfile

bendlab, mpiexec, ranks = sys.argv[1], sys.argv[2], sys.argv[3]
ARGS = ["shear", "--solver", "lbm", "--mesh", "mt1:320", "--radius-lu", "4", "--box", "2.5,2.5,3", "--G", "0.2",
        "--t-end", "0.05", "--snapshot-every", "0.02", "--sample-every", "0.005", "--no-plot"]
ENV = dict(os.environ, OMP_NUM_THREADS="1", OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
MPI = [mpiexec, "-n", ranks, "--oversubscribe"]


def run(cmd, check=True):
    r = subprocess.run(cmd, capture_output=True, text=True, env=ENV, timeout=240)
    if check and r.returncode != 0:
        sys.exit(f"FAILED ({r.returncode}): {' '.join(cmd)}\n{r.stdout}\n{r.stderr}")
    return r


def same_series(a, b, what):
    ta, tb = (a / "timeseries.csv").read_text(), (b / "timeseries.csv").read_text()
    assert ta.count("\n") > 5, f"{what}: {ta.count(chr(10))} lines"
    assert ta == tb, f"{what}: the time series differ\n{ta}\n{tb}"


def same_files(a, b, what, but=("timing.json",)):
    names = sorted(os.listdir(a))
    assert names == sorted(os.listdir(b)), (what, names, sorted(os.listdir(b)))
    for n in names:
        if n == "checkpoint.json":  # all but its clock
            ca, cb = json.loads((a / n).read_text()), json.loads((b / n).read_text())
            ca.pop("wall_seconds"), cb.pop("wall_seconds")
            assert ca == cb, f"{what}: {n} differs"
        elif n not in but and not n.endswith(".lock"):
            assert (a / n).read_bytes() == (b / n).read_bytes(), f"{what}: {n} differs"


with tempfile.TemporaryDirectory() as d:
    d = pathlib.Path(d)
    serial = run([bendlab] + ARGS + ["--out", str(d / "serial")])
    par = run(MPI + [bendlab] + ARGS + ["--out", str(d / "par")])
    assert sorted(os.listdir(d / "serial")) == sorted(os.listdir(d / "par")), (os.listdir(d / "serial"), os.listdir(d / "par"))
    same_series(d / "serial", d / "par", "mpirun")
    assert len(par.stdout.strip().splitlines()) == 1, f"summary printed {len(par.stdout.splitlines())} times"
    a, b = json.loads(serial.stdout), json.loads(par.stdout)
    assert a == b, (a, b)
    # Interrupted on N ranks after the first snapshot (the 4th report), resumed by the serial program:
    # every file of the uninterrupted run, the later snapshots and checkpoints at its steps.
    run(MPI + [bendlab] + ARGS + ["--out", str(d / "resumed"), "--stop-after-steps", "5"])
    run([bendlab] + ARGS + ["--out", str(d / "resumed"), "--resume"])
    same_series(d / "serial", d / "resumed", "resume")
    same_files(d / "serial", d / "resumed", "resume")
    # A refused option on every rank: a non-zero status and one line, from rank 0, naming it.
    (d / "file").write_text("")
    bad = run(MPI + [bendlab] + ARGS + ["--out", str(d / "file")], check=False)
    assert bad.returncode != 0, "an error must end the run with a non-zero status"
    assert "error: --out" in bad.stderr and "is a file, not a folder" in bad.stderr, bad.stderr
    assert bad.stderr.count("error: --out") == 1, bad.stderr
    assert "rank" not in bad.stderr.split("error: --out")[0].splitlines()[-1], bad.stderr

# Many cells: each rank owns whole cells (docs/mpi.md, "Many cells").
FLOW = ["flow", "--geometry", "tube", "--diameter", "9", "--length", "12", "--dx", "0.5", "--tau", "1",
        "--pseudo-shear-rate", "100", "--cells", "2", "--mesh", "mt1:320", "--t-end", "4e-5", "--sample-every", "4e-6",
        "--snapshot-every", "2e-5"]


with tempfile.TemporaryDirectory() as d:
    d = pathlib.Path(d)
    serial = run([bendlab] + FLOW + ["--out", str(d / "serial")])
    par = run(MPI + [bendlab] + FLOW + ["--out", str(d / "par")])
    same_series(d / "serial", d / "par", "flow, mpirun")
    same_files(d / "serial", d / "par", "flow, mpirun")
    assert len(par.stdout.strip().splitlines()) == 1, f"summary printed {len(par.stdout.splitlines())} times"
    # Interrupted on N ranks and resumed by the serial program, and the other way round, before the
    # first snapshot (the 5th report) and after it: every file of the uninterrupted run.
    for stop in ("4", "7"):
        run(MPI + [bendlab] + FLOW + ["--out", str(d / f"resumed{stop}"), "--stop-after-steps", stop])
        run([bendlab] + FLOW + ["--out", str(d / f"resumed{stop}"), "--resume"])
        same_files(d / "serial", d / f"resumed{stop}", f"flow stopped after {stop} reports, resumed by the serial command")
        run([bendlab] + FLOW + ["--out", str(d / f"resumed2_{stop}"), "--stop-after-steps", stop])
        run(MPI + [bendlab] + FLOW + ["--out", str(d / f"resumed2_{stop}"), "--resume"])
        same_files(d / "serial", d / f"resumed2_{stop}", f"flow stopped after {stop} reports, resumed on N ranks")
    same_series(d / "serial", d / "resumed7", "flow, resumed by the serial command")
    # The shear box stays on one process: refused on every rank with one line.
    bad = run(MPI + [bendlab, "flow", "--geometry", "shear", "--height", "10", "--width", "10", "--length", "10",
                     "--shear-rate", "100", "--cells", "1", "--out", str(d / "shear")], check=False)
    if int(ranks) > 1:
        assert bad.returncode != 0 and bad.stderr.count("--geometry shear runs on one process") == 1, bad.stderr
        assert not (d / "shear").exists(), "a refused run must not write its folder"
print(f"cli_mpi_check: mpirun -n {ranks} bendlab shear --solver lbm and bendlab flow match the serial command")
