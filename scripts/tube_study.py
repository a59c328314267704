#!/usr/bin/python3
"""Blood in a glass tube: apparent viscosity, the Fahraeus effect and the cell-free layer against
Pries et al., and what the bending algorithm changes (`bendlab flow` runs; issue "Blood in a glass
tube").

    /usr/bin/python3 scripts/tube_study.py [--only diameters|hematocrit|methods|resolution|sensitivity|net_force|doc]
                                           [--t-end S] [--jobs N] [--methods LIST] [--bendlab PATH]
                                           [--work DIR]
                                           [--doc FILE] [--list]

Parts (each run one `bendlab flow` process):
  methods     D = 10 um at tube hematocrit 0.3 with Methods C, A, D, M and without bending, the
              same seed: eta_app, H_D, the cell-free layer and the cells' shapes side by side.
  diameters   D = 10, 15, 20 um at H_T = 0.3, Method C.
  hematocrit  D = 10 um at H_T = 0.2 and 0.4, Method C.
  resolution  the D = 10 um, H_T = 0.3, Method C case with 5120-triangle cells.
  sensitivity the same case with the repulsion's cutoff halved (0.25 um) and with a periodic
              length of three diameters.
  net_force   the same case with Methods C and D whose bending force's net force and torque are
              removed on each cell (flow --bending-net-force remove).
  doc         only regenerates the document from the runs that are done.
Without --only: methods, then diameters, hematocrit, resolution, sensitivity and net_force.

The model is the flow command's red blood cell with its cited defaults (docs/conventions.md §6:
eq. (15) at R = 3.91 um, Skalak G_s = 5.3 uN/m, C = 10, kappa_B = 2e-19 J, 1280 triangles),
plasma 1.2 mPa s, dx = 0.5 um, fixed before any comparison; the study chooses tau = 1.82, the
relaxation time of HemoCell's dt = 1e-7 s at dx = 0.5 um (nu = 1.1e-6 m^2/s), so that a step
covers 2.6 times the physical time of tau = 1 (the walls stay exactly halfway with TRT), the
pseudo-shear rate 100 1/s (Pries' data hold from 50 1/s) and a periodic length of two diameters
(the cells' count rounds H_T: the placed value is what the tables show). Nothing is tuned to the
laws it is compared with.

Every run's folder lies under --work (default studies/tube, kept in git without its fluid states:
studies/README.md). A run whose summary.json matches is not run again; a run that failed while
stepping is recorded, not retried (scripts/study_runner.py). Run the parts in the background:
    OMP_NUM_THREADS=1 nohup /usr/bin/python3 scripts/tube_study.py --only methods > results/tube.log 2>&1 &
Writes docs/results/tube_flow.md and its figures (docs/results/tube_flow/) from every run that is
done, and says which are missing.

The net force of each bending method (A, C, D, M) on the cells of a methods run's last snapshot
(`bendlab forces` on every cell, kappa_B of the run, in pN) is kept in the run's net_force.json
(the snapshots are not kept in git), beside the driving force per cell; with the runs' figures it
gives the document's stated answer to which method a suspension should use.
"""
import argparse
import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import study_runner  # noqa: E402
from study_runner import ROOT, fmt_g  # noqa: E402

DX = 0.5
TAU = 1.82
PSEUDO_SHEAR_RATE = 100.0
T_END = 0.1
SEED = 1
SAMPLE_EVERY = 1e-4
SNAPSHOT_EVERY = 0.01
METHODS = ["C", "A", "D", "M", "none"]


def say(msg):
    print(time.strftime("%H:%M:%S"), msg, flush=True)


# ----------------------------------------------------------------------------- the laws

def pries_in_vitro(D, H_D):
    """eta_rel of blood in a glass tube of diameter D (um) at discharge hematocrit H_D, Pries et al.
    1992 (Am J Physiol 263:H1770; shared/spec/CELLS_IN_CHANNELS.md section 5)."""
    eta45 = 220 * math.exp(-1.3 * D) + 3.2 - 2.44 * math.exp(-0.06 * D ** 0.645)
    s = 1 / (1 + 1e-11 * D ** 12)
    C = (0.8 + math.exp(-0.075 * D)) * (-1 + s) + s
    return 1 + (eta45 - 1) * ((1 - H_D) ** C - 1) / ((1 - 0.45) ** C - 1)


def fahraeus(D, H_D):
    """H_T / H_D in a tube of diameter D (um), Pries et al. 1990 (CELLS_IN_CHANNELS.md section 5)."""
    return H_D + (1 - H_D) * (1 + 1.7 * math.exp(-0.415 * D) - 0.6 * math.exp(-0.011 * D))


def pries_hematocrit(D, eta_rel):
    """The discharge hematocrit at which Pries' in-vitro law gives eta_rel in a tube of diameter D
    (the law grows with H_D; bisection over [0, 0.95]), or None outside its range."""
    lo, hi = 0.0, 0.95
    if not pries_in_vitro(D, lo) <= eta_rel <= pries_in_vitro(D, hi):
        return None
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if pries_in_vitro(D, mid) < eta_rel else (lo, mid)
    return 0.5 * (lo + hi)


# What the document sets beside the cell-free layer: only values whose source was read.
CELL_FREE_LAYER_LITERATURE = (
    "Fedosov, Caswell, Popel & Karniadakis, Microcirculation 17:615 (2010), \"Blood flow and cell-free "
    "layer in microvessels\": simulated cell-free layers of about 0.5-1 um in tubes of 10 um at H_T "
    "0.3, growing with the diameter to about 1.5-2 um at 20 um; the experiments they compare with "
    "(Reinke et al. 1987, Kim et al. 2007) scatter widely")


# ----------------------------------------------------------------------------- runs

