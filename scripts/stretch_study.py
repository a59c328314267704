#!/usr/bin/python3
"""Optical-tweezers stretching of a red blood cell with every bending method and both elastic laws,
against Mills et al. (2004), regenerated from `bendlab stretch` runs.

    /usr/bin/python3 scripts/stretch_study.py [--mesh MESH] [--methods LIST] [--laws LIST]
                                              [--max-iterations N] [--jobs N] [--bendlab PATH]
                                              [--work DIR] [--doc FILE] [--list]

Every run is `bendlab stretch` with bendlab flow's red blood cell (docs/conventions.md §7: shape of
eq. (15) at R = 3.91 um, G_s = 5.3 uN/m, Skalak C = 10, kappa_B = 2e-19 J, the flow's volume force)
at the forces of Mills et al.'s measurements (scripts/mills2004_stretch.csv), for each bending
method of `bendlab methods` and each law (skalak, neo-hookean), on --mesh (default mt1:1280); and
Method C with the Skalak law on mt1:320 and mt1:5120 as the check of the mesh. Nothing is fitted to
the data.

Runs live in --work (default studies/stretch, kept in git: studies/README.md). A finished run
(summary.json with the run's arguments) is taken from there; a run that failed is recorded (its
summary.json says where it stopped, or failed.json why it could not start) and not run again until
its folder is deleted. Writes docs/results/rbc_stretch.md and its figures (docs/results/rbc_stretch/).
"""
import argparse
import csv
import json
import math
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import study_runner  # noqa: E402
from plot_stretch import draw_mills, read_mills  # noqa: E402
from study_runner import ROOT  # noqa: E402

LAWS = ["skalak", "neo-hookean"]
MESH_CHECK = ["mt1:320", "mt1:5120"]  # Method C, Skalak, besides the study's mesh
FINE_MESH = "mt1:5120"  # Methods C and M with both laws: M's check on the finer mesh
FAILURE_FIELDS = {}
# bendlab stretch's --relaxation auto: the methods whose linearised force is far from symmetric.
OVERDAMPED_METHODS = ("M",)


@dataclass(frozen=True)
class StretchRun(study_runner.StudyRun):
    method: str
    law: str
    mesh: str
    forces: tuple
    max_iterations: int

    @property
    def name(self):
        return f"{self.method}_{self.law}_{self.mesh.replace(':', '')}"

    def arguments(self, out):
        # --overwrite: the runner writes run.log into the folder first; a stretch run's own files
        # are the only ones it removes.
        return ["stretch", "--method", self.method, "--law", self.law, "--mesh", self.mesh,
                "--forces", ",".join(f"{f:g}" for f in self.forces),
                "--max-iterations", str(self.max_iterations), "--no-plots", "--overwrite", "--out", str(out)]

    def key(self):
        # The relaxation is bendlab stretch's default for the method (--relaxation auto), recorded
        # in the summary: runs made before it was recorded (all by FIRE) are made again.
        return {"method": self.method, "elastic_law": self.law, "mesh": self.mesh,
                "forces_pN": [float(f) for f in self.forces], "max_iterations": self.max_iterations,
                "relaxation": "overdamped" if self.method in OVERDAMPED_METHODS else "fire"}

    def resume_key(self):
        return self.key()

    def label(self):
        return f"{self.method} {self.law} {self.mesh}"


def method_names(bendlab):
    out = subprocess.run([str(bendlab), "methods", "--json"], capture_output=True, text=True, check=True).stdout
    return [m["name"] for m in json.loads(out)]


def outcome(runner, run, result):
    """(summary or None, failure reason or None) of a run: a summary that did not converge is a
    failure with the reason it gives; a run without summary was recorded as failed."""
    # A run that stopped at a force it could not relax exits with an error but leaves its summary.
    s = result.summary or study_runner.finished(runner.folder(run), run)
    if s is None:
        error = result.error or "no summary"
        if not result.cached:
            study_runner.write_failure(runner.folder(run), runner.identity(run), error)
        return None, error
    if not s.get("converged", False):
        points = s.get("points") or [{}]
        last = points[-1]
        return s, f"F = {last.get('force_pN', float('nan')):g} pN: {last.get('failure') or 'not converged'}"
    return s, None


