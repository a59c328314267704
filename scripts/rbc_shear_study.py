#!/usr/bin/python3
"""A red blood cell in shear flow: tumbling, swinging and tank-treading (issue: biconcave,
stress-free reference shape), regenerated from `bendlab shear --shape ...` runs.

    /usr/bin/python3 scripts/rbc_shear_study.py [--only jeffery|sweep|lbm|doc] [--triangles LIST]
                                                [--G LIST] [--t-end T] [--bendlab PATH]
                                                [--work DIR] [--doc FILE] [--list]

Parts (each run one `bendlab shear ... --no-plot` process, run one after the other):
  jeffery  the rigid-body check: an oblate spheroid of aspect ratio c/a = 1/2, stress-free as it
           starts, with a membrane so stiff (G = 1e-3) that it hardly deforms, at 1280 triangles;
           its tumbling period against Jeffery's T = 2 pi (r + 1/r) / gamma, r = 2.
  sweep    the red blood cell (--shape rbc, stress-free biconcave, Skalak membrane with C = 10,
           Method C bending with kappa_b_hat = 0.002) at a sweep of G, BIM, at --triangles
           (default 1280; 5120 for the subset given with --G).
  lbm      one case of the sweep, G = --lbm-G, by the lattice Boltzmann solver at R = 8 lattice units,
           against the BIM run of the same case (tumbling period).
  reference  the sweep's cell at --ref-G with a stress-free oblate spheroid (c/a = 0.9, the cell's
           area) in place of the biconcave reference.
  doc      only regenerates the document from the runs that are done.
All BIM runs use the stiff-stable Runge-Kutta-Chebyshev integrator (--integrator rkc, rtol = atol =
1e-4) and the tree quadrature in mixed precision (--bim-quadrature tree-mixed): Cash-Karp's steps
are bounded by the membrane's stiffness at G = 1e-3 (docs/results/stiff_stepping.md).

Every run's folder lies under --work (default studies/rbc_shear, kept in git: studies/README.md). A
run whose summary.json reaches its t_end is not run again (scripts/study_runner.py); an interrupted
one continues from its checkpoint (--resume). Run the long parts in the background, one at a time:
    OMP_NUM_THREADS=1 nohup /usr/bin/python3 scripts/rbc_shear_study.py --only sweep \\
        > results/rbc_shear_sweep.log 2>&1 &
Writes docs/results/rbc_shear.md and its figures (docs/results/rbc_shear/) from every run that is
done, and says which are missing.
"""
import argparse
import math
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import study_runner  # noqa: E402
from study_runner import ROOT, fmt_g  # noqa: E402

SKALAK_C = 10.0
KAPPA_B_HAT = 0.002
METHOD = "C"
TILT = 45.0
RTOL = ATOL = 1e-4
QUADRATURE = "tree-mixed"
JEFFERY = {"shape": "oblate", "aspect": 0.5, "G": 1e-3, "mesh": "mt1:1280", "t_end": 32.0, "tilt": 0.0}
DEFAULT_G = [0.01, 0.03, 0.04, 0.05, 0.06, 0.08, 0.1, 0.3]

