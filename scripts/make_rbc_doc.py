#!/usr/bin/python3
"""Writes docs/results/rbc.md from the output folder of `bendlab rbc`.

    /usr/bin/python3 scripts/make_rbc_doc.py STUDY_DIR [RESULTS_DIR] [--command "..."]

STUDY_DIR is the --out folder of `bendlab rbc` (after its plots were drawn). RESULTS_DIR (default
docs/results of this repository) receives rbc.md and, in rbc/, the plots and the small tables
(errors.csv, timings.csv, errors.json, table2.md, table3.md); the large per-node files stay in
STUDY_DIR. --command is the command line quoted at the top of the document. --polar DIR adds
the errors of Method S with the icosahedron's vertex at the poles (the --out folder of
`bendlab rbc --base polar --families mt1 --methods S --no-plots`) beside the default orientation.
--extra DIR merges the errors.json of another study of the same meshes and other methods (e.g.
`bendlab rbc --methods J --out DIR`) into STUDY_DIR's tables, so a method added later is run alone;
its plots (DIR/*.png) are copied with the prefix "extra_".

Our tables 2 and 3 are set beside the paper's, transcribed below from
  A. Guckenberger, M. P. Schraml, P. G. Chen, M. Leonetti, S. Gekle, "On the bending algorithms
  for soft objects in flows", Comput. Phys. Commun. 207 (2016) 1-23, tables 2 and 3
  (the specification, /work/shared/spec/000_f8e619346cfc3715.txt).
The paper's tables use MT2 meshes for Methods A-E and MT1 for Method S; resolutions 320-81920.
"""
import json
import os
import shutil
import sys

PAPER_SOURCE = ("Guckenberger et al., *On the bending algorithms for soft objects in flows*, "
                "Comput. Phys. Commun. 207 (2016), tables 2 and 3")
PAPER_METHODS = ["A", "B", "C", "D", "E", "S"]
# Methods beyond the paper: no paper symbol exists for them (Method J: Juelicher 1996, docs/design.md).
NOT_IN_PAPER = {"ED": "the paper's proposed mixture (E for n, H, K and D's operator for Lap H), not in its tables",
                "J": "Juelicher's edge-based mean curvature and its energy gradient (Juelicher 1996, compared by "
                     "Bian et al. 2020); the paper has no Method J",
                "M": "Monge jets (../shared/spec/METHOD_M.md): a degree-6 height polynomial fitted on the 3-ring in the "
                     "chart of the 2-ring's covariance normal gives n, H and K, and the fits' Laplace-Beltrami operator "
                     "applied to H gives Lap H; beyond the paper, its answer to the paper's open problem (no method's "
                     "maximal error of f converges)"}
# None: the method does not compute the quantity (empty cell in the paper).
PAPER_TABLE2 = {
    "max": {
        "K": [None, None, "○", "○", "●", "○"],
        "H": [None, None, "○", "●", "●", "○"],
        "lapH": [None, None, "■", "○", "■", None],
        "f": ["■", "■", "■", "○", "■", "■"],
    },
    "avg": {
        "K": [None, None, "●", "●", "●", "●"],
        "H": [None, None, "●", "●", "●", "●"],
        "lapH": [None, None, "○", "●", "○", None],
        "f": ["■", "○", "○", "●", "○", "○"],
    },
}
PAPER_TABLE3_METHODS = ["A", "B", "C", "D", "E"]
PAPER_TABLE3 = {
    "K": [None, None, "■", "■", "■"],
    "H": [None, None, "■", "●", "■"],
    "lapH": [None, None, "■", "○", "■"],
    "f": ["■", "■", "■", "○", "■"],
}
# What the paper's text (section 3 and appendix B, MT2) says about cells whose symbol is borderline:
# quoted beside our explanation where the cell differs. Keyed by (measure, quantity, method).
PAPER_TEXT = {
    ("max", "lapH", "D"): "Appendix B: on MT2 'the maximal error for the otherwise very robust Method D starts to "
                          "increase with resolutions beyond 20480 triangles'",
    ("max", "f", "D"): "Appendix B: for f 'the same observation as for Lap H hold for Methods C-E' (D's maximal "
                       "error grows beyond 20480 triangles on MT2)",
    ("avg", "lapH", "D"): "Appendix B: on MT2 D's 'rate for the average error is reduced from O(h^2) to O(h)'",
    ("avg", "f", "D"): "section 3.5: 'Method D appears to converge with O(h) only for the MT2 average error'",
    ("avg", "lapH", "C"): "section 3.4: 'Regarding the average error measure, Method C retains a systematic "
                          "deviation'",
    ("avg", "f", "C"): "section 3.5: 'The averaged error remains roughly constant for C'",
    ("avg", "lapH", "E"): "appendix B: on MT2 E's average error 'remains constant beyond 5120 triangles'",
}
MEANING2 = {"●": "convergence to zero", "○": "convergence to a systematic error", "■": "divergence"}
MEANING3 = {"●": "no troubles", "○": "problems in the maximal error only",
            "■": "a significant increase of both error measures"}
