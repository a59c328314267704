#!/usr/bin/python3
"""Why part (e.1)'s smallest shear rate, G = 0.0125 without bending, gives D_steady 1.09 times the
small-deformation value 25/4 G at 5120 triangles and 1.02 at 1280: the runs that tell the
candidate causes apart (wrinkling of the compressed membrane, the RKC integrator, the tree-mixed
quadrature) and the section of docs/results/shear.md that reports them (written by
scripts/shear_study.py --only e, which calls `section` below).

    /usr/bin/python3 scripts/small_g_study.py --list     # the runs, their commands and state
    OMP_NUM_THREADS=1 nice -n 10 /usr/bin/python3 scripts/small_g_study.py --run [--bendlab PATH]

--run runs the missing runs one after the other (scripts/study_runner.py; a run interrupted
continues from its checkpoint with --resume), into studies/small_g/<name>/ (kept in git without
snapshots: studies/README.md).
The reference run is part (e)'s own, studies/shear/none_mt1-5120_G0.0125_kb0_t10_rkc_tree-mixed.
"""
import argparse
import json
import math
import subprocess
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import study_runner  # noqa: E402
from study_runner import ROOT  # noqa: E402

WORK = ROOT / "studies" / "small_g"
SHEAR = ROOT / "studies" / "shear"
SLOPE = 25.0 / 4.0  # small-deformation theory, D = 25/4 G (docs/results/shear.md, part (a))


@dataclass(frozen=True)
class SmallG(study_runner.StudyRun):
    method: str
    triangles: int
    G: float
    kb: float
    t_end: float
    integrator: str = "rkc"
    quadrature: str = "tree-mixed"
    folder: str = ""  # a run of another study (relative to ROOT); empty: studies/small_g/<name>

    @property
    def name(self):
        return (f"{self.method}_mt1-{self.triangles}_G{self.G:g}_kb{self.kb:g}_t{self.t_end:g}"
                f"_{self.integrator}_{self.quadrature}")

    @property
    def path(self):
        return ROOT / self.folder if self.folder else WORK / self.name

    def arguments(self, out):
        return ["shear", "--method", self.method, "--mesh", f"mt1:{self.triangles}",
                "--G", f"{self.G:g}", "--kappa-b-hat", f"{self.kb:g}", "--t-end", f"{self.t_end:g}",
                "--out", study_runner.rel(out), "--no-plot", "--integrator", self.integrator,
                "--rtol", "1e-7", "--atol", "1e-6", "--bim-quadrature", self.quadrature]

    def resume_key(self):
        return {}  # any checkpoint in its folder

    def label(self):
        bend = "no bending" if self.method == "none" else f"Method {self.method}, kB_hat = {self.kb:g}"
        return (f"{self.triangles}, G = {self.G:g}, {bend}, "
                f"{'Cash-Karp' if self.integrator == 'cash-karp' else 'RKC'}, {self.quadrature}")


# In the order they are run: the question each answers first.
REFERENCE = SmallG("none", 5120, 0.0125, 0.0, 10.0,
                   folder="studies/shear/none_mt1-5120_G0.0125_kb0_t10_rkc_tree-mixed")
RUNS = [
    SmallG("C", 5120, 0.0125, 1e-3, 10.0),                  # a tiny bending modulus damps wrinkles
    SmallG("none", 1280, 0.0125, 0.0, 10.0),                # the coarse mesh, same integrator and quadrature
    SmallG("none", 5120, 0.0125, 0.0, 4.0, "cash-karp"),    # is RKC the cause?
    SmallG("none", 5120, 0.00625, 0.0, 10.0),               # half the shear rate
    SmallG("none", 5120, 0.0125, 0.0, 4.0, "rkc", "all7"),  # is the tree-mixed quadrature the cause?
    SmallG("C", 1280, 0.0125, 1e-3, 10.0),                  # mesh convergence with the tiny modulus
    SmallG("C", 5120, 0.00625, 1e-3, 10.0),
    SmallG("C", 5120, 0.025, 1e-3, 10.0),                   # the slope, and what 1e-3 costs in D
    SmallG("none", 1280, 0.00625, 0.0, 10.0),
    SmallG("C", 1280, 0.00625, 1e-3, 10.0),
    SmallG("C", 5120, 0.0125, 3e-4, 10.0),                  # D against kB_hat -> 0
    SmallG("C", 1280, 0.0125, 3e-4, 10.0),
]
# Part (e)'s other runs without bending: how the wrinkles grow as G falls.
PART_E = [SmallG("none", 5120, G, 0.0, 10.0, folder=f"studies/shear/none_mt1-5120_G{G:g}_kb0_t10_rkc_tree-mixed")
          for G in (0.025, 0.05, 0.1, 0.2)]