@dataclass(frozen=True)
class Run(study_runner.StudyRun):
    """A flow run: its folder, diameter, tube hematocrit, bending method, mesh and end."""
    name: str
    diameter: float
    hematocrit: float
    method: str
    mesh: str
    t_end: float
    contact_cutoff: float = 0.0   # um; 0: the flow command's default, one dx
    length_factor: float = 2.0    # the periodic length in tube diameters
    net_force: str = "keep"       # --bending-net-force: keep, or remove the bending force's net force
    time_scale: float = 1.0       # --time-scale S: S times the density, S times fewer steps (Stokes flow)
    start_arguments = ("--overwrite",)

    def arguments(self, out):
        extra = ["--contact-cutoff", fmt_g(self.contact_cutoff)] if self.contact_cutoff else []
        # Explicit: the flow command removes the net force by default, and the study's runs keep it
        # unless they say otherwise.
        extra += ["--bending-net-force", self.net_force]
        extra += ["--time-scale", fmt_g(self.time_scale)] if self.time_scale != 1 else []
        return ["flow", "--geometry", "tube", "--diameter", fmt_g(self.diameter), "--length",
                fmt_g(self.length_factor * self.diameter), "--dx", fmt_g(DX), "--tau", fmt_g(TAU),
                "--pseudo-shear-rate", fmt_g(PSEUDO_SHEAR_RATE), "--hematocrit", fmt_g(self.hematocrit),
                "--seed", str(SEED), "--method", self.method, "--mesh", self.mesh, "--t-end", fmt_g(self.t_end),
                "--sample-every", fmt_g(SAMPLE_EVERY), "--snapshot-every", fmt_g(SNAPSHOT_EVERY)] + extra + [
                "--out", str(out)]

    def key(self):
        k = {"t_end": self.t_end, "diameter_um": self.diameter, "hematocrit": self.hematocrit,
             "method": self.method, "mesh": self.mesh, "tau": TAU, "dx_um": DX,
             "pseudo_shear_rate": PSEUDO_SHEAR_RATE, "seed": SEED, "contact_cutoff_um": self.contact_cutoff,
             "length_um": self.length_factor * self.diameter}
        if self.net_force != "keep":  # the flow command's summary has the key only when it is set
            k["bending_without_net_force"] = True
        if self.time_scale != 1:  # likewise
            k["time_scale"] = self.time_scale
        return k

    def label(self):
        extra = (f", cutoff {fmt_g(self.contact_cutoff)} um" if self.contact_cutoff else "") + (
            f", L = {fmt_g(self.length_factor)} D" if self.length_factor != 2.0 else "") + (
            ", net force removed" if self.net_force != "keep" else "") + (
            f", time scale {fmt_g(self.time_scale)}" if self.time_scale != 1 else "")
        return (f"D = {fmt_g(self.diameter)} um, H_T {fmt_g(self.hematocrit)}, Method {self.method}, "
                f"{self.mesh}{extra}")


def run(D, H, method="C", mesh="mt1:1280", t_end=T_END, contact_cutoff=0.0, length_factor=2.0, net_force="keep",
        time_scale=1.0):
    name = f"D{fmt_g(D)}_H{fmt_g(H)}_{method}_{mesh.replace(':', '')}"
    name += (f"_cut{fmt_g(contact_cutoff)}" if contact_cutoff else "") + (
        f"_L{fmt_g(length_factor)}D" if length_factor != 2.0 else "") + ("_noNF" if net_force != "keep" else "") + (
        f"_S{fmt_g(time_scale)}" if time_scale != 1 else "")
    return Run(name, D, H, method, mesh, t_end, contact_cutoff, length_factor, net_force, time_scale)


# The time scale of the 20 um tube: 20 times the density (Re 0.68 <= 0.85, Mach 0.026) makes its run
# of about 5.7 hours on one core one of about 17 minutes (docs/results/time_scaling.md: up to
# S = 100 the 10 um tube's results stay within 2 standard errors of the unscaled run).
D20_TIME_SCALE = 20.0


def parts(t_end, methods=METHODS):
    return {
        "methods": [run(10, 0.3, m, t_end=t_end) for m in methods],
        "diameters": [run(D, 0.3, t_end=t_end, time_scale=D20_TIME_SCALE if D == 20 else 1.0) for D in (10, 15, 20)],
        "hematocrit": [run(10, H, t_end=t_end) for H in (0.2, 0.4)],
        "resolution": [run(10, 0.3, "C", "mt1:5120", t_end=t_end)],
        # What the departure from Pries' law could come from: the repulsion's reach and the period.
        "sensitivity": [run(10, 0.3, t_end=t_end, contact_cutoff=0.25), run(10, 0.3, t_end=t_end, length_factor=3.0)],
        # Methods C and D with their bending force's net force and torque removed (--bending-net-force
        # remove): whether that net force is what sets them apart from Method A.
        "net_force": [run(10, 0.3, m, t_end=t_end, net_force="remove") for m in ("C", "D")],
    }


# ----------------------------------------------------------------------------- the document

def done(r, work):
    s = study_runner.read_summary(work / r.name)
    return s if s is not None and study_runner.matches(s, r.key()) else None


def unfinished(r, work):
    """What a run without a summary reached, from the last progress line of its run.log ("t = T /
    T_END s ... elapsed S s"): how far it got and the wall time that took; "not run yet" without one."""
    import re
    m = re.match(r"t = ([0-9.eE+-]+) / ([0-9.eE+-]+) s .*elapsed ([0-9.]+) s",
                 study_runner.last_progress_line(work / r.name))
    if not m:
        return "not run yet"
    t, t_end, wall = (float(v) for v in m.groups())
    return (f"unfinished: t = {num(t, 3)} s of {num(t_end, 3)} s reached in {wall:.0f} s of wall time (about "
            f"{wall * t_end / t / 3600:.1f} h for the whole run at that rate)")


def threads_note(work, r):
    """" on N threads" where a start of the run names OMP_NUM_THREADS other than 1 on its run.log's
    launch line (the largest such N), else "" (the study's command sets 1)."""
    counts = [int(c) for c in study_runner.threads_of(work / r.name) if c and c.isdigit() and int(c) != 1]
    return f" on {max(counts)} threads" if counts else ""


def failure(r, work):
    """The run's error as the document shows it (without the program's prefix and the checkpoint's
    path), or None where it did not fail."""
    import re
    f = study_runner.read_json(work / r.name / "failed.json")
    if not isinstance(f, dict) or not f.get("error"):
        return None
    text = f["error"].removeprefix("bendlab: error: ")
    return re.sub(r"; the last checkpoint, at [^=]+= ([0-9.eE+-]+), is whole in '[^']*'$", "", text)


