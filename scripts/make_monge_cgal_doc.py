#!/usr/bin/python3
"""Writes docs/results/monge_cgal.md: Method M's H and K against CGAL's Monge_via_jet_fitting.

    /usr/bin/python3 scripts/make_monge_cgal_doc.py [--build DIR] [--results DIR] [--repeats R]
                                                    [--skip-run] [--out FILE]

Runs (unless --skip-run) `monge_cgal_compare --repeats R` from the release build (built only where
CGAL is installed: `apt-get install libcgal-dev`, then `cmake --preset release && cmake --build
--preset release --target monge_cgal_compare`; CGAL is an optional peer, not a dependency) with one
OpenMP thread, and writes its CSV, its support check and the machine to DIR (default
docs/results/monge_cgal), then the document from them. The program's header (bench/monge_cgal_compare.cpp)
says what is compared and how.
"""
import argparse
import csv
import datetime
import math
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FITS = ["M5", "M4", "M6", "CGAL4", "CGAL5"]
FIT_TEXT = {
    "M5": "M, degree 5 (METHOD_M.md's degree; the supports are its 3-ring widened to 24 points)",
    "M6": "M, degree 6 (the method's default) on the same supports (the method itself widens a support of fewer than 31 points)",
    "M4": "M, degree 4",
    "CGAL4": "CGAL, d_fitting = 4, d_monge = 4",
    "CGAL5": "CGAL, d_fitting = 5, d_monge = 4",
}
FAMILY_TEXT = {"mt1": "MT1", "irregular": "irregular"}


def command_line(build, repeats):
    return [os.path.join(build, "monge_cgal_compare"), "--repeats", str(repeats)]


def cpu_model():
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    for line in out.splitlines():
        if line.startswith("Model name:"):
            return line.split(":", 1)[1].strip()
    return "unknown"