def summary(run):
    return study_runner.read_summary(run.path)


# ----------------------------------------------------------------------------- shapes

def read_vtp(path):
    """Points and triangles of a `bendlab shear` snapshot (.vtp, ASCII or base64 inline)."""
    root = ET.parse(path).getroot()
    piece = root.find(".//Piece")

    def array(parent, name=None):
        for da in parent.iter("DataArray"):
            if name is None or da.get("Name") == name:
                if da.get("format", "ascii") != "ascii":
                    raise ValueError(f"{path}: only ASCII DataArrays are read")
                return np.array(da.text.split(), dtype=float)
        raise KeyError(name)

    pts = array(piece.find("Points")).reshape(-1, 3)
    polys = piece.find("Polys")
    conn = array(polys, "connectivity").astype(int)
    offsets = array(polys, "offsets").astype(int)
    if not np.all(np.diff(np.concatenate([[0], offsets])) == 3):
        raise ValueError(f"{path}: not a triangle mesh")
    return pts, conn.reshape(-1, 3)


def checkpoint_positions(run_dir):
    c = json.loads((Path(run_dir) / "checkpoint.json").read_text())
    return np.asarray(c["positions"], float).reshape(-1, 3), float(c["time"])


def smooth_part(x, degree=6):
    """Normal displacement of the vertices x from their smooth shape: r(theta, phi) about the
    centroid fitted with real spherical harmonics up to `degree` (least squares); returns the
    residual r - r_fit (the short-wavelength part) and the fitted r."""
    c = x - x.mean(axis=0)
    r = np.linalg.norm(c, axis=1)
    th = np.arccos(np.clip(c[:, 2] / r, -1, 1))
    ph = np.arctan2(c[:, 1], c[:, 0])
    cols = []
    from scipy.special import sph_harm
    for l in range(degree + 1):
        for m in range(0, l + 1):
            y = sph_harm(m, l, ph, th)
            cols.append(y.real)
            if m > 0:
                cols.append(y.imag)
    A = np.array(cols).T
    coef, *_ = np.linalg.lstsq(A, r, rcond=None)
    fit = A @ coef
    return r - fit, fit


def spectrum(x, degree):
    """Amplitude of r(theta, phi) about the centroid per spherical-harmonic degree 0..degree
    (least squares over the vertices): a wrinkle pattern shows as a peak at high degree."""
    from scipy.special import sph_harm
    c = x - x.mean(axis=0)
    r = np.linalg.norm(c, axis=1)
    th = np.arccos(np.clip(c[:, 2] / r, -1, 1))
    ph = np.arctan2(c[:, 1], c[:, 0])
    cols, deg = [], []
    for l in range(degree + 1):
        for m in range(0, l + 1):
            y = sph_harm(m, l, ph, th)
            cols.append(y.real)
            deg.append(l)
            if m > 0:
                cols.append(y.imag)
                deg.append(l)
    coef, *_ = np.linalg.lstsq(np.array(cols).T, r, rcond=None)
    deg = np.array(deg)
    return np.array([math.sqrt(float(np.sum(coef[deg == l] ** 2))) for l in range(degree + 1)])


SMOOTH_DEGREE = 8  # the "smooth shape": spherical harmonics up to this degree


def roughness(x):
    """RMS and maximum normal displacement of the vertices from the smooth shape, in R."""
    res, _ = smooth_part(x, SMOOTH_DEGREE)
    return float(np.sqrt(np.mean(res ** 2))), float(np.abs(res).max())


def snapshots(run):
    """(gamma t, path) of the run's .vtp snapshots, from shapes.pvd."""
    try:
        root = ET.parse(run.path / "shapes.pvd").getroot()
    except (OSError, ET.ParseError):
        return []
    out = []
    for ds in root.iter("DataSet"):
        f = run.path / ds.get("file")
        if f.exists():
            out.append((float(ds.get("timestep")), f))
    return sorted(out)


def read_series(run):
    return study_runner.read_series(run.path, ("gamma_t", "D", "theta"))


_mesh_cache = {}
BENDLAB = ROOT / "build" / "release" / "bendlab"  # --bendlab; set by shear_study.py's --bendlab too


def mesh_of(triangles):
    """Vertices (on the unit sphere) and triangles of mt1:N, written by `bendlab mesh` (the
    snapshots are not kept in git); the vertex order is that of `bendlab shear --mesh mt1:N`."""
    if triangles not in _mesh_cache:
        import tempfile
        level = {320: 2, 1280: 3, 5120: 4, 20480: 5}[triangles]
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "mesh.vtp"
            subprocess.run([str(BENDLAB), "mesh", "--family", "mt1", "--level", str(level), "--out", str(out)],
                           check=True, capture_output=True)
            _mesh_cache[triangles] = read_vtp(out)
    return _mesh_cache[triangles]