def failed_at(error):
    """The time (s) a flow run's error names as the last step's, else None."""
    import re
    m = re.search(r"the run failed after step \d+ \((?:gamma t|t \(s\)) = ([0-9.eE+-]+)\)", error or "")
    return float(m.group(1)) if m else None


def num(x, digits=4):
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else f"{x:.{digits}g}"


def mean_se(s, key):
    v = s.get(key) or {}
    return v.get("mean"), v.get("standard_error")


def pm(s, key, digits=4):
    m, e = mean_se(s, key)
    return f"{num(m, digits)} ± {num(e, 2)}"


def read_csv(path):
    import csv
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError:
        return None
    return {k: np.array([study_runner.number(r[k]) for r in rows]) for k in rows[0]} if rows else None


def cell_shapes(work, r, s):
    """Mean Taylor deformation and axis angle of the cells over the steady window."""
    c = read_csv(work / r.name / "cells.csv")
    if c is None:
        return None, None
    begin = s["steady_window_s"][0]
    sel = c["t_s"] >= begin - 1e-12
    return float(np.mean(c["D"][sel])), float(np.mean(c["axis_angle_deg"][sel]))


# ----------------------------------------------------------------------------- net force

# The methods whose force on a run's cells the study evaluates, on the same shapes.
NET_FORCE_METHODS = ["A", "C", "D", "M"]
NET_FORCE_FILE = "net_force.json"


def run_log_parameters(folder):
    """kappa_B (J), the body force (N/m^3) and the number of cells, as the run's log states them."""
    import re
    try:
        text = (folder / "run.log").read_text()
    except OSError:
        return None
    kappa = re.search(r"kappa_B = ([-+0-9.eE]+) J", text)
    force = re.search(r"body force ([-+0-9.eE]+) N/m\^3", text)
    cells = re.search(r"^cells: (\d+) x", text, re.M)
    if not (kappa and force and cells):
        return None
    return float(kappa.group(1)), float(force.group(1)), int(cells.group(1))


def snapshot_times(folder):
    """{snapshot file name: t (s)} from the run's shapes.pvd."""
    import re
    try:
        text = (folder / "shapes.pvd").read_text()
    except OSError:
        return {}
    return {m.group(2): float(m.group(1)) for m in re.finditer(r'timestep="([^"]+)"[^>]*file="([^"]+)"', text)}


def net_force_record(bendlab, work, r):
    """The net force of each method of NET_FORCE_METHODS on every cell of the run's last snapshot, in pN
    (`bendlab forces` on each cell, kappa_B in pN um), beside the driving force per cell (the body force
    times the tube's volume over the number of cells). Kept in the run's net_force.json, so that a
    checkout without the snapshots writes the same document; None where the run has neither."""
    import json
    import subprocess
    import tempfile
    from tube_shapes import read_vtp
    folder = work / r.name
    cached = study_runner.read_json(folder / NET_FORCE_FILE)
    vtps = sorted(folder.glob("snapshot_*.vtp"))
    if isinstance(cached, dict) and (not vtps or cached.get("snapshot") == vtps[-1].name) and \
            cached.get("methods", {}).keys() == set(NET_FORCE_METHODS):
        return cached
    params = run_log_parameters(folder)
    if not vtps or params is None or bendlab is None:
        return cached if isinstance(cached, dict) else None
    kappa_J, body_force, n_cells = params
    kappa_pN_um = kappa_J * 1e18
    volume_m3 = math.pi * (0.5e-6 * r.diameter) ** 2 * (r.length_factor * r.diameter * 1e-6)
    driving_pN = body_force * volume_m3 / n_cells * 1e12
    pts, tris, body = read_vtp(vtps[-1], with_body=True)
    rec = {"snapshot": vtps[-1].name, "t_s": snapshot_times(folder).get(vtps[-1].name),
           "kappa_pN_um": kappa_pN_um, "driving_per_cell_pN": driving_pN, "flow_axis": "x", "methods": {}}
    with tempfile.TemporaryDirectory() as tmp:
        meshes = []
        for c in range(int(body.max()) + 1):
            idx = np.flatnonzero(body == c)
            local = tris[body[tris[:, 0]] == c] - idx[0]
            x = pts[idx] - pts[idx].mean(axis=0)
            path = Path(tmp) / f"cell_{c}.off"
            path.write_text(f"OFF\n{len(x)} {len(local)} 0\n" + "".join(f"{a!r} {b!r} {d!r}\n" for a, b, d in x)
                            + "".join(f"3 {i} {j} {k}\n" for i, j, k in local))
            meshes.append(path)
        for m in NET_FORCE_METHODS:
            net, rms, errors = [], [], []
            for c, mesh in enumerate(meshes):
                out = Path(tmp) / f"forces_{m}_{c}.csv"
                done_ = subprocess.run([str(bendlab), "forces", "--mesh", str(mesh), "--method", m, "--kappa-b",
                                        repr(kappa_pN_um), "--out", str(out)], capture_output=True, text=True)
                if done_.returncode != 0:
                    errors.append(f"cell {c}: {(done_.stderr or done_.stdout).strip().splitlines()[-1]}")
                    continue
                f = read_csv(out)
                F = np.stack([f["Fx"], f["Fy"], f["Fz"]], axis=1)
                net.append(F.sum(axis=0).tolist())
                rms.append(float(np.sqrt((F ** 2).sum(axis=1).mean())))
            rec["methods"][m] = {"net_pN": net, "rms_node_pN": rms, "errors": errors}
    tmp_file = folder / (NET_FORCE_FILE + ".tmp")
    tmp_file.write_text(json.dumps(rec, indent=1))
    tmp_file.replace(folder / NET_FORCE_FILE)
    return rec


