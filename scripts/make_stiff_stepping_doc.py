#!/usr/bin/python3
"""Writes the measured table of docs/results/stiff_stepping.md from `bendlab shear` run folders.

    scripts/make_stiff_stepping_doc.py RUN_FOLDER... [--doc docs/results/stiff_stepping.md]

Each folder is a finished or still running `bendlab shear` run (summary.json when finished,
checkpoint.json and timeseries.csv always). Rows are grouped by (mesh, method, G, kappa_b_hat);
in each group the Cash-Karp run with the smallest rtol is the reference. D(2) is D at gamma t = 2:
the row at gamma t = 2 exactly for a run that ends there, else the cubic through the four accepted
steps around gamma t = 2 (the step is about 0.03 there, so the interpolation error is far below
the integration error). The table replaces the text between the markers
<!-- measured:begin --> and <!-- measured:end --> of the document.
"""
import argparse
import csv
import json
import os
import sys

BEGIN, END = "<!-- measured:begin -->", "<!-- measured:end -->"


def read_series(folder):
    with open(os.path.join(folder, "timeseries.csv")) as f:
        rows = list(csv.DictReader(f))
    return [float(r["gamma_t"]) for r in rows], [float(r["D"]) for r in rows]


def D_at(t, D, when):
    if not t or t[-1] < when - 1e-12:
        return None
    for k, tk in enumerate(t):
        if abs(tk - when) <= 1e-12:
            return D[k]
        if tk > when:
            break
    lo = max(0, min(k - 2, len(t) - 4))
    xs, ys = t[lo:lo + 4], D[lo:lo + 4]
    value = 0.0
    for i, (xi, yi) in enumerate(zip(xs, ys)):
        w = 1.0
        for j, xj in enumerate(xs):
            if j != i:
                w *= (when - xj) / (xi - xj)
        value += w * yi
    return value


def load(folder):
    summary_path = os.path.join(folder, "summary.json")
    finished = os.path.exists(summary_path)
    if finished:
        with open(summary_path) as f:
            s = json.load(f)
        timing_path = os.path.join(folder, "timing.json")
        if os.path.exists(timing_path):  # the wall time lives beside the results
            with open(timing_path) as f:
                s["wall_seconds"] = json.load(f).get("wall_seconds")
    else:  # a run still going: its identity and counters from the checkpoint
        with open(os.path.join(folder, "checkpoint.json")) as f:
            c = json.load(f)
        s = dict(c["arguments"])
        s["velocity_evaluations"] = c.get("counters", {}).get("velocity_evaluations")
        s["wall_seconds"] = c.get("wall_seconds")
        s["_t_counted"] = c["time"]  # the counters are those of the checkpoint
        integ = c.get("solver_state", {}).get("integrator")
        if integ:
            s["integrator"] = integ["name"]
            tot = integ["state"]["totals"]
            s["integrator_stats"] = {"mean_stages": tot["stages"] / max(tot["steps"], 1),
                                     "max_stages": tot["max_stages"],
                                     "spectral_radius": integ["state"]["spectral_radius"]}
    t, D = read_series(folder)
    s["_folder"] = folder
    s["_finished"] = finished
    s["_t_reached"] = t[-1] if t else 0.0
    s["_D2"] = D_at(t, D, 2.0)
    s.setdefault("_t_counted", s["_t_reached"])
    s.setdefault("integrator", s.get("integrator", "cash-karp"))
    return s


def fmt(x, spec):
    return "–" if x is None else format(x, spec)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("folders", nargs="+")
    ap.add_argument("--doc", default=os.path.join(os.path.dirname(__file__), "..", "docs", "results", "stiff_stepping.md"))
    a = ap.parse_args()
    runs = [load(f) for f in a.folders]
    groups = {}
    for r in runs:
        groups.setdefault((r["mesh"], r["method"], r["G"], r["kappa_b_hat"]), []).append(r)
    out = []
    w = out.append
    for (mesh, method, G, kb), rs in groups.items():
        refs = [r for r in rs if r["integrator"] == "cash-karp"]
        ref = min(refs, key=lambda r: r.get("rtol", 1)) if refs else None
        w(f"### {mesh}, Method {method}, G = {G}, κ̂_B = {kb}")
        w("")
        w("| integrator | BIM quadrature | rtol / atol | γt reached | D_steady | D_steady vs Cash-Karp | D(2) | D(2) vs Cash-Karp | velocity evaluations"
          " (at the checkpoint for a running run) | evaluations per unit γt | fewer than Cash-Karp (per unit γt) | mean / max stages | ρ (last, ×1.1) | wall |")
        w("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for r in sorted(rs, key=lambda r: (r["integrator"] != "cash-karp", -r.get("rtol", 0))):
            ev = r.get("velocity_evaluations")
            per = ev / r["_t_counted"] if ev and r["_t_counted"] > 0 else None
            ref_per = None
            if ref and ref.get("velocity_evaluations") and ref["_t_reached"] > 0:
                ref_per = ref["velocity_evaluations"] / ref["_t_counted"]
            gain = ref_per / per if per and ref_per and r is not ref else None
            dev = None
            if ref and r is not ref and r["_D2"] is not None and ref["_D2"] is not None:
                dev = (r["_D2"] - ref["_D2"]) / ref["_D2"]
            # D_steady only where both runs reached gamma t = 10 (finished, with a summary).
            dev_steady = None
            if ref and r is not ref and r["_finished"] and ref["_finished"] and r.get("D_steady") and ref.get("D_steady"):
                dev_steady = (r["D_steady"] - ref["D_steady"]) / ref["D_steady"]
            st = r.get("integrator_stats", {})
            stages = f"{st['mean_stages']:.1f} / {st['max_stages']}" if st else "–"
            rho = fmt(st.get("spectral_radius"), ".3g") if st else "–"
            wall = r.get("wall_seconds")
            state = "" if r["_finished"] else " (running)"
            w(f"| {r['integrator']}{state} | {r.get('bim_quadrature', 'all7')} | {r.get('rtol', '–')} / {r.get('atol', '–')} | {r['_t_reached']:.4g} | "
              f"{fmt(r.get('D_steady'), '.6f')} | "
              f"{'reference' if r is ref else (fmt(100 * dev_steady, '+.4f') + '%' if dev_steady is not None else '–')} | "
              f"{fmt(r['_D2'], '.6f')} | "
              f"{'reference' if r is ref else (fmt(100 * dev, '+.4f') + '%' if dev is not None else '–')} | "
              f"{fmt(ev, 'd')} | {fmt(per, '.0f')} | {fmt(gain, '.1f') + '×' if gain else '–'} | {stages} | {rho} | "
              f"{fmt(wall, '.0f')} s |")
        w("")
        w("Folders: " + ", ".join(f"`{os.path.basename(os.path.normpath(r['_folder']))}`" for r in rs))
        w("")
    table = "\n".join(out)
    with open(a.doc) as f:
        doc = f.read()
    if BEGIN not in doc or END not in doc:
        sys.exit(f"{a.doc}: the markers {BEGIN} and {END} are missing")
    head, rest = doc.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    with open(a.doc, "w") as f:
        f.write(head + BEGIN + "\n" + table + "\n" + END + tail)


if __name__ == "__main__":
    main()
