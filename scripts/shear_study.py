#!/usr/bin/python3
"""The capsule-in-shear-flow study of the paper's section 4, regenerated from `bendlab shear` runs.

    /usr/bin/python3 scripts/shear_study.py [--jobs N] [--t-end T] [--only a|b|c|e] [--bendlab PATH]
                                            [--work DIR] [--doc FILE] [--triangles LIST]
                                            [--triangles-a N] [--triangles-e N] [--progress-every S]
                                            [--list]

Quick check of the whole chain (a few minutes): --t-end 0.2 --triangles 320 --triangles-a 320
--work /tmp/shear_preview --doc /tmp/shear_preview/shear.md. The full study (the defaults) is
about an hour of CPU time, most of it Method A at 1280 triangles (gamma dt ~ 1e-3).

Writes docs/results/shear.md and the PNGs it shows (docs/results/shear/):
  (a) no bending, 1280 triangles, G = 0.0125 ... 0.2: D against gamma t (figure 12a) and the
      steady D against G (figure 12b) with the small-G slope, small-deformation theory and the
      published values at G = 0.1;
  (b) every registered method (A, B, C, D, E, ED, S, J, M) at 320 and 1280 triangles for (G, kB_hat) = (0.05, 0.0375) and
      (0.2, 0.15): D against gamma t, all methods in one plot per pair and resolution (figures 13
      and 14);
  (c) the average gamma dt over gamma t in [5, 10] (table 4) beside the paper's values, and the
      wall time of every run.
  (e) only with --only e: the paper's resolution, 5120 triangles, every run with the stiff-stable
      Runge-Kutta-Chebyshev integrator (`--integrator rkc --rtol 1e-7 --atol 1e-6`; Cash-Karp is
      too slow there, docs/results/stiff_stepping.md): figure 12 (no bending, the five G), figure 14
      (every registered method at both (G, kB_hat) pairs), table 4 (the paper's Cash-Karp mean
      gamma dt beside RKC's mean step, BIM evaluations and stages), figure 16 (C and S at G = 0.05,
      kB_hat = 0.0375), figure 17 (A and C at kB_hat = 2/15, G = 0.05 and 0.2) and the study's wall
      time. 5 + 2 x (number of methods) + 4 runs (27 with A, B, C, D, E, ED, S, J, M). The paper gives
      the literature values of figures 16 and 17 only as plots, so they are not drawn. Beside
      figure 12's table, the runs of scripts/small_g_study.py (studies/small_g) that explain its
      smallest G (wrinkles without bending), where they have been run.
      --bim-quadrature-e tree runs them with the BIM's tree quadrature (within 1e-5 of all7;
      Method C at 5120 to gamma t = 10 in 249 s on 2 idle cores, D_steady equal to all7's to 1.4e-7),
      --bim-quadrature-e tree-mixed with its single-precision sums (about 1.9 times faster than
      tree in a whole run of Method A at 5120 triangles; docs/results/shear.md reports the study's
      measured run and wall time).
      The section sits between markers at the end of --doc: --only e replaces it (or appends it)
      and leaves the rest of the document as it is; a run of parts (a)-(c) keeps it. Run it in the
      background, one thread per run (with all7, about 10 hours of run time):
          mkdir -p results && OMP_NUM_THREADS=1 nohup /usr/bin/python3 scripts/shear_study.py \
              --only e --jobs 2 --bim-quadrature-e tree-mixed > results/shear_study_e.log 2>&1 &
      Quick check of the chain (under a minute on one core): --only e --triangles-e 320 --t-end 0.2
      --jobs 1 --work /tmp/shear_e --doc /tmp/shear_e/shear.md.

--list prints the runs of the chosen parts (or of --add-methods) with the command line of each
and whether it is done, resumes from a checkpoint or is still to run, and runs nothing:
    /usr/bin/python3 scripts/shear_study.py --only e --list

Every run is one `bendlab shear ... --no-plot` process whose output folder lies under --work
(default studies/shear, kept in git: studies/README.md), started by scripts/study_runner.py. A run
whose summary.json exists and matches the arguments is not run again; a run that was interrupted
continues from its checkpoint (--resume). Interrupting the study and starting it again with the
same options therefore loses at most the work since the last checkpoint of each running run.

--add-methods S runs only Method S (and the cheap no-bending references) of parts (b) and (c)
and writes them into a section of their own at the end of the existing --doc, keeping the rest:
    /usr/bin/python3 scripts/shear_study.py --add-methods S --triangles 1280 --jobs 1

--only a|b|c runs only the runs of that part; the other parts appear in the document when all
their runs are already in the work folder. Part (e) runs only with --only e. --t-end below 10
gives a quick preview: the steady values and the average step size are then taken over the last
half of each run (as `bendlab shear` does) and the document says so.
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from inset_limits import inset_ylim  # noqa: E402
import small_g_study  # noqa: E402
import study_runner  # noqa: E402
from study_runner import close, fmt_g, matches  # noqa: E402

METHODS = []  # the bending methods, from `bendlab methods --json` (set in main)
G_SWEEP = [0.0125, 0.025, 0.05, 0.1, 0.2]
PAIRS = [(0.05, 0.0375), (0.2, 0.15)]

# Part (e), the paper's resolution: every run with the stiff-stable Runge-Kutta-Chebyshev
# integrator (docs/results/stiff_stepping.md) at the tolerances of the paper's Cash-Karp runs.
E_INTEGRATOR = "rkc"
# The BIM's regular quadrature of part (e) (`--bim-quadrature-e`): all7 (the reference) or tree
# (within 1e-5 of it, faster at 5120 triangles). Part of an RKC run's identity: a tree run's folder
# name ends in _tree and its summary.json must name the quadrature.
E_QUADRATURE = "all7"
RTOL, ATOL = "1e-7", "1e-6"
# A run fails once it takes more accepted steps than this: 4 times the most any run of the paper's
# cases needs (24402, C at 5120 triangles by Cash-Karp); a shape that goes unstable makes its step
# collapse to 1e-10 and would crawl on for days. Such a failure, like any other failure during the
# steps (a singular fit, a non-finite force: deterministic, so a rerun repeats it), is recorded in
# the run's folder (failed.json) and reported, not retried: delete the folder to run it again.
MAX_STEPS = 100_000
FIG16_METHODS = ["C", "S"]  # figure 16: G = 0.05, kB_hat = 0.0375 (runs of figure 14)
FIG17_KB = 2.0 / 15.0  # figure 17: Methods A and C at kB_hat = 2/15, G = 0.05 and 0.2
FIG17_G = [0.05, 0.2]
FIG17_METHODS = ["A", "C"]

# Paper, table 4: average gamma dt over gamma t in [5, 10] chosen by the Cash-Karp stepper
# (rtol 1e-7, atol 1e-6 R), BIM, MT1 meshes. Keys: (G, kB_hat) -> triangles -> method
# ("none" is the kB_hat = 0 column). The paper has no column for ED.
PAPER_TABLE4 = {
    (0.05, 0.0375): {
        320: {"none": "0.081", "A": "0.016", "B": "0.060", "C": "0.057", "D": "0.085", "E": "0.057"},
        1280: {"none": "0.064", "A": "0.0015", "B": "0.0057", "C": "0.0056", "D": "0.063", "E": "0.0060"},
        5120: {"none": "0.029", "A": "0.00014", "B": "0.00053", "C": "0.00052", "D": "0.0085", "E": "0.00056"},
    },
    (0.2, 0.15): {
        320: {"none": "0.20", "A": "0.013", "B": "0.052", "C": "0.050", "D": "0.15", "E": "0.048"},
        1280: {"none": "0.16", "A": "0.0012", "B": "0.0050", "C": "0.0049", "D": "0.078", "E": "0.0051"},
        5120: {"none": "0.13", "A": "0.00011", "B": "0.00046", "C": "0.00046", "D": "0.0076", "E": "0.00048"},
    },
}

# Published steady deformation at G = 0.1 without bending (5120 triangles and the references of
# the paper's figure 12b: Le et al. 2009 and 2011, Pozrikidis 2001, Tsubota 2014,
# Barthes-Biesel et al. 2010, Sinha et al. 2015): the values lie in this range.
PUBLISHED_D_G01 = (0.37, 0.40)

# Small-deformation theory (Barthes-Biesel & Rallison 1981) for an initially spherical capsule in
# simple shear, any viscosity ratio: D = 5/4 Ca (2 + nu_s) / (1 + nu_s) with Ca = mu gamma R / Gs,
# Gs the small-strain shear modulus and nu_s the surface Poisson ratio of the membrane
# (equivalently D = Ca (15/8 + 5 Gs / (8 Ks)), Ks the area-dilatation modulus). The neo-Hookean law
# has Ks = 3 Gs, nu_s = 1/2, so D = 25/12 Ca (the same as 25/4 mu gamma R / Es with the surface
# Young modulus Es = 3 Gs). Our kS is 3 Gs (docs/conventions.md §2): Ca = 3 G and D = 25/4 G.
SMALL_DEFORMATION_SLOPE = 25.0 / 4.0

METHOD_STYLE = {
    "none": dict(color="0.55", ls="--", lw=1.2),
    "A": dict(color="tab:blue"), "B": dict(color="tab:orange"), "C": dict(color="tab:green"),
    "D": dict(color="tab:red"), "E": dict(color="tab:purple"), "ED": dict(color="tab:brown", ls="-."),
    "S": dict(color="black", ls=":"), "J": dict(color="tab:olive", ls="--"),
    "M": dict(color="tab:cyan", ls="-."),
}


def bending_methods(bendlab):
    """The names of the bending methods the binary knows, in its table's order."""
    out = subprocess.run([str(bendlab), "methods", "--json"], check=True, capture_output=True, text=True).stdout
    return [m["name"] for m in json.loads(out)]