def principal_tensions(x, triangles):
    """Per triangle, the smaller and larger principal tension of the neo-Hookean law (eq. 18), in
    units of the shear modulus Gs: T_i = (lambda_i^2 - 1 / (lambda_1 lambda_2)^2) / (lambda_1 lambda_2),
    the stretches lambda from the rest shape, the unit sphere of mt1:N."""
    p0, tri = mesh_of(triangles)
    a, b, c = tri.T
    E0 = np.stack([p0[b] - p0[a], p0[c] - p0[a]], axis=2)
    E = np.stack([x[b] - x[a], x[c] - x[a]], axis=2)
    M = np.linalg.solve(np.einsum("tki,tkj->tij", E0, E0), np.einsum("tki,tkj->tij", E, E))
    ev = np.sort(np.real(np.linalg.eigvals(M)), axis=1)
    J = np.sqrt(ev[:, 0] * ev[:, 1])
    return (ev[:, 0] - 1 / J ** 2) / J, (ev[:, 1] - 1 / J ** 2) / J, np.sqrt(ev), J


def triangle_areas(x, tri):
    return 0.5 * np.linalg.norm(np.cross(x[tri[:, 1]] - x[tri[:, 0]], x[tri[:, 2]] - x[tri[:, 0]]), axis=1)


def compression(smooth_run, wrinkled_run, data):
    """The area fraction of the smooth run's membrane under compression (smaller principal tension
    negative), and the share of the wrinkled run's squared normal displacement that lies there
    (matched by direction from the centroid: the tank-treading capsule's strain field is steady in
    the flow's frame, not on the material)."""
    tri = mesh_of(smooth_run.triangles)[1]
    xs = data[smooth_run]["x"]
    tmin, _, lam, J = principal_tensions(xs, smooth_run.triangles)
    comp = tmin < 0
    A = triangle_areas(xs, tri)
    frac = float(A[comp].sum() / A.sum())
    x = data[wrinkled_run]["x"]
    tri_w = mesh_of(wrinkled_run.triangles)[1]
    res, _ = smooth_part(x, SMOOTH_DEGREE)
    cs = xs[tri].mean(axis=1) - xs.mean(axis=0)
    cs /= np.linalg.norm(cs, axis=1)[:, None]
    cw = x[tri_w].mean(axis=1) - x.mean(axis=0)
    cw /= np.linalg.norm(cw, axis=1)[:, None]
    inside = comp[np.argmax(cw @ cs.T, axis=1)]
    Aw = triangle_areas(x, tri_w)
    w = (res[tri_w] ** 2).mean(axis=1) * Aw
    rms_in = math.sqrt(float(w[inside].sum() / Aw[inside].sum()))
    rms_out = math.sqrt(float(w[~inside].sum() / Aw[~inside].sum())) if (~inside).any() else math.nan
    return dict(frac=frac, rms_in=rms_in, rms_out=rms_out, lam=(float(lam.min()), float(lam.max())),
                J=(float(J.min()), float(J.max())))


def final_positions(run):
    """The shape at the end of the run (its checkpoint holds the positions at full precision)."""
    return checkpoint_positions(run.path)


# ----------------------------------------------------------------------------- the document

def window_mean(series, t0, t1):
    """dt-weighted mean of D and theta over gamma t in [t0, t1] (trapezoidal in t)."""
    t = series["gamma_t"]
    sel = (t >= t0) & (t <= t1)
    if sel.sum() < 2:
        return None, None
    return (float(np.trapz(series["D"][sel], t[sel]) / (t[sel][-1] - t[sel][0])),
            float(np.trapz(series["theta"][sel], t[sel]) / (t[sel][-1] - t[sel][0])))


def collect(runs):
    """What the document needs of each finished run."""
    data = {}
    for run in runs:
        s = summary(run)
        if s is None or not (run.path / "checkpoint.json").exists():
            continue
        x, t = final_positions(run)
        rms, mx = roughness(x)
        L = 36 if run.triangles >= 5120 else 20
        sp = spectrum(x, L)
        high = [l for l in range(10, L + 1, 2)]
        peak = max(high, key=lambda l: sp[l])
        rough_t = []
        for ts, f in snapshots(run):
            rough_t.append((ts, roughness(read_vtp(f)[0])[0]))
        data[run] = dict(summary=s, series=read_series(run), x=x, rms=rms, max=mx, spectrum=sp,
                         peak=peak, rough_t=rough_t, wall=s["wall_seconds"])
    return data


