#!/usr/bin/python3
"""Blood in a glass tube: apparent viscosity, the Fahraeus effect and the cell-free layer against
Pries et al., and what the bending algorithm changes (`bendlab flow` runs; issue "Blood in a glass
tube").

    /usr/bin/python3 scripts/tube_study.py [--only diameters|hematocrit|methods|resolution|sensitivity|doc]
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
  doc         only regenerates the document from the runs that are done.
Without --only: methods, then diameters, hematocrit and resolution.

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
    start_arguments = ("--overwrite",)

    def arguments(self, out):
        extra = ["--contact-cutoff", fmt_g(self.contact_cutoff)] if self.contact_cutoff else []
        return ["flow", "--geometry", "tube", "--diameter", fmt_g(self.diameter), "--length",
                fmt_g(self.length_factor * self.diameter), "--dx", fmt_g(DX), "--tau", fmt_g(TAU),
                "--pseudo-shear-rate", fmt_g(PSEUDO_SHEAR_RATE), "--hematocrit", fmt_g(self.hematocrit),
                "--seed", str(SEED), "--method", self.method, "--mesh", self.mesh, "--t-end", fmt_g(self.t_end),
                "--sample-every", fmt_g(SAMPLE_EVERY), "--snapshot-every", fmt_g(SNAPSHOT_EVERY)] + extra + [
                "--out", str(out)]

    def key(self):
        return {"t_end": self.t_end, "diameter_um": self.diameter, "hematocrit": self.hematocrit,
                "method": self.method, "mesh": self.mesh, "tau": TAU, "dx_um": DX,
                "pseudo_shear_rate": PSEUDO_SHEAR_RATE, "seed": SEED, "contact_cutoff_um": self.contact_cutoff,
                "length_um": self.length_factor * self.diameter}

    def label(self):
        extra = (f", cutoff {fmt_g(self.contact_cutoff)} um" if self.contact_cutoff else "") + (
            f", L = {fmt_g(self.length_factor)} D" if self.length_factor != 2.0 else "")
        return (f"D = {fmt_g(self.diameter)} um, H_T {fmt_g(self.hematocrit)}, Method {self.method}, "
                f"{self.mesh}{extra}")


def run(D, H, method="C", mesh="mt1:1280", t_end=T_END, contact_cutoff=0.0, length_factor=2.0):
    name = f"D{fmt_g(D)}_H{fmt_g(H)}_{method}_{mesh.replace(':', '')}"
    name += (f"_cut{fmt_g(contact_cutoff)}" if contact_cutoff else "") + (
        f"_L{fmt_g(length_factor)}D" if length_factor != 2.0 else "")
    return Run(name, D, H, method, mesh, t_end, contact_cutoff, length_factor)


def parts(t_end, methods=METHODS):
    return {
        "methods": [run(10, 0.3, m, t_end=t_end) for m in methods],
        "diameters": [run(D, 0.3, t_end=t_end) for D in (10, 15, 20)],
        "hematocrit": [run(10, H, t_end=t_end) for H in (0.2, 0.4)],
        "resolution": [run(10, 0.3, "C", "mt1:5120", t_end=t_end)],
        # What the departure from Pries' law could come from: the repulsion's reach and the period.
        "sensitivity": [run(10, 0.3, t_end=t_end, contact_cutoff=0.25), run(10, 0.3, t_end=t_end, length_factor=3.0)],
    }


# ----------------------------------------------------------------------------- the document

def done(r, work):
    s = study_runner.read_summary(work / r.name)
    return s if s is not None and study_runner.matches(s, r.key()) else None


def failure(r, work):
    f = study_runner.read_json(work / r.name / "failed.json")
    return f.get("error") if isinstance(f, dict) else None


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
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]} if rows else None


def cell_shapes(work, r, s):
    """Mean Taylor deformation and axis angle of the cells over the steady window."""
    c = read_csv(work / r.name / "cells.csv")
    if c is None:
        return None, None
    begin = s["steady_window_s"][0]
    sel = c["t_s"] >= begin - 1e-12
    return float(np.mean(c["D"][sel])), float(np.mean(c["axis_angle_deg"][sel]))


def write_doc(argv, work, doc, all_parts, binary_commit=None):
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
                rows.append(f"| {cell(r)} | " + (f"failed: {err}" if err else "not run yet") + " |" + " |" * 9)
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
                        f"{s['wall_seconds']:.0f} s |")
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
    L += ["## Diameter", ""]
    L += table("diameters", "D (um)", lambda r: fmt_g(r.diameter))
    L += ["## Hematocrit", ""]
    L += table("hematocrit", "H_T target", lambda r: fmt_g(r.hematocrit))
    L += ["## Resolution", "", "The D = 10 um, H_T = 0.3, Method C case with cells of 1280 and 5120 triangles:", ""]
    L += table("resolution", "mesh", lambda r: r.mesh)
    L += ["## Sensitivity", "",
          "The D = 10 um, H_T = 0.3, Method C case (first row) with the repulsion's cutoff halved to 0.25 um "
          "(from one dx), and with the periodic length three diameters instead of two:", ""]
    base = all_parts["methods"][0] if all_parts["methods"] and all_parts["methods"][0].method == "C" else None
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

    L += ["## Cell-free layer beside the literature", "", CELL_FREE_LAYER_LITERATURE + ".", ""]
    total = study_runner.total_wall(s for _, s in have)
    binaries = {}
    for r, _ in have:
        binaries.setdefault(study_runner.binary_of(work / r.name) or "unknown", []).append(r.name)
    L += ["## Run time", "", f"The runs shown took {total:.0f} s of wall time together (one thread each, on a "
          "machine shared with other work). The programs that made them, as each run.log's command names it: "
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
    p.add_argument("--only", choices=["methods", "diameters", "hematocrit", "resolution", "sensitivity", "doc"],
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
    order = ["methods", "diameters", "hematocrit", "resolution", "sensitivity"]
    todo = [] if a.only == "doc" else (all_parts[a.only] if a.only else [r for k in order for r in all_parts[k]])
    if a.list:
        return study_runner.Runner(a.bendlab, work).list(todo, f"part {a.only or 'all'}")
    if todo:
        study_runner.Runner(study_runner.bendlab_binary(a.bendlab), work, jobs=a.jobs, say=say).run_all(todo)
    write_doc(sys.argv[1:], work, doc, all_parts, a.binary_commit)
    return 0


if __name__ == "__main__":
    sys.exit(main())
