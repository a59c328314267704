#!/usr/bin/python3
"""Writes docs/benchmarks.md from the JSON reports of scripts/run_benchmarks.sh.

    /usr/bin/python3 scripts/make_benchmarks_doc.py --results results/bench --out docs/benchmarks.md

Reads <results>/machine.txt and <results>/bench_{geometry,bending,bim}.json (Google Benchmark's
--benchmark_format=json). Standard library only.

With --section order, only the section "Order of the methods" of an existing --out is written
again, from the BM_Order rows of <results>/bench_bending.json (and the load averages of
<results>/machine.txt, if any), the rest of the document left as it is:

    OMP_NUM_THREADS=1 ./build/release/bench_bending --benchmark_filter='BM_Order/' \\
        --benchmark_repetitions=3 --benchmark_enable_random_interleaving=true \\
        --benchmark_format=json > results/order/bench_bending.json
    /usr/bin/python3 scripts/make_benchmarks_doc.py --section order --results results/order
"""
import argparse
import json
import os
import sys

# Above this one-minute load average (on the 2-core reference machine) the timings are disturbed
# by other work, the two-thread ones most.
BUSY_LOAD = 2.5

# The targets of the performance issue.
BIM_TARGET_S = 0.1            # s per single-layer evaluation, 5120 triangles, 2 threads
CB_TARGET_VPS = 3.0e6         # vertices per second per core, Methods B and C, 81920 triangles
E_TARGET_VPS = 0.5e6          # vertices per second per core, Method E, 81920 triangles
M_OVER_C_TARGET = 10.0  # Method M's forces at most this many times Method C's (issue: Method M, speed)
# Topology + geometry at 81920 triangles: the time is reported; set a limit in seconds here to
# have it judged.
GEOMETRY_TARGET_S = None

# Approximate operations per target-source pair of the Stokeslet kernel (differences, |r|^2,
# 1/|r| counted as two, f.r / r^3, three accumulations), to set its speed against the
# multiply-add peak.
STOKESLET_FLOPS_PER_PAIR = 30


def parse_name(name):
    """'BM_Compute/A/triangles:5120/threads:1/real_time' -> ('BM_Compute', 'A', {'triangles': 5120, ...})."""
    parts = [p for p in name.split("/") if p and p != "real_time"]
    family, variant, args = parts[0], [], {}
    for p in parts[1:]:
        if ":" in p:
            k, v = p.split(":", 1)
            try:
                args[k] = int(v)
            except ValueError:
                args[k] = v
        else:
            variant.append(p)
    return family, "/".join(variant), args


def seconds(b):
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b.get("time_unit", "ns")]
    return b["real_time"] * scale


def cpu_seconds(b):
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b.get("time_unit", "ns")]
    return b["cpu_time"] * scale


def load_report(path):
    if not os.path.exists(path):
        return None
    with open(path) as f:
        report = json.load(f)
    rows = []
    for b in report.get("benchmarks", []):
        if b.get("run_type", "iteration") != "iteration":
            continue
        family, variant, args = parse_name(b["name"])
        rows.append({"family": family, "variant": variant, "args": args, "b": b,
                     "error": b.get("error_message") if b.get("error_occurred") else None})
    return {"context": report.get("context", {}), "rows": rows}


def read_machine(path):
    info = {}
    if os.path.exists(path):
        with open(path) as f:
            for line in f:
                if ":" in line:
                    k, v = line.split(":", 1)
                    info[k.strip()] = v.strip()
    return info


def si(x, unit=""):
    if x is None:
        return "-"
    for factor, prefix in ((1e9, "G"), (1e6, "M"), (1e3, "k")):
        if abs(x) >= factor:
            return f"{x / factor:.3g} {prefix}{unit}".rstrip()
    return f"{x:.3g} {unit}".rstrip()


def ms(s):
    if s is None:
        return "-"
    return f"{s * 1e3:.4g}"