# What the document says of the literature: only what was read (abstracts), with its address.
LITERATURE = [
    ("Abkarian, Faivre & Viallat, Phys. Rev. Lett. 98, 188302 (2007), \"Swinging of red blood cells "
     "under shear flow\" (abstract, https://discovery.researcher.life/article/swinging-of-red-blood-cells-"
     "under-shear-flow/21d3116ae6f43d31a383b83f2876bc82)",
     "experiments: at moderate shear stress (eta gamma about 0.1 Pa) red cells swing, an oscillation of "
     "the inclination superimposed on tank-treading, with the swinging period half the tank-treading "
     "period; on decreasing the stress, an intermittent regime of successive swinging and tumbling in a "
     "narrow range, then pure tumbling at low stress. Their suspending fluid is more viscous than the "
     "cytoplasm (viscosity ratio below 1), and their model is a fluid ellipsoid with a membrane "
     "unstrained in its own shape (shape memory)."),
    ("Vlahovska, Young, Danker & Misbah, \"On the complex dynamics of a red blood cell in simple shear "
     "flow\", arXiv:1007.0444 (abstract, https://ar5iv.labs.arxiv.org/html/1007.0444)",
     "theory for a nearly spherical particle with a visco-elastic incompressible interface: "
     "deformability moves the tumbling-to-swinging transition as the shear rate increases; "
     "intermittency near the transition appears only for a fixed shape and disappears for a "
     "deformable particle."),
    ("Noguchi, \"Swinging and synchronized rotations of red blood cells in simple shear flow\", "
     "arXiv:0905.0180 (abstract, https://ar5iv.labs.arxiv.org/html/0905.0180)",
     "a three-variable model (shape, inclination, membrane phase): tank-treading with swinging at high "
     "shear rate and low internal viscosity, tumbling at low shear rate, and between them synchronized "
     "rotations with integer frequency ratios besides intermittent rotation."),
    ("Minetti, Audemar, Podgorski, Coupier & Viallat, \"Dynamics of a large population of red blood "
     "cells under shear flow\", arXiv:1902.03042 (abstract, https://ar5iv.labs.arxiv.org/html/1902.03042)",
     "experiments on many cells: flipping (tumbling) well described by Jeffery orbits at physiological "
     "suspending viscosity; transitions to and from tank-treading, with hysteresis, in the more "
     "viscous suspending fluid."),
]


def say(msg):
    print(time.strftime("%H:%M:%S"), msg, flush=True)


@dataclass(frozen=True)
class Run(study_runner.StudyRun):
    """A run of the study: its folder's name, its `bendlab shear` options, its end and its title.
    A finished run is one whose summary reaches t_end; a run resumes from any checkpoint of its
    folder, and starts afresh with --overwrite."""
    name: str
    args: tuple
    t_end: float
    title: str
    start_arguments = ("--overwrite",)

    def arguments(self, out):
        return ["shear", *self.args, "--t-end", fmt_g(self.t_end), "--snapshot-every", "1", "--no-plot",
                "--out", str(out)]

    def resume_key(self):
        return {}

    def label(self):
        return self.title


def bim_args(shape, G, mesh, tilt, aspect=None, kappa=KAPPA_B_HAT):
    a = ["--shape", shape, "--tilt", fmt_g(tilt), "--membrane", "skalak", "--skalak-c", fmt_g(SKALAK_C),
         "--G", fmt_g(G), "--mesh", mesh, "--integrator", "rkc", "--rtol", fmt_g(RTOL), "--atol", fmt_g(ATOL),
         "--bim-quadrature", QUADRATURE]
    if aspect is not None:
        a += ["--aspect", fmt_g(aspect)]
    if kappa > 0:
        a += ["--method", METHOD, "--kappa-b-hat", fmt_g(kappa)]
    return a


def jeffery_run():
    j = JEFFERY
    name = f"jeffery_{j['shape']}{fmt_g(j['aspect'])}_G{fmt_g(j['G'])}_{j['mesh'].replace(':', '-')}"
    args = ["--shape", j["shape"], "--aspect", fmt_g(j["aspect"]), "--membrane", "skalak", "--skalak-c",
            fmt_g(SKALAK_C), "--G", fmt_g(j["G"]), "--mesh", j["mesh"], "--integrator", "rkc", "--rtol",
            fmt_g(RTOL), "--atol", fmt_g(ATOL), "--bim-quadrature", QUADRATURE]
    return Run(name, tuple(args), j["t_end"], "Jeffery check")


def sweep_runs(Gs, triangles, t_end):
    runs = []
    for n in triangles:
        for G in Gs:
            runs.append(Run(f"rbc_G{fmt_g(G)}_mt1-{n}", tuple(bim_args("rbc", G, f"mt1:{n}", TILT)), t_end,
                            f"RBC G = {fmt_g(G)}, {n} triangles"))
    return runs


REFERENCE_ASPECT = 0.9


