#!/usr/bin/python3
"""Membrane forces every N steps: what HemoCell's time-scale separation costs in the tube's results.

    /usr/bin/python3 scripts/membrane_every_study.py [--every LIST] [--jobs N] [--bendlab PATH]
                                                     [--work DIR] [--doc FILE] [--list] [--doc-only]

`bendlab flow --membrane-every N` computes the cells' membrane forces every N lattice steps and
holds them in between, as HemoCell does (its stepMaterialEvery, 20 by default). This study runs the
tube study's reference case (D = 10 um, 20 um periodic, dx = 0.5 um, tau = 1.82, pseudo-shear rate
100 1/s, H_T 0.3, seed 1, Method C with its net force kept, mt1:1280, to t = 0.1 s) at time scale 10
(docs/results/time_scaling.md) for each N of --every (1, 5, 10 and 20 by default) and compares eta_app,
H_D and the cell-free layer with N = 1 in standard errors (the two runs' combined), beside each run's
wall time. Nothing is tuned.

Runs lie under --work (default studies/membrane_every); a finished run is not run again
(scripts/study_runner.py). Writes docs/results/membrane_every.md, which
docs/results/suspension_performance.md includes.
"""
import argparse
import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import study_runner  # noqa: E402
from study_runner import ROOT, fmt_g  # noqa: E402

EVERY = [1, 5, 10, 20]
TIME_SCALE = 10.0
MEASURES = [("apparent_viscosity", "eta_app / eta"), ("discharge_hematocrit", "H_D"),
            ("cell_free_layer_um", "cell-free layer (um)")]


@dataclass(frozen=True)
class HeldRun(study_runner.StudyRun):
    every: int
    t_end: float = 0.1
    start_arguments = ("--overwrite",)

    @property
    def name(self):
        return f"D10_H0.3_C_mt11280_S{fmt_g(TIME_SCALE)}_N{self.every}"

    def arguments(self, out):
        return study_runner.tube_reference_arguments(
            ["--time-scale", fmt_g(TIME_SCALE), "--membrane-every", str(self.every)], self.t_end, out)

    def key(self):
        return {"t_end": self.t_end, **study_runner.TUBE_REFERENCE_KEY, "time_scale": TIME_SCALE,
                "membrane_every": self.every}

    def assumed(self):
        # The identity leaves membrane_every out when it is 1.
        return {"membrane_every": 1}

    def label(self):
        return f"D = 10 um, H_T 0.3, Method C, time scale {fmt_g(TIME_SCALE)}, membrane forces every {self.every}"


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--every", default=",".join(str(n) for n in EVERY),
                    help="the N of --membrane-every, comma-separated (1 is the reference and always run)")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--bendlab", default="build/release/bendlab")
    ap.add_argument("--work", default=str(ROOT / "studies" / "membrane_every"))
    ap.add_argument("--doc", default=str(ROOT / "docs" / "results" / "membrane_every.md"))
    ap.add_argument("--list", action="store_true", help="print the runs and their state; run nothing")
    ap.add_argument("--doc-only", action="store_true", help="write the document from the finished runs; run nothing")
    args = ap.parse_args(argv[1:])
    every = study_runner.number_list(args.every, "--every", lambda n: n >= 1 and n == int(n),
                                     "must be a whole number >= 1")
    every = sorted({1} | {int(n) for n in every})
    runs = [HeldRun(n) for n in every]
    work = Path(args.work)
    bendlab = study_runner.bendlab_binary(args.bendlab) if not args.doc_only else None
    runner = study_runner.Runner(bendlab, work, jobs=args.jobs)
    if args.list:
        return runner.list(runs, "membrane every N")
    if not args.doc_only:
        runner.run_all(runs)

    summaries = {r.every: study_runner.read_summary(work / r.name) for r in runs}
    reference = summaries[1]
    L = ["# Membrane forces every N steps against every step", ""]
    L += study_runner.generated_by(study_runner.invocation(Path(__file__), argv[1:]))
    L += [f"from {study_runner.source_commit() or 'an unknown commit'} on {study_runner.machine()}, "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}.", "",
          f"The tube study's reference case (D = 10 um, H_T 0.3, Method C, mt1:1280, dx = 0.5 um, tau = 1.82, "
          f"to t = 0.1 s) at time scale {fmt_g(TIME_SCALE)}, with the membrane forces computed every N lattice "
          "steps and held in between (`bendlab flow --membrane-every N`; HemoCell's default is 20). Each measure "
          "is the steady window's mean ± its standard error (docs/conventions.md §6); in brackets the difference "
          "from N = 1 in the two runs' combined standard errors. The wall time is the run's own (summary.json), "
          "on the threads it was given, on a shared machine.", "",
          "| N | lattice steps | wall time | " + " | ".join(label for _, label in MEASURES) + " |",
          "|---|---|---|" + "---|" * len(MEASURES)]
    failures = {}
    for r in runs:
        s = summaries[r.every]
        if s is None:
            state, info = runner.state(r)
            if state == "failed":
                failures[r.every] = info
                text = "failed: " + info.replace("bendlab: error: ", "").split("; the last checkpoint")[0]
            else:
                text = "not run yet"
            L.append(f"| {r.every} | {text} | | " + " | " * (len(MEASURES) - 1) + " |")
            continue
        cells = []
        for key, _ in MEASURES:
            m = s[key]
            text = f"{m['mean']:.4g} ± {m['standard_error']:.2g}"
            if r.every != 1 and reference is not None:
                z, _ = study_runner.standard_errors_apart(m, reference[key])
                text += f" ({z:+.1f})"
            cells.append(text)
        steps = round(s["t_end"] / s["dt_s"])
        wall = s.get("wall_seconds", math.nan)
        wall_text = f"{wall:.0f} s" if math.isfinite(wall) else ""
        L.append(f"| {r.every} | {steps} | {wall_text} | " + " | ".join(cells) + " |")
    if reference is not None:
        outside = [r.every for r in runs if r.every != 1 and summaries[r.every] is not None
                   and any(abs(study_runner.standard_errors_apart(summaries[r.every][k], reference[k])[0]) > 2 for k, _ in MEASURES)]
        inside = [r.every for r in runs if r.every != 1 and summaries[r.every] is not None and r.every not in outside]
        L += ["", "Within 2 standard errors of N = 1 on all three measures: "
              + (", ".join(f"N = {n}" for n in inside) if inside else "none")
              + ("; outside: " + ", ".join(f"N = {n}" for n in outside) if outside else "") + "."]
        if failures:
            dt = reference["dt_s"]
            held = [r.every for r in runs if summaries[r.every] is not None]
            L += ["", "Held time N dt of the runs that finished: "
                  + ", ".join(f"{n * dt:.2g} s (N = {n})" for n in held)
                  + "; of those that failed: " + ", ".join(f"{n * dt:.2g} s (N = {n})" for n in failures)
                  + f". Time scaling makes dt {fmt_g(TIME_SCALE)} times longer, so the same N holds the forces "
                    f"{fmt_g(TIME_SCALE)} times longer. HemoCell's default, 20 steps of its 1e-7 s (2e-6 s), is "
                    f"N = {max(1, round(2e-6 / dt))} here."]
    L.append("")
    Path(args.doc).write_text("\n".join(L) + "\n")
    print(f"membrane_every_study: wrote {args.doc}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