QUANTITY_NAMES = {"K": "K", "H": "H", "lapH": "Lap H", "f": "f", "n": "n"}
S_FAMILY = "mt1"  # the paper's meshes for Method S
# METHOD_S.md section 5 (an independent implementation of S: MT1 RBC, L P = X, 6-point rule, the
# default icosahedron): max / avg errors by N_T, and E_B (exact 48.47346).
METHOD_S_EXPECTED = {
    320: {"n": (1.2e-2, 3.6e-3), "H": (0.13, 3.2e-2), "K": (0.33, 4.2e-2), "f": (0.32, 0.141), "E": 48.4662},
    1280: {"n": (2.4e-3, 5.7e-4), "H": (5.5e-2, 9.0e-3), "K": (0.19, 1.3e-2), "f": (0.36, 0.049), "E": 48.4763},
    5120: {"n": (1.0e-3, 8.7e-5), "H": (5.0e-2, 2.6e-3), "K": (0.19, 3.8e-3), "f": (1.7, 0.060), "E": 48.4742},
    20480: {"n": (4.7e-4, 1.1e-5), "H": (4.9e-2, 7.2e-4), "K": (0.19, 1.1e-3), "f": (8.5, 0.072), "E": 48.4736},
}
DEFAULT_JITTER, DEFAULT_JITTER_SEED = 0.25, 28  # bendlab rbc's --jitter and --jitter-seed defaults
COPIED = ["errors.csv", "timings.csv", "errors.json", "table2.md", "table3.md"]


def paper_cell(table, methods, quantity, method):
    if method not in methods:
        return None
    return table[quantity][methods.index(method)]


def fmt_slope(s):
    return "n/a" if s is None else f"{s:+.1f}"


def fmt_err(e):
    return "n/a" if e is None else f"{e:.3g}"


def explain_rate(fit, paper, thresholds, measure, max_paper_triangles=81920):
    tri = fit["triangles"]
    tail = min(len(tri), thresholds["tail_points"])
    errs = fit["error"]
    ours = fit["symbol"]
    text = (f"our slope over the {tail} finest meshes ({tri[-tail]}-{tri[-1]} triangles) is "
            f"{fmt_slope(fit['slope_tail'])}, between the two finest {fmt_slope(fit['slope_last'])} "
            f"(error {fmt_err(errs[-2])} -> {fmt_err(errs[-1])}), which reads as {MEANING2.get(ours, ours)}; "
            f"the paper saw {MEANING2[paper]}")
    if tri[-1] < max_paper_triangles:
        text += f" at resolutions up to {max_paper_triangles} (ours stop at {tri[-1]})"
    # Name the case where the trend is only a matter of where the thresholds cut.
    s = fit["slope_tail"]
    if s is not None and (abs(s - thresholds["to_zero_slope"]) < 0.15 or abs(s - thresholds["diverge_slope"]) < 0.15):
        text += "; the slope lies near a threshold, so the symbol is marginal"
    quote = PAPER_TEXT.get((measure, fit["quantity"], fit["method"]))
    if quote:
        text += f" (the paper's text, {quote})"
    return text + "."


def explain_trouble(c, paper, factor):
    return (f"at h = {c['h']:.4f} the {c['triangles']}-triangle mesh has maximal / average errors "
            f"{fmt_err(c['max_error'])} / {fmt_err(c['avg_error'])}, {c['ratio_max']:.2g}x / {c['ratio_avg']:.2g}x "
            f"the homogeneous {c['origin'].upper()} meshes at that h (threshold {factor}x), which reads as "
            f"{MEANING3.get(c['symbol'], c['symbol'])}; the paper saw {MEANING3[paper]} on its 3848-triangle mesh.")


