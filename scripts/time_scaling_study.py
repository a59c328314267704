#!/usr/bin/python3
"""Time scaling of a flow run: how far the plasma's density may be raised before the tube's results move.

    /usr/bin/python3 scripts/time_scaling_study.py [--scales LIST] [--jobs N] [--bendlab PATH]
                                                   [--work DIR] [--doc FILE] [--list] [--doc-only]

In Stokes flow the plasma's density only sets the Reynolds number: S times the density makes dt S
times longer at the same tau and dx (a run takes S times fewer steps) and Re S times larger. This
study runs the tube study's reference case (scripts/tube_study.py: D = 10 um, 20 um periodic,
dx = 0.5 um, tau = 1.82, pseudo-shear rate 100 1/s, H_T 0.3, seed 1, Method C with its net force
kept, mt1:1280, to t = 0.1 s) with `--plasma-density` S times 1025 kg/m^3 for each S of --scales,
and compares eta_app, H_D and the cell-free layer with the unscaled run of the tube study
(studies/tube/D10_H0.3_C_mt11280), in standard errors (the two runs' combined). The largest S
within 2 standard errors on all three sets the bound on Re that `bendlab flow --time-scale`
enforces (lbm::kMaxScaledReynolds). Nothing is tuned.

Runs lie under --work (default studies/time_scaling); a finished run is not run again
(scripts/study_runner.py). Writes docs/results/time_scaling.md.
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

DENSITY = 1025.0
SCALES = [10.0, 20.0, 50.0, 100.0]
REFERENCE = ROOT / "studies" / "tube" / "D10_H0.3_C_mt11280"
MEASURES = [("apparent_viscosity", "eta_app / eta"), ("discharge_hematocrit", "H_D"),
            ("cell_free_layer_um", "cell-free layer (um)")]


@dataclass(frozen=True)
class ScaledRun(study_runner.StudyRun):
    scale: float
    t_end: float = 0.1
    start_arguments = ("--overwrite",)

    @property
    def name(self):
        return f"D10_H0.3_C_mt11280_S{fmt_g(self.scale)}"

    def arguments(self, out):
        return study_runner.tube_reference_arguments(["--plasma-density", fmt_g(DENSITY * self.scale)], self.t_end,
                                                     out)

    def key(self):
        return {"t_end": self.t_end, **study_runner.TUBE_REFERENCE_KEY, "plasma_density": DENSITY * self.scale}

    def label(self):
        return f"D = 10 um, H_T 0.3, Method C, density x {fmt_g(self.scale)}"


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scales", default=",".join(fmt_g(s) for s in SCALES), help="density factors S, comma-separated")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--bendlab", default="build/release/bendlab")
    ap.add_argument("--work", default=str(ROOT / "studies" / "time_scaling"))
    ap.add_argument("--doc", default=str(ROOT / "docs" / "results" / "time_scaling.md"))
    ap.add_argument("--list", action="store_true", help="print the runs and their state; run nothing")
    ap.add_argument("--doc-only", action="store_true", help="write the document from the finished runs; run nothing")
    args = ap.parse_args(argv[1:])
    scales = study_runner.number_list(args.scales, "--scales", lambda s: s >= 1,
                                      "factor must be a finite number >= 1")
    runs = [ScaledRun(s) for s in scales]
    work = Path(args.work)
    bendlab = study_runner.bendlab_binary(args.bendlab) if not args.doc_only else None
    runner = study_runner.Runner(bendlab, work, jobs=args.jobs)
    if args.list:
        return runner.list(runs, "time scaling")
    if not args.doc_only:
        runner.run_all(runs)

    reference = study_runner.read_summary(REFERENCE)
    if reference is None:
        raise SystemExit(f"error: the unscaled run {REFERENCE} has no summary.json (run scripts/tube_study.py)")
    L = ["# Time scaling: the plasma's density against the tube's results", ""]
    L += study_runner.generated_by(study_runner.invocation(Path(__file__), argv[1:]))
    L += [f"from {study_runner.source_commit() or 'an unknown commit'} on {study_runner.machine()}, "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}.", "",
          "The tube study's reference case (D = 10 um, H_T 0.3, Method C, mt1:1280, dx = 0.5 um, tau = 1.82, "
          "to t = 0.1 s) with the plasma's density S times 1025 kg/m^3: dt and Re grow S-fold, the Stokes "
          "flow's results should not move. Each measure is the steady window's mean ± its standard error "
          "(docs/conventions.md §6); in brackets the difference from S = 1 in the two runs' combined standard "
          "errors.", "",
          "| S | Re | lattice steps | wall time | " + " | ".join(label for _, label in MEASURES) + " |",
          "|---|---|---|---|" + "---|" * len(MEASURES)]

    def row(label, s, ref):
        cells = []
        for key, _ in MEASURES:
            m = s[key]
            text = f"{m['mean']:.4g} ± {m['standard_error']:.2g}"
            if ref is not None:
                z, _ = study_runner.standard_errors_apart(m, ref[key])
                text += f" ({z:+.1f})"
            cells.append(text)
        steps = round(s["t_end"] / s["dt_s"])
        wall_text = f"{s['wall_seconds']:.0f} s" if math.isfinite(s.get("wall_seconds", math.nan)) else ""
        return f"| {label} | {s['reynolds']:.3g} | {steps} | {wall_text} | " + " | ".join(cells) + " |"

    L.append(row("1", reference, None))
    largest_ok = 1.0
    failed_at = None
    for r in runs:
        s = study_runner.read_summary(work / r.name)
        if s is None:
            L.append(f"| {fmt_g(r.scale)} | not run yet | | | " + " | " * (len(MEASURES) - 1) + " |")
            continue
        L.append(row(fmt_g(r.scale), s, reference))
        ok = all(abs(study_runner.standard_errors_apart(s[key], reference[key])[0]) <= 2 for key, _ in MEASURES)
        if ok and failed_at is None:
            largest_ok = max(largest_ok, r.scale)
        elif not ok and failed_at is None:
            failed_at = r.scale
    L += ["", f"The largest S within 2 standard errors of S = 1 on all three measures, with every smaller S of the "
              f"list also within: **{fmt_g(largest_ok)}** (Re = {reference['reynolds'] * largest_ok:.3g})"
              + (f"; S = {fmt_g(failed_at)} is the first outside." if failed_at else ".")
              + " `bendlab flow --time-scale` refuses a Reynolds number above lbm::kMaxScaledReynolds, set from "
                "this table.",
          "",
          f"Beyond S = {fmt_g(0.1 / reference['mach'])} this case's peak lattice velocity passes the Mach bound "
          f"(Ma = {reference['mach']:.3g} S, refused above 0.1), which the flow command enforces whatever the "
          "time scale.", ""]
    Path(args.doc).write_text("\n".join(L) + "\n")
    print(f"time_scaling_study: wrote {args.doc}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
