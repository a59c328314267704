#!/usr/bin/python3
"""Plots of the static RBC study (paper section 3) from the output folder of `bendlab rbc`.

    /usr/bin/python3 scripts/plot_rbc.py DIR

Reads DIR/errors.csv and DIR/values_<family>_<triangles>.csv; writes into DIR
  errors_<quantity>_<family>.png   maximal and average error against 1/h, with guide slopes
                                   h^1, h^2, h^-1, h^-2 (figures 3, 5, 7, 10; MT2: B.19-B.23);
                                   the inhomogeneous mesh of the family is the star with a tick,
                                   the open markers are the octahedron meshes (MT1 plots) or the
                                   MT1 meshes the irregular family jitters (irregular plots).
  values_<quantity>_<family>_<N>.png  numerical values against the polar angle theta, one panel
                                   per method, with the exact curve (figures 4, 6, 8), at the
                                   finest mesh up to 5120 triangles.
"""
import csv
import math
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

QUANTITIES = {
    "n": "normal vector $\\varepsilon_n$",
    "H": "mean curvature $\\varepsilon_H$",
    "K": "Gaussian curvature $\\varepsilon_K$",
    "lapH": "$\\Delta_S H$: $\\varepsilon_{\\Delta_S H}$",
    "f": "force density $\\varepsilon_f$",
}
VALUE_COLUMNS = {"H": ("H", "H_exact", "$H$"), "lapH": ("lapH", "lapH_exact", "$\\Delta_S H$"),
                 "f": ("f_abs", "f_abs_exact", "$|\\mathbf{f}|$")}
PLOTTED_FAMILIES = ("mt1", "mt2", "irregular")
# The family drawn with open markers beside a family, and how the plot's title names it.
COMPANION = {"mt1": ("octa", "octahedron meshes"), "irregular": ("mt1", "the MT1 meshes before the jitter")}
MARKERS = {"A": "o", "B": "s", "C": "^", "D": "v", "E": "D", "ED": "P", "S": "X", "J": "h", "M": "d"}


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def fnum(s):
    try:
        return float(s)
    except ValueError:
        return math.nan


def guide_lines(ax, inv_h, errors):
    """Black lines with slopes 1, 2, -1, -2 in log-log (error ~ h^p), anchored at the data."""
    x = np.array(sorted(inv_h))
    e = np.array([v for v in errors if v > 0 and math.isfinite(v)])
    if len(x) < 2 or len(e) == 0:
        return
    x0 = math.sqrt(x[0] * x[-1])
    y0 = math.exp(np.mean(np.log(e)))
    xs = np.array([x[0], x[-1]])
    for p, style in ((1, "-"), (2, "--"), (-1, "-."), (-2, ":")):
        ax.plot(xs, y0 * (xs / x0) ** (-p), "k" + style, lw=0.8, label=f"$h^{{{p}}}$")


def plot_errors(rows, out_dir):
    by = defaultdict(list)
    for r in rows:
        by[(r["family"], r["quantity"], r["method"])].append(r)
    families = [f for f in PLOTTED_FAMILIES if any(r["family"] == f for r in rows)]
    methods = list(dict.fromkeys(r["method"] for r in rows))
    written = []
    for fam in families:
        for q in QUANTITIES:
            if not any((fam, q, m) in by for m in methods):
                continue
            fig, axes = plt.subplots(1, 2, figsize=(11, 4.3))
            for ax, col, title in ((axes[0], "max_error", "maximal error"), (axes[1], "avg_error", "average error")):
                all_x, all_e = [], []
                for i, m in enumerate(methods):
                    color = f"C{i}"
                    pts = sorted(by.get((fam, q, m), []), key=lambda r: -fnum(r["h"]))
                    if not pts:
                        continue
                    x = [1 / fnum(r["h"]) for r in pts]
                    e = [fnum(r[col]) for r in pts]
                    all_x += x
                    all_e += e
                    ax.plot(x, e, "-", marker=MARKERS.get(m, "o"), color=color, label=m)
                    if fam in COMPANION:
                        other = by.get((COMPANION[fam][0], q, m), [])
                        if other:
                            ax.plot([1 / fnum(r["h"]) for r in other], [fnum(r[col]) for r in other],
                                    linestyle="none", marker=MARKERS.get(m, "o"), mfc="none", color=color)
                    for r in by.get(("rivara-" + fam, q, m), []):
                        xi, ei = 1 / fnum(r["h"]), fnum(r[col])
                        ax.plot([xi], [ei], marker="*", ms=12, color=color, mec="k", linestyle="none")
                        ax.annotate("", xy=(xi, ei * 1.25), xytext=(xi, ei * 2.2),
                                    arrowprops=dict(arrowstyle="-", color=color, lw=1.5))
                if all_x:
                    guide_lines(ax, all_x, all_e)
                ax.set_xscale("log")
                ax.set_yscale("log")
                ax.set_xlabel("$1/h$")
                ax.set_title(f"{QUANTITIES[q]}, {title}")
                ax.grid(True, which="both", alpha=0.3)
            axes[1].legend(fontsize=7, ncol=2)
            notes = (["stars: inhomogeneous mesh (Rivara)"] if fam != "irregular" else [])
            if fam in COMPANION and any((COMPANION[fam][0], q, m) in by for m in methods):
                notes.append("open markers: " + COMPANION[fam][1])
            note = ", ".join(notes) or "irregular meshes"
            fam_title = "irregular (MT1 jittered)" if fam == "irregular" else fam.upper()
            fig.suptitle(f"RBC, {fam_title} meshes ({note})", fontsize=10)
            fig.tight_layout()
            name = f"errors_{q}_{fam}.png"
            fig.savefig(os.path.join(out_dir, name), dpi=110)
            plt.close(fig)
            written.append(name)
    return written


