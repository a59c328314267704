#!/usr/bin/python3
"""bendlab's pipeflow step set against HemoCell's, like for like, in one run of one script.

    /usr/bin/python3 scripts/hemocell_like_for_like.py --hemocell BIN --case DIR
                     [--bench build/release/bench_suspension] [--iterations N] [--rounds N]
                     [--mpirun mpirun] [--min-time S] [--out docs/results/hemocell_like_for_like.md]

HemoCell is not a dependency of bendlab and is not built by it. Build it from its public sources
(UvaCsl/HemoCell d916987 on Palabos v2.3.0) with the recipe of the peers' folder, whose
`pipeflow_bench` is HemoCell's pipeflow example with timers around its main loop (the physics
unchanged). Then:
  --hemocell  that pipeflow_bench binary;
  --case      HemoCell's examples/pipeflow folder (config.xml, tube.stl, RBC.xml, PLT.xml, *.pos),
              copied to a scratch folder for each run, which is removed afterwards.

Each round runs, one after the other (never two at once: the machine has two cores):
  - bendlab's bench_suspension: BM_PipeflowStep (every force every step) and
    BM_PipeflowStepEvery20 (membrane forces every 20 steps, `flow --membrane-every 20`), on 1 and
    2 threads;
  - HemoCell's pipeflow on 1 and 2 MPI ranks with its default updates (stepMaterialEvery 20,
    stepParticleEvery 5) and with every force and position every step (both 1), for --iterations
    steps after its initialisation and warm-up. Its output, CSV and checkpoint intervals are set
    beyond the run, so that neither code writes files while timed; everything else is its
    config.xml as published.
HemoCell's figure is its compute-only rate (its iterate() and the driving force, rank 0's clock
after a barrier); bendlab's is Google Benchmark's real time per step. Every figure is the median
over the rounds, with the smallest and largest. The ratios set each bendlab setting against the
HemoCell setting that updates the membrane as often: every step against every step, every 20
against the default. Writes the document (included by docs/results/suspension_performance.md).
Standard library only.
"""
import argparse
import datetime
import json
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

SETTINGS = [  # (key, stepMaterialEvery, stepParticleEvery, what)
    ("default", 20, 5, "default updates: membrane forces every 20 steps, positions every 5"),
    ("every", 1, 1, "every force and position every step"),
]
BENDLAB = [  # (benchmark family, key of the HemoCell setting it matches, what)
    ("BM_PipeflowStep", "every", "every force every step"),
    ("BM_PipeflowStepEvery20", "default", "membrane forces every 20 steps (`--membrane-every 20`), the rest every step"),
]
RANKS = [1, 2]


class Failure(RuntimeError):
    pass


def load_average():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def set_tag(xml, tag, value):
    """The XML text with the value of every <tag> element replaced (HemoCell's config format)."""
    new, n = re.subn(rf"<{tag}>[^<]*</{tag}>", f"<{tag}> {value} </{tag}>", xml)
    if n == 0:
        raise Failure(f"the case's config.xml has no <{tag}> element")
    return new


def hemocell_run(a, ranks, material, particle):
    """One HemoCell run; returns the parsed '(Bench)' figures."""
    with open(os.path.join(a.case, "config.xml")) as f:
        xml = f.read()
    beyond = a.iterations + 1000  # no output, CSV or checkpoint while timed
    for tag, value in (("tmax", a.iterations), ("tmeas", beyond), ("tcsv", beyond), ("tcheckpoint", beyond),
                       ("stepMaterialEvery", material), ("stepParticleEvery", particle)):
        xml = set_tag(xml, tag, value)
    work = tempfile.mkdtemp(prefix="hemocell_")
    try:
        case = os.path.join(work, "case")
        shutil.copytree(a.case, case, ignore=shutil.ignore_patterns("output*", "out_*", "config_*.xml"))
        with open(os.path.join(case, "config_bench.xml"), "w") as f:
            f.write(xml)
        command = [a.mpirun, "-np", str(ranks)]
        if os.geteuid() == 0:
            command.append("--allow-run-as-root")
        command += [os.path.abspath(a.hemocell), "config_bench.xml"]
        r = subprocess.run(command, cwd=case, capture_output=True, text=True, timeout=a.timeout)
        text = r.stdout + r.stderr
        if r.returncode != 0:
            raise Failure(f"HemoCell ({ranks} ranks) exited with {r.returncode}:\n" + text[-2000:])
    finally:
        shutil.rmtree(work, ignore_errors=True)
    fig = {}
    for line in text.splitlines():
        words = line.split()
        if not words or words[0] != "(Bench)":
            continue
        for k in range(1, len(words) - 1):
            try:
                value = float(words[k + 1])
            except ValueError:
                continue
            key = words[k]
            if key == "it_per_s":
                key = "compute_it_per_s" if words[1].startswith("compute_only") else "loop_it_per_s"
            fig.setdefault(key, value)
    missing = [k for k in ("compute_it_per_s", "loop_it_per_s", "lattice_nodes", "fluid_nodes", "RBC") if k not in fig]
    if missing:
        raise Failure(f"HemoCell's output lacks the '(Bench)' figures {missing}: is --hemocell its pipeflow_bench?\n"
                      + text[-2000:])
    return fig


