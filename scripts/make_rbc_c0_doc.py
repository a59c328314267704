#!/usr/bin/python3
"""Writes docs/results/rbc_c0.md from studies of `bendlab rbc --c0 X` (spontaneous curvature).

    /usr/bin/python3 scripts/make_rbc_c0_doc.py BASELINE_JSON STUDY_DIR [STUDY_DIR ...] \
        [--results DIR] [--command "..."]

BASELINE_JSON is the errors.json of the study without c0 (docs/results/rbc/errors.json, the same
MT1 and MT2 meshes); each STUDY_DIR is the --out folder of one `bendlab rbc --c0 X` (after its plots
were drawn). DIR (default docs/results of this repository) receives rbc_c0.md and, in rbc_c0/c0_X/,
each study's small tables (errors.csv, errors.json, timings.csv, table2.md) and its plots of f.

With c0 only the force density changes (n, H, K and Lap H do not depend on c0), so the page
compares the convergence of f: for every family, measure and method, the symbol and fitted slope
of table 2 (docs/results/rbc.md: ● to zero, ○ to a systematic error, ■ diverges) and the error on
the finest mesh, at c0 = 0 and at each c0 of the studies.
"""
import json
import os
import shutil
import sys

FAMILIES = ["mt1", "mt2"]
MEASURES = [("max", "maximal"), ("avg", "average")]
COPIED = ["errors.csv", "errors.json", "timings.csv", "table2.md"]