def plot_values(out_dir):
    files = defaultdict(dict)
    for name in os.listdir(out_dir):
        if name.startswith("values_") and name.endswith(".csv"):
            fam, tri = name[len("values_"):-len(".csv")].rsplit("_", 1)
            files[fam][int(tri)] = name
    written = []
    for fam in PLOTTED_FAMILIES:
        sizes = [n for n in files.get(fam, {}) if n <= 5120]
        if not sizes:
            continue
        n_t = max(sizes)
        rows = read_rows(os.path.join(out_dir, files[fam][n_t]))
        methods = list(dict.fromkeys(r["method"] for r in rows))
        for q, (col, exact, label) in VALUE_COLUMNS.items():
            shown = [m for m in methods
                     if any(math.isfinite(fnum(r[col])) for r in rows if r["method"] == m)]
            if not shown:
                continue
            ncol = min(3, len(shown))
            nrow = math.ceil(len(shown) / ncol)
            fig, axes = plt.subplots(nrow, ncol, figsize=(4.2 * ncol, 3.3 * nrow), squeeze=False, sharex=True)
            first = [r for r in rows if r["method"] == shown[0]]
            theta_exact = np.array([fnum(r["theta"]) for r in first])
            order = np.argsort(theta_exact)
            exact_vals = np.array([fnum(r[exact]) for r in first])[order]
            for k, m in enumerate(shown):
                ax = axes[k // ncol][k % ncol]
                sel = [r for r in rows if r["method"] == m]
                ax.plot([fnum(r["theta"]) for r in sel], [fnum(r[col]) for r in sel], ".", ms=2.5,
                        color=f"C{methods.index(m)}", label=f"Method {m}")
                ax.plot(theta_exact[order], exact_vals, "k--", lw=1, label="exact")
                lo, hi = np.nanmin(exact_vals), np.nanmax(exact_vals)
                pad = 0.5 * (hi - lo) + 1e-12
                # Keep the exact curve readable; outliers leave the frame. |f| is not negative.
                ax.set_ylim(max(lo - pad, 0.0) if q == "f" else lo - pad, hi + pad)
                ax.set_title(f"Method {m}", fontsize=9)
                ax.set_xlabel("$\\theta$")
                ax.set_ylabel(label)
                ax.set_xticks([0, math.pi / 4, math.pi / 2, 3 * math.pi / 4, math.pi])
                ax.set_xticklabels(["0", "π/4", "π/2", "3π/4", "π"])
                ax.grid(True, alpha=0.3)
            for k in range(len(shown), nrow * ncol):
                axes[k // ncol][k % ncol].axis("off")
            fig.suptitle(f"{label} on the RBC, {fam.upper()} {n_t} triangles (dashed: exact)", fontsize=10)
            fig.tight_layout()
            name = f"values_{q}_{fam}_{n_t}.png"
            fig.savefig(os.path.join(out_dir, name), dpi=110)
            plt.close(fig)
            written.append(name)
    return written


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: plot_rbc.py DIR (the --out folder of `bendlab rbc`)")
    out_dir = sys.argv[1]
    errors = os.path.join(out_dir, "errors.csv")
    if not os.path.isfile(errors):
        sys.exit(f"plot_rbc.py: {errors} not found")
    written = plot_errors(read_rows(errors), out_dir) + plot_values(out_dir)
    print(f"plot_rbc.py: wrote {len(written)} plots to {out_dir}", file=sys.stderr)


if __name__ == "__main__":
    main()
