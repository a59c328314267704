"""The section "Order of the methods" of docs/benchmarks.md (scripts/make_benchmarks_doc.py
--section order): written from the BM_Order rows of a bench_bending report into an existing
document, in place of the section if it is there, before "Running one benchmark" if not, the
rest of the document unchanged."""
import json
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "make_benchmarks_doc.py"


def order_report(times):
    """A bench_bending JSON report with BM_Order rows: times[(q, p)] = (cpu ms, page faults per call)."""
    rows = []
    for (q, p), (cpu, faults) in times.items():
        rows.append({"name": f"BM_Order/{q}/after:{p}/iterations:5/real_time", "run_type": "iteration",
                     "real_time": cpu * 1.5, "cpu_time": cpu, "time_unit": "ms", "iterations": 5,
                     "page_faults_per_call": faults, "vertices": 40962})
    rows.append({"name": "BM_Compute/C/triangles:81920/threads:1/real_time", "run_type": "iteration",
                 "real_time": 9.0, "cpu_time": 8.0, "time_unit": "ms", "iterations": 50})
    return {"context": {}, "benchmarks": rows}


def run(tmp_path, times, doc):
    results = tmp_path / "results"
    results.mkdir(exist_ok=True)
    (results / "bench_bending.json").write_text(json.dumps(order_report(times)))
    (results / "machine.txt").write_text("load_start: 0.5 0.6 0.7\nload_end: 0.8 0.9 1.0\n")
    out = tmp_path / "benchmarks.md"
    out.write_text(doc)
    subprocess.run([sys.executable, str(SCRIPT), "--section", "order", "--results", str(results), "--out", str(out)],
                   check=True)
    return out.read_text()


def test_section_inserted_before_the_last_one_and_the_rest_kept(tmp_path):
    doc = "# Benchmarks\n\n## Bending\n\ntable\n\n## Running one benchmark\n\n    cmd\n"
    times = {("A", "A"): (12.0, 0.0), ("A", "C"): (13.0, 0.0), ("C", "A"): (8.0, 0.0), ("C", "C"): (9.0, 2.0)}
    text = run(tmp_path, times, doc)
    assert text.startswith("# Benchmarks\n\n## Bending\n\ntable\n\n## Order of the methods (`BM_Order`)")
    assert text.rstrip().endswith("## Running one benchmark\n\n    cmd")
    assert "| Q, after P: | A | C | spread | noise | page faults per call (max) |" in text
    assert "| A | 12 | 13 | 1.08 | - | 0 |" in text
    assert "| C | 8 | 9 | 1.13 | - | 2 |" in text
    assert "0.5 0.6 0.7" in text and "0.8 0.9 1.0" in text


def test_section_replaced_in_place(tmp_path):
    doc = ("# Benchmarks\n\n## Order of the methods (`BM_Order`)\n\nold table\n\n"
           "## Running one benchmark\n\n    cmd\n")
    text = run(tmp_path, {("C", "C"): (9.0, 0.0)}, doc)
    assert "old table" not in text
    assert text.count("## Order of the methods") == 1
    assert "| C | 9 | 1.00 | - | 0 |" in text


def test_repetitions_give_medians_and_noise(tmp_path):
    # Three repetitions of each pair (rows with the same name): the median in the cell, the
    # largest coefficient of variation of a pair as the row's noise.
    results = tmp_path / "results"
    results.mkdir()
    rows = []
    for p, reps in (("A", (10.0, 11.0, 12.0)), ("C", (10.0, 10.0, 10.0))):
        for cpu in reps:
            rows.append({"name": f"BM_Order/C/after:{p}/iterations:5/real_time", "run_type": "iteration",
                         "real_time": cpu, "cpu_time": cpu, "time_unit": "ms", "iterations": 5,
                         "page_faults_per_call": 0.0})
        rows.append({"name": f"BM_Order/C/after:{p}/iterations:5/real_time_mean", "run_type": "aggregate",
                     "aggregate_name": "mean", "real_time": 11.0, "cpu_time": 11.0, "time_unit": "ms"})
    (results / "bench_bending.json").write_text(json.dumps({"context": {}, "benchmarks": rows}))
    out = tmp_path / "benchmarks.md"
    out.write_text("# Benchmarks\n\n## Running one benchmark\n")
    subprocess.run([sys.executable, str(SCRIPT), "--section", "order", "--results", str(results), "--out", str(out)],
                   check=True)
    text = out.read_text()
    assert "the median of 3 repetitions" in text
    assert "| C | 11 | 10 | 1.10 | 9% | 0 |" in text