def net_force_section(bendlab, work, runs):
    """The document's lines on the net bending force per cell, from the runs that have a record."""
    L = []
    for r in runs:
        rec = net_force_record(bendlab, work, r)
        if rec is None:
            continue
        t = rec.get("t_s")
        L += [f"On the cells of the run {r.label()}, at t = {num(t, 3)} s ({rec['snapshot']}); the driving force "
              f"per cell (body force x tube volume / cells) is {num(rec['driving_per_cell_pN'], 3)} pN:", "",
              "| method | net force along the flow, mean over cells (pN) | largest net force over cells (pN) | "
              "largest / driving force per cell | rms node force (pN) | cells it failed on |",
              "| --- | --- | --- | --- | --- | --- |"]
        for m in NET_FORCE_METHODS:
            e = rec["methods"].get(m, {})
            net = np.array(e.get("net_pN") or np.zeros((0, 3)))
            if len(net):
                mag = np.linalg.norm(net, axis=1)
                L.append(f"| {m} | {num(float(net[:, 0].mean()), 3)} | {num(float(mag.max()), 3)} | "
                         f"{num(float(mag.max()) / rec['driving_per_cell_pN'], 3)} | "
                         f"{num(float(np.mean(e['rms_node_pN'])), 3)} | {len(e.get('errors', []))} |")
            else:
                L.append(f"| {m} | - | - | - | - | {len(e.get('errors', []))} ({'; '.join(e.get('errors', []))}) |")
        L.append("")
    if not L:
        return []
    return ["## The net force of the bending force on a cell", "",
            "Every method's force on the same shapes: each cell of a run's last snapshot, alone (`bendlab forces`, "
            "kappa_B of the run). A membrane's internal forces must sum to zero on each cell: the continuous "
            "bending force of a closed surface does, as the variation of an energy that a translation leaves "
            "unchanged. Method A is the exact gradient of such a discrete energy, so its net force is zero to "
            "round-off; Methods C, D and M evaluate the continuous force density at the vertices, and their "
            "discretisation errors need not cancel over a cell. What does not cancel pushes the cell through "
            "the plasma and the plasma the other way: a force the physics does not have.", ""] + L


def answer(bendlab, work, runs, without_net_force=()):
    """The stated answer to "does the bending algorithm change what the suspension does, and which
    should a user pick", from the runs of the methods part, the net forces on their cells and the
    runs whose bending force has its net force removed (without_net_force)."""
    rows = [(r, done(r, work)) for r in runs]
    ran = [(r, s) for r, s in rows if s is not None]
    failed = [(r, failure(r, work)) for r, s in rows if s is None and failure(r, work)]
    if len(ran) < 2:
        return []
    eta = {r.method: mean_se(s, "apparent_viscosity") for r, s in ran}
    hd = {r.method: mean_se(s, "discharge_hematocrit") for r, s in ran}
    cfl = {r.method: mean_se(s, "cell_free_layer_um") for r, s in ran}
    lo = min(eta, key=lambda m: eta[m][0])
    hi = max(eta, key=lambda m: eta[m][0])
    z = (eta[hi][0] - eta[lo][0]) / math.hypot(eta[hi][1], eta[lo][1])
    bending = [m for m in eta if m != "none"]
    L = ["**The answer.** Yes, beyond the noise: over the methods that ran, eta_app / eta goes from "
         f"{num(eta[lo][0])} (Method {lo}) to {num(eta[hi][0])} (Method {hi}), {z:.0f} standard errors apart "
         f"({(eta[hi][0] - eta[lo][0]) / eta[lo][0]:+.1%}); H_D from {num(min(v[0] for v in hd.values()), 3)} to "
         f"{num(max(v[0] for v in hd.values()), 3)}, the cell-free layer from {num(min(v[0] for v in cfl.values()), 3)} "
         f"to {num(max(v[0] for v in cfl.values()), 3)} um."]
    if "none" in eta and bending:
        spread = max(eta[m][0] for m in bending) - min(eta[m][0] for m in bending)
        L[-1] += (f" Bending itself moves eta_app by {min(abs(eta[m][0] - eta['none'][0]) for m in bending):.3g} "
                  f"to {max(abs(eta[m][0] - eta['none'][0]) for m in bending):.3g} from the run without it; the "
                  f"choice among the bending methods that finished, by {spread:.3g}.")
    for r, err in failed:
        t = failed_at(err)
        L[-1] += (f" Method {r.method} did not finish: it failed at t = {num(t, 3)} s of {num(r.t_end, 3)} s "
                  f"({err.split(': ')[-1] if ': ' in err else err}).")
    # The net forces: the largest on any recorded shapes, per method, against the driving force per
    # cell and against the method's own rms force on a node.
    worst, own = {}, {}
    for r in runs:
        rec = net_force_record(bendlab, work, r)
        if rec is None:
            continue
        for m, e in rec["methods"].items():
            net = np.array(e.get("net_pN") or np.zeros((0, 3)))
            if len(net):
                mag = np.linalg.norm(net, axis=1)
                worst[m] = max(worst.get(m, 0.0), float(mag.max()) / rec["driving_per_cell_pN"])
                own[m] = max(own.get(m, 0.0), float(np.max(mag / np.maximum(e["rms_node_pN"], 1e-300))))
    if worst:
        L[-1] += (" What the static benchmark cannot show is whether a method's forces on a cell sum to zero: "
                  "on the shapes of these runs (the section below), the largest net force on a cell is "
                  + ", ".join(f"{worst[m]:.2g} of the driving force per cell and {own[m]:.2g} times its own rms "
                              f"node force for Method {m}" for m in sorted(worst))
                  + " (a sum of 642 node forces of random sign would be about 25 of them; more is a bias).")
    # What to pick: a method whose net force vanishes (round-off) and that ran; then the others that
    # ran, with their net force; not those that failed.
    ran_methods = [m for m in bending]
    exact = [m for m in ran_methods if worst.get(m, 1.0) < 1e-9]
    unfit = sorted({r.method for r, _ in failed})
    usable = [m for m in ran_methods if m not in exact and m not in unfit]
    clean = {r.method: mean_se(s, "apparent_viscosity") for r in without_net_force
             if r.method in eta and (s := done(r, work)) is not None}
    L[-1] += without_net_force_answer(eta, clean)
    pick = []
    removed = sorted(clean)
    if len(removed) >= 2:
        pick.append(f"Method {' or '.join(removed)} with its net force removed (`--bending-net-force remove`): "
                    "they then come together, as above")
    if exact:
        pick.append(f"a method whose force is the exact gradient of a discrete energy (Method {', '.join(exact)} "
                    "here; B and J are of the same kind): its net force and torque on every cell vanish by "
                    "construction")
    if usable:
        pick.append(" or ".join(f"Method {m}" + (f" knowing that it can push a cell against the flow with up to "
                                                 f"{worst[m]:.2g} of the driving force" if m in worst else "")
                                for m in usable))
    if pick:
        L[-1] += (" So, for a suspension at this resolution (1280 triangles, dx = 0.5 um), pick " + "; or ".join(pick)
                  + ".")
    if unfit:
        L[-1] += (" Not Method " + ", ".join(unfit) + " at this resolution: "
                  + "; ".join(f"{m} failed" + (f", and its net force reached {worst[m]:.2g} of the driving force "
                                                 "on the shapes below" if m in worst else "") for m in unfit) + ".")
    L[-1] += " Which figures have converged is the resolution section's question, not this table's."
    return L + [""]