def say(msg):
    print(msg, flush=True)


def fmt_arg(x):
    """A number for the command line: as fmt_g where that reads back as the same double, else all
    the digits (2/15 is 0.13333333333333333, not 0.133333), so that summary.json matches the run."""
    x = float(x)
    return fmt_g(x) if float(fmt_g(x)) == x else repr(x)


@dataclass(frozen=True)
class Run(study_runner.StudyRun):
    method: str  # "none" or a bending method
    triangles: int
    G: float
    kappa_b: float
    t_end: float
    integrator: str = "cash-karp"  # `bendlab shear --integrator`; the paper's Cash-Karp by default

    @property
    def mesh(self):
        return f"mt1:{self.triangles}"

    @property
    def name(self):
        # Cash-Karp runs keep the names they always had (their work folders stay valid).
        return (f"{self.method}_mt1-{self.triangles}_G{fmt_g(self.G)}_kb{fmt_g(self.kappa_b)}"
                f"_t{fmt_g(self.t_end)}" + ("" if self.integrator == "cash-karp" else f"_{self.integrator}")
                + ("" if self.quadrature == "all7" else f"_{self.quadrature}"))

    @property
    def quadrature(self):
        """The BIM quadrature: E_QUADRATURE for part (e)'s runs, all7 for the Cash-Karp ones."""
        return "all7" if self.integrator == "cash-karp" else E_QUADRATURE

    def label(self):
        return (f"method {self.method:>4}, {self.triangles:4d} triangles, G = {fmt_g(self.G)}, "
                f"kB_hat = {fmt_g(self.kappa_b)}" + ("" if self.integrator == "cash-karp" else f", {self.integrator}"))

    def arguments(self, out):
        args = ["shear", "--method", self.method, "--mesh", self.mesh, "--G", fmt_arg(self.G),
                "--kappa-b-hat", fmt_arg(self.kappa_b), "--t-end", fmt_arg(self.t_end), "--out", str(out),
                "--no-plot"]
        if self.integrator != "cash-karp":
            # The tolerances of the paper's Cash-Karp runs (which are bendlab shear's defaults),
            # spelled out so that the command line says what was run.
            args += ["--integrator", self.integrator, "--rtol", RTOL, "--atol", ATOL]
        if self.quadrature != "all7":
            args += ["--bim-quadrature", self.quadrature]
        return args + ["--max-steps", str(MAX_STEPS)]

    def resume_key(self):
        """The arguments a checkpoint of this run holds."""
        return {"method": self.method, "mesh": self.mesh, "G": self.G, "kappa_b_hat": self.kappa_b,
                "integrator": self.integrator, "bim_quadrature": self.quadrature}

    def key(self):
        """The fields of the summary.json this run writes."""
        key = dict(self.resume_key(), t_end=self.t_end)
        if self.integrator != "cash-karp":
            key.update(rtol=float(RTOL), atol=float(ATOL))
        return key

    def assumed(self):
        # Summaries written before the options existed: Cash-Karp, every triangle by the 7-point rule.
        return {"integrator": "cash-karp", "bim_quadrature": "all7"}


def runner(bendlab, work, jobs=1, progress_every=60.0):
    """The study's runner: a failure is recorded with the step budget it ran under."""
    return study_runner.Runner(bendlab, work, jobs, failure_fields={"max_steps": MAX_STEPS},
                               progress_every=progress_every, say=say)


# The steady window of each t_end, as `bendlab shear` reports it in summary.json (the library
# defines the window and its statistics; this script only reads them).
_steady_windows = {}


def note_steady_windows(results):
    """Remembers the steady window of each t_end from the finished runs' summaries."""
    for r in results:
        try:
            _steady_windows[float(r.summary["t_end"])] = [float(x) for x in r.summary["steady_window"]]
        except (AttributeError, KeyError, TypeError, ValueError):
            pass


def failure_reason(error):
    """A run's error as the document shows it: without the program's prefix and the checkpoint's path."""
    text = (error or "").removeprefix("bendlab: error: ")
    return re.sub(r"; the last checkpoint, at gamma t = ([0-9.eE+-]+), is whole in '[^']*'$",
                  r" (last checkpoint at gamma t = \1)", text)


def part_runs(part, t_end, triangles, triangles_a, triangles_e=5120):
    if part == "a":
        return [Run("none", triangles_a, G, 0.0, t_end) for G in G_SWEEP]
    if part == "e":
        n, it = triangles_e, E_INTEGRATOR
        return ([Run("none", n, G, 0.0, t_end, it) for G in G_SWEEP]
                + [Run(m, n, G, kb, t_end, it) for (G, kb) in PAIRS for m in METHODS]
                + [Run(m, n, G, FIG17_KB, t_end, it) for G in FIG17_G for m in FIG17_METHODS if m in METHODS])
    if part == "b":
        return [Run(m, n, G, kb, t_end) for (G, kb) in PAIRS for n in triangles for m in METHODS]
    if part == "c":
        return ([Run("none", n, G, 0.0, t_end) for (G, kb) in PAIRS for n in triangles]
                + [Run(m, n, G, kb, t_end) for (G, kb) in PAIRS for n in triangles for m in METHODS])
    raise ValueError(part)


# ----------------------------------------------------------------------------- plots and tables

def load_series(results, work):
    for r in results.values():
        if r.ok and not r.series:
            try:
                columns = ("gamma_t", "D", "theta", "volume", "dt")
                r.series = study_runner.read_series(work / r.run.name, columns) or {}
            except (ValueError, KeyError):
                r.series = {}


def num(x, digits=4):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    return f"{x:.{digits}g}"


def steady_label(t_end):
    """The steady window of the runs ending at t_end, from their summary.json."""
    w = _steady_windows.get(float(t_end))
    return f"[{fmt_g(w[0])}, {fmt_g(w[1])}]" if w else "(the window of summary.json)"


def fit_slope(G, D):
    """Least-squares slope of D = s G through the origin."""
    G, D = np.asarray(G), np.asarray(D)
    return float(np.dot(G, D) / np.dot(G, G))