def reference_runs(Gs, t_end):
    """The sweep's cell with a stress-free oblate spheroid of c/a = REFERENCE_ASPECT (of the cell's
    area) in place of the biconcave reference."""
    return [Run(f"rbc_G{fmt_g(G)}_ref-oblate{fmt_g(REFERENCE_ASPECT)}_mt1-1280",
                (*bim_args("rbc", G, "mt1:1280", TILT), "--reference-shape", "oblate", "--reference-aspect",
                 fmt_g(REFERENCE_ASPECT)),
                t_end, f"RBC G = {fmt_g(G)}, oblate reference, 1280 triangles") for G in Gs]


def lbm_run(G, t_end, radius):
    # A box of 6 x 6 x 10 R (the paper's wall distance 10 R, the periodic directions narrower than
    # its 8 R) and Re = 0.5 (particle Reynolds number 0.1): 2.5 times fewer lattice steps than the
    # paper's Re = 0.2, so that the run takes tens of minutes instead of hours.
    args = ["--solver", "lbm", "--radius-lu", fmt_g(radius), "--box", "6,6,10", "--reynolds", "0.5", "--shape", "rbc", "--tilt", fmt_g(TILT), "--membrane",
            "skalak", "--skalak-c", fmt_g(SKALAK_C), "--G", fmt_g(G), "--mesh", "mt1:1280", "--method", METHOD,
            "--kappa-b-hat", fmt_g(KAPPA_B_HAT), "--sample-every", "0.01"]
    return Run(f"lbm_rbc_G{fmt_g(G)}_R{fmt_g(radius)}_mt1-1280", tuple(args), t_end,
               f"RBC G = {fmt_g(G)}, LBM R = {radius}")


def done(run, work):
    """The summary of a finished run, else None."""
    return study_runner.finished(work / run.name, run)


def read_series(folder):
    return study_runner.read_series(folder) or {}


def jeffery_angle(t, r, phi0):
    """Jeffery's orbit, unwrapped: tan phi = r tan(omega (t + t0)), omega = r / (1 + r^2) (gamma = 1),
    phi measured from e_z towards e_x, r the spheroid's c / a."""
    w = r / (1 + r * r)
    s0 = math.atan(math.tan(phi0) / r)
    out = []
    for x in t:
        a = w * x + s0
        out.append(math.atan(r * math.tan(a)) + math.pi * math.floor(a / math.pi + 0.5))
    return out


def tumbling_period(series, begin, end):
    """The tumbling period over [begin, end] as capsule/motion.hpp measures it: twice the mean
    interval from begin to the first crossings of phi(begin) + k pi (linear interpolation)."""
    t, phi = series["gamma_t"], series["axis_angle"]
    pts = [(a, b) for a, b in zip(t, phi) if begin <= a <= end + 1e-9]
    i0 = next(i for i, a in enumerate(t) if a >= begin)
    if i0 > 0 and t[i0] > begin:
        f = (begin - t[i0 - 1]) / (t[i0] - t[i0 - 1])
        pts.insert(0, (begin, phi[i0 - 1] + f * (phi[i0] - phi[i0 - 1])))
    p0 = pts[0][1]
    sign = 1 if pts[-1][1] >= p0 else -1
    times, k = [], 1
    for (ta, pa), (tb, pb) in zip(pts, pts[1:]):
        while sign * (pb - p0) >= k * math.pi:
            level = p0 + sign * k * math.pi
            f = (level - pa) / (pb - pa) if pb != pa else 1.0
            times.append(ta + max(0.0, min(1.0, f)) * (tb - ta))
            k += 1
    return (2 * (times[-1] - begin) / len(times), len(times)) if times else (None, 0)


def num(x, digits=4):
    return "—" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{x:.{digits}g}"