def without_net_force_answer(eta, clean):
    """What removing the bending force's net force does to the methods' spread of eta_app (eta, clean:
    (mean, standard error) per method of the plain runs and of those without the net force), or ""
    while fewer than two of the latter are done."""
    if len(clean) < 2:
        return ""
    lo, hi = min(clean, key=lambda m: clean[m][0]), max(clean, key=lambda m: clean[m][0])
    before = abs(eta[hi][0] - eta[lo][0])
    after = clean[hi][0] - clean[lo][0]
    z = after / math.hypot(clean[hi][1], clean[lo][1])
    text = (f" With their net force and torque removed on each cell (the section below), Methods {lo} and {hi} "
            f"give eta_app / eta = {num(clean[lo][0])} and {num(clean[hi][0])}: {after:.2g} apart "
            f"({z:.0f} standard errors) where the plain runs were {before:.3g} apart")
    if "none" in eta:
        off = max(abs(v[0] - eta["none"][0]) for v in clean.values())
        text += f", and within {off:.2g} of the run without bending"
        if "A" in eta:
            text += f" (Method A, whose force has no net force to remove: {eta['A'][0] - eta['none'][0]:+.3g} from it)"
    text += (f". Most of what separated Methods {lo} and {hi} in a suspension was the net force their "
             f"discretisation leaves on a cell, not their bending; `flow --bending-net-force remove` takes it off.")
    return text


def departure_evidence(work, all_parts):
    """What the runs say about where the departure from Pries' law comes from: each variant of the
    D = 10 um, H_T 0.3, Method C run against it (in standard errors), and the hematocrit at which
    the law would give each Method C run's eta_app."""
    by_name = {r.name: (r, done(r, work)) for part in all_parts.values() for r in part}
    base = by_name.get(run(10, 0.3).name, (None, None))[1]
    if base is None:
        return []
    e0, se0 = mean_se(base, "apparent_viscosity")
    law0 = pries_in_vitro(10, mean_se(base, "discharge_hematocrit")[0])
    L = ["What the finished runs say about the candidates (each against the D = 10 um, H_T 0.3, Method C "
         f"run, eta_app {num(e0)} ± {num(se0, 2)}, {(e0 - law0) / law0:+.1%} from the law):", ""]
    variants = [(run(10, 0.3, "none"), "without bending (no bending force, so no net force of one)"),
                (run(10, 0.3, "C", net_force="remove"), "Method C with its bending force's net force and torque removed"),
                (run(10, 0.3, contact_cutoff=0.25), "the repulsion's cutoff halved to 0.25 um"),
                (run(10, 0.3, length_factor=3.0), "a periodic length of three diameters"),
                (run(10, 0.3, "C", "mt1:5120"), "cells of 5120 triangles")]
    for r, what in variants:
        s = by_name.get(r.name, (None, None))[1]
        if s is None:
            L.append(f"- {what}: not run yet.")
            continue
        e, se = mean_se(s, "apparent_viscosity")
        law = pries_in_vitro(r.diameter, mean_se(s, "discharge_hematocrit")[0])
        z = (e - e0) / math.hypot(se, se0) if math.hypot(se, se0) > 0 else math.inf
        L.append(f"- {what}: eta_app {num(e)} ± {num(se, 2)} ({e - e0:+.3g}, {z:+.1f} standard errors of the "
                 f"difference), {(e - law) / law:+.1%} from the law.")
    rows = []
    for r in all_parts.get("methods", [])[:1] + all_parts.get("hematocrit", []):
        s = by_name.get(r.name, (None, None))[1]
        if s is None or r.method != "C":
            continue
        e, _ = mean_se(s, "apparent_viscosity")
        hd, _ = mean_se(s, "discharge_hematocrit")
        h = pries_hematocrit(r.diameter, e)
        if h is not None and hd:
            rows.append((r, hd, h))
    if len(rows) > 1:
        ratios = [h / hd for _, hd, h in rows]
        L += ["", "The discharge hematocrit at which Pries' law would give each Method C run's eta_app, against "
              "the one the run measured: " + "; ".join(
                  f"H_T {fmt_g(r.hematocrit)}: {h:.3f} for {hd:.3f} (x {h / hd:.2f})" for r, hd, h in rows) + ". "
              "Cells that the fluid sees larger than their meshes by a fixed margin (the immersed boundary "
              "spreads each vertex's force over one dx either side) would need one factor at every hematocrit; "
              + (f"the factors here differ by {max(ratios) / min(ratios) - 1:.0%}, so such a margin alone does "
                 "not account for the departure." if max(ratios) / min(ratios) > 1.1 else
                 f"the factors here agree within {max(ratios) / min(ratios) - 1:.0%}, as such a margin would "
                 "give.")]
    return L + [""]