def section_a(results, runs, fig_dir, rel, t_end, suffix="", slope_note=""):
    lines = ["## (a) No bending: deformation against shear rate (figure 12)", ""]
    n = runs[0].triangles
    ok = [results[r] for r in runs if results[r].ok]
    bad = [results[r] for r in runs if not results[r].ok]
    lines.append(f"Capsule without bending resistance (kB_hat = 0), MT1 mesh with {n} triangles, "
                 f"gamma t from 0 to {fmt_g(t_end)}. The paper uses 5120 triangles.")
    lines.append("")

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for r in ok:
        s = r.series
        if s:
            ax.plot(s["gamma_t"], s["D"], label=f"G = {fmt_g(r.run.G)}")
    ax.set_xlabel(r"$\dot\gamma t$")
    ax.set_ylabel("D")
    ax.set_xlim(0, t_end)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend()
    ax.set_title(f"no bending, {n} triangles (cf. figure 12a)")
    fig.tight_layout()
    fig.savefig(fig_dir / f"fig12a_D_time{suffix}.png", dpi=110)
    plt.close(fig)

    G = np.array([r.run.G for r in ok])
    D = np.array([r.summary["D_steady"] if r.summary["D_steady"] is not None else math.nan for r in ok])
    good = np.isfinite(D)
    G, D = G[good], D[good]
    order = np.argsort(G)
    G, D = G[order], D[order]
    slope2 = fit_slope(G[:2], D[:2]) if len(G) >= 2 else math.nan
    slope3 = fit_slope(G[:3], D[:3]) if len(G) >= 3 else math.nan

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.plot(G, D, "o-", label=f"bendlab, {n} triangles")
    gx = np.linspace(0, max(G.max() if len(G) else 0.2, 0.2), 50)
    if math.isfinite(slope3):
        ax.plot(gx[gx <= 0.08], slope3 * gx[gx <= 0.08], ":", color="tab:blue",
                label=f"fit D = {slope3:.2f} G (three smallest G)")
    ax.plot(gx[gx <= 0.08], SMALL_DEFORMATION_SLOPE * gx[gx <= 0.08], "k--",
            label="small deformation: D = 25/4 G (= 25/12 Ca)")
    lo, hi = PUBLISHED_D_G01
    ax.errorbar([0.1], [(lo + hi) / 2], yerr=[[(hi - lo) / 2]], fmt="none", ecolor="tab:red", capsize=5,
                lw=2, label="published range at G = 0.1 (figure 12b)")
    ax.set_xlabel("G")
    ax.set_ylabel(f"D averaged over $\\dot\\gamma t \\in$ {steady_label(t_end)}")
    ax.set_xlim(0, gx[-1] * 1.05)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(f"steady deformation, no bending (cf. figure 12b)")
    fig.tight_layout()
    fig.savefig(fig_dir / f"fig12b_D_steady{suffix}.png", dpi=110)
    plt.close(fig)

    lines += [f"![D against gamma t]({rel}/fig12a_D_time{suffix}.png)", "",
              f"![steady D against G]({rel}/fig12b_D_steady{suffix}.png)", ""]
    lines += [f"Steady values (time average over gamma t in {steady_label(t_end)}, weighted by the step "
              "size), beside the small-deformation result D = 25/4 G:", "",
              "| G | Ca = 3 G | D_steady | theta_steady / pi | 25/4 G | D_steady / (25/4 G) | mean gamma dt | steps | wall s |",
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in sorted(ok, key=lambda r: r.run.G):
        s = r.summary
        lin = SMALL_DEFORMATION_SLOPE * r.run.G
        d = s["D_steady"]
        th = s["theta_steady"]
        lines.append(f"| {fmt_g(r.run.G)} | {fmt_g(3 * r.run.G)} | {num(d)} | "
                     f"{num(th / math.pi if th is not None else None)} | {lin:.4g} | "
                     f"{num(d / lin if d is not None else None, 3)} | {num(s['mean_gamma_dt'], 3)} | "
                     f"{s['steps']} | {s['wall_seconds']:.0f} |")
    for r in bad:
        lines.append(f"| {fmt_g(r.run.G)} | {fmt_g(3 * r.run.G)} | failed: {r.error} | | | | | | |")
    lines.append("")
    lo, hi = PUBLISHED_D_G01
    d01 = next((r.summary["D_steady"] for r in ok if close(r.run.G, 0.1)), None)
    lines += [
        f"- Small-G slope, least squares through the origin: **D = {num(slope2, 4)} G** from the two "
        f"smallest G, **D = {num(slope3, 4)} G** from the three smallest." + slope_note,
        "- Small-deformation theory (Barthes-Biesel & Rallison 1981): an initially spherical capsule in "
        "simple shear takes D = 5/4 Ca (2 + nu_s) / (1 + nu_s), with Ca = mu gamma R / Gs, Gs the "
        "small-strain shear modulus and nu_s the surface Poisson ratio of the membrane, whatever the "
        "viscosity ratio. The neo-Hookean law has nu_s = 1/2 (area-dilatation modulus 3 Gs), "
        "so D = 25/12 Ca, which is D = 25/4 mu gamma R / Es written with the surface "
        "Young modulus Es = 3 Gs. Our kS is 3 Gs (docs/conventions.md §2), so Ca = 3 G and the "
        "theory gives **D = 25/4 G = 6.25 G**. (D = 25/4 Ca with Ca = 3 G, i.e. 18.75 G, would mix "
        "the two moduli.) The theory holds for D << 1; the membrane softens in the neo-Hookean law "
        "at finite strain and the computed D falls below the line as G grows.",
        f"- At G = 0.1 the literature of the paper's figure 12b (5120 triangles) lies in "
        f"D = {lo:.2f} - {hi:.2f}; here D_steady = {num(d01)} with {n} triangles.",
    ]
    if t_end < 10:
        lines.append(f"- Preview run (gamma t up to {fmt_g(t_end)}): the capsule has not reached its "
                     "steady state, so the steady values are not comparable with the paper's.")
    lines.append("")
    return lines


def section_b(results, runs, fig_dir, rel, t_end, none_results, suffix="", integrator="cash-karp"):
    lines = ["## (b) All bending methods: deformation against time (figures 13 and 14)", ""]
    lines.append("All methods on MT1 meshes, gamma t from 0 to " + fmt_g(t_end) + ". The grey dashed "
                 "curve is the capsule without bending (kB_hat = 0) at the same G and resolution, when "
                 "that run exists. The paper's figure 14 shows 5120 triangles, figure 13 the resolutions "
                 "320, 1280, 5120 per method at G = 0.2."
                 + (" The inset magnifies gamma t in [5, " + fmt_g(t_end) + "] on the curves with bending: "
                    "its vertical range is theirs in that window plus 15 % (scripts/inset_limits.py), so "
                    "the no-bending curve, and a method whose mean there lies more than 5 % from the "
                    "median of the methods (named in the inset's title), are seen on the main axes only."
                    if t_end > 5 else ""))
    lines.append("")
    triangles = sorted({r.triangles for r in runs})
    for (G, kb) in PAIRS:
        lines.append(f"### G = {fmt_g(G)}, kB_hat = {fmt_g(kb)}")
        lines.append("")
        for n in triangles:
            fig, ax = plt.subplots(figsize=(7.0, 4.6))
            curves = []
            ref = none_results.get((n, G))
            if ref is not None and ref.ok and ref.series:
                curves.append(("no bending", "none", ref.series))
            for m in METHODS:
                r = results.get(Run(m, n, G, kb, t_end, integrator))
                if r is not None and r.ok and r.series:
                    curves.append((m, m, r.series))
            for label, key, s in curves:
                ax.plot(s["gamma_t"], s["D"], label=label, **METHOD_STYLE.get(key, {}))
            # The inset zooms on the steady state of the methods with bending (inset_limits.py):
            # the no-bending curve, and a method far from the others, stay on the main axes only.
            # It sits in the empty band between the bending curves and the no-bending one; the
            # main axes reach 1.9 times the highest bending curve to make room for it.
            lim = (inset_ylim([(k, s["gamma_t"], s["D"]) for _, k, s in curves], (5.0, t_end))
                   if t_end > 5 else None)
            top = max([float(np.max(s["D"])) for _, _, s in curves] or [1.0])
            if lim is not None:
                lo, hi, left_out = lim
                bend_top = max(float(np.max(s["D"])) for _, k, s in curves if k != "none")
                top = max(top, 1.9 * bend_top)
                ins = ax.inset_axes([0.42, 0.5, 0.55, 0.34])
                for label, key, s in curves:
                    sel = s["gamma_t"] >= 5
                    if key not in left_out:
                        ins.plot(s["gamma_t"][sel], s["D"][sel], **METHOD_STYLE.get(key, {}))
                ins.set_xlim(5, t_end)
                ins.set_ylim(lo, hi)
                ins.tick_params(labelsize=7)
                ins.grid(alpha=0.3)
                off = [("no bending" if k == "none" else k) for k in left_out]
                ins.set_title(r"$\dot\gamma t \in [5, %g]$" % t_end
                              + (" (not shown: " + ", ".join(off) + ")" if off else ""), fontsize=8)
            ax.set_xlabel(r"$\dot\gamma t$")
            ax.set_ylabel("D")
            ax.set_xlim(0, t_end)
            ax.set_ylim(0, 1.05 * top)
            ax.grid(alpha=0.3)
            ax.legend(loc="upper left", fontsize=8, ncol=2)
            ax.set_title(f"G = {fmt_g(G)}, kB_hat = {fmt_g(kb)}, {n} triangles")
            fig.tight_layout()
            name = f"fig14_G{fmt_g(G)}_kb{fmt_g(kb)}_{n}{suffix}.png"
            fig.savefig(fig_dir / name, dpi=110)
            plt.close(fig)
            lines += [f"![D against gamma t, G = {fmt_g(G)}, {n} triangles]({rel}/{name})", ""]

        # Steady D per method and resolution, and the change from the coarsest to the finest mesh.
        header = "| method | " + " | ".join(f"D_steady, {n}" for n in triangles)
        if len(triangles) > 1:
            header += f" | D_{triangles[0]} / D_{triangles[-1]} - 1"
        header += " | theta_steady / pi, " + str(triangles[-1]) + " |"
        lines += [f"Steady values over gamma t in {steady_label(t_end)}:", "", header,
                  "|" + " --- |" * (header.count("|") - 1)]
        for m in ["none"] + METHODS:
            cells, ds = [], []
            for n in triangles:
                r = none_results.get((n, G)) if m == "none" else results.get(Run(m, n, G, kb, t_end, integrator))
                if r is None:
                    cells.append("")
                    ds.append(None)
                elif not r.ok:
                    cells.append("failed")
                    ds.append(None)
                else:
                    cells.append(num(r.summary["D_steady"]))
                    ds.append(r.summary["D_steady"])
            if all(c == "" for c in cells):
                continue
            row = f"| {'no bending' if m == 'none' else m} | " + " | ".join(cells)
            if len(triangles) > 1:
                a, b = ds[0], ds[-1]
                row += " | " + (f"{100 * (a - b) / b:+.1f} %" if a is not None and b else "")
            last = (none_results.get((triangles[-1], G)) if m == "none"
                    else results.get(Run(m, triangles[-1], G, kb, t_end, integrator)))
            th = last.summary["theta_steady"] if last is not None and last.ok else None
            row += " | " + (num(th / math.pi) if th is not None else "") + " |"
            lines.append(row)
        lines.append("")
    if t_end < 10:
        lines += [f"Preview run (gamma t up to {fmt_g(t_end)}): the curves show only the start-up.", ""]
    return lines


def section_c(results, runs, t_end):
    lines = ["## (c) Average time step (table 4) and run times", ""]
    triangles = sorted({r.triangles for r in runs})
    window = steady_label(t_end)
    lines.append(f"Mean of the accepted Cash-Karp steps gamma dt whose end lies in gamma t in {window} "
                 "(`mean_gamma_dt` of summary.json), relative tolerance 1e-7, absolute tolerance 1e-6 R, "
                 "as in the paper. Paper: table 4 (BIM, MT1). The paper has no column for ED or J (Jülicher, beyond the paper); "
                 "'no bending' is its kB_hat = 0 column.")
    if t_end < 10:
        lines.append(f"Preview run: the window is gamma t in {window}, not [5, 10]; the steps early in a "
                     "run need not match the steady ones, so the ratios are not those of the full study.")
    lines.append("")
    cols = ["none"] + METHODS
    head = "| triangles | | " + " | ".join("no bending" if c == "none" else c for c in cols) + " |"
    sep = "|" + " --- |" * (len(cols) + 2)
    for (G, kb) in PAIRS:
        lines += [f"### G = {fmt_g(G)}, kB_hat = {fmt_g(kb)} (paper: table 4{'a' if G < 0.1 else 'b'})",
                  "", head, sep]
        for n in triangles:
            ours, paper, ratio = [], [], []
            for c in cols:
                r = results.get(Run(c, n, G, 0.0 if c == "none" else kb, t_end))
                v = r.summary["mean_gamma_dt"] if r is not None and r.ok else None
                p_text = PAPER_TABLE4[(G, kb)].get(n, {}).get(c)
                p = float(p_text) if p_text is not None else None
                ours.append("failed" if r is not None and not r.ok else num(v, 3))
                paper.append(p_text if p_text is not None else "-")
                ratio.append(f"{v / p:.2f}" if v is not None and p else "-")
            lines.append(f"| {n} | ours | " + " | ".join(ours) + " |")
            lines.append(f"| {n} | paper | " + " | ".join(paper) + " |")
            lines.append(f"| {n} | ours / paper | " + " | ".join(ratio) + " |")
        lines.append("")

    lines += ["### Run times", "",
              "Wall time of each `bendlab shear` run (one process, the machine shared with the "
              "other runs of the study), accepted steps, velocity evaluations and the relative "
              "volume change at the end.", ""]
    entries = [([fmt_g(G), fmt_g(0.0 if c == "none" else kb), str(n), "no bending" if c == "none" else c],
                results.get(Run(c, n, G, 0.0 if c == "none" else kb, t_end)))
               for (G, kb) in PAIRS for n in triangles for c in cols]
    lines += study_runner.run_time_table(
        ["G", "kB_hat", "triangles", "method"], entries,
        run_time_columns("velocity evaluations", ("steps / s", lambda s: (
            f"{s['steps'] / s['wall_seconds'] if s['wall_seconds'] > 0 else math.nan:.3g}"))), missing=None)
    lines.append("")
    return lines


def run_time_columns(evaluations, *more):
    """The measured columns of the run-time tables: wall time, accepted and rejected steps, the
    velocity evaluations (headed `evaluations`), the columns `more` and the relative volume change."""
    return [("wall s", lambda s: f"{s['wall_seconds']:.0f}"), ("steps", lambda s: str(s["steps"])),
            ("rejected", lambda s: str(s.get("rejected_steps", ""))),
            (evaluations, lambda s: str(s.get("velocity_evaluations", ""))), *more,
            ("volume change", lambda s: f"{(s['final_volume'] - s['initial_volume']) / s['initial_volume']:.1e}")]


def demote(lines, title):
    """Lines of a part's section as a subsection of part (e): '## ...' becomes '### title', deeper
    headings one level deeper."""
    out = []
    for l in lines:
        if l.startswith("## "):
            out.append("### " + title)
        elif l.startswith("###"):
            out.append("#" + l)
        else:
            out.append(l)
    return out


def stat(summary, key):
    v = (summary.get("integrator_stats") or {}).get(key)
    return v if isinstance(v, (int, float)) else None


def paper_dt(G, kb, n, method):
    text = PAPER_TABLE4.get((G, kb), {}).get(n, {}).get(method)
    return (text, float(text)) if text is not None else (None, None)


def curve_plot(ax, results, keys, t_end, title):
    """D against gamma t of the runs `keys` (label -> Run) on `ax`."""
    for label, (style, run) in keys.items():
        r = results.get(run)
        if r is not None and r.ok and r.series:
            ax.plot(r.series["gamma_t"], r.series["D"], label=label, **METHOD_STYLE.get(style, {}))
    ax.set_xlabel(r"$\dot\gamma t$")
    ax.set_ylabel("D")
    ax.set_xlim(0, t_end)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title(title, fontsize=10)


def steady_cell(r, key="D_steady", scale=1.0):
    if r is None:
        return "not run"
    if not r.ok:
        return "failed"
    v = r.summary.get(key)
    return num(v / scale if v is not None else None)


def section_e(results, runs, fig_dir, rel, t_end, n, meta):
    """Part (e): figures 12, 14, 16, 17 and table 4 at n triangles (the paper's 5120) with the
    Runge-Kutta-Chebyshev integrator. `meta` holds the invocation's command, commit and wall time."""
    it = E_INTEGRATOR
    suffix = f"_{n}_{it}"
    ok = [results[r] for r in runs if r in results and results[r].ok]
    failed = [r for r in runs if r in results and not results[r].ok]
    missing = [r for r in runs if r not in results]
    run_wall = study_runner.total_wall(r.summary for r in ok)
    evals = sum(int(r.summary.get("velocity_evaluations") or 0) for r in ok)
    cached = sum(1 for r in ok if r.cached)
    lines = [E_BEGIN, "",
             f"## (e) {n} triangles with the Runge-Kutta-Chebyshev integrator (figures 12, 14, 16, 17; table 4)",
             "", *study_runner.generated_by(meta["command"]),
             f"- source commit: {meta['commit']}" if meta.get("commit") else None,
             f"- runs: {len(runs)} ({len(ok)} finished, {cached} of them taken from the work folder"
             + (f", {len(failed)} failed" if failed else "") + (f", {len(missing)} not run" if missing else "")
             + f"), {meta['jobs']} in parallel on {meta['cores']} cores",
             f"- **wall time of the {n}-triangle study: {run_wall:.0f} s ({run_wall / 3600:.2f} h) of run time "
             f"together** (the sum of the runs' timing.json `wall_seconds`, which add up the parts of a "
             f"resumed run), {evals} BIM evaluations in all; this invocation took {meta['wall']:.0f} s "
             f"({meta['wall'] / 3600:.2f} h) of wall time"
             + (" (runs taken from the work folder cost it nothing)" if cached else ""),
             f"- gamma t from 0 to **{fmt_g(t_end)}** in every run"
             + ("" if t_end >= 10 else " (a preview: the paper runs to 10)"),
             "",
             f"Every run is `bendlab shear --method METHOD --mesh mt1:{n} --G G --kappa-b-hat KB --t-end T --no-plot "
             f"--integrator {it} --rtol {RTOL} --atol {ATOL}"
             + ("" if E_QUADRATURE == "all7" else f" --bim-quadrature {E_QUADRATURE}")
             + "`: the boundary integral method as in parts "
             "(a)-(c), but stepped by the second-order Runge-Kutta-Chebyshev method, whose stages grow with "
             "the stiffness bending adds so that the step is set by accuracy, not by stability "
             "(docs/results/stiff_stepping.md: for Method C at 5120 triangles, G = 0.2, kB_hat = 0.15 its "
             "steady D is 0.0002 % from Cash-Karp's with 22.6 times fewer BIM evaluations). The tolerances "
             f"are those of the paper's Cash-Karp runs. Steady values are time averages over gamma t in "
             f"{steady_label(t_end)}."
             + {"all7": "",
                "tree": " The BIM's tree quadrature gives velocities within about 2e-6 (relative, maximum "
                        "over nodes) of the all-7-point rule at 5120 triangles (stokes_single_layer.hpp).",
                "tree-mixed": " The BIM's tree quadrature with single-precision sums (tree-mixed) gives "
                              "velocities within about 2e-6 (relative, maximum over nodes) of the all-7-point "
                              "rule at 5120 triangles, 3.7 to 3.9 times faster than it on one thread "
                              "(stokes_single_layer.hpp)."}[E_QUADRATURE],
             ""]
    lines = [l for l in lines if l is not None]
    if n != 5120:
        lines += [f"**Preview at {n} triangles** (--triangles-e {n}): the paper's figures and table 4 "
                  "below are at 5120 triangles; the paper's values quoted are those of this resolution "
                  "where table 4 has them.", ""]

    # Figure 12: no bending, five G.
    runs_a = [r for r in runs if r.method == "none"]
    if runs_a and all(r in results for r in runs_a):
        # Beside the table: why its smallest G differs between the resolutions (the runs of
        # scripts/small_g_study.py, in studies/small_g).
        small_g = (small_g_study.section(fig_dir, rel)
                   if n == 5120 and t_end >= 10 and E_QUADRATURE == "tree-mixed" else [])
        note = (" Without bending the membrane wrinkles at these G, at the mesh's own wavelength, so these "
                "slopes depend on the mesh; the slope from smooth runs is given below." if small_g else "")
        lines += demote(section_a(results, runs_a, fig_dir, rel, t_end, suffix, note),
                        f"(e.1) No bending: deformation against shear rate (figure 12), {n} triangles")
        lines += small_g

    # Figure 14: every method at the two cases of the paper.
    none_results = {(n, G): results[r] for r in runs_a if r in results for (G, kb) in PAIRS if close(r.G, G)}
    runs_b = [r for r in runs if r.method != "none" and (r.G, r.kappa_b) in PAIRS]
    body = section_b(results, runs_b, fig_dir, rel, t_end, none_results, f"_{it}", it)
    lines += demote(body, f"(e.2) All bending methods: deformation against time (figure 14), {n} triangles")

    # Table 4: the paper's Cash-Karp step beside RKC's step and evaluations.
    lines += [f"### (e.3) Average time step (table 4) and BIM evaluations, {n} triangles", "",
              f"Paper: mean gamma dt of its Cash-Karp runs over gamma t in [5, 10] (table 4, BIM, MT1, "
              f"{n} triangles). RKC: `mean_gamma_dt` of summary.json (accepted steps ending in gamma t in "
              f"{steady_label(t_end)}), the BIM evaluations of the whole run (`velocity_evaluations`: "
              "stages, power iterations for the spectral radius, the re-evaluation after the volume "
              "rescale) and the mean number of stages per step. The last column is what Cash-Karp would "
              f"need at the paper's steady step over the whole run, 6 x {fmt_g(t_end)} / gamma dt (six "
              "evaluations per step, rejected steps and the start-up not counted): an estimate for scale, "
              "not a measurement. The paper has no column for ED, S or J.", ""]
    if t_end < 10:
        lines += [f"Preview run: the RKC window is gamma t in {steady_label(t_end)}, not [5, 10], so the "
                  "ratios are not those of the full study.", ""]
    for (G, kb) in PAIRS:
        lines += [f"#### G = {fmt_g(G)}, kB_hat = {fmt_g(kb)} (paper: table 4{'a' if G < 0.1 else 'b'})", "",
                  "| method | paper: Cash-Karp gamma dt | RKC gamma dt | RKC / paper | RKC evaluations | "
                  "accepted / rejected steps | mean stages | Cash-Karp evaluations at the paper's step (estimate) | wall s |",
                  "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
        for m in ["none"] + METHODS:
            r = results.get(Run(m, n, G, 0.0 if m == "none" else kb, t_end, it))
            if r is None:
                continue
            p_text, p = paper_dt(G, kb, n, m)
            name = "no bending" if m == "none" else m
            if not r.ok:
                lines.append(f"| {name} | {p_text or '-'} | failed | | | | | | |")
                continue
            s = r.summary
            v = s.get("mean_gamma_dt")
            stages = stat(s, "mean_stages")
            lines.append(f"| {name} | {p_text or '-'} | {num(v, 3)} | {f'{v / p:.2g}' if v and p else '-'} | "
                         f"{s.get('velocity_evaluations', '')} | {s['steps']} / {s.get('rejected_steps', '')} | "
                         f"{num(stages, 3)} | {f'{6 * t_end / p:.2g}' if p else '-'} | {s['wall_seconds']:.0f} |")
        lines.append("")

    # Figure 16: Methods C and S at G = 0.05, kB_hat = 0.0375.
    G16, kb16 = PAIRS[0]
    m16 = [m for m in FIG16_METHODS if m in METHODS]
    keys = {f"Method {m}": (m, Run(m, n, G16, kb16, t_end, it)) for m in m16}
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    curve_plot(ax, results, keys, t_end, f"G = {fmt_g(G16)}, kB_hat = {fmt_g(kb16)}, {n} triangles (cf. figure 16)")
    fig.tight_layout()
    name16 = f"fig16_C_S{suffix}.png"
    fig.savefig(fig_dir / name16, dpi=110)
    plt.close(fig)
    rc = results.get(Run("C", n, G16, kb16, t_end, it))
    rs = results.get(Run("S", n, G16, kb16, t_end, it))
    dc = rc.summary["D_steady"] if rc is not None and rc.ok else None
    ds = rs.summary["D_steady"] if rs is not None and rs.ok else None
    lines += [f"### (e.4) Methods C and S against the literature (figure 16), {n} triangles", "",
              f"![D against gamma t, C and S]({rel}/{name16})", "",
              "| method | D_steady | theta_steady / pi |", "| --- | --- | --- |",
              f"| C | {steady_cell(rc)} | {steady_cell(rc, 'theta_steady', math.pi)} |",
              f"| S | {steady_cell(rs)} | {steady_cell(rs, 'theta_steady', math.pi)} |", "",
              (f"S against C: {100 * (ds - dc) / dc:+.2f} % in D_steady." if dc and ds else
               "S against C: not available (a run is missing or failed)."), "",
              "The paper's figure 16 compares C and S with the recent literature at the same G and kB_hat "
              "(Pozrikidis 2001 with a Hookean law, Huang et al. with Zarda's bending model, and others "
              "named only in the plot). The literature values appear in the paper only as curves in the "
              "plot: neither its text nor the specification gives them as numbers, so they are not drawn "
              "here. The text says only that they scatter by up to about 20 %.", ""]

    # Figure 17: Methods A and C at kB_hat = 2/15.
    m17 = [m for m in FIG17_METHODS if m in METHODS]
    fig, axes = plt.subplots(1, len(FIG17_G), figsize=(10.5, 4.2))
    for ax, G in zip(np.atleast_1d(axes), FIG17_G):
        keys = {f"Method {m}": (m, Run(m, n, G, FIG17_KB, t_end, it)) for m in m17}
        curve_plot(ax, results, keys, t_end, f"G = {fmt_g(G)}, kB_hat = 2/15, {n} triangles")
    fig.suptitle("cf. figure 17", fontsize=10)
    fig.tight_layout()
    name17 = f"fig17_A_C{suffix}.png"
    fig.savefig(fig_dir / name17, dpi=110)
    plt.close(fig)
    lines += [f"### (e.5) Methods A and C at kB_hat = 2/15 (figure 17), {n} triangles", "",
              f"![D against gamma t, A and C, kB_hat = 2/15]({rel}/{name17})", "",
              "| G | D_steady, A | D_steady, C | A / C - 1 | theta_steady / pi, A | theta_steady / pi, C |",
              "| --- | --- | --- | --- | --- | --- |"]
    for G in FIG17_G:
        ra = results.get(Run("A", n, G, FIG17_KB, t_end, it))
        rc = results.get(Run("C", n, G, FIG17_KB, t_end, it))
        da = ra.summary["D_steady"] if ra is not None and ra.ok else None
        dc = rc.summary["D_steady"] if rc is not None and rc.ok else None
        lines.append(f"| {fmt_g(G)} | {steady_cell(ra)} | {steady_cell(rc)} | "
                     f"{f'{100 * (da - dc) / dc:+.1f} %' if da and dc else ''} | "
                     f"{steady_cell(ra, 'theta_steady', math.pi)} | {steady_cell(rc, 'theta_steady', math.pi)} |")
    lines += ["", "The paper's figure 17 draws Tsubota 2014 (BIM, 4604 flat triangles; his model KN is Method A, "
              "model H is Method C) beside its A and C. Tsubota's values appear in the paper only as curves "
              "in the plot, not as numbers in its text or in the specification, so they are not drawn here. "
              "The paper says its A and C agree with his extremely well.", ""]
    if t_end < 10:
        lines += [f"Preview run (gamma t up to {fmt_g(t_end)}): the curves show only the start-up.", ""]

    # Run times.
    lines += [f"### (e.6) Run times, {n} triangles", "",
              "Each `bendlab shear` run: wall time (timing.json; the machine shared with the other runs of "
              "the study), accepted and rejected steps, BIM evaluations, mean stages per step, the largest "
              "spectral radius estimate (x1.1) and the relative volume change at the end.", ""]
    entries = [([fmt_g(run.G), "2/15" if close(run.kappa_b, FIG17_KB) else fmt_g(run.kappa_b),
                 "no bending" if run.method == "none" else run.method], results.get(run)) for run in runs]
    lines += study_runner.run_time_table(
        ["G", "kB_hat", "method"], entries,
        run_time_columns("BIM evaluations", ("mean stages", lambda s: num(stat(s, "mean_stages"), 3)),
                         ("spectral radius max", lambda s: num(stat(s, "spectral_radius_max"), 3))),
        total=f"| | | **all {len(runs)} runs** | **{run_wall:.0f}** | | | **{evals}** | | | |",
        failure=lambda r: f"failed: {r.error}")
    lines.append("")
    lines += quadrature_cross_check(results, runs, meta.get("work"))
    lines += [E_END, ""]
    return lines


# Part (e)'s tree quadratures and the one each is checked against where both have run.
OTHER_TREE = {"tree": "tree-mixed", "tree-mixed": "tree"}


def quadrature_cross_check(results, runs, work):
    """(e.7): the runs that finished with both tree quadratures (tree and tree-mixed, the
    same terms summed in double and in single precision) side by side, where the work folder has
    the other's finished run folders. Empty when it has none."""
    other = OTHER_TREE.get(E_QUADRATURE)
    if other is None or work is None:
        return []
    rows = []
    for run in runs:
        r = results.get(run)
        if r is None or not r.ok:
            continue
        name = run.name[: -len(E_QUADRATURE)] + other
        s = study_runner.read_summary(work / name)
        if (s is None or s.get("bim_quadrature") != other
                or not matches({**s, "bim_quadrature": E_QUADRATURE}, run.key(), run.assumed())):
            continue
        a, b = r.summary, s
        kb = "2/15" if close(run.kappa_b, FIG17_KB) else fmt_g(run.kappa_b)
        rows.append(f"| {fmt_g(run.G)} | {kb} | {'no bending' if run.method == 'none' else run.method} | "
                    f"{a['D_steady']:.6f} | {b['D_steady']:.6f} | {a['D_steady'] / b['D_steady'] - 1:+.1e} | "
                    f"{a['theta_steady'] / b['theta_steady'] - 1:+.1e} | {a.get('velocity_evaluations', '')} / "
                    f"{b.get('velocity_evaluations', '')} | {a['wall_seconds']:.0f} / {b['wall_seconds']:.0f} |")
    if not rows:
        return []
    return [f"### (e.7) Cross-check: the same runs with the {other} quadrature", "",
            f"The runs of this section that also finished with `--bim-quadrature {other}` (folders ending "
            f"in `_{other}` in the work folder): the steady values and their relative difference, BIM "
            f"evaluations and wall time ({E_QUADRATURE} / {other}; the wall times come from different "
            "loads of the shared machine).", "",
            f"| G | kB_hat | method | D_steady, {E_QUADRATURE} | D_steady, {other} | D difference | "
            f"theta difference | evaluations | wall s |",
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- |", *rows, ""]


E_BEGIN = "<!-- rkc-study:begin -->"
E_END = "<!-- rkc-study:end -->"


def replace_block(text, begin, end, block):
    """`text` with its block between the markers begin and end replaced by `block` (which starts
    with begin and ends with end), or `block` appended where `text` has no such block."""
    block = block.strip("\n")
    if begin in text and end in text:
        head, _, rest = text.partition(begin)
        tail = rest.partition(end)[2].strip("\n")
        return head.rstrip("\n") + "\n\n" + block + "\n" + ("\n" + tail + "\n" if tail else "")
    return text.rstrip("\n") + "\n\n" + block + "\n"


def old_block(path, begin, end):
    """The marked block of an existing document, or None."""
    try:
        text = path.read_text()
    except OSError:
        return None
    if begin in text and end in text:
        return begin + text.partition(begin)[2].partition(end)[0] + end
    return None


def added_runs(added, t_end, triangles):
    """The runs of --add-methods: the added methods and the no-bending references of (b) and (c)."""
    return ([Run(m, n, G, kb, t_end) for (G, kb) in PAIRS for n in triangles for m in added]
            + [Run("none", n, G, 0.0, t_end) for (G, kb) in PAIRS for n in triangles])


# ----------------------------------------------------------------------------- main

def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--jobs", type=int, default=2, help="runs in parallel (default 2)")
    ap.add_argument("--t-end", type=float, default=10.0,
                    help="end of every run in gamma t (default 10; smaller for a quick preview)")
    ap.add_argument("--only", choices=["a", "b", "c", "e"],
                    help="run only the runs of this part; e (5120 triangles, RKC) is run only when asked "
                         "for and writes its own section at the end of --doc, keeping the rest")
    ap.add_argument("--bendlab", default="build/release/bendlab", help="the bendlab binary")
    ap.add_argument("--work", default="studies/shear",
                    help="folder of the runs (the cache; kept in git so that a study resumes on another machine)")
    ap.add_argument("--doc", default="docs/results/shear.md",
                    help="the document to write; its figures go to a folder of the same name without .md")
    ap.add_argument("--triangles", default="320,1280",
                    help="resolutions of parts (b) and (c), comma separated (default 320,1280)")
    ap.add_argument("--progress-every", type=float, default=60,
                    help="seconds between progress lines of the running runs (default 60)")
    ap.add_argument("--triangles-a", type=int, default=1280, help="resolution of part (a) (default 1280)")
    ap.add_argument("--triangles-e", type=int, default=5120,
                    help="resolution of part (e) (default 5120, the paper's; smaller for a quick preview)")
    ap.add_argument("--bim-quadrature-e", choices=["all7", "tree", "tree-mixed"], default="all7",
                    help="BIM quadrature of part (e)'s runs: all7 (default, the reference), tree (within "
                         "1e-5 of it, faster at 5120 triangles; its runs are cached under names ending in _tree) "
                         "or tree-mixed (the tree with single-precision sums; names ending in _tree-mixed)")
    ap.add_argument("--list", action="store_true",
                    help="print the runs the chosen parts need, with their command lines and whether each "
                         "is done, can resume from a checkpoint or is still to run; runs nothing")
    ap.add_argument("--add-methods", default="",
                    help="comma-separated bending methods to add to an existing --doc: runs only these "
                         "methods (and the no-bending references) of parts (b) and (c) at --triangles and "
                         "writes them into a section of their own at the end of the document, leaving the "
                         "rest of it as it is")
    args = ap.parse_args()
    global E_QUADRATURE
    E_QUADRATURE = args.bim_quadrature_e
    if args.jobs < 1:
        ap.error("--jobs must be at least 1")
    if not args.t_end > 0:
        ap.error("--t-end must be positive")
    try:
        triangles = sorted({int(x) for x in args.triangles.split(",") if x.strip()})
    except ValueError:
        ap.error("--triangles takes numbers separated by commas, e.g. 320,1280")
    if not triangles:
        ap.error("--triangles is empty")

    command = study_runner.invocation(__file__, sys.argv[1:])
    bendlab = study_runner.bendlab_binary(args.bendlab)
    METHODS[:] = bending_methods(bendlab)
    small_g_study.BENDLAB = bendlab  # writes the meshes its shape pictures need
    work = Path(args.work).resolve()
    doc = Path(args.doc).resolve()
    fig_dir = doc.with_suffix("")
    if not args.list:
        work.mkdir(parents=True, exist_ok=True)
        fig_dir.mkdir(parents=True, exist_ok=True)
    if args.add_methods:
        added = [m for m in args.add_methods.split(",") if m.strip()]
        unknown = [m for m in added if m not in METHODS]
        if unknown:
            ap.error(f"--add-methods: unknown method(s) {', '.join(unknown)} (known: {', '.join(METHODS)})")
        if args.list:
            return runner(bendlab, work).list(added_runs(added, args.t_end, triangles),
                                              f"--add-methods {','.join(added)}")
        if not doc.is_file():
            ap.error(f"--add-methods: no document {doc} to add to")
        return add_methods(added, args, command, bendlab, work, doc, fig_dir, triangles)

    if args.triangles_e not in [20 * 4 ** k for k in range(8)]:
        ap.error("--triangles-e must be an MT1 size (20 * 4^k, e.g. 320, 1280, 5120)")
    parts = [args.only] if args.only else ["a", "b", "c"]
    runs_of = {p: part_runs(p, args.t_end, triangles, args.triangles_a, args.triangles_e) for p in "abce"}
    todo = list(dict.fromkeys(r for p in parts for r in runs_of[p]))
    # Long runs first, so that the parallel runs end close together: bending methods at the
    # finest mesh, then by the paper's step size. RKC's stage count grows with the square root of
    # the stiffness that sets Cash-Karp's step; Method S costs about twice C per evaluation.
    def cost(r):
        dt = float(PAPER_TABLE4.get((r.G, r.kappa_b), {}).get(r.triangles, {}).get(r.method, "0.05"))
        if r.integrator != "cash-karp":
            # The paper's Cash-Karp step of the pair with this G (figure 17's kB_hat is not in
            # table 4); ED, S and J relative to C as measured with Cash-Karp at 1280 triangles.
            pair = next(((G, kb) for (G, kb) in PAIRS if close(G, r.G)), PAIRS[0])
            row = PAPER_TABLE4[pair].get(r.triangles) or PAPER_TABLE4[pair][5120]
            m = r.method if r.method in row else "C"
            dt = float(row[m]) * {"ED": 4.9, "S": 0.18}.get(r.method, 1.0)
            return -(r.triangles ** 2) * (2 if r.method == "S" else 1) / math.sqrt(dt)
        return -(r.triangles ** 1.5) * (4 if r.method == "D" else 1) / dt
    todo.sort(key=cost)
    study = runner(bendlab, work, args.jobs, args.progress_every)
    if args.list:
        return study.list(todo, f"part(s) {', '.join(parts)}")

    say(f"shear study: {len(todo)} runs (parts {', '.join(parts)}), t_end {fmt_g(args.t_end)}, "
        f"{args.jobs} in parallel, work folder {work}")
    start = time.monotonic()
    results = study.run_all(todo)
    wall = time.monotonic() - start

    commit = study_runner.source_commit()
    if parts == ["e"]:
        note_steady_windows(results.values())
        load_series(results, work)
        meta = dict(command=command, commit=commit, wall=wall, jobs=args.jobs,
                    cores=study_runner.cores(), work=work)
        rel = os.path.relpath(fig_dir, doc.parent)
        block = "\n".join(section_e(results, runs_of["e"], fig_dir, rel, args.t_end, args.triangles_e, meta))
        text = doc.read_text() if doc.is_file() else (
            "# Capsule in shear flow (paper section 4)\n\nParts (a)-(c) are written by "
            "scripts/shear_study.py without --only e; this document has only part (e) so far.\n")
        doc.parent.mkdir(parents=True, exist_ok=True)
        tmp = doc.with_suffix(".md.tmp")
        tmp.write_text(replace_block(text, E_BEGIN, E_END, block).replace("\n\n\n", "\n\n"))
        tmp.replace(doc)
        failed = [r for r in results.values() if not r.ok]
        say(f"wrote part (e) of {doc} and its figures in {fig_dir}/ ({wall:.0f} s; {len(failed)} failed runs)")
        return 1 if failed else 0

    # Parts not run now enter the document when all their runs are in the work folder.
    shown = []
    for p in "abc":
        if p in parts:
            shown.append(p)
            continue
        cached = {r: study.cached(r) for r in runs_of[p]}
        if all(c is not None and c.ok for c in cached.values()):
            results.update({r: c for r, c in cached.items() if r not in results})
            shown.append(p)
    # The no-bending reference curves of part (b), when they exist.
    none_results = {}
    for n in triangles:
        for (G, kb) in PAIRS:
            r = Run("none", n, G, 0.0, args.t_end)
            res = results.get(r) or study.cached(r)
            if res is not None and res.ok:
                results.setdefault(r, res)
                none_results[(n, G)] = res
    note_steady_windows(results.values())
    load_series(results, work)

    run_wall = study_runner.total_wall(r.summary for r in results.values() if r.ok)
    failed = [r for r in results.values() if not r.ok]
    rel = os.path.relpath(fig_dir, doc.parent)
    lines = ["# Capsule in shear flow (paper section 4)", "", *study_runner.generated_by(command),
             f"- machine: {study_runner.machine()}; {args.jobs} runs in parallel",
             f"- gamma t from 0 to **{fmt_g(args.t_end)}** in every run"
             + ("" if args.t_end >= 10 else " (a preview: the paper runs to 10)"),
             f"- total wall time of this invocation: {wall:.0f} s ({wall / 60:.1f} min); the runs shown "
             f"took {run_wall:.0f} s of run time together ({len([r for r in results.values() if r.cached])} "
             "taken from the work folder)",
             f"- parts shown: {', '.join(shown)}" + (f"; failed runs: {len(failed)}" if failed else ""),
             f"- source commit: {commit}" if commit else None,
             "",
             "Every run is `bendlab shear --method METHOD --mesh mt1:N --G G --kappa-b-hat KB --t-end T --no-plot` "
             "(boundary integral method, Cash-Karp with relative tolerance 1e-7 and absolute tolerance "
             "1e-6 R). Units: G = mu gamma R / kS and kB_hat = kB / (R^2 kS) with the neo-Hookean "
             "modulus kS of eq. (18), which is three times the shear modulus Gs: the capillary number "
             "of the literature is Ca = mu gamma R / Gs = 3 G. D and theta come from the ellipsoid "
             "with the inertia tensor of the enclosed volume. Steady values are time averages over "
             f"gamma t in {steady_label(args.t_end)}.", ""]
    lines = [l for l in lines if l is not None]
    if "a" in shown:
        lines += section_a(results, runs_of["a"], fig_dir, rel, args.t_end)
    if "b" in shown:
        lines += section_b(results, runs_of["b"], fig_dir, rel, args.t_end, none_results)
    if "c" in shown:
        lines += section_c(results, runs_of["c"], args.t_end)
    for p in "abc":
        if p not in shown:
            lines += [f"## ({p})", "", f"Not shown: part ({p}) was not run with these options "
                      f"(run `--only {p}` or without --only).", ""]
    if failed:
        lines += ["### Failed runs", "",
                  "Runs that ended with an error (their last checkpoint kept in the work folder; a run that "
                  f"failed while stepping, or spent the budget of {MAX_STEPS} accepted steps, is not run again "
                  "until its folder is deleted):", ""]
        lines += [f"- {r.run.label()}: {failure_reason(r.error)}" for r in sorted(failed, key=lambda r: r.run.label())]
        lines.append("")
    text = "\n".join(lines)
    # Part (e) is written by --only e alone: its section of the earlier document stays.
    kept = old_block(doc, E_BEGIN, E_END)
    if kept is not None:
        text = replace_block(text, E_BEGIN, E_END, kept)
    doc.parent.mkdir(parents=True, exist_ok=True)
    tmp = doc.with_suffix(".md.tmp")
    tmp.write_text(text.replace("\n\n\n", "\n\n"))
    tmp.replace(doc)
    say(f"wrote {doc} and {fig_dir}/ ({wall:.0f} s; {len(failed)} failed runs)")
    return 1 if failed else 0


ADDED_BEGIN = "<!-- added-methods:begin -->"
ADDED_END = "<!-- added-methods:end -->"


def add_methods(added, args, command, bendlab, work, doc, fig_dir, triangles):
    """Runs `added` (and the no-bending references) for parts (b) and (c) and writes them into the
    document's added-methods section, which replaces an earlier one; the rest of the document is
    kept: its figures and tables come from an invocation whose runs need not be in the work folder."""
    METHODS[:] = added
    runs = added_runs(added, args.t_end, triangles)
    say(f"shear study: adding {', '.join(added)}: {len(runs)} runs, {args.jobs} in parallel, work folder {work}")
    start = time.monotonic()
    results = runner(bendlab, work, args.jobs, args.progress_every).run_all(runs)
    wall = time.monotonic() - start
    note_steady_windows(results.values())
    load_series(results, work)
    none_results = {(r.triangles, r.G): res for r, res in results.items() if r.method == "none"}
    rel = os.path.relpath(fig_dir, doc.parent)
    suffix = "_" + "".join(added)
    commit = study_runner.source_commit()
    lines = [ADDED_BEGIN, "", f"## (d) Methods added to the study: {', '.join(added)}", "",
             *study_runner.generated_by(command),
             f"(source commit {commit}, {wall:.0f} s of wall time). The sections above come from the earlier "
             "invocation quoted at the top; its work folder (the time series of every run) is not kept in "
             f"the tree, so {', '.join(added)} cannot be drawn into the same figures without rerunning the "
             "whole study (the command at the top does that, with every registered method). Here each "
             "added method is drawn with the no-bending reference, rerun with the same arguments (its "
             "steady values and steps agree with the tables above to the digits shown when the code is "
             "unchanged), and the tables have the same columns as (b) and (c): compare with the rows above.",
             ""]
    if "S" in added:
        lines += ["Method S moves the nodes with the flow like every other method: the nodes are the "
                  "limit points of the Loop surface, and every force evaluation solves L P = X for the "
                  "control points P, computes the weak-form force density on the limit surface and returns "
                  "F_i = f_i A_mixed,i at the nodes (docs/design.md). The paper ran S with an implicit "
                  "integrator (section 4.3.1); its table 4 has no column for S. Here S uses the same explicit "
                  "Cash-Karp stepper as A-E.", ""]
        if max(triangles) < 1280:
            lines += ["Only the resolutions given by --triangles are here. At 1280 triangles S's explicit "
                      "steps are about 5x smaller than C's at the start (gamma dt 9e-4 against 4.6e-3 at "
                      "gamma t = 0.04, G = 0.05, measured when this section was first generated) and each "
                      "step costs about twice C's, so a run to gamma t = 10 was estimated at about two hours "
                      "on the shared 2-core machine: `--add-methods S --triangles 320,1280` adds them.", ""]
    body = section_b(results, runs, fig_dir, rel, args.t_end, none_results, suffix)
    body += section_c(results, runs, args.t_end)
    body = [l.replace("## (b) All bending methods", "### (b) Added methods").replace(
        "## (c) Average time step", "### (c) Average time step") if l.startswith("## ") else
            ("#" + l if l.startswith("### ") else l) for l in body]
    lines += body + [ADDED_END, ""]
    text = doc.read_text()
    if ADDED_BEGIN in text and ADDED_END in text:
        head, _, rest = text.partition(ADDED_BEGIN)
        _, _, tail = rest.partition(ADDED_END)
        text = head.rstrip("\n") + "\n\n" + "\n".join(lines) + tail.lstrip("\n")
    else:
        text = text.rstrip("\n") + "\n\n" + "\n".join(lines)
    tmp = doc.with_suffix(".md.tmp")
    tmp.write_text(text.replace("\n\n\n", "\n\n"))
    tmp.replace(doc)
    failed = [r for r in results.values() if not r.ok]
    say(f"wrote the added-methods section of {doc} ({wall:.0f} s; {len(failed)} failed runs)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