def bendlab_run(a):
    """One bench_suspension process; returns {(family, threads): steps per second and counters}."""
    families = "|".join(f for f, _, _ in BENDLAB)
    out = tempfile.NamedTemporaryFile(suffix=".json", delete=False)
    out.close()
    try:
        command = [a.bench, f"--benchmark_filter=^({families})/", f"--benchmark_min_time={a.min_time}",
                   f"--benchmark_out={out.name}", "--benchmark_out_format=json"]
        r = subprocess.run(command, capture_output=True, text=True, timeout=a.timeout)
        if r.returncode != 0:
            raise Failure(f"{a.bench} exited with {r.returncode}:\n" + (r.stdout + r.stderr)[-2000:])
        with open(out.name) as f:
            report = json.load(f)
    finally:
        os.unlink(out.name)
    figures = {}
    for b in report["benchmarks"]:
        if b.get("run_type", "iteration") != "iteration":
            continue
        if b.get("error_occurred"):
            raise Failure(f"{b['name']}: {b.get('error_message', 'error')}")
        parts = b["name"].split("/")
        figures[(parts[0], int(parts[1]))] = {"steps_per_second": b["steps_per_second"], "cells": b.get("cells"),
                                              "vertices": b.get("vertices")}
    return figures


def spread(values):
    m = statistics.median(values)
    return m, min(values), max(values)