def resolution_verdict(work, runs):
    """Which of the D = 10 um, H_T 0.3, Method C run's figures have converged with the cells' mesh:
    each figure of the finest run against the coarsest, in standard errors of the difference and
    relative, beside the departure from the laws that it would have to explain."""
    finished = [(r, s) for r in runs if (s := done(r, work)) is not None]
    if len(finished) < 2:
        return []
    (rc, sc), (rf, sf) = finished[0], finished[-1]
    parts = []
    for key, what in (("apparent_viscosity", "eta_app / eta"), ("discharge_hematocrit", "H_D"),
                      ("cell_free_layer_um", "the cell-free layer")):
        (ec, sec), (ef, sef) = mean_se(sc, key), mean_se(sf, key)
        se = math.hypot(sec, sef)
        z = (ef - ec) / se if se > 0 else math.inf
        parts.append(f"{what} {num(ec)} -> {num(ef)} ({(ef - ec) / ec:+.1%}, {z:+.1f} standard errors of the "
                     "difference)")
    law_c = pries_in_vitro(rc.diameter, mean_se(sc, "discharge_hematocrit")[0])
    law_f = pries_in_vitro(rf.diameter, mean_se(sf, "discharge_hematocrit")[0])
    ec, ef = mean_se(sc, "apparent_viscosity")[0], mean_se(sf, "apparent_viscosity")[0]
    return [f"From {rc.mesh} to {rf.mesh}: " + "; ".join(parts) + ". Against Pries' in-vitro law at each run's "
            f"own H_D, eta_app goes from {(ec - law_c) / law_c:+.1%} to {(ef - law_f) / law_f:+.1%}. A change "
            "within about two standard errors is one these runs cannot tell from noise; a larger one means the "
            f"figure has not converged at {rc.mesh}.", ""]


def net_force_removed_section(work, all_parts, table_of):
    """The methods runs beside their twins without the bending force's net force and torque: each
    twin against its plain run and against Method A, in standard errors."""
    if not all_parts.get("net_force"):
        return []
    methods = {r.method: r for r in all_parts["methods"]}
    rows = [methods[m] for m in ("A",) if m in methods]
    for r in all_parts["net_force"]:
        rows += [methods[r.method]] if r.method in methods else []
        rows.append(r)
    L = ["## The bending force without its net force", "",
         "Methods C and D with their bending force's net force and torque taken off each cell "
         "(`--bending-net-force remove`, docs/conventions.md §6), beside their plain runs and Method A, whose "
         "force has none to take off:", ""]
    L += table_of({"rows": rows}, "rows", "run", lambda r: f"Method {r.method}" + (
        ", net force removed" if r.net_force != "keep" else ""))

    def diff(a, b):
        sa, sb = done(a, work), done(b, work)
        if sa is None or sb is None:
            return None
        (ea, sea), (eb, seb) = mean_se(sa, "apparent_viscosity"), mean_se(sb, "apparent_viscosity")
        se = math.hypot(sea, seb)
        return f"{ea - eb:+.3g} ({(ea - eb) / se if se > 0 else math.inf:+.1f} standard errors)"
    lines = []
    for r in all_parts["net_force"]:
        plain, a = methods.get(r.method), methods.get("A")
        parts = [f"against plain Method {r.method} {d}" for d in [diff(r, plain) if plain else None] if d] + [
            f"against Method A {d}" for d in [diff(r, a) if a else None] if d]
        if parts:
            lines.append(f"Method {r.method} without its net force: eta_app " + ", ".join(parts))
    if lines:
        L += ["; ".join(lines) + ".", ""]
    return L