def loadavg():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def run(results, build, repeats):
    program = os.path.join(build, "monge_cgal_compare")
    if not os.path.exists(program):
        sys.exit("make_monge_cgal_doc.py: %s not found: install libcgal-dev and build the target "
                 "monge_cgal_compare (cmake --build --preset release --target monge_cgal_compare)" % program)
    os.makedirs(results, exist_ok=True)
    load_start = loadavg()
    proc = subprocess.run(command_line(build, repeats), env=dict(os.environ, OMP_NUM_THREADS="1"),
                          capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit("make_monge_cgal_doc.py: monge_cgal_compare failed:\n" + proc.stderr)
    with open(os.path.join(results, "compare.csv"), "w") as f:
        f.write(proc.stdout)
    with open(os.path.join(results, "check.txt"), "w") as f:
        f.write(proc.stderr)
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip()
    dirty = subprocess.run(["git", "diff", "--quiet", "HEAD"], cwd=ROOT).returncode != 0
    cgal = subprocess.run(["dpkg-query", "-W", "-f=${Version}", "libcgal-dev"], capture_output=True,
                          text=True).stdout.strip() or "unknown"
    with open(os.path.join(results, "machine.txt"), "w") as f:
        f.write("date: %s\n" % datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"))
        f.write("commit: %s%s\n" % (commit, " (with uncommitted changes)" if dirty else ""))
        f.write("cpu: %s\n" % cpu_model())
        f.write("nproc: %d\n" % os.cpu_count())
        f.write("cgal: libcgal-dev %s\n" % cgal)
        f.write("repeats: %d\n" % repeats)
        f.write("load_start: %s\n" % load_start)
        f.write("load_end: %s\n" % loadavg())


def read_rows(results):
    with open(os.path.join(results, "compare.csv")) as f:
        rows = list(csv.DictReader(f))
    data = {}
    for r in rows:
        key = (r["family"], int(r["triangles"]), r["fit"])
        data[key] = {k: (float(v) if k not in ("family", "fit") else v) for k, v in r.items()}
    return data


def g(x):
    return "%.3g" % x


def slope(points):
    """Least-squares slope of log(error) against log(h), h ~ triangles^(-1/2)."""
    xs = [-0.5 * math.log(t) for t, _ in points]
    ys = [math.log(e) for _, e in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)


def write_doc(results, out, build, repeats):
    data = read_rows(results)
    with open(os.path.join(results, "machine.txt")) as f:
        machine = f.read().strip()
    with open(os.path.join(results, "check.txt")) as f:
        check = f.read().strip()
    families = []
    sizes = {}
    for (fam, tri, _fit) in data:
        if fam not in families:
            families.append(fam)
        sizes.setdefault(fam, set()).add(tri)
    sizes = {f: sorted(s) for f, s in sizes.items()}

    cmd = " ".join(os.path.relpath(a, ROOT) if os.path.isabs(a) else a for a in command_line(build, repeats))
    L = []
    L.append("# Method M against CGAL's jet fitting (H and K on the same supports)")
    L.append("")
    L.append("Generated by `/usr/bin/python3 scripts/make_monge_cgal_doc.py` (do not edit by hand).")
    L.append("")
    L.append("Method M (METHOD_M.md, `monge_jet.hpp`) fits at each node a height polynomial without constant term "
             "in a chart whose normal is the covariance normal of the 2-ring, by normal equations and a Cholesky "
             "factorisation. CGAL's `Monge_via_jet_fitting` (CGAL 5.5, header only; an optional peer, not a "
             "dependency of bendlab) fits a full jet, constant term included, in the PCA frame of all the points, "
             "by an SVD (`Eigen::JacobiSVD`) of the design matrix, and returns the principal curvatures k1 >= k2 "
             "of the Monge form (d_monge <= 4 and <= d_fitting; d_fitting = 5 with d_monge = 4 is allowed).")
    L.append("")
    L.append("Every fit gets, at every node, the same points: those `monge_jet_fit` uses for M's default "
             "degree-5 fit (3-ring, widened to at least 24 points; %d-%d points on these meshes), the node "
             "first for CGAL. The program checks that M's degree-5 H and K per node equal `monge_jet_fit`'s "
             "bit for bit, so the supports are the method's. CGAL's Monge normal is turned to the analytic "
             "outward normal; with it CGAL's curvatures are the eigenvalues of I^-1 II with II = n . X_uu, "
             "negative on a sphere, so H = -(k1 + k2) / 2 (H > 0 on a sphere, docs/conventions.md) and "
             "K = k1 k2." % (min(r["support_min"] for r in data.values()), max(r["support_max"] for r in data.values())))
    L.append("")
    L.append("Surfaces: the red blood cell of the static study (`make_rbc()`, eq. (15)), meshed by MT1 and by "
             "the irregular family (MT1 jittered tangentially by 0.25 of the mean edge, `irregular_sphere_mesh`). "
             "Errors as in eq. (17): |H_a - H| / max|H_a| per node (likewise K), the maximum and the mean over "
             "the nodes. Fits:")
    L.append("")
    for fit in FITS:
        L.append("- `%s`: %s" % (fit, FIT_TEXT[fit]))
    L.append("")
    L.append("Command (one OpenMP thread; the fits are single-threaded loops over the vertices):")
    L.append("")
    L.append("```")
    L.append("OMP_NUM_THREADS=1 " + cmd)
    L.append("```")
    L.append("")
    L.append("```")
    L.append(machine)
    L.append("```")
    L.append("")
    L.append("Support check (stderr of the program):")
    L.append("")
    L.append("```")
    L.append(check)
    L.append("```")
    L.append("")

    for q, qname in (("H", "H"), ("K", "K")):
        L.append("## Errors of %s (eq. (17), relative to max|%s| of the surface)" % (qname, qname))
        L.append("")
        head = "| mesh | triangles | " + " | ".join("%s max | %s mean" % (f, f) for f in FITS) + " |"
        L.append(head)
        L.append("|" + " --- |" * (2 + 2 * len(FITS)))
        for fam in families:
            for tri in sizes[fam]:
                cells = []
                for fit in FITS:
                    r = data[(fam, tri, fit)]
                    cells.append(g(r["max_" + q]))
                    cells.append(g(r["mean_" + q]))
                L.append("| %s | %d | %s |" % (FAMILY_TEXT.get(fam, fam), tri, " | ".join(cells)))
        L.append("")
        fin = {fam: sizes[fam][-3:] for fam in families}
        L.append("Order of the maximum error (least-squares slope of log error against log h over the three finest "
                 "meshes, h ~ triangles^-1/2):")
        L.append("")
        L.append("| mesh | " + " | ".join(FITS) + " |")
        L.append("|" + " --- |" * (1 + len(FITS)))
        for fam in families:
            if len(fin[fam]) < 3:
                continue
            cells = [("%.2f" % slope([(t, data[(fam, t, fit)]["max_" + q]) for t in fin[fam]])) for fit in FITS]
            L.append("| %s (%d-%d) | %s |" % (FAMILY_TEXT.get(fam, fam), fin[fam][0], fin[fam][-1], " | ".join(cells)))
        L.append("")

    L.append("## Time per vertex")
    L.append("")
    L.append("One fit per vertex (frame and solve; the points gathered beforehand), best of the repeats by wall "
             "time (steady_clock), and the thread's processor time in that repeat. On a shared machine the "
             "processor time is the steadier figure (the process is descheduled while others run: compare "
             "load_start, load_end and nproc above), and the ratios are taken of it.")
    L.append("")
    L.append("| mesh | triangles | " + " | ".join("%s cpu (us) | %s wall (us)" % (f, f) for f in FITS)
             + " | CGAL4 / M4 | CGAL5 / M5 | CGAL4 / M5 |")
    L.append("|" + " --- |" * (2 + 2 * len(FITS) + 3))
    ratios = {"CGAL4 / M4": [], "CGAL5 / M5": [], "CGAL4 / M5": []}
    for fam in families:
        for tri in sizes[fam]:
            c = {fit: data[(fam, tri, fit)]["cpu_us_per_vertex"] for fit in FITS}
            w = {fit: data[(fam, tri, fit)]["us_per_vertex"] for fit in FITS}
            r = {"CGAL4 / M4": c["CGAL4"] / c["M4"], "CGAL5 / M5": c["CGAL5"] / c["M5"],
                 "CGAL4 / M5": c["CGAL4"] / c["M5"]}
            for k, v in r.items():
                ratios[k].append(v)
            cells = []
            for fit in FITS:
                cells += ["%.2f" % c[fit], "%.2f" % w[fit]]
            L.append("| %s | %d | %s | %.1f | %.1f | %.1f |" % (FAMILY_TEXT.get(fam, fam), tri, " | ".join(cells),
                                                                r["CGAL4 / M4"], r["CGAL5 / M5"], r["CGAL4 / M5"]))
    L.append("")

    # The reading: every figure below comes from the tables above.
    L.append("## Reading")
    L.append("")
    finest = {fam: sizes[fam][-1] for fam in families}
    lines = []
    for q in ("H", "K"):
        parts = []
        for fam in families:
            t = finest[fam]
            m5 = data[(fam, t, "M5")]["max_" + q]
            best_cgal = min(("CGAL4", "CGAL5"), key=lambda f: data[(fam, t, f)]["max_" + q])
            cg = data[(fam, t, best_cgal)]["max_" + q]
            m4 = data[(fam, t, "M4")]["max_" + q]
            c4 = data[(fam, t, "CGAL4")]["max_" + q]
            parts.append("%s %d: M5 %s, the better CGAL fit (%s) %s (%.2f x M5's); at degree 4 M %s, CGAL %s "
                         "(%.2f x)" % (FAMILY_TEXT.get(fam, fam), t, g(m5), best_cgal, g(cg), cg / m5, g(m4),
                                       g(c4), c4 / m4))
        lines.append("- Maximum error of %s at the finest mesh: %s." % (q, "; ".join(parts)))
    wins = []
    for q in ("H", "K"):
        for stat in ("max", "mean"):
            n_m5_best = 0
            total = 0
            for fam in families:
                for tri in sizes[fam]:
                    total += 1
                    vals = {f: data[(fam, tri, f)]["%s_%s" % (stat, q)] for f in ("M5", "M4", "CGAL4", "CGAL5")}
                    if min(vals, key=vals.get) == "M5":
                        n_m5_best += 1
            wins.append("%s error of %s: %d of %d" % (stat, q, n_m5_best, total))
    lines.append("- Meshes on which M5 has the smallest error of the four fits of degree 4 and 5: %s." % "; ".join(wins))
    for q in ("H", "K"):
        parts = []
        for fam in families:
            t = finest[fam]
            vals = {f: data[(fam, t, f)]["mean_" + q] for f in FITS}
            best = min(vals, key=vals.get)
            other = "" if best == "M5" else "; M5 %s" % g(vals["M5"])
            parts.append("%s %d: %s (%s%s)" % (FAMILY_TEXT.get(fam, fam), t, best, g(vals[best]), other))
        lines.append("- Smallest mean error of %s at the finest mesh: %s." % (q, "; ".join(parts)))
    for k, v in ratios.items():
        lines.append("- Processor time %s: %.1f to %.1f over all meshes." % (k, min(v), max(v)))
    invalid = sorted("%s %d %s" % (FAMILY_TEXT.get(k[0], k[0]), k[1], k[2]) for k, r in data.items() if r["valid"] != 1)
    L.extend(lines)
    L.append("")
    robustness = ("no fit was refused and no value is NaN on these meshes (column `valid` of compare.csv)"
                  if not invalid else "fits with a refused or NaN node: " + ", ".join(invalid))
    L.append("What this does and does not show: the fits differ in three ways at once (M has no constant term, "
             "so its surface passes through the node; the chart normal is the 2-ring covariance normal for M and "
             "the PCA axis of the whole support for CGAL; normal equations with Cholesky against an SVD), and "
             "this comparison does not separate their effects on the error. The SVD is the more robust solver "
             "for ill-conditioned supports; here " + robustness + ". The times are of these implementations as they are "
             "(CGAL's generic kernel and dynamic-size matrices against M's fixed-size ones), not of the "
             "mathematics. Only H and K are compared: CGAL returns no Lap H, which M's force needs (eq. (10)); "
             "its third- and fourth-order Monge coefficients would give one, which is not done here.")
    L.append("")
    os.makedirs(os.path.dirname(out), exist_ok=True)
    with open(out, "w") as f:
        f.write("\n".join(L))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build", "release"))
    ap.add_argument("--results", default=os.path.join(ROOT, "docs", "results", "monge_cgal"))
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--skip-run", action="store_true")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "monge_cgal.md"))
    a = ap.parse_args()
    if not a.skip_run:
        run(a.results, a.build, a.repeats)
    write_doc(a.results, a.out, a.build, a.repeats)
    print("wrote", a.out)


if __name__ == "__main__":
    main()