def ratio_report(interleaved, apart):
    """A bench_bending report with Method M's and C's forces timed apart (M `apart` times C) and in
    turn (BM_ForcesRatio, M `interleaved` times C)."""
    def row(name, real, cpu, **counters):
        return dict({"name": name, "run_type": "iteration", "real_time": real, "cpu_time": cpu,
                     "time_unit": "ms", "iterations": 10}, **counters)
    return {"context": {}, "benchmarks": [
        row("BM_Forces/C/triangles:20480/threads:1/real_time", 1.5, 1.5),
        row("BM_Forces/M/triangles:20480/threads:1/real_time", 1.5 * apart, 1.5 * apart),
        row("BM_ForcesRatio/M/over:C/triangles:20480/real_time", 16.0, 16.0, ratio=interleaved,
            m_ms=1.5 * interleaved, c_ms=1.5)]}


def m_target_line(tmp_path, interleaved, apart):
    results = tmp_path / "results"
    results.mkdir(exist_ok=True)
    (results / "bench_bending.json").write_text(json.dumps(ratio_report(interleaved, apart)))
    (results / "machine.txt").write_text("load_start: 0.5 0.6 0.7\nload_end: 0.8 0.9 1.0\n")
    out = tmp_path / "benchmarks.md"
    subprocess.run([sys.executable, str(SCRIPT), "--results", str(results), "--out", str(out)], check=True)
    lines = [l for l in out.read_text().splitlines() if l.startswith("| Method M (`forces`)")]
    assert len(lines) == 1
    return lines[0]


def test_method_m_target_is_judged_on_the_calls_in_turn(tmp_path):
    # A machine that slowed down while M's forces ran alone: apart 12.3 times, in turn 9.0.
    line = m_target_line(tmp_path, interleaved=9.0, apart=12.3)
    assert "9.0 times" in line and "timed apart (BM_Forces): 12.3 times" in line
    assert "| met |" in line


def test_method_m_target_not_met_in_turn(tmp_path):
    line = m_target_line(tmp_path, interleaved=11.0, apart=9.0)
    assert "**not met**" in line


def b_doc(tmp_path, compute_ms, forces_ms):
    """The document of a report whose Method B compute and forces take these one-thread times at
    81920 triangles (40962 vertices)."""
    def row(name, t):
        return {"name": name, "run_type": "iteration", "real_time": t, "cpu_time": t, "time_unit": "ms",
                "iterations": 10, "vertices": 40962, "vertices_per_s_per_thread": 40962 / (t * 1e-3)}
    results = tmp_path / "results"
    results.mkdir(exist_ok=True)
    report = {"context": {}, "benchmarks": [row("BM_Compute/B/triangles:81920/threads:1/real_time", compute_ms),
                                            row("BM_Forces/B/triangles:81920/threads:1/real_time", forces_ms)]}
    (results / "bench_bending.json").write_text(json.dumps(report))
    (results / "machine.txt").write_text("load_start: 0.5 0.6 0.7\nload_end: 0.8 0.9 1.0\n")
    out = tmp_path / "benchmarks.md"
    subprocess.run([sys.executable, str(SCRIPT), "--results", str(results), "--out", str(out)], check=True)
    return out.read_text()


def test_b_compute_not_met_states_why_from_the_two_times(tmp_path):
    # 3 M vertices/s is 13.65 ms for 40962 vertices: compute 17 ms misses it, forces 9 ms meets it.
    doc = b_doc(tmp_path, compute_ms=17.0, forces_ms=9.0)
    why = [l for l in doc.splitlines() if l.startswith("Why Method B's `compute` is not met")]
    assert len(why) == 1
    assert "(9 ms," in why[0] and "(8 ms more)" in why[0]
    # The geometry pass would have to fit in 13.654 - 9 = 4.654 ms: 0.58 of its 8 ms.
    assert "0.58 of what it takes here" in why[0]


def test_b_compute_met_needs_no_reason(tmp_path):
    doc = b_doc(tmp_path, compute_ms=12.0, forces_ms=9.0)
    assert "Why Method B" not in doc