def md_table(header, rows):
    out = "| " + " | ".join(header) + " |\n|" + "---|" * len(header) + "\n"
    for r in rows:
        out += "| " + " | ".join(r) + " |\n"
    return out


def table2_section(study, family, measure):
    # The paper's S column is on MT1 meshes (A-E on MT2): S's cells come from our MT1 fits.
    fits = {(f["method"], f["quantity"]): f for f in study["rates"]
            if f["family"] == (S_FAMILY if f["method"] == "S" else family) and f["measure"] == measure}
    methods = study["options"]["methods"]
    cols = list(dict.fromkeys(methods + PAPER_METHODS))
    rows, diffs = [], []
    for q in ["K", "H", "lapH", "f", "n"]:
        cells = [QUANTITY_NAMES[q]]
        for m in cols:
            f = fits.get((m, q))
            ours = f["symbol"] if f else ""
            paper = paper_cell(PAPER_TABLE2[measure], PAPER_METHODS, q, m) if q in PAPER_TABLE2[measure] else None
            paper_text = paper if paper else ("" if (m in PAPER_METHODS and q != "n") else "n/a")
            cells.append(f"{ours or '–'} / {paper_text or '–'}")
            if f and paper and f["symbol"] != paper:
                diffs.append([QUANTITY_NAMES[q], m, f["symbol"], paper,
                              explain_rate(f, paper, study["thresholds"], measure)])
        rows.append(cells)
    return md_table(["quantity"] + cols, rows), diffs


def table3_section(study, family):
    checks = {(c["method"], c["quantity"]): c for c in study["inhomogeneous"] if c["family"] == family}
    refused = {r["method"]: r["reason"] for r in study.get("refused", []) if r["family"] == family}
    methods = study["options"]["methods"]
    cols = list(dict.fromkeys(methods + PAPER_TABLE3_METHODS))
    rows, diffs = [], []
    factor = study["thresholds"]["inhomogeneous_factor"]
    for q in ["K", "H", "lapH", "f", "n"]:
        cells = [QUANTITY_NAMES[q]]
        for m in cols:
            c = checks.get((m, q))
            paper = paper_cell(PAPER_TABLE3, PAPER_TABLE3_METHODS, q, m) if q in PAPER_TABLE3 else None
            ours = f"{c['symbol']} ({c['ratio_max']:.2g} / {c['ratio_avg']:.2g})" if c and c["ratio_max"] is not None else "–"
            if m in refused:
                ours = "n/a¹"
            cells.append(f"{ours} / {paper or '–'}")
            if c and paper and c["symbol"] != paper:
                diffs.append([QUANTITY_NAMES[q], m, c["symbol"], paper, explain_trouble(c, paper, factor)])
        rows.append(cells)
    table = md_table(["quantity"] + cols, rows)
    for m, reason in refused.items():
        table += f"\n¹ Method {m} refuses this mesh: {reason}. (The paper's table 3 has no column for S either.)\n"
    return table, diffs


def rows_of(study, family, method):
    """{triangles: {quantity: (max, avg)}} of one family and method."""
    out = {}
    for r in study["rows"]:
        if r["family"] == family and r["method"] == method:
            out.setdefault(r["triangles"], {})[r["quantity"]] = (r["max_error"], r["avg_error"])
    return out


