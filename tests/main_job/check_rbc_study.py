#!/usr/bin/env python3
"""Runs the static RBC study as a user does and checks what it wrote.

    check_rbc_study.py BENDLAB OUT [rbc options...]

Starts `BENDLAB rbc --out OUT [options]` (an argument vector, no shell) and checks: exit status 0;
errors.csv, errors.json, timings.csv, table2.md and table3.md written; a row of errors.csv for every
method of `BENDLAB methods --json`, every family and every mesh of the family up to
--max-triangles (default: the command's own, 81920), each error a finite number; with plots, the
PNG files of every family. The README's main job is this study with no options (the release
build's test); the sanitizer build runs it to 32768 triangles without plots, which reaches every
method on every family at the size where the heap corruption of method ED showed.
"""
import csv
import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

FAMILIES = ["mt1", "mt2", "octa", "inhomogeneous", "irregular"]
# The families with plots of their own (scripts/plot_rbc.py, PLOTTED_FAMILIES; the Rivara meshes
# are drawn on their origin's plot).
PLOTTED_FAMILIES = ["mt1", "mt2", "irregular"]


def option(args, name, default):
    return args[args.index(name) + 1] if name in args else default


def expected_meshes(family, max_triangles):
    """(family name in errors.csv, triangles) of every mesh the study makes for `family`."""
    if family == "inhomogeneous":  # 320-triangle MT1 and MT2 refined by Rivara passes: sizes vary
        return None
    base, first = (8, 3) if family == "octa" else (20, 2)
    sizes, level = [], first
    while base * 4 ** level <= max_triangles:
        sizes.append(base * 4 ** level)
        level += 1
    return sizes


def main():
    bendlab, out, rest = sys.argv[1], Path(sys.argv[2]), sys.argv[3:]
    shutil.rmtree(out, ignore_errors=True)
    methods = [m["name"] for m in json.loads(subprocess.run([bendlab, "methods", "--json"], check=True,
                                                            capture_output=True, text=True).stdout)]
    run = subprocess.run([bendlab, "rbc", "--out", str(out), *rest], capture_output=True, text=True)
    sys.stderr.write(run.stderr[-4000:])
    problems = []
    if run.returncode != 0:
        problems.append(f"bendlab rbc exited with status {run.returncode}")
    for name in ["errors.csv", "errors.json", "timings.csv", "table2.md", "table3.md"]:
        if not (out / name).is_file() or (out / name).stat().st_size == 0:
            problems.append(f"{name} is missing or empty")
    max_triangles = int(option(rest, "--max-triangles", "81920"))
    families = option(rest, "--families", ",".join(FAMILIES)).split(",")
    rows = []
    if (out / "errors.csv").is_file():
        with open(out / "errors.csv", newline="") as f:
            rows = list(csv.DictReader(f))
    seen = {(r["family"], int(r["triangles"]), r["method"]) for r in rows}
    # A mesh a method refuses by its own rule (S: two extraordinary vertices in a face of a Rivara
    # mesh) is reported in errors.json's "refused", with the reason, instead of a row.
    refused = set()
    if (out / "errors.json").is_file():
        for r in json.loads((out / "errors.json").read_text()).get("refused", []):
            refused.add((r["family"], int(r["triangles"]), r["method"]))
            if not r.get("reason"):
                problems.append(f"errors.json: the refusal of {r['method']} on {r['family']} gives no reason")
    seen |= refused
    for r in rows:
        for key in ("max_error", "avg_error"):
            if not math.isfinite(float(r[key])):
                problems.append(f"errors.csv: {key} of {r['family']} {r['triangles']} {r['method']} "
                                f"{r['quantity']} is {r[key]}")
    for family in families:
        sizes = expected_meshes(family, max_triangles)
        for method in methods:
            if sizes is None:
                for name in ("rivara-mt1", "rivara-mt2"):
                    if not any(f == name and m == method for f, _, m in seen):
                        problems.append(f"errors.csv has no row of method {method} on {name}")
                continue
            for n in sizes:
                if (family, n, method) not in seen:
                    problems.append(f"errors.csv has no row of method {method} on {family} {n}")
    if "--no-plots" not in rest:
        for family in families:
            if family in PLOTTED_FAMILIES and not list(out.glob(f"errors_*_{family}.png")):
                problems.append(f"no errors_<quantity>_{family}.png plot")
    for p in problems[:40]:
        print("check_rbc_study:", p)
    if problems:
        print(f"check_rbc_study: {len(problems)} problems")
        return 1
    print(f"check_rbc_study: {len(rows)} rows of {len(methods)} methods on {len(families)} families, files whole")
    return 0


if __name__ == "__main__":
    sys.exit(main())