def write_doc(args, work, doc, fig_dir, sweep, jeff, lbm, bim_ref, ref, wall_now):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig_dir.mkdir(parents=True, exist_ok=True)
    rel = os.path.relpath(fig_dir, doc.parent)
    L = ["# A red blood cell in shear flow: tumbling, swinging and tank-treading", "",
         "Generated by `scripts/rbc_shear_study.py` from the runs in `studies/rbc_shear/` (each a "
         "`bendlab shear` run; the commands are listed at the end). Conventions: "
         "docs/conventions.md §2 (capsule shapes; orientation and tank-treading; units R = mu = gamma = 1, "
         "G = mu gamma R / kS, Ca = mu gamma R / Gs = 3 G).", ""]
    # --- Jeffery ---
    L += ["## Rigid-body check: Jeffery's tumbling period", ""]
    s = done(jeff, work)
    if s is None:
        L += ["Not run yet.", ""]
    else:
        r = JEFFERY["aspect"]
        T = 2 * math.pi * (r + 1 / r)
        m = s["motion"]
        Tm = m["tumbling_period"]
        series = read_series(work / jeff.name)
        t, phi = series["gamma_t"], series["axis_angle"]
        exact = jeffery_angle(t, r, phi[0])
        dev = max(abs(a - b) for a, b in zip(phi, exact))
        V0 = s["initial_volume"]
        dv = max(abs(v - V0) / V0 for v in series["volume"])
        a0 = s["capsule_shape"]["mesh_area"]
        da = max(abs(a - a0) / a0 for a in series["area"])
        D0 = (1 - r) / (1 + r)
        dD = max(abs(d - D0) for d in series["D"])
        L += [f"An oblate spheroid, c/a = {fmt_g(r)}, stress-free as it starts (the reference is itself), "
              f"Skalak membrane with C = {fmt_g(SKALAK_C)} at G = {fmt_g(JEFFERY['G'])}, no bending, "
              f"{s['triangles']} triangles, its axis of symmetry starting along e_z (tilt 0), to gamma t = "
              f"{fmt_g(jeff.t_end)}, `--integrator rkc --rtol {fmt_g(RTOL)} --atol {fmt_g(ATOL)} "
              f"--bim-quadrature {QUADRATURE}`.", "",
              "| quantity | value |", "| --- | --- |",
              f"| Jeffery's period T = 2 pi (r + 1/r), r = {fmt_g(1 / r)} | {T:.5f} |",
              f"| measured tumbling period (summary.json, window {m['window'][0]:g}-{m['window'][1]:g}, "
              f"{m['axis_half_turns']} half turns) | {num(Tm, 6)} |",
              f"| relative error | {num(abs(Tm - T) / T if Tm else None, 3)} |",
              f"| motion | {m['motion']} |",
              f"| largest deviation of the axis angle from Jeffery's orbit over the run (rad) | {dev:.3g} |",
              f"| largest deviation of D from the rigid body's {D0:.4f} | {dD:.3g} |",
              f"| largest relative volume change | {dv:.2g} |",
              f"| largest relative area change | {da:.2g} |",
              f"| wall time (timing.json) | {s['wall_seconds']:.0f} s |", ""]
        fig, ax = plt.subplots(figsize=(6, 3.5))
        ax.plot(t, phi, label="bendlab (BIM, 1280 triangles)")
        ax.plot(t, exact, "--", label="Jeffery")
        ax.set_xlabel("gamma t")
        ax.set_ylabel("axis angle (rad)")
        ax.legend()
        fig.tight_layout()
        fig.savefig(fig_dir / "jeffery.png", dpi=110)
        plt.close(fig)
        L += [f"![axis angle of the stiff spheroid against Jeffery's orbit]({rel}/jeffery.png)", ""]
    # --- sweep ---
    L += ["## The red blood cell at a sweep of G", "",
          f"The analytic red blood cell of eq. (15) scaled to the volume 4 pi/3 of the unit sphere (reduced "
          f"volume 0.644; docs/conventions.md), stress-free in its biconcave shape, Skalak membrane with "
          f"C = {fmt_g(SKALAK_C)} (area modulus {fmt_g(1 + 2 * SKALAK_C)} Gs), Method {METHOD} bending with "
          f"kappa_b_hat = {fmt_g(KAPPA_B_HAT)} (kB / (Gs R^2) = {fmt_g(3 * KAPPA_B_HAT)}), viscosity ratio 1 "
          f"(the BIM's single layer), its axis of symmetry starting at {fmt_g(TILT)} degrees from e_z towards "
          f"e_x, to gamma t = {fmt_g(args.t_end)}; motion and periods from the last half of each run "
          f"(capsule/motion.hpp). Angles grow in the sense the flow turns a body.", ""]
    rows = []
    for run in sweep:
        s = done(run, work)
        rows.append((run, s))
    have = [(run, s) for run, s in rows if s is not None]
    missing = [run.label() for run, s in rows if s is None]
    if have:
        L += ["| triangles | G | Ca = 3G | motion | tumbling period | tumbling frequency | tank-treading period | "
              "tank-treading frequency | swinging period | swing amplitude (deg) | D_steady | wall time |",
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
        for run, s in have:
            m = s["motion"]
            tp, tt = m["tumbling_period"], m["tank_treading_period"]
            L.append(f"| {s['triangles']} | {fmt_g(s['G'])} | {fmt_g(3 * s['G'])} | {m['motion']} | {num(tp)} | "
                     f"{num(1 / tp if tp else None)} | {num(tt)} | {num(1 / tt if tt else None)} | "
                     f"{num(m['swinging_period'])} | "
                     f"{num(math.degrees(m['swing_amplitude']) if m['motion'] == 'swinging' else None, 3)} | "
                     f"{num(s['D_steady'])} | {s['wall_seconds']:.0f} s |")
        L.append("")
        for n in sorted({s["triangles"] for _, s in have}):
            fig, ax = plt.subplots(figsize=(6.5, 3.8))
            for run, s in have:
                if s["triangles"] != n:
                    continue
                series = read_series(work / run.name)
                ax.plot(series["gamma_t"], series["axis_angle"], label=f"G = {fmt_g(s['G'])}")
            ax.set_xlabel("gamma t")
            ax.set_ylabel("axis of symmetry angle (rad)")
            ax.set_title(f"RBC, {n} triangles")
            ax.legend()
            fig.tight_layout()
            fig.savefig(fig_dir / f"orientation_{n}.png", dpi=110)
            plt.close(fig)
            L += [f"![orientation angle against time, {n} triangles]({rel}/orientation_{n}.png)", ""]
        fig, ax = plt.subplots(figsize=(6, 3.8))
        for n in sorted({s["triangles"] for _, s in have}):
            sel = [s for _, s in have if s["triangles"] == n]
            g1 = [s["G"] for s in sel if s["motion"]["tumbling_period"]]
            f1 = [1 / s["motion"]["tumbling_period"] for s in sel if s["motion"]["tumbling_period"]]
            g2 = [s["G"] for s in sel if s["motion"]["tank_treading_period"]]
            f2 = [1 / s["motion"]["tank_treading_period"] for s in sel if s["motion"]["tank_treading_period"]]
            ax.plot(g1, f1, "o-", label=f"tumbling, {n}")
            ax.plot(g2, f2, "s--", label=f"tank-treading, {n}")
        ax.set_xscale("log")
        ax.set_xlabel("G")
        ax.set_ylabel("frequency (per gamma t)")
        ax.legend()
        fig.tight_layout()
        fig.savefig(fig_dir / "frequencies.png", dpi=110)
        plt.close(fig)
        L += [f"![tumbling and tank-treading frequencies against G]({rel}/frequencies.png)", ""]
        for n in sorted({s["triangles"] for _, s in have}):
            sel = sorted((s for _, s in have if s["triangles"] == n), key=lambda s: s["G"])
            tumbling = [s["G"] for s in sel if s["motion"]["motion"] == "tumbling"]
            treading = [s["G"] for s in sel if s["motion"]["motion"] in ("swinging",)]
            if tumbling and treading and max(tumbling) < min(treading):
                L.append(f"**Transition at {n} triangles:** tumbling up to G = {fmt_g(max(tumbling))} "
                         f"(Ca = {fmt_g(3 * max(tumbling))}), swinging with tank-treading from G = "
                         f"{fmt_g(min(treading))} (Ca = {fmt_g(3 * min(treading))}); runs in between "
                         f"are {', '.join(s['motion']['motion'] + ' at G = ' + fmt_g(s['G']) for s in sel if max(tumbling) < s['G'] < min(treading)) or 'not made'}.")
            else:
                L.append(f"At {n} triangles: " + ", ".join(f"{s['motion']['motion']} at G = {fmt_g(s['G'])}"
                                                             for s in sel) + ".")
            L.append("")
    if missing:
        L += ["Runs of the sweep not made (5120 triangles only for a subset of G, as time allowed): " + ", ".join(missing) + ".", ""]
    # --- LBM ---
    L += ["## BIM against LBM", ""]
    sb, sl = (done(bim_ref, work) if bim_ref else None), (done(lbm, work) if lbm else None)
    if sb is None or sl is None:
        L += ["Not run yet" + (f" ({lbm.label()} against {bim_ref.label()})." if lbm else "."), ""]
    else:
        begin, end = lbm.t_end / 2, lbm.t_end
        pb, kb = tumbling_period(read_series(work / bim_ref.name), begin, end)
        pl, kl = tumbling_period(read_series(work / lbm.name), begin, end)
        lat = sl["lattice"]
        L += [f"The red blood cell of the sweep at G = {fmt_g(sl['G'])}, 1280 triangles, by the boundary integral "
              f"method (unbounded shear, the sweep's run) and by the lattice Boltzmann method at R = "
              f"{fmt_g(sl['radius_lu'])} lattice units, box {'x'.join(fmt_g(b) for b in sl['box'])} R (walls at "
              f"z = +-{fmt_g(sl['box'][2] / 2)} R), Re = {fmt_g(sl['reynolds'])} (particle Reynolds number "
              f"{lat['particle_reynolds']:.3g}), {lat['steps']} lattice steps. Tumbling periods over the same "
              f"window, gamma t in [{fmt_g(begin)}, {fmt_g(end)}], measured as capsule/motion.hpp measures them "
              f"(twice the mean interval to the crossings of phi(t_b) + k pi):", "",
              "| solver | motion (its own summary) | half turns in the window | tumbling period | wall time |",
              "| --- | --- | --- | --- | --- |",
              f"| BIM | {sb['motion']['motion']} | {kb} | {num(pb)} | {sb['wall_seconds']:.0f} s (to gamma t = "
              f"{fmt_g(sb['t_end'])}) |",
              f"| LBM | {sl['motion']['motion']} | {kl} | {num(pl)} | {sl['wall_seconds']:.0f} s |", "",
              f"Relative difference of the tumbling periods: {num(abs(pb - pl) / pb if pb and pl else None, 3)}.", ""]
    # --- reference shape ---
    L += ["## A spheroidal stress-free shape", ""]
    pairs = [(r, done(r, work), done(sweep_runs([float(r.name.split("_G")[1].split("_")[0])], [1280], args.t_end)[0], work))
             for r in ref]
    if not any(p[1] for p in pairs):
        L += ["Not run yet.", ""]
    else:
        L += [f"The same cell with the elastic law's reference an oblate spheroid of c/a = {fmt_g(REFERENCE_ASPECT)} "
              f"and the cell's area (`--reference-shape oblate --reference-aspect {fmt_g(REFERENCE_ASPECT)}`), "
              f"so that the biconcave cell starts prestressed, against the stress-free biconcave reference:", "",
              "| G | reference | motion | tumbling period | tank-treading period | swinging period | D_steady |",
              "| --- | --- | --- | --- | --- | --- | --- |"]
        for r, s_ref, s_own in pairs:
            for label, s in (("biconcave (initial)", s_own), (f"oblate {fmt_g(REFERENCE_ASPECT)}", s_ref)):
                if s is None:
                    continue
                m = s["motion"]
                L.append(f"| {fmt_g(s['G'])} | {label} | {m['motion']} | {num(m['tumbling_period'])} | "
                         f"{num(m['tank_treading_period'])} | {num(m['swinging_period'])} | {num(s['D_steady'])} |")
        L.append("")
    # --- literature ---
    L += ["## Beside the literature", "",
          "What was read (abstracts only) and what it reports; the setups differ from this study's as said:", ""]
    for source, text in LITERATURE:
        L.append(f"- {source}: {text}")
    L += ["", "Differences of setup: this study's viscosity ratio is 1 (the BIM's single layer; the experiments "
          "suspend cells in a fluid more viscous than the cytoplasm), its membrane has no viscosity, its "
          "stress-free shape is the biconcave one (not a spheroid; `--reference-shape` gives that), its "
          "membrane is the Skalak law with C = 10 (the lipid bilayer's area incompressibility only "
          "approximated), and its cell is at infinite dilution in unbounded shear (LBM: between walls). "
          "No quantitative transition value for viscosity ratio 1 was found in the abstracts read, so the "
          "comparison is qualitative: tumbling at low G, swinging with tank-treading at high G.", ""]
    total = study_runner.total_wall(done(r, work) for r in sweep + [jeff] + ref + ([lbm] if lbm else []))
    L += ["## Run time", "",
          f"The runs shown took {total:.0f} s of wall time together (sum of their timing.json `wall_seconds`, "
          f"one thread each, on a machine shared with other work); this invocation of the script took "
          f"{wall_now():.0f} s.", ""]
    L += ["## Commands", "", "Each run shown, as the script starts it (a run stopped before its end continues "
          "with the same command and `--resume` in place of `--overwrite`):", "", "```"]
    listed = set()
    for run in [jeff] + sweep + ref + ([bim_ref, lbm] if lbm else []):
        if done(run, work) and run.name not in listed:
            listed.add(run.name)
            L.append(" ".join(study_runner.command("bendlab", run, Path("studies/rbc_shear") / run.name)))
    L += ["```", ""]
    doc.parent.mkdir(parents=True, exist_ok=True)
    doc.write_text("\n".join(L))
    say(f"wrote {doc}")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--only", choices=["jeffery", "sweep", "lbm", "reference", "doc"], default=None)
    p.add_argument("--ref-G", default="0.05,0.1", help="G values of the spheroidal-reference runs")
    p.add_argument("--triangles", default="1280")
    p.add_argument("--G", default=",".join(fmt_g(g) for g in DEFAULT_G))
    p.add_argument("--doc-triangles", default="1280,5120", help="triangle counts the document shows")
    p.add_argument("--doc-G", default=None, help="G values the document shows (default: --G)")
    p.add_argument("--t-end", type=float, default=100.0)
    p.add_argument("--lbm-G", type=float, default=0.01)
    p.add_argument("--lbm-radius", type=float, default=8)
    p.add_argument("--lbm-t-end", type=float, default=30.0)
    p.add_argument("--bendlab", default=str(ROOT / "build" / "release" / "bendlab"))
    p.add_argument("--work", default=str(ROOT / "studies" / "rbc_shear"))
    p.add_argument("--doc", default=str(ROOT / "docs" / "results" / "rbc_shear.md"))
    p.add_argument("--list", action="store_true")
    a = p.parse_args()
    start = time.time()
    work, doc = Path(a.work), Path(a.doc)
    work.mkdir(parents=True, exist_ok=True)
    Gs = [float(x) for x in a.G.split(",")]
    tri = [int(x) for x in a.triangles.split(",")]
    jeff = jeffery_run()
    sweep = sweep_runs(Gs, tri, a.t_end)
    lbm = lbm_run(a.lbm_G, a.lbm_t_end, a.lbm_radius)
    bim_ref = sweep_runs([a.lbm_G], [1280], a.t_end)[0]
    ref = reference_runs([float(x) for x in a.ref_G.split(",")], a.t_end)
    todo = {"jeffery": [jeff], "sweep": sweep, "lbm": [bim_ref, lbm], "reference": ref, "doc": [],
            None: [jeff] + sweep}[a.only]
    if a.list:
        return study_runner.Runner(a.bendlab, work).list(todo, f"part {a.only or 'jeffery and sweep'}")
    if todo:
        # One after the other; the document is written when every run has finished.
        results = study_runner.Runner(study_runner.bendlab_binary(a.bendlab), work).run_all(todo)
        if not all(r.ok for r in results.values()):
            return 1
    doc_G = [float(x) for x in (a.doc_G or a.G).split(",")]
    doc_sweep = [r for n in (int(x) for x in a.doc_triangles.split(",")) for r in sweep_runs(doc_G, [n], a.t_end)]
    write_doc(a, work, doc, doc.parent / "rbc_shear", doc_sweep, jeff, lbm, bim_ref, ref, lambda: time.time() - start)


if __name__ == "__main__":
    sys.exit(main())