def b_compute_reason(bend):
    """Why Method B's `compute` misses the per-core target where its `forces` meets it, from the two
    one-thread times: `compute` is the force kernel plus a full MeshGeometry pass (the mixed areas,
    the normals and the angle-sum K it reports), which `forces` does not need. [] where it is met."""
    rc = find(bend, "BM_Compute", "B", triangles=81920, threads=1)
    rf = find(bend, "BM_Forces", "B", triangles=81920, threads=1)
    vc, vf = counter(rc, "vertices_per_s_per_thread"), counter(rf, "vertices_per_s_per_thread")
    if vc is None or vf is None or vc >= CB_TARGET_VPS or vf < CB_TARGET_VPS:
        return []
    tc, tf = seconds(rc["b"]), seconds(rf["b"])
    return [f"Why Method B's `compute` is not met: it is the force kernel that `forces` runs ({ms(tf)} ms, "
            f"{si(vf)} vertices/s, met) followed by a full `MeshGeometry` pass for the mixed areas, the normals "
            f"and the angle-sum K that `compute` reports ({ms(tc - tf)} ms more). A flow solver calls `forces`; the static study calls `compute` once per mesh, "
            f"where its {ms(tc)} ms do not matter. The target would need the geometry pass below "
            f"{ms(40962 / CB_TARGET_VPS - tf)} ms, {(40962 / CB_TARGET_VPS - tf) / (tc - tf):.2f} of what it takes here."]


def find(report, family, variant=None, **args):
    if report is None:
        return None
    for r in report["rows"]:
        if r["family"] != family or (variant is not None and r["variant"] != variant):
            continue
        if all(r["args"].get(k) == v for k, v in args.items()):
            return r
    return None


def counter(row, name):
    if row is None or row["error"]:
        return None
    return row["b"].get(name)


def verdict(ok):
    return "met" if ok else "**not met**"


ORDER_HEADING = "## Order of the methods (`BM_Order`)"