def write_doc(argv, work, doc, all_parts, binary_commit=None, bendlab=None):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig_dir = doc.parent / "tube_flow"
    fig_dir.mkdir(parents=True, exist_ok=True)
    rel = fig_dir.name
    L = ["# Blood in a glass tube", ""]
    L += study_runner.generated_by(study_runner.invocation(Path(__file__), argv))
    L += [f"from {study_runner.source_commit() or 'an unknown commit'} on {study_runner.machine()}, "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}"
          + (f"; the runs were made by the bendlab of commit {binary_commit}" if binary_commit else "") + ".", ""]
    L += ["Red blood cells (the flow command's defaults, docs/conventions.md §6: eq. (15) at R = 3.91 um, "
          "Skalak G_s = 5.3 uN/m, C = 10, kappa_B = 2e-19 J) in a rigid tube of diameter D, periodic over "
          f"2 D, driven at the pseudo-shear rate v/D = {fmt_g(PSEUDO_SHEAR_RATE)} 1/s of the cell-free flow "
          f"(Pries' data hold from 50 1/s), dx = {fmt_g(DX)} um, tau = {fmt_g(TAU)} (HemoCell's dt = 1e-7 s at "
          f"dx = 0.5 um), seed {SEED}. Each run reports the steady-window means (the last half of the run) "
          "with the standard errors of ten batch means (docs/conventions.md §6). The laws are evaluated at "
          "the discharge hematocrit H_D each run measures; no parameter is tuned to them.", ""]

    # The transient: eta_app against time, every finished run.
    runs = [r for p in all_parts.values() for r in p]
    finished = [(r, done(r, work)) for r in dict.fromkeys(runs)]
    have = [(r, s) for r, s in finished if s is not None]
    if have:
        fig, ax = plt.subplots(figsize=(6.5, 3.8))
        for r, s in have:
            series = study_runner.read_series(work / r.name, ["t_s", "apparent_viscosity"])
            if series is not None:
                ax.plot(1e3 * series["t_s"], series["apparent_viscosity"], lw=1, label=r.label())
        ax.axvline(1e3 * have[0][1]["steady_window_s"][0], color="k", ls=":", lw=1)
        ax.set_xlabel("t (ms)")
        ax.set_ylabel("eta_app / eta")
        ax.legend(fontsize=6)
        fig.tight_layout()
        fig.savefig(fig_dir / "transient.png", dpi=110)
        plt.close(fig)
        L += ["## The transient and the window", "",
              f"![eta_app / eta against time; the dotted line starts the steady window]({rel}/transient.png)", ""]

    def table(part, first_column, cell):
        return table_of(all_parts, part, first_column, cell)

    def table_of(parts_, part, first_column, cell):
        rows = ["| " + first_column + " | H_T placed | H_D | eta_app / eta | Pries 1992 at H_D | "
                "H_T / H_D (H_T mean over H_D mean) | Fahraeus at H_D | cell-free layer (um) | cell D | "
                "cell axis angle (deg) | wall time |",
                "|" + " --- |" * 11]
        for r in parts_[part]:
            s = done(r, work)
            if s is None:
                err = failure(r, work)
                rows.append(f"| {cell(r)} | " + (f"failed: {err}" if err else unfinished(r, work)) + " |" + " |" * 9)
                continue
            hd, _ = mean_se(s, "discharge_hematocrit")
            ht, _ = mean_se(s, "tube_hematocrit")
            eta, _ = mean_se(s, "apparent_viscosity")
            D = s["diameter_um"]
            shape_D, angle = cell_shapes(work, r, s)
            rows.append(f"| {cell(r)} | {num(s['achieved_hematocrit_placed'], 3)} | {pm(s, 'discharge_hematocrit', 3)} | "
                        f"{pm(s, 'apparent_viscosity')} | {num(pries_in_vitro(D, hd) if hd else None)} | "
                        f"{num(ht / hd if hd else None, 3)} | {num(fahraeus(D, hd) if hd else None, 3)} | "
                        f"{pm(s, 'cell_free_layer_um', 3)} | {num(shape_D, 3)} | {num(angle, 3)} | "
                        f"{s['wall_seconds']:.0f} s{threads_note(work, r)} |")
        return rows + [""]

    L += ["## The bending algorithm in a suspension", "",
          "D = 10 um, H_T = 0.3, the same seed (the same initial cells), Methods C, A, D, M and no bending:", ""]
    L += table("methods", "method", lambda r: r.method)
    m = [(r, done(r, work)) for r in all_parts["methods"]]
    m = [(r, s) for r, s in m if s is not None]
    if len(m) >= 2:
        ref = next(((r, s) for r, s in m if r.method == "C"), m[0])
        e0, se0 = mean_se(ref[1], "apparent_viscosity")
        lines = []
        for r, s in m:
            if r is ref[0]:
                continue
            e, se = mean_se(s, "apparent_viscosity")
            if None in (e, se, e0, se0):
                continue
            z = (e - e0) / math.hypot(se, se0) if math.hypot(se, se0) > 0 else math.inf
            lines.append(f"Method {r.method}: eta_app differs from C's by {e - e0:+.3g} ({z:+.1f} standard "
                         f"errors of the difference)")
        L += ["Against Method C: " + "; ".join(lines) + ". A difference beyond about two standard errors is "
              "one the runs resolve; a smaller one is noise at this run length.", ""]
    L += answer(bendlab, work, all_parts["methods"], all_parts["net_force"])
    L += net_force_removed_section(work, all_parts, table_of)
    # Every finished run against the laws, as the acceptance reads them.
    against = []
    for r, s_ in have:
        hd, _ = mean_se(s_, "discharge_hematocrit")
        ht, _ = mean_se(s_, "tube_hematocrit")
        eta, se = mean_se(s_, "apparent_viscosity")
        if not hd or eta is None:
            continue
        law = pries_in_vitro(r.diameter, hd)
        dev = (eta - law) / law
        fdev = ht / hd - fahraeus(r.diameter, hd)
        against.append(f"- {r.label()}: eta_app {dev:+.1%} from Pries' in-vitro law "
                       f"({'within' if abs(dev) <= 0.10 else 'outside'} 10 %); H_T / H_D {fdev:+.3f} from the "
                       f"Fahraeus law ({'within' if abs(fdev) <= 0.05 else 'outside'} 0.05)")
    if against:
        L += ["## Against the laws", ""] + against + ["",
              "Where a run lies outside, the candidates the study has to weigh with runs of their own are the "
              "resolution (the cell's mesh, and dx: the tube is 20 dx across at D = 10 um), the repulsion's "
              "cutoff (one dx of fluid kept between membranes and from the wall adds to a cell's effective "
              "size), the relaxation time (the immersed boundary's effective radius grows with tau), the "
              "periodic length (two diameters: five cells at D = 10 um) and the membrane's missing viscosity; "
              "none of them is tuned here.", ""]
        L += departure_evidence(work, all_parts)
    L += ["## Diameter", ""]
    L += table("diameters", "D (um)", lambda r: fmt_g(r.diameter))
    L += ["## Hematocrit", ""]
    L += table("hematocrit", "H_T target", lambda r: fmt_g(r.hematocrit))
    L += ["## Resolution", "", "The D = 10 um, H_T = 0.3, Method C case with cells of 1280 and 5120 triangles:", ""]
    # The D = 10 um, H_T 0.3, Method C run of the methods part: the first row of the resolution and
    # sensitivity tables.
    base = all_parts["methods"][0] if all_parts["methods"] and all_parts["methods"][0].method == "C" else None
    res = dict(all_parts)
    res["resolution"] = ([base] if base else []) + all_parts["resolution"]
    L += table_of(res, "resolution", "mesh", lambda r: r.mesh)
    L += resolution_verdict(work, res["resolution"])
    L += ["## Sensitivity", "",
          "The D = 10 um, H_T = 0.3, Method C case (first row) with the repulsion's cutoff halved to 0.25 um "
          "(from one dx), and with the periodic length three diameters instead of two:", ""]
    sens = dict(all_parts)
    sens["sensitivity"] = ([base] if base else []) + all_parts["sensitivity"]
    L += table_of(sens, "sensitivity", "variant",
                  lambda r: ", ".join(filter(None, [f"cutoff {fmt_g(r.contact_cutoff)} um" if r.contact_cutoff else "",
                                                    f"L = {fmt_g(r.length_factor)} D" if r.length_factor != 2.0 else ""]))
                  or "as in the methods table")

    # eta_rel and H_T / H_D against D, beside the laws.
    d_runs = [(r, done(r, work)) for r in all_parts["diameters"]]
    d_runs = [(r, s) for r, s in d_runs if s is not None]
    if d_runs:
        Ds = np.linspace(8, 30, 200)
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.6))
        for h in (0.2, 0.3, 0.4):
            a1.plot(Ds, [pries_in_vitro(D, h) for D in Ds], lw=1, label=f"Pries 1992, H_D {h}")
            a2.plot(Ds, [fahraeus(D, h) for D in Ds], lw=1, label=f"Fahraeus law, H_D {h}")
        for r, s in d_runs:
            eta, se = mean_se(s, "apparent_viscosity")
            hd, _ = mean_se(s, "discharge_hematocrit")
            ht, _ = mean_se(s, "tube_hematocrit")
            a1.errorbar([r.diameter], [eta], yerr=[se or 0], fmt="ko")
            if hd:
                a2.plot([r.diameter], [ht / hd], "ko")
        a1.set_xlabel("D (um)"), a1.set_ylabel("eta_app / eta"), a1.legend(fontsize=7)
        a2.set_xlabel("D (um)"), a2.set_ylabel("H_T / H_D"), a2.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(fig_dir / "viscosity_fahraeus.png", dpi=110)
        plt.close(fig)
        L += [f"![eta_rel and H_T/H_D against D with the laws at H_D 0.2, 0.3, 0.4]({rel}/viscosity_fahraeus.png)", ""]

    # Radial profiles of the finished runs.
    if have:
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.6))
        for r, s in have:
            p = read_csv(work / r.name / "profiles.csv")
            if p is None:
                continue
            a1.plot(p["r_um"], p["velocity_um_s"], lw=1, label=r.label())
            a2.plot(p["r_um"], p["hematocrit"], lw=1, label=r.label())
        a1.set_xlabel("r (um)"), a1.set_ylabel("u_x (um/s)"), a1.legend(fontsize=6)
        a2.set_xlabel("r (um)"), a2.set_ylabel("local hematocrit")
        fig.tight_layout()
        fig.savefig(fig_dir / "profiles.png", dpi=110)
        plt.close(fig)
        L += ["## Profiles over the steady window", "", f"![velocity and local hematocrit against r]({rel}/profiles.png)", ""]

    # Pictures of the cells at the end: drawn from the last snapshot where the folder still has it.
    pics = []
    for r, s in have:
        png = fig_dir / f"cells_{r.name}.png"
        vtp = sorted((work / r.name).glob("snapshot_*.vtp"))
        if vtp and render_cells(vtp[-1], s, png):
            pass
        if png.exists():
            pics.append(f"![cells at the end, {r.label()}]({rel}/{png.name})")
    if pics:
        L += ["## The cells at the end", ""] + [p + "\n" for p in pics]

    L += net_force_section(bendlab, work, all_parts["methods"])
    L += ["## Cell-free layer beside the literature", "", CELL_FREE_LAYER_LITERATURE + ".", ""]
    total = study_runner.total_wall(s for _, s in have)
    binaries = {}
    for r, _ in have:
        binaries.setdefault(study_runner.binary_of(work / r.name) or "unknown", []).append(r.name)
    several = [(r.name, study_runner.threads_of(work / r.name)) for r, _ in have if threads_note(work, r)]
    L += ["## Run time", "", f"The runs shown took {total:.0f} s of wall time together (one thread each, as the "
          "study's command sets OMP_NUM_THREADS=1" + ("; except " + "; ".join(
              f"{name}, whose starts ran on " + ", ".join(c or "unrecorded" for c in counts) + " threads (its run.log's "
              "launch lines)" for name, counts in several) if several else "") + "; on a machine shared with other "
          "work). The programs that made them, as each run.log's command names it: "
          + "; ".join(f"`{Path(b).name}` ({', '.join(names)})" for b, names in sorted(binaries.items())) + ".", ""]
    L += ["## Commands", "", "Each run shown, as the script starts it (`--resume` continues one):", "", "```"]
    for r, s in have:
        L.append(" ".join(study_runner.command("bendlab", r, Path("studies/tube") / r.name)))
    L += ["```", ""]
    doc.write_text("\n".join(L))
    say(f"wrote {doc}")


