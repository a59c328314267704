#!/usr/bin/python3
"""Many cells in a tube: the step rate against HemoCell's, the cells' share of a step and the memory
per extra cell (issue "Many cells in channel and tube flow", benchmark).

    /usr/bin/python3 scripts/make_suspension_performance_doc.py [--bench build/release/bench_suspension]
                                                                [--runs N] [--json FILE ...]
                                                                [--before BENCH] [--before-json FILE ...]
                                                                [--out docs/results/suspension_performance.md]

Runs bench/bench_suspension.cpp (Google Benchmark, JSON) --runs times (default 3, each a fresh
process), or reads earlier reports with --json, and writes, for the tube of HemoCell's pipeflow
example (25 um across, 50 um long, dx = 0.5 um, 36 red blood cells of 1280 triangles with Method C
and 6 small stiff cells, every force updated every step):
  - steps per second on 1 and 2 threads against HemoCell's 26 and 48 (built from its own sources on
    this kind of machine, membrane forces every 20 steps, positions every 5) and the target of 5
    times those;
  - the cells' share of a step, 1 - (fluid step alone) / (whole step), target at most one half;
  - the same tube at tube hematocrit 0.3 (placement permitting);
  - the heap in use per added cell against positions and forces alone (48 bytes per vertex);
  - the whole step in fluid steps on the pipeflow case and on the tube study's reference case
    (D = 10 um, 5 cells, time scale 10), on 1 and 2 threads, and with --before (an older build of
    bench_suspension, run alternately with this one in the same run) the same before, with the
    ratios: targets at most 4.2 fluid steps on the pipeflow case and 1.7 times the one-thread step
    on two threads;
  - the step table also as the section "Suspension step" of docs/benchmarks.md (--benchmarks-doc);
  - docs/results/hemocell_like_for_like.md (scripts/hemocell_like_for_like.py, which needs a HemoCell
    build) and docs/results/membrane_every.md (scripts/membrane_every_study.py), included as they stand.
Every figure is the median over the runs; the load average before and after is recorded. The
timings are only as quiet as the machine. Standard library only.
"""
import argparse
import datetime
import json
import os
import statistics
import subprocess
import sys

HEMOCELL = {1: 26.0, 2: 48.0}
FACTOR = 5.0
CELLS_SHARE_TARGET = 0.5
POSITIONS_AND_FORCES = 48.0  # bytes per vertex: 3 + 3 doubles


