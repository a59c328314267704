#!/usr/bin/python3
"""The plot of a `bendlab stretch` run: the axial and transverse diameters of the cell against the
stretching force, beside the optical-tweezers measurements of Mills et al. (2004) with their
scatter (mills2004_stretch.csv, beside this script). Started by `bendlab stretch` with an argument
vector; writes RUN_FOLDER/stretch.png.

    /usr/bin/python3 scripts/plot_stretch.py RUN_FOLDER

The study (stretch_study.py) imports read_mills() and draw_mills() from here.
"""
import csv
import json
import sys
from pathlib import Path

MILLS = Path(__file__).resolve().parent / "mills2004_stretch.csv"


def read_mills(path=MILLS):
    """column -> list of floats of the experimental data (force_pN, axial_um, axial_low_um, ...)."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def read_run(folder):
    """stretch.csv of a run folder: column -> list of floats."""
    with open(Path(folder) / "stretch.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]} if rows else {}


def draw_mills(ax, mills):
    """The experiment: means as markers, the scatter as bars and a shaded band."""
    f = mills["force_pN"]
    for name, colour in (("axial", "0.35"), ("transverse", "0.35")):
        mean, lo, hi = mills[f"{name}_um"], mills[f"{name}_low_um"], mills[f"{name}_high_um"]
        ax.fill_between(f, lo, hi, color="0.85", zorder=0)
        ax.errorbar(f, mean, yerr=[[m - l for m, l in zip(mean, lo)], [h - m for m, h in zip(mean, hi)]],
                    fmt="s", ms=4, color=colour, mfc="white", capsize=2, lw=0.8, zorder=3,
                    label="Mills et al. 2004" if name == "axial" else None)


def main(argv):
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    folder = Path(argv[1])
    run = read_run(folder)
    try:
        summary = json.loads((folder / "summary.json").read_text())
    except (OSError, ValueError):
        summary = {}
    fig, ax = plt.subplots(figsize=(6, 4.5))
    draw_mills(ax, read_mills())
    if run:
        ax.plot(run["force_pN"], run["axial_diameter_um"], "o-", color="C0", label="axial (bendlab)")
        ax.plot(run["force_pN"], run["transverse_diameter_um"], "o-", color="C3", label="transverse (bendlab)")
    title = "optical-tweezers stretching"
    if summary:
        title += (f": {summary.get('elastic_law')} G_s = {summary.get('shear_modulus', 0) * 1e6:g} uN/m, "
                  f"method {summary.get('method')}, {summary.get('mesh')}")
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("force F (pN)")
    ax.set_ylabel("diameter (um)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="center right")
    fig.tight_layout()
    fig.savefig(folder / "stretch.png", dpi=120)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