def render_cells(vtp, summary, png):
    """Draws the cells of a snapshot (.vtp: every cell's triangles, coloured by cell) in the tube."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    from tube_shapes import read_vtp
    try:
        pts, tris, cell = read_vtp(vtp, with_body=True)
    except (OSError, ValueError):
        return False
    fig = plt.figure(figsize=(8, 3.6))
    ax = fig.add_subplot(111, projection="3d")
    colours = plt.cm.tab10(cell[tris[:, 0]] % 10)
    ax.add_collection3d(Poly3DCollection(pts[tris], facecolors=colours, edgecolor="none", alpha=0.9))
    L, R = summary["length_um"], 0.5 * summary["diameter_um"]
    ax.set_xlim(-L / 2 - 4, L / 2 + 4), ax.set_ylim(-R, R), ax.set_zlim(-R, R)
    ax.set_box_aspect((L + 8, 2 * R, 2 * R))
    ax.set_xlabel("x (um)")
    ax.view_init(elev=15, azim=-70)
    fig.tight_layout()
    fig.savefig(png, dpi=100)
    plt.close(fig)
    return True


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--only", choices=["methods", "diameters", "hematocrit", "resolution", "sensitivity", "net_force",
                                      "doc"],
                   default=None)
    p.add_argument("--t-end", type=float, default=T_END, help="end of every run, s")
    p.add_argument("--jobs", type=int, default=1)
    p.add_argument("--methods", default=",".join(METHODS),
                   help="the bending methods of part methods, in the order they run (default: all)")
    p.add_argument("--bendlab", default=str(ROOT / "build" / "release" / "bendlab"))
    p.add_argument("--work", default=str(ROOT / "studies" / "tube"))
    p.add_argument("--doc", default=str(ROOT / "docs" / "results" / "tube_flow.md"))
    p.add_argument("--list", action="store_true")
    p.add_argument("--binary-commit", default=None,
                   help="the commit the --bendlab binary was built from, when it is not this checkout's")
    a = p.parse_args()
    work, doc = Path(a.work), Path(a.doc)
    work.mkdir(parents=True, exist_ok=True)
    all_parts = parts(a.t_end, [m for m in a.methods.split(",") if m])
    order = ["methods", "diameters", "hematocrit", "resolution", "sensitivity", "net_force"]
    todo = [] if a.only == "doc" else (all_parts[a.only] if a.only else [r for k in order for r in all_parts[k]])
    if a.list:
        return study_runner.Runner(a.bendlab, work).list(todo, f"part {a.only or 'all'}")
    if todo:
        study_runner.Runner(study_runner.bendlab_binary(a.bendlab), work, jobs=a.jobs, say=say).run_all(todo)
    binary = Path(a.bendlab)
    write_doc(sys.argv[1:], work, doc, all_parts, a.binary_commit, binary if binary.exists() else None)
    return 0


if __name__ == "__main__":
    sys.exit(main())