def method_s_section(study, polar):
    """Method S on MT1 beside METHOD_S.md section 5, for both icosahedron orientations."""
    md = ["## Method S: the icosahedron's orientation\n"]
    md.append("Method S's errors concentrate at the extraordinary (valence-5) vertices, so they depend on where "
              "the icosahedron puts them on the RBC. **default**: vertices at (±1, ±φ, 0)/|.|, four of them on "
              "the equator, i.e. on the RBC's rim, where the curvature is largest; **polar**: a vertex at each "
              "pole (`icosahedron_polar()`, `bendlab rbc --base polar`). The tables above use the default. "
              "Each cell: ours max / avg, and in brackets the ratio ours / METHOD_S.md section 5 (an "
              "independent implementation, default orientation) for max and avg.\n")
    for label, st in (("default", study), ("polar", polar)):
        if st is None:
            continue
        rows = rows_of(st, S_FAMILY, "S")
        if not rows:
            continue
        header = ["N_T"] + [f"ε_{q}" for q in ("n", "H", "K", "f")]
        table = []
        for n in sorted(rows):
            cells = [str(n)]
            for q in ("n", "H", "K", "f"):
                mx, avg = rows[n].get(q, (None, None))
                if mx is None:
                    cells.append("–")
                    continue
                cell = f"{mx:.2g} / {avg:.2g}"
                exp = METHOD_S_EXPECTED.get(n, {}).get(q)
                if exp and label == "default":
                    cell += f" ({mx / exp[0]:.2f}, {avg / exp[1]:.2f})"
                cells.append(cell)
            table.append(cells)
        md.append(f"### {label} orientation (MT1)\n\n" + md_table(header, table))
    if polar is not None:
        md.append("\nThe polar study: `" + polar.get("command", "bendlab rbc --base polar --families mt1 --methods S")
                  + "` (its errors.json is `rbc/errors_polar.json`).\n")
    return md


# Why a method beyond the paper behaves as it does (data-independent; the numbers are in the tables).
EXPLANATION = {
    "J": "With the barycentric area (a third of the adjacent faces) J's H is exact only where the one-ring "
         "is made of near-equilateral triangles. Around a vertex of valence v whose ring is v isosceles "
         "triangles with apex angle 2 pi / v (the self-similar rings around the 12 valence-5 vertices of the "
         "MT1 and MT2 families, and the valence-4 vertices of the octahedron family) H_i R tends to "
         "3 / (4 cos^2(pi / v)) instead of 1 (1.146 for v = 5, tested in tests/bending/test_julicher.cpp; 1.5 for v = 4, "
         "1.4997 measured on the 8192-triangle octahedron sphere), "
         "whatever the resolution. So the maximal errors of H and K stay at a constant level while the "
         "averages converge at about second order, and f = -dE/dx / A_mixed, which differentiates that "
         "defect, grows at those vertices under refinement.",
}


def merge_study(study, extra):
    """Adds the methods of `extra` (a study of the same meshes) to `study`, in place."""
    if [(m["family"], m["triangles"]) for m in extra["meshes"]] != [(m["family"], m["triangles"]) for m in study["meshes"]]:
        sys.exit("make_rbc_doc.py: --extra: the extra study's meshes differ from the main study's")
    new = [m for m in extra["options"]["methods"] if m not in study["options"]["methods"]]
    for key in ("rows", "rates", "inhomogeneous", "timings", "refused"):
        study.setdefault(key, [])
        study[key] += [r for r in extra.get(key, []) if r["method"] in new]
    study["options"]["methods"] = study["options"]["methods"] + new
    return new


def extra_section(study, methods):
    """Max / avg errors of methods beyond the paper on every mesh family, from the study's rows."""
    md = []
    for m in methods:
        md.append(f"## Method {m}: errors on every mesh family (not in the paper)\n")
        md.append(f"{NOT_IN_PAPER.get(m, 'not in the paper')}. Each cell: max / avg error of eq. (17); – : not "
                  "computed by the method.\n")
        if m in EXPLANATION:
            md.append(EXPLANATION[m] + "\n")
        quantities = [q for q in ("n", "H", "K", "lapH", "f")
                      if any(r["method"] == m and r["quantity"] == q for r in study["rows"])]
        fams = list(dict.fromkeys(r["family"] for r in study["rows"] if r["method"] == m))
        table = []
        for fam in fams:
            rows = rows_of(study, fam, m)
            for n in sorted(rows):
                cells = [fam, str(n)]
                for q in quantities:
                    mx, avg = rows[n].get(q, (None, None))
                    cells.append("–" if mx is None else f"{mx:.3g} / {avg:.3g}")
                table.append(cells)
        md.append(md_table(["family", "N_T"] + [f"ε_{QUANTITY_NAMES[q]}" for q in quantities], table))
    return md