STYLE = {
    REFERENCE: dict(color="tab:red", lw=1.6),
    RUNS[0]: dict(color="tab:green", lw=1.6),
    RUNS[1]: dict(color="tab:blue", lw=1.2),
    RUNS[2]: dict(color="black", ls=":", lw=1.6),
    RUNS[3]: dict(color="tab:orange", lw=1.2),
    RUNS[4]: dict(color="tab:purple", ls="--", lw=1.4),
    RUNS[5]: dict(color="tab:cyan", ls="--", lw=1.2),
    RUNS[6]: dict(color="tab:olive", lw=1.2),
    RUNS[7]: dict(color="tab:brown", lw=1.2),
    RUNS[8]: dict(color="tab:gray", lw=1.0),
    RUNS[9]: dict(color="tab:pink", ls="--", lw=1.0),
    RUNS[10]: dict(color="darkgreen", ls="-.", lw=1.4),
    RUNS[11]: dict(color="lime", ls="-.", lw=1.0),
}


def plot_time(data, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11.5, 5.6))
    for run, d in data.items():
        if run in PART_E:
            continue
        st = STYLE.get(run, {})
        a1.plot(d["series"]["gamma_t"], d["series"]["D"] / (SLOPE * run.G), label=run.label(), **st)
        if d["rough_t"]:
            t, r = zip(*[p for p in d["rough_t"] if p[0] > 0])
            a2.plot(t, r, marker="o", ms=3, **st)
        else:
            a2.plot([run.t_end], [d["rms"]], marker="*", ms=10, ls="none", **{k: v for k, v in st.items() if k == "color"})
    a1.axhline(1.0, color="0.5", lw=0.8)
    a1.set_xlabel(r"$\dot\gamma t$")
    a1.set_ylabel(r"$D \,/\, (25/4\ G)$")
    a1.set_ylim(0.8, 1.25)
    a1.set_xlim(0, 10)
    a1.grid(alpha=0.3)
    fig.legend(*a1.get_legend_handles_labels(), fontsize=7, loc="lower center", ncol=3)
    a2.set_xlabel(r"$\dot\gamma t$")
    a2.set_ylabel(f"rms normal displacement from the smooth shape / R")
    a2.set_yscale("log")
    a2.set_ylim(bottom=1e-7)
    a2.set_xlim(0, 10)
    a2.grid(alpha=0.3)
    a2.set_title(f"smooth shape: spherical harmonics to degree {SMOOTH_DEGREE} (* end of a run without snapshots)",
                 fontsize=8)
    fig.tight_layout(rect=(0, 0.2, 1, 1))
    fig.savefig(path, dpi=100)
    plt.close(fig)