def load_average():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def medians(reports):
    """{(family, argument): {field: median}} over the reports, errors kept as 'error'."""
    values = {}
    for report in reports:
        for b in report["benchmarks"]:
            if b.get("run_type", "iteration") != "iteration":
                continue
            parts = b["name"].split("/")
            arg = next((int(p) for p in parts[1:] if p.isdigit()), None)
            row = values.setdefault((parts[0], arg), {})
            if b.get("error_occurred"):
                row.setdefault("error", b.get("error_message", "error"))
                continue
            for k, v in b.items():
                if isinstance(v, (int, float)) and not isinstance(v, bool):
                    row.setdefault(k, []).append(float(v))
    return {key: {k: (statistics.median(v) if isinstance(v, list) else v) for k, v in row.items()}
            for key, row in values.items()}


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--bench", default="build/release/bench_suspension")
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--json", nargs="*", default=None, help="earlier reports instead of running")
    p.add_argument("--before", default=None, help="an older bench_suspension to set against this one")
    p.add_argument("--before-json", nargs="*", default=None, help="earlier reports of the older build")
    p.add_argument("--before-label", default="the build given as --before",
                   help="what the older build is (its commit), for the document")
    p.add_argument("--save-json", default=None,
                   help="a folder to keep this run's reports in (after.N.json, before.N.json) for --json")
    p.add_argument("--out", default="docs/results/suspension_performance.md")
    p.add_argument("--benchmarks-doc", default="docs/benchmarks.md",
                   help="where the step table also goes, as its section (empty: nowhere)")
    a = p.parse_args()
    before_reports = []
    load_start = load_average()
    reports = []
    if a.json:
        for path in a.json:
            with open(path) as f:
                reports.append(json.load(f))
    else:
        if not os.access(a.bench, os.X_OK):
            sys.exit(f"error: no benchmark program at '{a.bench}' (cmake --build --preset release)")
        if a.before and not os.access(a.before, os.X_OK):
            sys.exit(f"error: no benchmark program at '{a.before}' (--before)")
        for k in range(a.runs):
            print(f"make_suspension_performance_doc: run {k + 1} of {a.runs}", flush=True)
            out = subprocess.run([a.bench, "--benchmark_format=json", "--benchmark_min_time=3"],
                                 capture_output=True, text=True, check=True).stdout
            reports.append(json.loads(out))
            if a.before:
                out = subprocess.run([a.before, "--benchmark_format=json", "--benchmark_min_time=3",
                                      "--benchmark_filter=BM_(Pipeflow|Tube10)(Step|Fluid)/"],
                                     capture_output=True, text=True, check=True).stdout
                before_reports.append(json.loads(out))
    if a.before_json:
        for path in a.before_json:
            with open(path) as f:
                before_reports.append(json.load(f))
    load_end = load_average()
    if a.save_json:
        os.makedirs(a.save_json, exist_ok=True)
        for name, group in (("after", reports), ("before", before_reports)):
            for k, r in enumerate(group):
                with open(os.path.join(a.save_json, f"{name}.{k + 1}.json"), "w") as f:
                    json.dump(r, f)
    m = medians(reports)
    def ms(row):  # every benchmark of bench_suspension reports milliseconds
        return row["real_time"]
    argv = " ".join(sys.argv[1:])
    L = ["# Many cells in a tube: performance", "",
         "Generated by", "", f"    /usr/bin/python3 scripts/make_suspension_performance_doc.py {argv}".rstrip(), "",
         f"on {datetime.datetime.now(datetime.timezone.utc).strftime('%Y-%m-%d %H:%M UTC')}, {len(reports)} runs of "
         f"`bench_suspension` (medians), load average {load_start} before and {load_end} after (the machine "
         "is shared: a run can differ from the next by a third).", "",
         "The tube of HemoCell's `pipeflow` example: 25 um across, 50 um long, dx = 0.5 um (100 x 54 x 54 nodes, "
         "TRT, interpolated bounce-back), 36 red blood cells of 1280 triangles (Skalak, Method C) and 6 small "
         "stiff spheres, every membrane force, contact and immersed-boundary update every step (HemoCell "
         "updates membrane forces every 20 steps and positions every 5).", "",
         "| threads | bendlab steps/s | HemoCell steps/s | ratio | target (5 x HemoCell) | fluid step alone (ms) | "
         "whole step (ms) | cells' share of a step | target (at most 1/2) |",
         "|---|---|---|---|---|---|---|---|---|"]
    for t in (1, 2):
        step, fluid = m.get(("BM_PipeflowStep", t)), m.get(("BM_PipeflowFluid", t))
        if not step or "error" in step or not fluid or "error" in fluid:
            L.append(f"| {t} | not measured | {HEMOCELL[t]:g} | - | - | - | - | - | - |")
            continue
        rate = step["steps_per_second"]
        share = 1 - ms(fluid) / ms(step)
        L.append(f"| {t} | {rate:.1f} | {HEMOCELL[t]:g} | {rate / HEMOCELL[t]:.2f} | "
                 f"{'met' if rate >= FACTOR * HEMOCELL[t] else '**not met**'} ({FACTOR * HEMOCELL[t]:g}) | "
                 f"{ms(fluid):.2f} | {ms(step):.2f} | {share:.2f} | "
                 f"{'met' if share <= CELLS_SHARE_TARGET else '**not met**'} |")
    L += ["", "The same tube at tube hematocrit 0.3 (red blood cells only, placed from seed 1):", "",
          "| threads | steps/s | cells | vertices |", "|---|---|---|---|"]
    for t in (1, 2):
        row = m.get(("BM_PipeflowHt03Step", t))
        if not row:
            L.append(f"| {t} | not measured | - | - |")
        elif "error" in row:
            L.append(f"| {t} | not placed: {row['error']} | - | - |")
        else:
            L.append(f"| {t} | {row['steps_per_second']:.1f} | {row['cells']:.0f} | {row['vertices']:.0f} |")
    # The step in fluid steps, before and after.
    mb = medians(before_reports) if before_reports else {}
    step_start = len(L) + 3  # the table's description and rows, also written to docs/benchmarks.md
    L += ["", "## The step in fluid steps", "",
          "CPU cost of a whole step over that of the fluid step alone on the same lattice (real time, one "
          "process), on the pipeflow case (HemoCell's pipeflow tube, bench/pipeflow_case.hpp) and on the tube study's reference case (D = 10 um, 20 um periodic, "
          "tau = 1.82, 5 red blood cells of 1280 triangles, time scale 10: 40 x 24 x 24 nodes). "
          + (f"Before: {a.before_label}, run alternately with this one in the same run. "
             if before_reports else "No earlier build was measured in this run. ")
          + "Targets: the pipeflow step at most 4.2 fluid steps on one thread; two threads at least 1.7 times "
            "one.", "",
          "| case | threads | " + ("step before (ms) | fluid steps before | " if before_reports else "")
          + "step (ms) | fluid (ms) | fluid steps | " + ("speed-up | " if before_reports else "")
          + "2 threads / 1 |",
          "|---|---|" + ("---|---|" if before_reports else "") + "---|---|---|" + ("---|" if before_reports else "")
          + "---|"]
    for case, family in (("pipeflow", "Pipeflow"), ("D = 10 um tube", "Tube10")):
        for t in (1, 2):
            step, fluid = m.get((f"BM_{family}Step", t)), m.get((f"BM_{family}Fluid", t))
            if not step or "error" in step or not fluid or "error" in fluid:
                L.append(f"| {case} | {t} | not measured |")
                continue
            cells = [case, str(t)]
            b_step, b_fluid = mb.get((f"BM_{family}Step", t)), mb.get((f"BM_{family}Fluid", t))
            if before_reports:
                if b_step and b_fluid and "error" not in b_step and "error" not in b_fluid:
                    cells += [f"{ms(b_step):.2f}", f"{ms(b_step) / ms(b_fluid):.2f}"]
                else:
                    cells += ["-", "-"]
            cells += [f"{ms(step):.2f}", f"{ms(fluid):.2f}", f"{ms(step) / ms(fluid):.2f}"]
            if before_reports:
                cells.append(f"{ms(b_step) / ms(step):.2f}" if b_step and "error" not in b_step else "-")
            one = m.get((f"BM_{family}Step", 1))
            cells.append(f"{ms(one) / ms(step):.2f}" if t == 2 and one and "error" not in one else "")
            L.append("| " + " | ".join(cells) + " |")
    step_table = L[step_start:]
    mem = m.get(("BM_ExtraCellMemory", None))
    L += ["", "Memory per extra cell (the heap in use, glibc's mallinfo2, grown when 20 red blood cells of 642 "
          "vertices join the pipeflow case and it steps twice):", ""]
    if mem and "error" not in mem:
        L += [f"{mem['bytes_per_cell'] / 1e3:.0f} kB per cell, {mem['bytes_per_vertex']:.0f} bytes per vertex, "
              f"against {POSITIONS_AND_FORCES:.0f} bytes per vertex for positions and forces alone: what a cell adds "
              "is per-vertex arrays only (positions, forces, velocities, its immersed-boundary stencils and its "
              "contact-search entries), no copy of its kind's topology, reference shape or bending caches, which "
              "every cell of a kind shares. The contact search's Verlet list holds 4 bytes per partner within the "
              "cutoff plus its skin, and the cells added here lie on top of the first (each a whole period away, so "
              "that the run stays finite): every vertex has the partners of 20 coinciding membranes, the list's "
              "worst case; cells that only touch give each vertex a few.", ""]
    else:
        L += ["not measured", ""]
    L += ["Where a target is not met, the reason is in docs/design.md (\"Many cells: where the time goes\").", ""]
    for name in ("hemocell_like_for_like.md", "membrane_every.md"):
        held = os.path.join(os.path.dirname(a.out) or ".", name)
        if os.path.exists(held):
            with open(held) as f:
                lines = f.read().splitlines()
            L += ["## " + lines[0].lstrip("# ") + f" (docs/results/{name}, included)", ""] + lines[1:]
    os.makedirs(os.path.dirname(a.out) or ".", exist_ok=True)
    tmp = a.out + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(L))
    os.replace(tmp, a.out)
    print(f"make_suspension_performance_doc: wrote {a.out}")
    if a.benchmarks_doc and os.path.exists(a.benchmarks_doc):
        write_benchmarks_section(a.benchmarks_doc, step_table, load_start, load_end)
        print(f"make_suspension_performance_doc: wrote its section of {a.benchmarks_doc}")


SECTION = "## Suspension step (`bench_suspension`)"


def write_benchmarks_section(path, table, load_before, load_after):
    """Replaces (or inserts before "## Running one benchmark") the suspension section of docs/benchmarks.md."""
    with open(path) as f:
        lines = f.read().split("\n")
    section = [SECTION, "", "Written by `scripts/make_suspension_performance_doc.py` (the full account, with HemoCell "
               "beside it, is docs/results/suspension_performance.md); load average "
               f"{load_before} before, {load_after} after.", ""] + table + [""]
    if SECTION in lines:
        start = lines.index(SECTION)
        end = next((k for k in range(start + 1, len(lines)) if lines[k].startswith("## ")), len(lines))
    else:
        start = end = next((k for k, line in enumerate(lines) if line.startswith("## Running one benchmark")), len(lines))
    lines[start:end] = section
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(lines))
    os.replace(tmp, path)


if __name__ == "__main__":
    main()