def max_error_overview_section(study):
    """The maximal errors of Lap H and f of every method on every refined family, side by side: the slope over
    the three finest meshes and the error at the finest (the paper's open problem in one table)."""
    fams = [f for f in ("mt1", "mt2", "octa", "irregular") if any(r["family"] == f for r in study["rates"])]
    methods = list(study["options"]["methods"])
    md = ["## The maximal error on every family, side by side\n"]
    md.append("The paper's central negative result is that no method's *maximal* error of f converges. Each cell: "
              "the least-squares slope s of log(max error) against log(1/h) over the three finest meshes "
              "(error ~ h^-s, so s = -2 is second order and s > 0 divergence) and, in brackets, the maximal error "
              "of eq. (17) at the finest mesh (81920 triangles; octa: its finest). – : not computed by the method.\n")
    for q in ("lapH", "f"):
        md.append(f"### Maximal error of {QUANTITY_NAMES[q]}\n")
        table = []
        for m in methods:
            cells = [m]
            for fam in fams:
                rate = next((r for r in study["rates"] if r["family"] == fam and r["method"] == m
                             and r["quantity"] == q and r["measure"] == "max"), None)
                if rate is None or rate.get("slope_tail") is None:
                    cells.append("–")
                else:
                    cells.append(f"{rate['slope_tail']:+.2f} ({rate['error'][-1]:.2g})")
            table.append(cells)
        md.append(md_table(["method"] + [f if f == "irregular" else f.upper() for f in fams], table))
    conv = []
    for fam in fams:
        rate = next((r for r in study["rates"] if r["family"] == fam and r["method"] == "M"
                     and r["quantity"] == "f" and r["measure"] == "max"), None)
        if rate is not None and rate.get("slope_tail") is not None:
            conv.append((fam, rate["slope_tail"], rate["error"][-1]))
    if conv:
        worst = max(c[1] for c in conv)
        largest = max(c[2] for c in conv)
        md.append(f"\nMethod M's maximal error of f converges on every family: slopes between "
                  f"{min(c[1] for c in conv):+.2f} and {worst:+.2f} over the three finest meshes (order "
                  f"{-worst:.1f} or better), at most {largest:.2g} of max|f| on the finest meshes.")
        # From which mesh on M has the smallest maximal error of f of all methods, per family.
        lead = []
        for fam in fams:
            sizes = sorted({r["triangles"] for r in study["rows"] if r["family"] == fam})
            best = {}
            for n in sizes:
                errs = {r["method"]: r["max_error"] for r in study["rows"]
                        if r["family"] == fam and r["triangles"] == n and r["quantity"] == "f"}
                best[n] = min(errs, key=errs.get) if errs else None
            first = next((n for k, n in enumerate(sizes) if all(best[m] == "M" for m in sizes[k:])), None)
            lead.append(f"{fam} from {first}" if first else f"{fam} never")
        md.append(" It has the smallest maximal error of f of all methods, on every finer mesh too: "
                  + ", ".join(lead) + " triangles. On the coarsest meshes the 3-ring covers a large part of the cell "
                  "and the degree-6 jet is poorly determined: at 320 triangles its maximal error is the largest of "
                  "the variational methods (the tables of Method M below).\n")
    return md


def jitter_args(opts):
    """The --jitter and --jitter-seed of a study that ran the irregular family with other than the defaults."""
    if "irregular" not in opts["families"]:
        return ""
    out = ""
    if opts.get("jitter", DEFAULT_JITTER) != DEFAULT_JITTER:
        out += f" --jitter {opts['jitter']}"
    if opts.get("jitter_seed", DEFAULT_JITTER_SEED) != DEFAULT_JITTER_SEED:
        out += f" --jitter-seed {opts['jitter_seed']}"
    return out


def irregular_section(study, study_dir, extra_dir, extra_methods):
    """Table 2's symbols on the irregular family beside MT1's, from table2.md of the studies."""
    opts = study["options"]
    md = ["## The irregular family (beyond the paper)\n"]
    md.append(f"MT1 with every node moved in its tangent plane by {opts.get('jitter', DEFAULT_JITTER)} times the mean "
              "length of its edges, in a direction drawn uniformly from std::mt19937_64 seeded with "
              f"{opts.get('jitter_seed', DEFAULT_JITTER_SEED)} + level, and projected back onto the sphere before "
              "the map to the RBC (docs/conventions.md §4). Unlike the Rivara meshes, every level is jittered "
              "afresh, so the meshes stay irregular under refinement: this is where a method's errors show "
              "whether it needs the regularity that MT1 and MT2 gain as they are refined. Cells: symbol (s_tail), "
              "as in table 2; the MT1 table above is the same meshes before the jitter.\n")
    for folder, label in ((study_dir, ""), (extra_dir, f" (Method(s) {', '.join(extra_methods)})")):
        if not folder:
            continue
        with open(os.path.join(folder, "table2.md")) as f:
            t2 = f.read()
        for part in t2.split("\n## ")[1:]:
            head, _, body = part.partition("\n")
            if head.startswith("irregular"):
                md.append(f"#### {head}{label}\n" + body.strip() + "\n")
    return md