def order_section(bend, machine):
    """Lines of the section on BM_Order: each method's time right after every other method."""
    rows = [r for r in bend["rows"] if r["family"] == "BM_Order" and not r["error"]] if bend else []
    if not rows:
        return []
    # In the order the pairs were registered (Q by Q, P by P: the registry's order of the methods),
    # not the order they ran in, which random interleaving shuffles.
    rows.sort(key=lambda r: r["b"].get("family_index", 0))
    methods = []
    for r in rows:
        if r["variant"] not in methods:
            methods.append(r["variant"])
    before = []
    for r in rows:
        if r["args"].get("after") not in before:
            before.append(r["args"].get("after"))
    # Every repetition of a pair (a report with --benchmark_repetitions has several rows per name).
    cell = {}
    for r in rows:
        cell.setdefault((r["variant"], r["args"].get("after")), []).append(r["b"])
    repetitions = max(len(v) for v in cell.values())

    def median(values):
        v = sorted(values)
        return 0.5 * (v[(len(v) - 1) // 2] + v[len(v) // 2])

    def cv(values):
        if len(values) < 2:
            return None
        m = sum(values) / len(values)
        return (sum((x - m) ** 2 for x in values) / (len(values) - 1)) ** 0.5 / m
    out = []
    w = out.append
    w(ORDER_HEADING)
    w("")
    w("Method Q's `compute_into` at 81920 triangles, one thread, right after an instance of method P")
    w("ran three times and was destroyed, as when the benchmarks of P and Q follow each other: every")
    w("method after every other (`BM_Order/<Q>/after:<P>`, 5 timed calls after 2 untimed ones). Before")
    w("the methods kept their workspaces (`bending/method_workspace.hpp`), Method C's compute took")
    w("46-70 ms of processor time after A and B against 7-14 ms alone in the same binary: each call")
    w("allocated about 12 MB, which glibc trimmed from the top of its heap when the call freed it")
    w("(whether it did depended on what A and B had left on the heap) and the next call faulted in")
    w("again, about 3100 page faults per call at 14-17 us each. Now no method allocates once warm")
    w("(`tests/allocation`), so no call faults in fresh pages: the table's last column, the most page")
    w("faults per call over all predecessors, is the evidence that does not depend on the machine's")
    w("load; the times vary only by the machine's noise.")
    w("")
    ls, le = machine.get("load_start"), machine.get("load_end")
    if ls or le:
        w(f"Load average (1, 5, 15 min) at the start: {ls or '-'}; at the end: {le or '-'} (2 cores).")
        w("")
    if repetitions > 1:
        w(f"Processor time of the benchmark's thread per call (ms), the median of {repetitions} repetitions")
        w("run in random order (`--benchmark_enable_random_interleaving`, so that a drift of the")
        w("machine's load over the run does not look like an effect of the order), Q in rows, P in")
        w("columns; spread = the largest over the smallest median of the row; noise = the largest")
        w("coefficient of variation of one pair's repetitions in the row, the machine's own scatter.")
    else:
        w("Processor time of the benchmark's thread per call (ms), Q in rows, P in columns; spread = the")
        w("largest over the smallest time of the row (one run of each pair: run with repetitions, as the")
        w("top of `scripts/make_benchmarks_doc.py` shows, to see the machine's own scatter).")
    w("")
    w("| Q, after P: | " + " | ".join(before) + " | spread | noise | page faults per call (max) |")
    w("| --- | " + " | ".join("---" for _ in before) + " | --- | --- | --- |")
    for q in methods:
        runs = [[cpu_seconds(b) * 1e3 for b in cell[(q, p)]] if (q, p) in cell else [] for p in before]
        times = [median(t) if t else None for t in runs]
        faults = [b.get("page_faults_per_call") for p in before for b in cell.get((q, p), [])]
        known = [t for t in times if t is not None]
        spread = f"{max(known) / min(known):.2f}" if known else "-"
        cvs = [c for c in (cv(t) for t in runs) if c is not None]
        noise = f"{max(cvs):.0%}" if cvs else "-"
        fmax = max((f for f in faults if f is not None), default=None)
        w(f"| {q} | " + " | ".join(f"{t:.4g}" if t is not None else "-" for t in times) +
          f" | {spread} | {noise} | {'-' if fmax is None else f'{fmax:.3g}'} |")
    w("")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--results", default="results/bench")
    ap.add_argument("--out", default="docs/benchmarks.md")
    ap.add_argument("--section", choices=["order"],
                    help="write only this section of an existing --out again (see the top of this script)")
    a = ap.parse_args()

    if a.section == "order":
        bend = load_report(os.path.join(a.results, "bench_bending.json"))
        section = order_section(bend, read_machine(os.path.join(a.results, "machine.txt")))
        if not section:
            sys.exit(f"make_benchmarks_doc: no BM_Order rows in {a.results}/bench_bending.json")
        with open(a.out) as f:
            lines = f.read().split("\n")
        if ORDER_HEADING in lines:
            i = lines.index(ORDER_HEADING)
            j = next((k for k in range(i + 1, len(lines)) if lines[k].startswith("## ")), len(lines))
            lines[i:j] = section
        else:  # before the closing section
            j = lines.index("## Running one benchmark") if "## Running one benchmark" in lines else len(lines)
            lines[j:j] = section
        tmp = a.out + ".tmp"
        with open(tmp, "w") as f:
            f.write("\n".join(lines))
        os.replace(tmp, a.out)
        return

    machine = read_machine(os.path.join(a.results, "machine.txt"))
    geo = load_report(os.path.join(a.results, "bench_geometry.json"))
    bend = load_report(os.path.join(a.results, "bench_bending.json"))
    bim = load_report(os.path.join(a.results, "bench_bim.json"))
    if not (geo or bend or bim):
        sys.exit(f"make_benchmarks_doc: no bench_*.json in {a.results}")

    def load1(s):
        try:
            return float(s.split()[0])
        except (AttributeError, IndexError, ValueError):
            return None

    load_start, load_end = load1(machine.get("load_start")), load1(machine.get("load_end"))
    busy = any(x is not None and x > BUSY_LOAD for x in (load_start, load_end))
    out = []
    w = out.append

    w("# Benchmarks")
    w("")
    w("Measured speed of the mesh, bending and boundary-integral code, written by")
    w("`scripts/make_benchmarks_doc.py` from the JSON reports of the command")
    w("")
    w(f"    {machine.get('command', 'bash scripts/run_benchmarks.sh')}")
    w("")
    w("which builds the release preset and runs `bench_geometry`, `bench_bending` and `bench_bim`")
    w("(sources in `bench/`). Times are wall-clock; \"per thread\" divides a rate by the OpenMP threads")
    w("(`omp_set_num_threads` inside each benchmark), so with one thread it is the rate of one core.")
    w("")
    w("## Machine")
    w("")
    w("| | |")
    w("| --- | --- |")
    w(f"| date | {machine.get('date', '-')} |")
    w(f"| commit | {machine.get('commit', '-')} |")
    w(f"| CPU | {machine.get('cpu_model', '-')} |")
    w(f"| cores (`nproc`) | {machine.get('nproc', '-')} |")
    w(f"| compiler | {machine.get('compiler', '-')} |")
    native = machine.get("native", "OFF") or "OFF"
    w(f"| `BENDLAB_NATIVE` (`-march=native`) | {native} |")
    w(f"| load average (1, 5, 15 min) at the start | {machine.get('load_start', '-')} |")
    w(f"| load average at the end | {machine.get('load_end', '-')} |")
    w("")
    if busy:
        w(f"**The machine was busy during this run** (one-minute load average above {BUSY_LOAD} on")
        w(f"{machine.get('nproc', '?')} cores): other processes competed for the cores, so every figure")
        w("below is lower than on a quiet machine, the two-thread ones much lower (OpenMP threads wait")
        w("for each other when one of them is descheduled). Run the command again on a quiet machine")
        w("before drawing conclusions from the two-thread columns.")
        w("")
    if native.upper() in ("OFF", "", "FALSE", "0"):
        w("The release preset compiles for the baseline x86-64 instruction set (SSE2, two doubles per")
        w("vector instruction) whatever the processor supports, except the boundary-integral kernel, which")
        w("is compiled for AVX-512, AVX2+FMA and baseline and picks the best at run time;")
        w("`-DBENDLAB_NATIVE=ON` compiles everything for the build machine's own instruction set.")
        w("")
    ctx = next((r["context"] for r in (geo, bend, bim) if r), {})
    if ctx.get("library_build_type") == "debug":
        w("Google Benchmark prints a warning that its library was built as DEBUG: that is the Debian")
        w("package's own build of the timing harness, not of the code measured.")
        w("")

    # ---------------------------------------------------------------- targets
    w("## Targets")
    w("")
    w("| target | measured (wall clock) | ratio (measured / target, > 1 is better) | verdict | on the thread's CPU time |")
    w("| --- | --- | --- | --- | --- |")
    tg = find(geo, "BM_TopologyPlusGeometry", triangles=81920) or find(geo, "BM_TopologyPlusGeometry")
    if tg and not tg["error"]:
        t = seconds(tg["b"])
        if GEOMETRY_TARGET_S:
            w(f"| topology + geometry, 81920 triangles, at most {GEOMETRY_TARGET_S * 1e3:g} ms | {ms(t)} ms | "
              f"{GEOMETRY_TARGET_S / t:.2f} | {verdict(t <= GEOMETRY_TARGET_S)} | {ms(cpu_seconds(tg['b']))} ms |")
        else:
            w(f"| topology + geometry, 81920 triangles (no limit set in `make_benchmarks_doc.py`) | {ms(t)} ms "
              f"({si(40962 / t)} vertices/s) | - | not judged | {ms(cpu_seconds(tg['b']))} ms |")
    else:
        w("| topology + geometry, 81920 triangles | not measured | - | **not met** | - |")

    def per_core_target(label, family, variant, target):
        r = find(bend, family, variant, triangles=81920, threads=1)
        v = counter(r, "vertices_per_s_per_thread")
        r2 = find(bend, family, variant, triangles=81920, threads=2)
        v2 = counter(r2, "vertices_per_s_per_thread")
        extra = f" (2 threads: {si(v2)}/s per thread)" if v2 else ""
        if v is None:
            w(f"| {label}, 81920 triangles, at least {si(target)} vertices/s per core | not measured | - | **not met** | - |")
        else:
            vc = r["b"]["vertices"] / cpu_seconds(r["b"])
            w(f"| {label}, 81920 triangles, at least {si(target)} vertices/s per core | {si(v)}/s on 1 thread{extra} | "
              f"{v / target:.2f} | {verdict(v >= target)} | {si(vc)}/s ({vc / target:.2f}) |")

    per_core_target("Method C (`compute`)", "BM_Compute", "C", CB_TARGET_VPS)
    per_core_target("Method B (`forces`, what a flow solver calls)", "BM_Forces", "B", CB_TARGET_VPS)
    per_core_target("Method B (`compute`, every quantity)", "BM_Compute", "B", CB_TARGET_VPS)
    per_core_target("Method E (`compute`, 1 ring)", "BM_Compute", "E", E_TARGET_VPS)
    reasons = b_compute_reason(bend)
    # Method M's cost relative to Method C's, node forces, one thread: judged on BM_ForcesRatio,
    # which calls both in every iteration (a drift of the machine's speed falls on both alike);
    # reports from before it existed fall back on the separate BM_Forces rows.
    for tri in (20480,):
        rm = find(bend, "BM_Forces", "M", triangles=tri, threads=1)
        rc = find(bend, "BM_Forces", "C", triangles=tri, threads=1)
        rr = find(bend, "BM_ForcesRatio", "M", over="C", triangles=tri)
        label = f"Method M (`forces`), {tri} triangles, 1 thread, at most {M_OVER_C_TARGET:g} times Method C's time"
        interleaved = counter(rr, "ratio")
        if interleaved:
            separate = ""
            if rm is not None and rc is not None and not rm["error"] and not rc["error"]:
                separate = f"; timed apart (BM_Forces): {seconds(rm['b']) / seconds(rc['b']):.1f} times"
            w(f"| {label} | {counter(rr, 'm_ms'):.4g} ms against {counter(rr, 'c_ms'):.4g} ms, called in turn "
              f"(`BM_ForcesRatio`, thread CPU time): {interleaved:.1f} times{separate} | "
              f"{M_OVER_C_TARGET / interleaved:.2f} | {verdict(interleaved <= M_OVER_C_TARGET)} | "
              f"{interleaved:.1f} times ({M_OVER_C_TARGET / interleaved:.2f}) |")
        elif rm is None or rc is None or rm["error"] or rc["error"]:
            w(f"| {label} | not measured | - | **not met** | - |")
        else:
            ratio = seconds(rm["b"]) / seconds(rc["b"])
            cpu_ratio = cpu_seconds(rm["b"]) / cpu_seconds(rc["b"])
            w(f"| {label} | {ms(seconds(rm['b']))} ms against {ms(seconds(rc['b']))} ms: {ratio:.1f} times | "
              f"{M_OVER_C_TARGET / ratio:.2f} | {verdict(ratio <= M_OVER_C_TARGET)} | {cpu_ratio:.1f} times "
              f"({M_OVER_C_TARGET / cpu_ratio:.2f}) |")
    # The solver's default quadrature (all7); reports from before the choice have no variant.
    r = find(bim, "BM_SingleLayer", "all7", triangles=5120, threads=2) or find(bim, "BM_SingleLayer", triangles=5120, threads=2)
    s = counter(r, "s_per_eval")
    if s is None:
        w(f"| single layer, 5120 triangles, 2 threads, at most {BIM_TARGET_S} s per evaluation | not measured | - | **not met** | - |")
    else:
        w(f"| single layer, 5120 triangles, 2 threads, at most {BIM_TARGET_S} s per evaluation | {s:.4g} s | "
          f"{BIM_TARGET_S / s:.2f} | {verdict(s <= BIM_TARGET_S)} | - |")
    w("")
    for reason in reasons:
        w(reason)
        w("")
    w("The per-core targets are judged on the one-thread run (one core's rate); the two-thread")
    w("rate per thread is shown beside it. The last column divides by the CPU time the benchmark's")
    w("thread actually ran instead of the wall clock: on a busy machine, where the thread waits for a")
    w("core, it estimates what a quiet machine gives (it is not the verdict).")
    if busy:
        w("On this busy machine a target that is not met may be met on a quiet one, and the margin of")
        w("one that is met is understated.")
    w("")

    # ---------------------------------------------------------------- geometry
    if geo:
        w("## Topology and geometry (`bench_geometry`)")
        w("")
        w("MT1 unit spheres; `BM_SphereMeshBuild`: the whole generator (refinement, projection,")
        w("validated `TriMesh`; its time is measured here, never asserted in a test);")
        w("`BM_TopologyBuild`: validated connectivity; `BM_MeshGeometry`: every")
        w("quantity of `MeshGeometry`; `BM_TopologyPlusGeometry`: a `TriMesh` from positions and faces,")
        w("then its geometry. OpenMP's default thread count (every core), since `bench_geometry` does")
        w("not set one; on a busy machine the parallel passes of `MeshGeometry` wait for each other, which")
        w("is what the small meshes' times show.")
        w("")
        w("| benchmark | triangles | time (ms) | vertices/s |")
        w("| --- | --- | --- | --- |")
        for r in geo["rows"]:
            b = r["b"]
            tri = int(b.get("triangles", 0))
            if r["error"]:
                w(f"| {r['family']} | {tri} | error: {r['error']} | - |")
                continue
            nv = tri // 2 + 2
            vps = b.get("vertices_per_s") or nv / seconds(b)
            w(f"| {r['family']} | {tri} | {ms(seconds(b))} | {si(vps)} |")
        w("")

    # ---------------------------------------------------------------- bending
    if bend:
        w("## Bending forces (`bench_bending`)")
        w("")
        w("MT1 meshes mapped onto the red blood cell of section 3; `compute` is timed as `compute_into`,")
        w("every per-vertex quantity into a result kept from call to call, `forces` the node forces only;")
        w("both after two untimed calls, which set up what a method keeps per mesh. Page faults per call:")
        w("minor faults of the process per timed call (`getrusage`), pages touched for the first time,")
        w("which no method causes once warm. Methods D and ED are O(N): Belkin's heat kernel truncated where its")
        w("weight falls below `kernel_cutoff` (1e-15), the neighbours found through a cell list once per")
        w("shape (`bending/belkin.hpp`); their O(N^2) all-pairs reference and D's cost per vertex and ratio")
        w("to C are measured by `bench/belkin_neighbours`. A method of registry cost O(N^2) would run a")
        w("single iteration at 81920 triangles. `E_rings2`, `E_rings3`: Method E fitted on 2 and 3 rings.")
        w("")
        w("| method | call | triangles | threads | time (ms) | CPU time of the main thread (ms) | vertices/s | vertices/s per thread | iterations | page faults per call |")
        w("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
        for r in bend["rows"]:
            if r["family"] == "BM_Order":
                continue  # its own section below
            b = r["b"]
            call = "forces" if r["family"] == "BM_Forces" else "compute"
            a_ = r["args"]
            if r["error"]:
                w(f"| {r['variant']} | {call} | {a_.get('triangles')} | {a_.get('threads')} | error: {r['error']} | - | - | - | - | - |")
                continue
            faults = b.get("page_faults_per_call")
            w(f"| {r['variant']} | {call} | {a_.get('triangles')} | {a_.get('threads')} | {ms(seconds(b))} | {ms(cpu_seconds(b))} | "
              f"{si(b.get('vertices_per_s'))} | {si(b.get('vertices_per_s_per_thread'))} | {b.get('iterations')} | "
              f"{'-' if faults is None else f'{faults:.3g}'} |")
        w("")
        out.extend(order_section(bend, machine))

    # ---------------------------------------------------------------- BIM
    if bim:
        w("## Boundary integral (`bench_bim`)")
        w("")
        w("One `StokesSingleLayer::velocity` on an MT1 unit sphere with the force density f = n z, with")
        w("each regular quadrature: `all7` (the default and reference: the 7-point rule over every triangle")
        w("for every node) and `adaptive` (the 7-point rule near a node, the moment-corrected centroid rule")
        w("on clusters of 32 triangles far from it; `flow/bim/stokes_single_layer.hpp`).")
        w("pairs = N_vertices x N_triangles x 7 for both (the pairs of the reference: for `adaptive` an")
        w("equivalent rate).")
        w("`BM_StokesletReference` is the regular part alone on contiguous arrays of the same points, with")
        w("the same arithmetic and nothing else, for three instruction sets: `baseline` (what the build")
        w("targets by default), `avx2` (4 doubles a vector, FMA) and `avx512` (8 doubles); the fastest is")
        w("what this machine does with the kernel's shape. Efficiency = single-layer pairs/s / the fastest")
        w("reference's pairs/s at the same size and threads (the reference in brackets); the last column")
        w("sets it against the `avx2` reference alone. The solver's kernel is compiled for AVX-512,")
        w("AVX2+FMA and baseline (`target_clones`) and runs the widest the processor has; it also")
        w("includes the polar integrals and the interpolation of f, which the reference does not.")
        w("")
        w("| benchmark | triangles | threads | s per evaluation | pairs/s | pairs/s per thread | efficiency | vs avx2 |")
        w("| --- | --- | --- | --- | --- | --- | --- | --- |")

        def best_reference(tri, thr):
            best = None
            for r in bim["rows"]:
                if (r["family"] == "BM_StokesletReference" and not r["error"] and r["args"].get("triangles") == tri
                        and r["args"].get("threads") == thr):
                    if best is None or r["b"]["pairs_per_s"] > best["b"]["pairs_per_s"]:
                        best = r
            return best

        skipped = set()
        for r in bim["rows"]:
            if r["family"] in ("BM_MultiplyAddPeak", "BM_QuadratureRatio", "BM_TreeParameters"):
                continue
            b, a_ = r["b"], r["args"]
            label = r["family"] + (f" ({r['variant']})" if r["variant"] else "")
            if r["error"]:
                skipped.add(f"{label}: {r['error']}")
                continue
            eff, eff2 = "-", "-"
            if r["family"] == "BM_SingleLayer":
                ref = best_reference(a_.get("triangles"), a_.get("threads"))
                if ref:
                    eff = f"{b['pairs_per_s'] / ref['b']['pairs_per_s']:.0%} ({ref['variant']})"
                ref2 = counter(find(bim, "BM_StokesletReference", "avx2", triangles=a_.get("triangles"),
                                    threads=a_.get("threads")), "pairs_per_s")
                if ref2:
                    eff2 = f"{b['pairs_per_s'] / ref2:.0%}"
            w(f"| {label} | {a_.get('triangles')} | {a_.get('threads')} | {seconds(b):.4g} | "
              f"{si(b.get('pairs_per_s'))} | {si(b.get('pairs_per_s_per_thread'))} | {eff} | {eff2} |")
        w("")
        def ratio_cells(b, other):
            """The time of all7 and of the other rule, the speed-up and the difference (one run)."""
            return (f"{b.get('s_all7', 0):.4g} | {b.get('s_' + other, float('nan')):.4g} | "
                    f"{b.get('speedup', 0):.2f} | {b.get('rel_diff', 0):.2e}")

        ratios = [r for r in bim["rows"] if r["family"] == "BM_QuadratureRatio" and not r["error"]]
        if ratios:
            w("`BM_QuadratureRatio`: both quadratures in every iteration of one run, on the red blood cell")
            w("(R = 1) and the 2:1:0.5 ellipsoid, force density = Method C's bending force density;")
            w("speedup = time of all7 / time of the other rule (adaptive; tree for the `_tree` shapes, tree-mixed,")
            w("the tree with single-precision sums, for `_tree_mixed`);")
            w("difference = max_i |u_other - u_all7| / max_i |u_all7| (each rule's defaults;")
            w("`stokes_single_layer.hpp` lists settings within 1e-5).")
            w("")
            w("| shape | triangles | threads | other rule | s all7 | s other | speedup | difference |")
            w("| --- | --- | --- | --- | --- | --- | --- | --- |")
            for r in ratios:
                b, a_ = r["b"], r["args"]
                other = next((q for q in ("tree-mixed", "tree") if "s_" + q in b), "adaptive")
                w(f"| {r['variant']} | {a_.get('triangles')} | {a_.get('threads')} | {other} | {ratio_cells(b, other)} |")
            w("")
        scan = [r for r in bim["rows"] if r["family"] == "BM_TreeParameters" and not r["error"]]
        if scan:
            w("`BM_TreeParameters`: the tree against all7 as above at 5120 triangles on one thread, around its")
            w("defaults (leaves of at most 32 triangles, degree 7, tolerance 2e-6):")
            w("")
            w("| shape | leaf | degree | tolerance | s all7 | s tree | speedup | difference |")
            w("| --- | --- | --- | --- | --- | --- | --- | --- |")
            for r in scan:
                b, a_ = r["b"], r["args"]
                tolerance = 1e-7 * float(a_.get("tolerance_1e-7", 0))
                w(f"| {r['variant']} | {a_.get('leaf')} | {a_.get('degree')} | {tolerance:.0e} | {ratio_cells(b, 'tree')} |")
            w("")
        peaks = [r for r in bim["rows"] if r["family"] == "BM_MultiplyAddPeak"]
        for r in peaks:
            if r["error"]:
                skipped.add(f"BM_MultiplyAddPeak ({r['variant']}): {r['error']}")
        if skipped:
            w("Not run: " + "; ".join(sorted(skipped)) + ".")
            w("")
        peaks = [r for r in peaks if not r["error"]]
        if peaks:
            w("Arithmetic peak (`BM_MultiplyAddPeak`: independent multiply-add chains in registers):")
            w("")
            w("| instruction set | threads | flops/s | flops/s per thread |")
            w("| --- | --- | --- | --- |")
            for r in peaks:
                w(f"| {r['variant']} | {r['args'].get('threads')} | {si(r['b'].get('flops_per_s'))} | "
                  f"{si(r['b'].get('flops_per_s_per_thread'))} |")
            w("")
            lines = []
            for r in peaks:
                if r["args"].get("threads") != 1:
                    continue
                ref = counter(find(bim, "BM_StokesletReference", r["variant"], triangles=5120, threads=1), "pairs_per_s")
                if ref:
                    ops = ref * STOKESLET_FLOPS_PER_PAIR
                    lines.append(f"{r['variant']} {si(ops)} operations/s, {ops / r['b']['flops_per_s']:.0%} of its peak")
            if lines:
                w(f"Counting about {STOKESLET_FLOPS_PER_PAIR} operations per pair (the square root and the division")
                w("as one each), the one-thread reference kernels at 5120 triangles do: " + "; ".join(lines) + ".")
                w("A square root and a division each occupy the divider for several multiply-add slots, so the")
                w("kernel is bound by them and stays well below the multiply-add peak even when written as")
                w("tightly as the reference.")
                w("")

    w("## Running one benchmark")
    w("")
    w("    cmake --preset release && cmake --build --preset release")
    w("    ./build/release/bench_bending --benchmark_filter='BM_Compute/C/'")
    w("    ./build/release/bench_bim --benchmark_filter='triangles:5120'")
    w("")
    os.makedirs(os.path.dirname(a.out) or ".", exist_ok=True)
    tmp = a.out + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(out))
    os.replace(tmp, a.out)


if __name__ == "__main__":
    main()