def plot_shapes(data, runs, path):
    """The final shapes of `runs`, coloured by the normal displacement from the smooth shape, seen
    along the vorticity axis (y: the shear plane x-z) and along the velocity gradient (z)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    runs = [r for r in runs if r in data]
    lim = max(data[r]["max"] for r in runs)
    rows = len(runs)
    fig = plt.figure(figsize=(7.6, 3.4 * rows + 0.7))
    cmap = plt.cm.RdBu_r
    for i, run in enumerate(runs):
        x = data[run]["x"]
        tri = mesh_of(run.triangles)[1]
        res, _ = smooth_part(x, SMOOTH_DEGREE)
        x = x - x.mean(axis=0)
        v = res[tri].mean(axis=1)
        fig.text(0.5, 1 - (i * 3.4 + 0.15) / (3.4 * rows + 0.7), f"{run.label()}, gamma t = {run.t_end:g}: "
                 f"rms {data[run]['rms']:.1e} R, max {data[run]['max']:.1e} R", ha="center", fontsize=8.5)
        for j, (elev, azim, view) in enumerate([(0, -90, "seen along y (vorticity): shear plane x-z"),
                                                (90, -90, "seen along z (velocity gradient): plane x-y")]):
            bottom = 1 - ((i + 1) * 3.4) / (3.4 * rows + 0.7)
            ax = fig.add_axes([0.02 + 0.49 * j, bottom, 0.47, 3.0 / (3.4 * rows + 0.7)], projection="3d")
            pc = Poly3DCollection(x[tri], facecolors=cmap(0.5 + 0.5 * v / lim), edgecolor="none")
            ax.add_collection3d(pc)
            for set_lim in (ax.set_xlim, ax.set_ylim, ax.set_zlim):
                set_lim(-0.9, 0.9)
            ax.set_box_aspect((1, 1, 1), zoom=1.35)
            ax.view_init(elev, azim)
            ax.set_axis_off()
            ax.text2D(0.5, 0.0, view, transform=ax.transAxes, ha="center", fontsize=7)
    cax = fig.add_axes([0.25, 0.25 / (3.4 * rows + 0.7), 0.5, 0.12 / (3.4 * rows + 0.7)])
    sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(-lim, lim))
    fig.colorbar(sm, cax=cax, orientation="horizontal",
                 label=f"normal displacement from the smooth shape (degree {SMOOTH_DEGREE}) / R")
    fig.savefig(path, dpi=100)
    plt.close(fig)


def plot_spectra(data, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7.0, 4.4))
    for run, d in data.items():
        if run.method != "none" and run not in (RUNS[0], RUNS[5]):
            continue
        if run.t_end < 10 or run.G > 0.1:  # the fit is ill-conditioned on the strongly deformed G = 0.2
            continue
        l = np.arange(0, len(d["spectrum"]), 2)
        st = dict(STYLE.get(run, {}))
        if run in PART_E:
            st = dict(color=matplotlib.cm.viridis(PART_E.index(run) / len(PART_E)), lw=1.0)
        ax.semilogy(l, d["spectrum"][l], label=run.label(), **st)
    ax.set_xlabel("spherical-harmonic degree l (even; odd degrees vanish by symmetry)")
    ax.set_ylabel("amplitude of r(theta, phi) / R")
    ax.set_title("shape at gamma t = 10", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=6.5)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def edge_length(triangles):
    """Mean edge of mt1:N on the unit sphere (N equilateral-ish triangles of area 4 pi / N)."""
    return math.sqrt(4 * math.pi / triangles * 4 / math.sqrt(3))


def find(data, method, triangles, G, kb, t_end=10.0, integrator="rkc", quadrature="tree-mixed"):
    for run in data:
        if (run.method, run.triangles, run.integrator, run.quadrature) == (method, triangles, integrator, quadrature) \
                and math.isclose(run.G, G) and math.isclose(run.kb, kb) and math.isclose(run.t_end, t_end):
            return run
    return None


def fmt(x, digits=4):
    return "n/a" if x is None or not math.isfinite(x) else f"{x:.{digits}g}"


def section(fig_dir, rel, heading="####"):
    """The section of docs/results/shear.md beside table (e.1): markdown lines; its figures are
    written to fig_dir and linked as rel/NAME. Empty when the reference run is missing."""
    data = collect([REFERENCE] + RUNS + PART_E)
    if REFERENCE not in data:
        return []
    fig_dir = Path(fig_dir)
    plot_time(data, fig_dir / "small_g_D_time.png")
    plot_spectra(data, fig_dir / "small_g_spectra.png")
    shape_runs = [find(data, "none", 1280, 0.0125, 0.0), REFERENCE, find(data, "C", 5120, 0.0125, 1e-3)]
    plot_shapes(data, [r for r in shape_runs if r is not None], fig_dir / "small_g_shapes.png")

    ref = data[REFERENCE]
    L = [f"{heading} Why G = 0.0125 differs between 1280 and 5120 triangles: the membrane wrinkles", "",
         "The runs below (scripts/small_g_study.py; folders in studies/small_g, the reference is the "
         "5120-triangle run of the table above) change one thing at a time: the mesh, the integrator "
         "(Cash-Karp instead of RKC, to gamma t = 4), the quadrature (all7 instead of tree-mixed, to "
         "gamma t = 4), a tiny bending modulus (Method C, kB_hat = 1e-3 and 3e-4) and the shear rate "
         "(G = 0.00625). Each is `bendlab shear --mesh mt1:N --G G --kappa-b-hat KB --t-end T --integrator I "
         "--rtol 1e-7 --atol 1e-6 --bim-quadrature Q` (the first line of each run.log). The shape is "
         "measured at the end of each run from its checkpoint: the radius r(theta, phi) about the "
         f"centroid is fitted by spherical harmonics to degree {SMOOTH_DEGREE} (the smooth shape); the "
         "normal displacement of the vertices from it (rms and largest) measures wrinkles, and the "
         "amplitude per degree (to degree 36 at 5120 triangles, 20 at 1280) gives their wavelength.", ""]

    rows = [r for r in [REFERENCE] + RUNS if r in data and r.t_end >= 10]
    L += ["| triangles | G | bending | D_steady | D_steady / (25/4 G) | theta_steady / pi | "
          "wrinkles: rms, R | largest, R | peak degree (l >= 10) | wavelength 2 pi R / l, edges | wall s |",
          "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for run in rows:
        d = data[run]
        sm = d["summary"]
        bend = "none" if run.method == "none" else f"{run.method}, kB_hat = {run.kb:g}"
        wrinkled = d["rms"] > 1e-4
        wl = f"{2 * math.pi / d['peak'] / edge_length(run.triangles):.1f}" if wrinkled else "-"
        L.append(f"| {run.triangles} | {run.G:g} | {bend} | {fmt(sm['D_steady'])} | "
                 f"{fmt(sm['D_steady'] / (SLOPE * run.G), 3)} | {fmt(sm['theta_steady'] / math.pi)} | "
                 f"{d['rms']:.1e} | {d['max']:.1e} | {d['peak'] if wrinkled else '-'} | {wl} | {d['wall']:.0f} |")
    L.append("")
    L += [f"![D and wrinkle amplitude against gamma t]({rel}/small_g_D_time.png)", "",
          f"![shapes at gamma t = 10]({rel}/small_g_shapes.png)", "",
          f"![spherical-harmonic amplitude of the shape]({rel}/small_g_spectra.png)", ""]

    # Integrator and quadrature: the same case to gamma t = 4, against the reference.
    checks = [r for r in RUNS if r in data and r.t_end < 10]
    if checks:
        L += ["The integrator and the quadrature, G = 0.0125 without bending at 5120 triangles to gamma t = 4, "
              "against the reference (RKC, tree-mixed) at the same times:", "",
              "| run | D at gamma t = 4 | reference | largest difference in D, gamma t in [0, 4] | "
              "largest difference in D, gamma t in [0, 1] | mean D over [2, 4] | reference |",
              "| --- | --- | --- | --- | --- | --- | --- |"]
        rs = ref["series"]
        for run in checks:
            s = data[run]["series"]
            t = s["gamma_t"]
            dref = np.interp(t, rs["gamma_t"], rs["D"])
            early = t <= 1.0
            m, _ = window_mean(s, 2.0, 4.0)
            mr, _ = window_mean(rs, 2.0, 4.0)
            what = ("Cash-Karp, tree-mixed" if run.integrator == "cash-karp" else f"RKC, {run.quadrature}")
            L.append(f"| {what} | {fmt(s['D'][-1])} | {fmt(float(np.interp(t[-1], rs['gamma_t'], rs['D'])))} | "
                     f"{np.abs(s['D'] - dref).max():.1e} | {np.abs(s['D'][early] - dref[early]).max():.1e} | "
                     f"{fmt(m)} | {fmt(mr)} |")
        L.append("")
    L += findings(data)
    return L


def high_degree_rms(sp, lmin=16):
    """RMS over the sphere of the part of r(theta, phi) of degree >= lmin (orthonormal harmonics)."""
    return math.sqrt(float(np.sum(sp[lmin:] ** 2)) / (4 * math.pi))


def pct(a, b):
    return 100.0 * (a - b) / b


def findings(data):
    """The explanation, with the numbers of the runs."""
    D = lambda r: data[r]["summary"]["D_steady"]  # noqa: E731
    ratio = lambda r: D(r) / (SLOPE * r.G)  # noqa: E731
    ref = REFERENCE
    n1280 = find(data, "none", 1280, 0.0125, 0.0)
    c5120 = find(data, "C", 5120, 0.0125, 1e-3)
    c1280 = find(data, "C", 1280, 0.0125, 1e-3)
    w5120 = find(data, "C", 5120, 0.0125, 3e-4)
    w1280 = find(data, "C", 1280, 0.0125, 3e-4)
    ck = find(data, "none", 5120, 0.0125, 0.0, 4.0, "cash-karp")
    a7 = find(data, "none", 5120, 0.0125, 0.0, 4.0, "rkc", "all7")
    h5120 = find(data, "none", 5120, 0.00625, 0.0)
    h1280 = find(data, "none", 1280, 0.00625, 0.0)
    hc5120 = find(data, "C", 5120, 0.00625, 1e-3)
    hc1280 = find(data, "C", 1280, 0.00625, 1e-3)
    qc5120 = find(data, "C", 5120, 0.025, 1e-3)
    out = ["What the runs show:", ""]

    if n1280 is not None:
        d, d1 = data[ref], data[n1280]
        out.append(
            f"- **Without bending the membrane wrinkles, at both resolutions, with the mesh's wavelength.** At "
            f"gamma t = 10 the 5120-triangle shape departs from its smooth shape by {d['rms']:.1e} R rms "
            f"({d['max']:.1e} R at most), the 1280-triangle one by {d1['rms']:.1e} R ({d1['max']:.1e} R), in "
            "stripes across the capsule (the shapes above). The amplitude spectrum peaks at degree "
            f"{d['peak']} at 5120 triangles and {d1['peak']} at 1280: wavelengths of "
            f"{2 * math.pi / d['peak'] / edge_length(5120):.1f} and "
            f"{2 * math.pi / d1['peak'] / edge_length(1280):.1f} edge lengths. The wavelength follows the mesh "
            "because a membrane without bending resistance has no length of its own to set it: the compressed "
            "regions of a neo-Hookean capsule at small capillary numbers buckle (Lac, Barthes-Biesel, Pelekasis "
            "and Tsamopoulos 2004), and the pattern that grows is a few edges long, whatever the mesh. A different wrinkle pattern "
            f"gives a different D: D_steady / (25/4 G) = {ratio(ref):.3f} at 5120 and {ratio(n1280):.3f} at 1280 "
            "triangles. Neither is the capsule's converged deformation.")
    if c5120 is not None:
        c = compression(c5120, ref, data)
        out.append(f"- **The wrinkles lie in the compressed membrane, which at this G is nearly all of it.** On the "
                   f"smooth capsule (kB_hat = 1e-3, G = 0.0125, 5120 triangles) the principal stretches span "
                   f"{c['lam'][0]:.3f} to {c['lam'][1]:.3f} while the area ratio stays within {c['J'][0]:.3f} to "
                   f"{c['J'][1]:.3f}: the shape changes more than the area, and the smaller principal tension of "
                   f"the neo-Hookean law is negative on {100 * c['frac']:.0f} % of the area. The run without bending "
                   f"(same G and mesh) has wrinkles of {c['rms_in']:.1e} R rms there, "
                   f"{c['rms_out']:.1e} R on the rest (regions matched by direction from the centroid).")
    pe = [(r, data[r]) for r in PART_E if r in data and r.G <= 0.1]
    if pe:
        amps = ", ".join(f"{high_degree_rms(d['spectrum']):.1e} R at G = {r.G:g}" for r, d in pe)
        out.append(f"- Part (e)'s other runs without bending wrinkle too, up to G = 0.05: the part of the "
                   f"5120-triangle shape at degrees 16 to 36 is {high_degree_rms(data[ref]['spectrum']):.1e} R rms "
                   f"at G = 0.0125, {amps} (spectra above); at G = 0.1 the spectrum falls smoothly with the "
                   "degree (no wrinkles). Compare tables (a) and (e.1) for D at the other G.")
    s_ref = data[ref]["series"]
    d1, _ = window_mean(s_ref, 0.8, 1.0)
    d2, _ = window_mean(s_ref, 1.6, 1.8)
    if d1 and d2:
        txt = (f"- D follows the wrinkles: the 5120-triangle run without bending reaches "
               f"D / (25/4 G) = {d1 / (SLOPE * ref.G):.3f} at gamma t = 0.8 to 1")
        if c5120 is not None:
            c1, _ = window_mean(data[c5120]["series"], 0.8, 1.0)
            txt += f" (with kB_hat = 1e-3: {c1 / (SLOPE * ref.G):.3f})"
        txt += (f", then jumps to {d2 / (SLOPE * ref.G):.3f} by gamma t = 1.6 to 1.8 while the wrinkles grow (right "
                "panel: the snapshots of the runs that keep them) and theta falls; it then wanders by a few "
                "per cent as the pattern rearranges.")
        out.append(txt)
    for run, what, cause in ((ck, "Cash-Karp", "the RKC integrator"), (a7, "all7", "the tree-mixed quadrature")):
        if run is None:
            continue
        s = data[run]["series"]
        t = s["gamma_t"]
        dref = np.interp(t, s_ref["gamma_t"], s_ref["D"])
        early = t <= 1.0
        m, _ = window_mean(s, 2.0, 4.0)
        mr, _ = window_mean(s_ref, 2.0, 4.0)
        out.append(f"- **Not {cause}.** {what} gives the same jump: D differs from the reference by at most "
                   f"{np.abs(s['D'][early] - dref[early]).max():.1e} to gamma t = 1 and "
                   f"{np.abs(s['D'] - dref).max():.1e} to gamma t = 4, and its mean D over gamma t in [2, 4] is "
                   f"{m / (SLOPE * run.G):.3f} x 25/4 G against the reference's {mr / (SLOPE * run.G):.3f}"
                   + (": the same wrinkles grow, from the mesh's own imperfections, whichever the " + what.lower()
                      .replace("cash-karp", "integrator").replace("all7", "quadrature") + "."
                      if np.abs(s["D"] - dref).max() < 1e-4 else
                      " (once the wrinkles grow, the runs' patterns need not coincide in detail)."))
    if c5120 is not None:
        txt = (f"- **A tiny bending modulus removes the wrinkles and the disagreement.** With kB_hat = 1e-3 "
               f"(Method C) the shape stays smooth ({data[c5120]['rms']:.1e} R rms at 5120 triangles) and "
               f"D_steady / (25/4 G) = {ratio(c5120):.3f}")
        if c1280 is not None:
            txt += (f" at 5120 and {ratio(c1280):.3f} at 1280 triangles ({pct(D(c5120), D(c1280)):+.2f} %, "
                    f"against {pct(D(ref), D(n1280)):+.1f} % without bending)" if n1280 is not None else "")
        txt += "."
        if w5120 is not None:
            txt += (f" With kB_hat = 3e-4 it is {ratio(w5120):.3f} (rms wrinkles {data[w5120]['rms']:.1e} R)"
                    + (f", and {ratio(w1280):.3f} at 1280 triangles" if w1280 is not None else "") + ".")
        out.append(txt)
    if h5120 is not None:
        txt = (f"- At G = 0.00625 without bending: D_steady / (25/4 G) = {ratio(h5120):.3f} at 5120 triangles "
               f"(wrinkles {data[h5120]['rms']:.1e} R rms)")
        if h1280 is not None:
            txt += f", {ratio(h1280):.3f} at 1280 ({data[h1280]['rms']:.1e} R)"
        if hc5120 is not None:
            txt += f"; with kB_hat = 1e-3, {ratio(hc5120):.3f} at 5120"
            if hc1280 is not None:
                txt += f" and {ratio(hc1280):.3f} at 1280"
        out.append(txt + ".")

    # The slope from the runs the explanation trusts: smooth (no wrinkles) and mesh-converged.
    trusted = [r for r in (hc5120, c5120) if r is not None]
    if trusted:
        G = np.array([r.G for r in trusted])
        Dv = np.array([D(r) for r in trusted])
        slope = float(np.dot(G, Dv) / np.dot(G, G))
        pts = " and ".join(f"{r.G:g}" for r in trusted)
        txt = (f"- **Small-G slope from the smooth runs** (kB_hat = 1e-3, 5120 triangles, G = {pts}), least squares "
               f"through the origin: **D = {slope:.3f} G**, {slope / SLOPE:.3f} times 25/4 G")
        if qc5120 is not None:
            txt += f" (at G = 0.025 the same modulus gives {ratio(qc5120):.3f} x 25/4 G: the finite-G softening)"
        txt += ". The theory's 25/4 G is for a membrane without bending resistance, and the bending modulus itself lowers D"
        if w5120 is not None and c5120 is not None:
            # D linear in kB_hat between 3e-4 and 1e-3, continued to 0.
            d0 = D(w5120) + (D(w5120) - D(c5120)) * w5120.kb / (c5120.kb - w5120.kb)
            txt += (f": at G = 0.0125 D_steady rises by {pct(D(w5120), D(c5120)):+.2f} % from kB_hat = 1e-3 to 3e-4, "
                    f"and continued linearly to kB_hat = 0 (a straight line through two points: an estimate) it gives "
                    f"D = {d0:.5f} = **{d0 / c5120.G:.3f} G**, {d0 / (SLOPE * c5120.G):.3f} times the theory's 25/4 G")
        out.append(txt + ".")
    out += ["", "So the 1.09 of table (e.1) is no fault of the integrator or the quadrature: without bending the "
            "capsule's compressed membrane wrinkles at the mesh's own wavelength, and D at G <= 0.0125 then "
            "depends on the mesh. The table keeps the runs without bending as the paper defines them; the "
            "small-G slope to compare with the theory is the one above, from runs whose shape is smooth.", ""]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--run", action="store_true", help="run the missing runs, one after the other")
    ap.add_argument("--list", action="store_true", help="print the runs, their commands and state")
    ap.add_argument("--bendlab", default=str(ROOT / "build" / "release" / "bendlab"))
    args = ap.parse_args()
    global BENDLAB
    BENDLAB = Path(args.bendlab)
    if args.list or not args.run:
        study_runner.Runner(args.bendlab, SHEAR).list([REFERENCE], "the reference, part (e)'s run")
        study_runner.Runner(args.bendlab, WORK).list(RUNS, "small-G study")
    if args.run:
        # One after the other; a failed run is reported and the next one starts.
        results = study_runner.Runner(study_runner.bendlab_binary(args.bendlab), WORK).run_all(RUNS)
        return 1 if any(not r.ok for r in results.values()) else 0


if __name__ == "__main__":
    sys.exit(main())