def main():
    args = sys.argv[1:]
    command = None
    polar_dir = None
    if "--polar" in args:
        i = args.index("--polar")
        polar_dir = args[i + 1]
        del args[i:i + 2]
    extra_dir = None
    if "--extra" in args:
        i = args.index("--extra")
        extra_dir = args[i + 1]
        del args[i:i + 2]
    if "--command" in args:
        i = args.index("--command")
        command = args[i + 1]
        del args[i:i + 2]
    if not args or len(args) > 2 or (polar_dir is not None and not os.path.isdir(polar_dir)):
        sys.exit(__doc__)
    study_dir = args[0]
    repo = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    results = args[1] if len(args) > 1 else os.path.join(repo, "docs", "results")
    with open(os.path.join(study_dir, "errors.json")) as f:
        study = json.load(f)
    extra_methods, extra = [], None
    main_methods = list(study["options"]["methods"])  # the main study's command line
    if extra_dir:
        with open(os.path.join(extra_dir, "errors.json")) as f:
            extra = json.load(f)
        extra_methods = merge_study(study, extra)
    polar = None
    if polar_dir:
        with open(os.path.join(polar_dir, "errors.json")) as f:
            polar = json.load(f)
        polar["command"] = (f"build/release/bendlab rbc --base polar --families mt1 --methods S "
                            f"--max-triangles {polar['options']['max_triangles']} --no-plots --out {polar_dir}")
    asset_dir = os.path.join(results, "rbc")
    os.makedirs(asset_dir, exist_ok=True)
    pngs = sorted(n for n in os.listdir(study_dir) if n.endswith(".png"))
    for name in COPIED + pngs:
        shutil.copyfile(os.path.join(study_dir, name), os.path.join(asset_dir, name))
    if polar_dir:
        shutil.copyfile(os.path.join(polar_dir, "errors.json"), os.path.join(asset_dir, "errors_polar.json"))
    extra_pngs = []
    if extra_dir:
        shutil.copyfile(os.path.join(extra_dir, "errors.json"), os.path.join(asset_dir, "errors_extra.json"))
        for name in sorted(n for n in os.listdir(extra_dir) if n.endswith(".png")):
            shutil.copyfile(os.path.join(extra_dir, name), os.path.join(asset_dir, "extra_" + name))
            extra_pngs.append("extra_" + name)

    th = study["thresholds"]
    opts = study["options"]
    if command is None:
        command = (f"build/release/bendlab rbc --max-triangles {opts['max_triangles']} "
                   f"--families {','.join(opts['families'])} --methods {','.join(main_methods)}"
                   + (f" --rings {opts['rings']}" if opts.get("rings") else "")
                   + jitter_args(opts)
                   + f" --out {study_dir} && /usr/bin/python3 scripts/make_rbc_doc.py {study_dir}"
                   + (f" --polar {polar_dir}" if polar_dir else "")
                   + (f" --extra {extra_dir}" if extra_dir else ""))
        if extra_dir:
            eo = extra["options"]
            command = (f"build/release/bendlab rbc --max-triangles {eo['max_triangles']} --families "
                       f"{','.join(eo['families'])} --methods {','.join(eo['methods'])}{jitter_args(eo)} "
                       f"--out {extra_dir} && " + command)
        if polar_dir:
            command = polar["command"] + " && " + command
    md = []
    md.append("# The static red blood cell (paper section 3)\n")
    md.append("Generated; do not edit. Regenerate with\n\n```sh\n" + command + "\n```\n")
    md.append("`bendlab rbc` runs the study, writes the tables and draws the plots (scripts/plot_rbc.py); "
              "scripts/make_rbc_doc.py writes this page and copies the plots and small tables to `rbc/`.\n")

    md.append("## Setup\n")
    m = study["maxima"]
    md.append(f"RBC of eq. (15), R = {study['radius']}, kB = {study['kappa_b']}. Error measures of eq. (17), "
              f"normalised by the maxima over the whole surface: max|H| = {m['H']:.6g}, max|K| = {m['K']:.6g}, "
              f"max|Lap H| = {m['lapH']:.6g}, max|f| = {m['f']:.6g}. h is the mean edge length of the RBC mesh.\n")
    md.append(md_table(["family", "level", "triangles", "vertices", "h"],
                       [[x["family"], str(x["level"]) + (" + 3 Rivara" if x["inhomogeneous"] else ""),
                         str(x["triangles"]), str(x["vertices"]), f"{x['h']:.5f}"] for x in study["meshes"]]))
    md.append("\nThe inhomogeneous meshes are the 320-triangle spheres after three passes of Rivara's bisection; "
              "the paper reports 3914 (MT1) and 3848 (MT2) triangles, tie-breaking changes the count. The "
              "irregular meshes (not in the paper) are the MT1 spheres with every node jittered; see the section "
              "on them below.\n")

    md.append("## Table 2: convergence\n")
    md.append(f"Symbols from the least-squares slope s of log(error) against log(1/h) on the finest meshes "
              f"(error ~ h^-s): over the {th['tail_points']} finest meshes (s_tail) and between the two finest "
              f"(s_last). ● converges to zero: s_tail <= {th['to_zero_slope']} and s_last <= {th['to_zero_slope']}; "
              f"■ diverges: s_tail >= {th['diverge_slope']:+} or s_last >= {th['diverge_slope']:+}; "
              f"○ converges to a systematic error: otherwise. Errors below {th['exact_error']:g} count as ●.\n")
    md.append(f"Each cell: **ours / paper**. Paper: {PAPER_SOURCE}, which uses MT2 meshes for Methods A-E "
              "and MT1 for S, so the comparison uses our MT2 meshes for A-E and our MT1 meshes for S; ED (the "
              "paper's proposed mixture: E for n, H, K and D's operator for Lap H), J (Juelicher's method, beyond "
              "the paper) and the normal n are not in the paper's table: their paper cells read n/a. – : not computed.\n")
    for measure, title in (("max", "maximal errors"), ("avg", "average errors")):
        table, diffs = table2_section(study, "mt2", measure)
        md.append(f"### Table 2 ({title}), MT2\n\n" + table)
        if diffs:
            md.append(f"\nCells where we differ from the paper ({title}):\n\n"
                      + md_table(["quantity", "method", "ours", "paper", "explanation"], diffs))
        else:
            md.append("\nEvery cell the paper fills agrees.\n")
    md.append("### Our MT1 version\n")
    md.append("Cells: symbol (s_tail). See `rbc/table2.md` for the octahedron family too.\n")
    with open(os.path.join(study_dir, "table2.md")) as f:
        t2 = f.read()
    for part in t2.split("\n## ")[1:]:
        head, _, body = part.partition("\n")
        if head.startswith("mt1"):
            md.append(f"#### {head}\n" + body.strip() + "\n")
    if extra_dir:
        with open(os.path.join(extra_dir, "table2.md")) as f:
            t2 = f.read()
        for part in t2.split("\n## ")[1:]:
            head, _, body = part.partition("\n")
            if head.startswith("mt1"):
                md.append(f"#### {head} (Method(s) {', '.join(extra_methods)})\n" + body.strip() + "\n")

    if any(m["family"] == "irregular" for m in study["meshes"]):
        md += irregular_section(study, study_dir, extra_dir, extra_methods)

    md += max_error_overview_section(study)

    md.append("## Table 3: the inhomogeneous mesh\n")
    beyond = [m for m in study["options"]["methods"] if m in NOT_IN_PAPER]
    if beyond:
        md.append(f"Methods {', '.join(beyond)} are not in the paper's table 3 (its cells read –).\n")
    md.append(f"Each cell: **ours (r_max / r_avg) / paper**, r = error of the inhomogeneous mesh divided by the "
              f"error of its homogeneous family at the same h (log-log interpolation between the homogeneous "
              f"meshes around it). ● no troubles: both r < {th['inhomogeneous_factor']}; ○ only the maximal error "
              f"worse: r_max >= {th['inhomogeneous_factor']}, r_avg < {th['inhomogeneous_factor']}; ■ the average "
              f"error worse too: r_avg >= {th['inhomogeneous_factor']}. Paper: {PAPER_SOURCE} (3848-triangle MT2 "
              "mesh), so the comparison uses our Rivara mesh from MT2.\n")
    for fam in ("rivara-mt2", "rivara-mt1"):
        if not any(c["family"] == fam for c in study["inhomogeneous"]):
            continue
        table, diffs = table3_section(study, fam)
        md.append(f"### {fam}\n\n" + table)
        if fam == "rivara-mt2":
            if diffs:
                md.append("\nCells where we differ from the paper:\n\n"
                          + md_table(["quantity", "method", "ours", "paper", "explanation"], diffs))
            else:
                md.append("\nEvery cell the paper fills agrees.\n")

    md += method_s_section(study, polar)
    md += extra_section(study, [m for m in study["options"]["methods"] if m in NOT_IN_PAPER and m != "ED"])

    md.append("## Plots\n")
    md.append("Errors against 1/h with guide slopes h^1, h^2, h^-1, h^-2 (figures 3, 5, 7, 10 and, for MT2, "
              "B.19-B.21, B.23); stars with a tick: the inhomogeneous mesh; open markers: the octahedron meshes "
              "(512, 2048 triangles) on the MT1 plots and the MT1 meshes on the irregular family's. Then the values against the polar angle theta (eq. 16) with the exact curve "
              "(figures 4, 6, 8). Per-node errors for figure 9 / B.22 are in the .vtp files of the study folder "
              "(errors_<family>_5120_<method>.vtp, fields eps_n, eps_H, eps_K, eps_lapH, eps_f).\n")
    for fam in ("mt1", "mt2", "irregular"):
        for q in ("n", "H", "K", "lapH", "f"):
            name = f"errors_{q}_{fam}.png"
            if name in pngs:
                md.append(f"![{QUANTITY_NAMES[q]} errors, {fam if fam == 'irregular' else fam.upper()}](rbc/{name})\n")
    for name in pngs:
        if name.startswith("values_"):
            md.append(f"![{name[:-4]}](rbc/{name})\n")
    if extra_pngs:
        md.append(f"The plots above are of the main study; those of Method(s) {', '.join(extra_methods)}, "
                  "run as a separate study of the same meshes (`--extra`), follow.\n")
        for name in extra_pngs:
            md.append(f"![{name[:-4]}](rbc/{name})\n")

    md.append("## Timings\n")
    md.append("Wall-clock seconds of one `BendingMethod::compute` (every quantity of a method), one run, on the "
              "machine that generated this page. The machine was shared and the methods use OpenMP, so times "
              "below about 0.1 s are dominated by thread scheduling; compare the largest meshes. Method S's times include "
              "its set-up for a new topology (patches, factorisation of the limit-mask matrix L, mass-matrix "
              "pattern, face colouring), which a flow run pays once; its cost per force evaluation is measured "
              "by bench/bench_bending.cpp (docs/design.md). n/a: the method refused the mesh.\n")
    timings = study["timings"]
    meshes = list(dict.fromkeys((t["family"], t["triangles"]) for t in timings))
    methods = opts["methods"]
    lookup = {(t["family"], t["triangles"], t["method"]): t["seconds"] for t in timings}
    md.append(md_table(["mesh"] + methods,
                       [[f"{fam} {n}"] + [f"{lookup[(fam, n, me)]:.3g}" if (fam, n, me) in lookup else "n/a" for me in methods]
                        for fam, n in meshes]))
    md.append("\nAll numbers: [rbc/errors.csv](rbc/errors.csv) (family,triangles,h,method,quantity,max_error,"
              "avg_error), [rbc/errors.json](rbc/errors.json) (also the fitted slopes), "
              "[rbc/timings.csv](rbc/timings.csv).\n")
    out = os.path.join(results, "rbc.md")
    with open(out, "w") as f:
        f.write("\n".join(md))
    print(f"make_rbc_doc.py: wrote {out}", file=sys.stderr)


if __name__ == "__main__":
    main()
