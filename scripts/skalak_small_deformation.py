#!/usr/bin/python3
"""Small-deformation check of the membrane laws: prints the markdown table of
docs/results/beyond_paper.md from the run folders of `bendlab shear` (no bending unless named).

    /usr/bin/python3 scripts/skalak_small_deformation.py RUN_DIR...

Each RUN_DIR holds summary.json and timeseries.csv. Theory (Barthes-Biesel & Rallison 1981): an
initially spherical capsule in simple shear takes D = 5/4 Ca (2 + nu_s) / (1 + nu_s) with
Ca = mu gamma R / Gs = 3 G (docs/conventions.md section 2) and nu_s = C / (1 + C) for the Skalak
law, 1/2 for the neo-Hookean law. D is reported twice: the summary's D_steady (dt-weighted mean
over gamma t in [5, 10]) and the dt-weighted mean over gamma t in [0.5, 1.5], the plateau reached
after the initial transient (the membrane relaxes in gamma t ~ 3 G), before the slow drift of the
compressible laws (see the document).
"""
import csv
import json
import math
import os
import sys


def window_mean(rows, a, b, key):
    s = w = 0.0
    for r in rows:
        t, dt = float(r["gamma_t"]), float(r["dt"])
        if a < t <= b:
            s += float(r[key]) * dt
            w += dt
    return s / w if w > 0 else float("nan")


def main():
    dirs = sys.argv[1:]
    if not dirs:
        sys.exit(__doc__)
    print("| law | C | nu_s | G | Ca = 3 G | triangles | bending | D theory | D in [0.5, 1.5] | ratio | "
          "D_steady [5, 10] | ratio | area(10) / area(0) - 1 | theta / pi in [0.5, 1.5] | steps | wall s |")
    print("|" + "---|" * 16)
    for d in dirs:
        with open(os.path.join(d, "summary.json")) as f:
            s = json.load(f)
        with open(os.path.join(d, "timeseries.csv")) as f:
            rows = list(csv.DictReader(f))
        law = s.get("membrane_law", "neo-hookean")
        C = s.get("skalak_c") if law == "skalak" else None
        nu = C / (1 + C) if C is not None else 0.5
        G = s["G"]
        theory = 1.25 * 3 * G * (2 + nu) / (1 + nu)
        early = window_mean(rows, 0.5, 1.5, "D")
        theta = window_mean(rows, 0.5, 1.5, "theta") / math.pi
        area = float(rows[-1]["area"]) / float(rows[0]["area"]) - 1
        bending = "none" if s["method"] == "none" else f"{s['method']}, kB_hat {s['kappa_b_hat']:g}"
        print(f"| {law} | {'' if C is None else f'{C:g}'} | {nu:.4g} | {G:g} | {3 * G:g} | {s['triangles']} | "
              f"{bending} | {theory:.5f} | {early:.5f} | {early / theory:.4f} | {s['D_steady']:.5f} | "
              f"{s['D_steady'] / theory:.4f} | {area:+.2e} | {theta:.4f} | {s['steps']} | {s['wall_seconds']:.0f} |")


if __name__ == "__main__":
    main()