def fmt_rate(values):
    m, lo, hi = spread(values)
    return f"{m:.1f} ({lo:.1f}-{hi:.1f})" if len(values) > 1 else f"{m:.1f}"


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--hemocell", required=True, help="HemoCell's pipeflow_bench binary")
    p.add_argument("--case", required=True, help="HemoCell's examples/pipeflow folder")
    p.add_argument("--bench", default="build/release/bench_suspension")
    p.add_argument("--iterations", type=int, default=1000, help="HemoCell steps timed per run (default 1000)")
    p.add_argument("--rounds", type=int, default=3, help="rounds of every run (default 3)")
    p.add_argument("--min-time", type=float, default=5.0, help="Google Benchmark's minimum time per figure, s")
    p.add_argument("--mpirun", default="mpirun")
    p.add_argument("--timeout", type=float, default=1800, help="seconds any one run may take")
    p.add_argument("--out", default="docs/results/hemocell_like_for_like.md")
    a = p.parse_args()
    for path, what in ((a.hemocell, "--hemocell"), (a.bench, "--bench")):
        if not (os.path.isfile(path) and os.access(path, os.X_OK)):
            sys.exit(f"error: {what} {path} is not an executable file")
    if not os.path.isfile(os.path.join(a.case, "config.xml")):
        sys.exit(f"error: --case {a.case} has no config.xml (HemoCell's examples/pipeflow folder)")
    if a.iterations < 100 or a.rounds < 1:
        sys.exit("error: --iterations must be at least 100 and --rounds at least 1")
    if shutil.which(a.mpirun) is None:
        sys.exit(f"error: {a.mpirun} not found")

    load_before = load_average()
    hemo = {}  # (setting, ranks) -> [figures]
    ours = {}  # (family, threads) -> [figures]
    try:
        for r in range(a.rounds):
            print(f"round {r + 1}/{a.rounds}: bendlab", flush=True)
            for k, v in bendlab_run(a).items():
                ours.setdefault(k, []).append(v)
            for key, material, particle, _ in SETTINGS:
                for ranks in RANKS:
                    print(f"round {r + 1}/{a.rounds}: HemoCell {key} on {ranks} rank(s)", flush=True)
                    hemo.setdefault((key, ranks), []).append(hemocell_run(a, ranks, material, particle))
    except (Failure, subprocess.TimeoutExpired) as e:
        sys.exit(f"error: {e}")
    load_after = load_average()

    def hemo_rates(key, ranks, field="compute_it_per_s"):
        return [f[field] for f in hemo[(key, ranks)]]

    def our_rates(family, threads):
        return [f["steps_per_second"] for f in ours[(family, threads)]]

    first = hemo[("default", 1)][0]
    ours_first = ours[(BENDLAB[0][0], 1)][0]
    try:
        commit = subprocess.run(["git", "-C", os.path.dirname(os.path.abspath(a.case)), "rev-parse", "--short=12", "HEAD"],
                                capture_output=True, text=True).stdout.strip() or "unknown"
    except OSError:
        commit = "unknown"
    L = ["# bendlab and HemoCell, like for like, on HemoCell's pipeflow case", "",
         f"Generated by `scripts/hemocell_like_for_like.py` on {datetime.date.today().isoformat()}, "
         f"{os.cpu_count()} cores (load average {load_before} before, {load_after} after), {a.rounds} rounds, "
         f"each running every figure one after the other. HemoCell {commit} (built from its public sources on "
         f"Palabos v2.3.0, its pipeflow example with timers around the main loop), {a.iterations} steps timed per "
         "run after its initialisation and warm-up, no output while timed; bendlab's `bench_suspension` "
         f"(Google Benchmark, at least {a.min_time:g} s per figure).", "",
         "The case: a tube 25 um across and 50 um long at dx = 0.5 um, red blood cells of HemoCell's and "
         "bendlab's own models and a few small stiff cells.", "",
         f"- HemoCell: {int(first['lattice_nodes'])} lattice nodes, {int(first['fluid_nodes'])} fluid, "
         f"{int(first['RBC'])} red blood cells and {int(first.get('PLT', 0))} platelets; BGK with Guo's forcing; "
         "cell-cell repulsion switched off in the example.",
         f"- bendlab: 100 x 54 x 54 nodes (fluid and wall), {int(ours_first['cells'])} cells "
         f"({int(ours_first['vertices'])} vertices: 36 red blood cells of 1280 triangles with Method C and "
         "6 small stiff spheres); TRT; cell-cell and wall contact on.", "",
         "Steps per second, median over the rounds (smallest-largest). HemoCell's is its compute-only "
         "rate (iterate() and the driving force, rank 0's clock after a barrier); its whole loop, the "
         "driving force's reset and bookkeeping included, is in the last column.", "",
         "| code | updates | ranks / threads | steps/s | whole loop |", "| --- | --- | --- | --- | --- |"]
    for key, _, _, what in SETTINGS:
        for ranks in RANKS:
            L.append(f"| HemoCell | {what} | {ranks} rank{'s' if ranks > 1 else ''} | {fmt_rate(hemo_rates(key, ranks))} "
                     f"| {fmt_rate(hemo_rates(key, ranks, 'loop_it_per_s'))} |")
    for family, _, what in BENDLAB:
        for threads in RANKS:
            L.append(f"| bendlab | {what} | {threads} thread{'s' if threads > 1 else ''} | "
                     f"{fmt_rate(our_rates(family, threads))} | |")
    L += ["", "bendlab's step rate over HemoCell's, the membrane updated as often (medians; the range is "
          "the ratio of the rounds' figures taken in the same round):", "",
          "| membrane forces | on 1 (rank or thread) | on 2 | 2 against 1, bendlab | 2 against 1, HemoCell |",
          "| --- | --- | --- | --- | --- |"]
    for family, key, _ in BENDLAB:
        cells = []
        for n in RANKS:
            per_round = [o / h for o, h in zip(our_rates(family, n), hemo_rates(key, n))]
            m, lo, hi = spread(per_round)
            cells.append(f"**{m:.2f}** ({lo:.2f}-{hi:.2f})" if len(per_round) > 1 else f"**{m:.2f}**")
        ours_scaling = statistics.median(our_rates(family, 2)) / statistics.median(our_rates(family, 1))
        hemo_scaling = statistics.median(hemo_rates(key, 2)) / statistics.median(hemo_rates(key, 1))
        every = "every step" if key == "every" else "every 20 steps"
        L.append(f"| {every} | {cells[0]} | {cells[1]} | {ours_scaling:.2f} | {hemo_scaling:.2f} |")
    L += ["", "What differs besides the code: HemoCell moves its cells every 5 steps in its default setting "
          "(bendlab every step in both), has no cell-cell repulsion in this example (bendlab's contacts "
          "are on) and uses BGK (bendlab TRT). Each of these makes HemoCell's step cheaper, not bendlab's.", ""]
    os.makedirs(os.path.dirname(a.out) or ".", exist_ok=True)
    tmp = a.out + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(L))
    os.replace(tmp, a.out)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