def series(summary):
    pts = summary["points"]
    return ([p["force_pN"] for p in pts], [p["axial_diameter_um"] for p in pts],
            [p["transverse_diameter_um"] for p in pts])


def within(summary, mills):
    """The Mills forces at which each diameter lies inside the experimental scatter."""
    f, a, t = series(summary)
    ok_a = ok_t = 0
    for k, force in enumerate(mills["force_pN"]):
        j = f.index(force) if force in f else None
        if j is None:
            continue
        ok_a += mills["axial_low_um"][k] <= a[j] <= mills["axial_high_um"][k]
        ok_t += mills["transverse_low_um"][k] <= t[j] <= mills["transverse_high_um"][k]
    return ok_a, ok_t


def plot_law(path, law, rows, mills):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4.8))
    draw_mills(ax, mills)
    for k, (method, s) in enumerate(rows):
        f, a, t = series(s)
        ax.plot(f, a, "-", marker=".", color=f"C{k}", lw=1, label=method)
        ax.plot(f, t, "--", marker=".", color=f"C{k}", lw=1)
    ax.set_title(f"{law} law, every bending method (axial solid, transverse dashed)", fontsize=9)
    ax.set_xlabel("force F (pN)")
    ax.set_ylabel("diameter (um)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2, loc="center right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_spread(path, by_law, mills):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4))
    f = mills["force_pN"]
    width = [h - l for l, h in zip(mills["axial_low_um"], mills["axial_high_um"])]
    ax.plot(f, width, "s-", color="0.5", mfc="white", label="experimental scatter, axial (high - low)")
    for k, (law, rows) in enumerate(by_law.items()):
        if len(rows) < 2:
            continue
        a = [series(s)[1] for _, s in rows]
        t = [series(s)[2] for _, s in rows]
        ax.plot(f, [max(c) - min(c) for c in zip(*a)], "o-", color=f"C{k}", label=f"methods' spread, axial, {law}")
        ax.plot(f, [max(c) - min(c) for c in zip(*t)], "o--", color=f"C{k}",
                label=f"methods' spread, transverse, {law}")
    ax.set_yscale("log")
    ax.set_xlabel("force F (pN)")
    ax.set_ylabel("um")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mesh", default="mt1:1280")
    ap.add_argument("--methods", default=None, help="comma-separated (default: every method of bendlab methods)")
    ap.add_argument("--laws", default=",".join(LAWS))
    ap.add_argument("--max-iterations", type=int, default=20000)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--bendlab", default="build/release/bendlab")
    ap.add_argument("--work", default=str(ROOT / "studies" / "stretch"))
    ap.add_argument("--doc", default=str(ROOT / "docs" / "results" / "rbc_stretch.md"))
    ap.add_argument("--list", action="store_true", help="print the runs and their state; run nothing")
    args = ap.parse_args(argv[1:])

    bendlab = study_runner.bendlab_binary(args.bendlab)
    methods = args.methods.split(",") if args.methods else method_names(bendlab)
    laws = args.laws.split(",")
    mills = read_mills()
    forces = tuple(mills["force_pN"])
    runs = [StretchRun(m, law, args.mesh, forces, args.max_iterations) for law in laws for m in methods]
    checks = [StretchRun("C", "skalak", mesh, forces, args.max_iterations) for mesh in MESH_CHECK
              if mesh != args.mesh]
    checks += [StretchRun(m, law, FINE_MESH, forces, args.max_iterations) for m in ("C", "M") for law in laws
               if FINE_MESH != args.mesh and (m, law) != ("C", "skalak") and m in methods]
    runner = study_runner.Runner(bendlab, args.work, jobs=args.jobs, failure_fields=FAILURE_FIELDS)
    if args.list:
        return runner.list(runs + checks, "stretch study")
    results = runner.run_all(runs + checks)

    doc = Path(args.doc)
    fig_dir = doc.parent / doc.stem
    fig_dir.mkdir(parents=True, exist_ok=True)
    outcomes = {r: outcome(runner, r, results[r]) for r in runs + checks}
    by_law = {law: [(r.method, outcomes[r][0]) for r in runs if r.law == law and outcomes[r][1] is None]
              for law in laws}
    for law, rows in by_law.items():
        plot_law(fig_dir / f"diameters_{law}.png", law, rows, mills)
    plot_spread(fig_dir / "method_spread.png", by_law, mills)

    L = study_runner.generated_by(study_runner.invocation(__file__, argv[1:]))
    L += [f"from the runs in `{study_runner.rel(args.work)}` (source {study_runner.source_commit() or 'unknown'}; "
          f"{study_runner.machine()}).", ""]
    L += ["# Optical-tweezers stretching of a red blood cell", "",
          "`bendlab stretch` with `bendlab flow`'s red blood cell (docs/conventions.md §7): the shape of the paper's "
          "eq. (15) with R = 3.91 um, Skalak law with G_s = 5.3 uN/m (Mills et al.'s own fit) and C = 10, or the "
          "neo-Hookean law with the same G_s, kappa_B = 2e-19 J, the flow runs' volume force; a total force F on "
          f"the 2 % of the vertices at each end of `{args.mesh}`, at the 13 forces of Mills et al.'s "
          "measurements (0-193 pN, scripts/mills2004_stretch.csv); equilibrium by FIRE (Method M: overdamped "
          "relaxation with Anderson mixing, bendlab stretch --relaxation auto; docs/conventions.md §7) to a largest "
          "nodal residual below 1e-4 pN, each force from the previous equilibrium. No parameter was tuned to the "
          "data: G_s is Mills et al.'s fit of a hyperelastic model to these experiments, the rest are "
          "bendlab flow's defaults.", "",
          "Mills et al. (2004, Mech. Chem. Biosyst. 1:169) stretched healthy red cells between two silica "
          "beads with optical tweezers and measured the axial and the transverse diameter (in the image "
          "plane) against the force; their figure gives the means and the scatter band. The grey band and "
          "bars below are that scatter; the data were read from their figure (the digitisation the CSE Lab's "
          "Korali/Mirheo stretching study distributes).", ""]

    L += ["## Runs", "", "| method | law | mesh | result | iterations (all forces) | wall time |",
          "| --- | --- | --- | --- | --- | --- |"]
    for r in runs + checks:
        s, failure = outcomes[r]
        wall = f"{s['wall_seconds']:.1f} s" if s and math.isfinite(s.get("wall_seconds", math.nan)) else ""
        if failure:
            L.append(f"| {r.method} | {r.law} | {r.mesh} | **failed**: {failure} | "
                     f"{s['iterations'] if s else ''} | {wall} |")
        else:
            L.append(f"| {r.method} | {r.law} | {r.mesh} | converged at every force | {s['iterations']} | {wall} |")
    L.append("")
    failed = [r for r in runs if outcomes[r][1]]
    if failed:
        L += ["A failed run is left out of the tables and plots below; its folder keeps what it reached "
              "(summary.json, stretch.csv and the shapes up to the force that failed), and the study does not "
              "run it again until the folder is deleted.", ""]

    for law in laws:
        rows = by_law[law]
        if not rows:
            continue
        L += [f"## Diameters, {law} law", "",
              f"![diameters, {law}]({fig_dir.name}/diameters_{law}.png)", "",
              "Axial / transverse diameter (um) at each force; Mills et al.'s mean [scatter].", "",
              "| F (pN) | " + " | ".join(m for m, _ in rows) + " | Mills et al. axial | Mills et al. transverse |",
              "| ---: |" + " --- |" * (len(rows) + 2)]
        for k, f in enumerate(forces):
            cells = []
            for _, s in rows:
                p = s["points"][k]
                cells.append(f"{p['axial_diameter_um']:.2f} / {p['transverse_diameter_um']:.2f}")
            L.append(f"| {f:g} | " + " | ".join(cells)
                     + f" | {mills['axial_um'][k]:.2f} [{mills['axial_low_um'][k]:.2f}, {mills['axial_high_um'][k]:.2f}]"
                     + f" | {mills['transverse_um'][k]:.2f} [{mills['transverse_low_um'][k]:.2f}, "
                       f"{mills['transverse_high_um'][k]:.2f}] |")
        L.append("")

    # Each method against C on the same mesh and law: the largest relative difference of a diameter.
    L += ["## Against Method C", "",
          "The largest relative difference from Method C's diameter on the same mesh and law, over the forces "
          "(|D - D_C| / D_C, axial and transverse):", "",
          "| method | law | mesh | axial | transverse |", "| --- | --- | --- | --- | --- |"]
    converged = {(r.method, r.law, r.mesh): outcomes[r][0] for r in runs + checks if outcomes[r][1] is None}
    for (method, law, mesh), s in converged.items():
        c = converged.get(("C", law, mesh))
        if method == "C" or c is None:
            continue
        _, a, t = series(s)
        _, ac, tc = series(c)
        da = max(abs(x - y) / y for x, y in zip(a, ac))
        dt = max(abs(x - y) / y for x, y in zip(t, tc))
        L.append(f"| {method} | {law} | {mesh} | {100 * da:.2f} % | {100 * dt:.2f} % |")
    L.append("")

    # Within the scatter.
    n = len(forces)
    L += ["## Within the experimental scatter?", "",
          f"At how many of the {n} forces each diameter lies inside Mills et al.'s scatter band:", "",
          "| method | law | axial | transverse | D_A at 193 pN (Mills 15.26 [12.95, 17.65]) | D_T at 193 pN "
          "(Mills 4.26 [3.44, 5.09]) | largest D_T above the band (um) |",
          "| --- | --- | --- | --- | --- | --- | --- |"]
    inside = []
    for r in runs:
        s, failure = outcomes[r]
        if failure:
            continue
        ok_a, ok_t = within(s, mills)
        last = s["points"][-1]
        above = max(p["transverse_diameter_um"] - h for p, h in zip(s["points"], mills["transverse_high_um"]))
        L.append(f"| {r.method} | {r.law} | {ok_a}/{n} | {ok_t}/{n} | {last['axial_diameter_um']:.2f} | "
                 f"{last['transverse_diameter_um']:.2f} | {above:+.2f} |")
        if ok_a == n and ok_t == n:
            inside.append(f"{r.method} ({r.law})")
    L.append("")
    L += [("Inside the scatter at every force, both diameters: " + ", ".join(inside) + ".") if inside else
          "No choice lies inside the scatter at every force in both diameters.", ""]

    # How much the method matters.
    L += ["## How much the bending algorithm matters", "",
          f"![spread]({fig_dir.name}/method_spread.png)", "",
          "The spread (largest minus smallest over the methods that converged) of each diameter, against the "
          "law's effect (Skalak minus neo-Hookean, Method C) and the width of the experimental scatter:", "",
          "| F (pN) | axial spread, skalak | transverse spread, skalak | axial spread, neo-Hookean | "
          "transverse spread, neo-Hookean | axial, skalak - neo-Hookean (C) | transverse, skalak - neo-Hookean (C) "
          "| scatter width, axial | scatter width, transverse |", "| ---: |" + " ---: |" * 8]
    c = {law: dict(by_law.get(law, [])).get("C") for law in laws}
    for k, f in enumerate(forces):
        cells = []
        for law in ("skalak", "neo-hookean"):
            rows = by_law.get(law, [])
            for col in ("axial_diameter_um", "transverse_diameter_um"):
                vals = [s["points"][k][col] for _, s in rows]
                cells.append(f"{max(vals) - min(vals):.3f}" if len(vals) > 1 else "")
        for col in ("axial_diameter_um", "transverse_diameter_um"):
            if c.get("skalak") and c.get("neo-hookean"):
                cells.append(f"{c['skalak']['points'][k][col] - c['neo-hookean']['points'][k][col]:+.3f}")
            else:
                cells.append("")
        cells.append(f"{mills['axial_high_um'][k] - mills['axial_low_um'][k]:.2f}")
        cells.append(f"{mills['transverse_high_um'][k] - mills['transverse_low_um'][k]:.2f}")
        L.append(f"| {f:g} | " + " | ".join(cells) + " |")
    L.append("")

    # The mesh.
    mesh_rows = [(r.mesh, outcomes[r]) for r in checks] + [
        (args.mesh, outcomes[r]) for r in runs if r.method == "C" and r.law == "skalak"]
    mesh_rows.sort(key=lambda m: int(m[0].split(":")[1]) if ":" in m[0] else 0)
    if mesh_rows:
        L += ["## The mesh (Method C, Skalak)", "", "| mesh | vertices | D_A at 0 pN | D_T at 0 pN | D_A at 193 pN | "
              "D_T at 193 pN | iterations | wall time |", "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
        for mesh, (s, failure) in mesh_rows:
            if failure:
                L.append(f"| {mesh} | failed: {failure} | | | | | | |")
                continue
            p0, p1 = s["points"][0], s["points"][-1]
            L.append(f"| {mesh} | {s['vertices']} | {p0['axial_diameter_um']:.3f} | {p0['transverse_diameter_um']:.3f} "
                     f"| {p1['axial_diameter_um']:.3f} | {p1['transverse_diameter_um']:.3f} | {s['iterations']} | "
                     f"{s['wall_seconds']:.1f} s |")
        L.append("")

    # What the tables say, computed from them.
    L += ["## Summary", ""]
    for law in laws:
        rows = by_law.get(law, [])
        if len(rows) < 2:
            continue
        worst = {}
        for col in ("axial_diameter_um", "transverse_diameter_um"):
            spreads = []
            for k, f in enumerate(forces):
                vals = [(s["points"][k][col], m) for m, s in rows]
                spreads.append((max(vals)[0] - min(vals)[0], f, max(vals)[1], min(vals)[1]))
            worst[col] = max(spreads)
        narrowest = min(h - l for l, h in zip(mills["transverse_low_um"], mills["transverse_high_um"]))
        L.append(f"- {law}: over the {len(rows)} methods that converged ({', '.join(m for m, _ in rows)}), the "
                 f"diameters differ by at most {worst['axial_diameter_um'][0]:.3f} um (axial, at "
                 f"{worst['axial_diameter_um'][1]:g} pN, {worst['axial_diameter_um'][2]} largest, "
                 f"{worst['axial_diameter_um'][3]} smallest) and {worst['transverse_diameter_um'][0]:.3f} um "
                 f"(transverse, at {worst['transverse_diameter_um'][1]:g} pN, {worst['transverse_diameter_um'][2]} "
                 f"largest, {worst['transverse_diameter_um'][3]} smallest); the narrowest experimental scatter "
                 f"band is {narrowest:.2f} um wide.")
    if c.get("skalak") and c.get("neo-hookean"):
        a = c["skalak"]["points"][-1]["axial_diameter_um"] - c["neo-hookean"]["points"][-1]["axial_diameter_um"]
        t = (c["skalak"]["points"][-1]["transverse_diameter_um"]
             - c["neo-hookean"]["points"][-1]["transverse_diameter_um"])
        L.append(f"- The elastic law (Method C) changes the diameters at {forces[-1]:g} pN by {a:+.3f} um (axial) and "
                 f"{t:+.3f} um (transverse), Skalak minus neo-Hookean.")
    for r in runs:
        if outcomes[r][1]:
            L.append(f"- {r.method} ({r.law}) did not reach equilibrium: {outcomes[r][1]}.")
    L.append("")
    doc.write_text("\n".join(L) + "\n")
    print(f"wrote {study_runner.rel(doc)} and {study_runner.rel(fig_dir)}/")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