def load(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def rate(study, family, measure, method, quantity="f"):
    for r in study["rates"]:
        if (r["family"], r["measure"], r["method"], r["quantity"]) == (family, measure, method, quantity):
            return r
    return None


def finest(study, family, method, measure, quantity="f"):
    rows = [r for r in study["rows"]
            if r["family"] == family and r["method"] == method and r["quantity"] == quantity]
    if not rows:
        return None
    r = max(rows, key=lambda r: r["triangles"])
    return r["triangles"], r["max_error" if measure == "max" else "avg_error"]


def cell(study, family, measure, method):
    r = rate(study, family, measure, method)
    if r is None:
        return "n/a"
    f = finest(study, family, method, measure)
    return f"{r['symbol']} ({r['slope_tail']:+.1f}), {f[1]:.2g}"


def label(c0):
    return f"c0 R = {c0:g}"


def main(argv):
    args = list(argv)
    results = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "docs", "results")
    command = ""
    if "--results" in args:
        i = args.index("--results")
        results = args[i + 1]
        del args[i:i + 2]
    if "--command" in args:
        i = args.index("--command")
        command = args[i + 1]
        del args[i:i + 2]
    if len(args) < 2:
        sys.exit(__doc__)
    baseline = load(args[0])
    studies = []
    for d in args[1:]:
        s = load(os.path.join(d, "errors.json"))
        if "c0" not in s:
            sys.exit(f"{d}: not a study with --c0 (no c0 in errors.json)")
        studies.append((d, s))
    methods = [m for m in studies[0][1]["options"]["methods"]]
    for d, s in studies:
        if s["options"]["methods"] != methods:
            sys.exit(f"{d}: other methods than {studies[0][0]}")
    out_dir = os.path.join(results, "rbc_c0")
    os.makedirs(out_dir, exist_ok=True)
    folders = {}
    for d, s in studies:
        name = f"c0_{s['c0']:g}".replace("-", "m").replace(".", "p")
        folders[s["c0"]] = name
        dest = os.path.join(out_dir, name)
        os.makedirs(dest, exist_ok=True)
        for f in COPIED:
            shutil.copy(os.path.join(d, f), os.path.join(dest, f))
        for f in sorted(os.listdir(d)):
            if f.endswith(".png") and ("_f_" in f):
                shutil.copy(os.path.join(d, f), os.path.join(dest, f))

    lines = ["# The static red blood cell with a spontaneous curvature", "",
             "Generated; do not edit. Regenerate with", "", "```sh", command or "(see scripts/make_rbc_c0_doc.py)",
             "```", "",
             "`bendlab rbc --c0 X` compares every method's force density with the exact force density of the RBC "
             "of eq. (15) with the energy `E = 2 kB ∫ (H − c0)² dA`, i.e. "
             "`f = 2 kB [Lap H + 2 (H − c0)(H² + c0 H − K)] n` from the exact H, K and Lap H "
             "(docs/conventions.md §5). Each method takes c0 in the form natural to it (§5): C, D, E, ED and M "
             "put their own H, K, Lap H and n into that force law; B, J and S differentiate their discrete "
             "energies with c0; A refuses c0 and is left out. n, H, K and Lap H do not depend on c0, so only f "
             "is compared here; the tables of those quantities are those of docs/results/rbc.md.", "",
             "Cells: the symbol of table 2 (● converges to zero, ○ to a systematic error, ■ diverges), the "
             "least-squares slope of log(error) against log(1/h) over the 3 finest meshes (docs/results/rbc.md), "
             "and the error of f on the finest mesh (eq. (17), relative to max|f| of the exact field, which "
             "depends on c0: " + ", ".join(
                 [f"{baseline['maxima']['f']:.6g} at c0 = 0"] +
                 [f"{s['maxima']['f']:.6g} at {label(s['c0'])}" for _, s in studies]) + ").", ""]
    c0s = [0.0] + [s["c0"] for _, s in studies]
    all_studies = [baseline] + [s for _, s in studies]
    kept, changed, moved = [], [], []
    for fam in FAMILIES:
        for measure, word in MEASURES:
            lines += [f"## {fam.upper()}, {word} error of f", "",
                      "| method | " + " | ".join(label(c) for c in c0s) + " | behaviour kept |",
                      "|---|" + "---|" * (len(c0s) + 1)]
            for m in methods:
                cells = [cell(s, fam, measure, m) for s in all_studies]
                symbols = [(rate(s, fam, measure, m) or {}).get("symbol") for s in all_studies]
                same = len(set(symbols)) == 1 and symbols[0] is not None
                (kept if same else changed).append(f"{m} ({fam.upper()}, {measure})")
                slopes = [(rate(s, fam, measure, m) or {}).get("slope_tail") for s in all_studies]
                if None not in slopes and max(slopes) - min(slopes) > 0.3:
                    moved.append(f"{m} ({fam.upper()}, {measure}: slope " +
                                 " / ".join(f"{x:+.1f}" for x in slopes) + ")")
                lines.append(f"| {m} | " + " | ".join(cells) + f" | {'yes' if same else '**no**'} |")
            lines.append("")
    lines += ["## Which methods keep their convergence behaviour", "",
              f"The symbol is the same at every c0 in {len(kept)} of {len(kept) + len(changed)} cells"
              + (" (every method, family and measure)." if not changed else "; it changes in: " +
                 ", ".join(changed) + "."), "",
              "Slopes that move by more than 0.3 between the c0 values: " +
              (", ".join(moved) if moved else "none") + ".", "",
              "A symbol may change where a slope lies near a threshold of table 2 (−0.5 for ●, +0.25 for ■); the "
              "slopes show how far the behaviour moved. The c0 part of the force law, "
              "2 kB [2 (H − c0)(H² + c0 H − K) − 2 H (H² − K)] = 4 kB c0 (K − c0 H), is algebraic in H and K, "
              "so for the variational methods it adds c0-weighted errors of H and K (which every method's "
              "tables in docs/results/rbc.md show converging at least as fast as f) to the error of the "
              "c0 = 0 law.", ""]
    lines += ["## Files", ""]
    for c in c0s[1:]:
        lines.append(f"- `rbc_c0/{folders[c]}/`: {label(c)}: errors.csv, errors.json, timings.csv, table2.md and "
                     "the plots of f (errors against h, values at 5120 triangles).")
    for c in c0s[1:]:
        for fam in FAMILIES:
            name = f"errors_f_{fam}.png"
            if os.path.exists(os.path.join(out_dir, folders[c], name)):
                lines += ["", f"![f errors, {fam.upper()}, {label(c)}](rbc_c0/{folders[c]}/{name})"]
    with open(os.path.join(results, "rbc_c0.md"), "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main(sys.argv[1:])
