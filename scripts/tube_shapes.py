#!/usr/bin/python3
"""One red blood cell in a tube: its shape at several rates (parachute, croissant, slipper; `bendlab flow --cells 1`).

    /usr/bin/python3 scripts/tube_shapes.py [--rates LIST] [--travel D] [--jobs N] [--bendlab PATH]
                                            [--work DIR] [--doc FILE] [--list] [--doc-only]

A single cell of the flow command's red blood cell (docs/conventions.md §6: eq. (15) at
R = 3.91 um, Skalak G_s = 5.3 uN/m, C = 10, kappa_B = 2e-19 J, Method C, 1280 triangles) in a
rigid tube of D = 10 um, periodic over 3 D, dx = 0.5 um, tau = 1.82 (the tube study's lattice),
started where the flow command's placement puts it (seed 1: off the axis, at a random
orientation), driven at each pseudo-shear rate v / D of --rates for long enough that the cell
travels about --travel (20) tube diameters. Nothing is tuned.

The shape measures (over the last quarter of each run's snapshots; mean and the spread) are read
from the second moments of the cell's surface, each triangle weighted by its area (exact for the
flat triangles), so that they describe the shape and not where the mesh's vertices crowd:
  offset        distance of the surface's centroid from the tube axis over the tube radius
                (0 on the axis; a parachute is centred, a slipper sits off it)
  roundness     sqrt(lambda_min / lambda_max) of the (y, z) block of the second moments: the
                cross-section seen along the flow (1 for a shape symmetric about the flow axis)
and, for the phase diagram of Fedosov, Peltomaki & Gompper, Soft Matter 10:4258 (2014), the
confinement chi = D_r / D (D_r = sqrt(A / pi), A the cell's area at rest) and the dimensionless
rate gamma* = (v / D) eta D_r^3 / kappa_B. A tilt of the principal axes is not among the measures:
the three moments of these cups lie within about a quarter of each other, so their axes swing by
tens of degrees between snapshots without the shape changing; a slipper is told by its offset.

Runs lie under --work (default studies/tube_shapes, kept in git without their fluid states and
snapshots; the measures of the snapshots are kept in each run's shape_measures.json, so the
document is written again on a fresh checkout, its pictures then left as they are); a finished run
is not run again (scripts/study_runner.py). Writes docs/results/tube_shapes.md and its pictures
(docs/results/tube_shapes/).
"""
import argparse
import json
import math
import os
import re
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import study_runner  # noqa: E402
from study_runner import ROOT, fmt_g  # noqa: E402

DIAMETER = 10.0
LENGTH = 3 * DIAMETER
DX = 0.5
TAU = 1.82
SEED = 1
RATES = [1600.0, 800.0, 400.0, 200.0, 100.0, 50.0]
TRAVEL_DIAMETERS = 20.0  # t_end = travel / rate: the cell-free mean velocity covers this many D
SNAPSHOTS = 40
PLASMA_VISCOSITY = 1.2e-3   # Pa s, the flow command's default
BENDING_MODULUS = 2e-19     # J, the flow command's default


def t_end_of(rate, travel=TRAVEL_DIAMETERS):
    return float(f"{travel / rate:.6g}")


@dataclass(frozen=True)
class ShapeRun(study_runner.StudyRun):
    rate: float
    t_end: float
    start_arguments = ("--overwrite",)

    @property
    def name(self):
        return f"D{fmt_g(DIAMETER)}_rate{fmt_g(self.rate)}"

    def arguments(self, out):
        return ["flow", "--geometry", "tube", "--diameter", fmt_g(DIAMETER), "--length", fmt_g(LENGTH),
                "--dx", fmt_g(DX), "--tau", fmt_g(TAU), "--pseudo-shear-rate", fmt_g(self.rate),
                "--cells", "1", "--seed", str(SEED), "--bending-net-force", "keep", "--t-end", fmt_g(self.t_end),
                "--sample-every", fmt_g(self.t_end / 400), "--snapshot-every", fmt_g(self.t_end / SNAPSHOTS),
                "--out", str(out)]

    def key(self):
        return {"t_end": self.t_end, "diameter_um": DIAMETER, "method": "C", "tau": TAU, "dx_um": DX,
                "pseudo_shear_rate": self.rate, "seed": SEED}

    def label(self):
        return f"one cell, D = {fmt_g(DIAMETER)} um, v/D = {fmt_g(self.rate)} 1/s"


# ----------------------------------------------------------------------------- snapshots

def read_vtp(path, with_body=False):
    """(points (n, 3), triangles (m, 3)) of an ASCII .vtp written by the flow command, and each
    vertex's cell index (its "body" array, zeros where it has none) when with_body."""
    text = Path(path).read_text()

    def array(name, optional=False):
        m = re.search(r'Name="%s"[^>]*>(.*?)</DataArray>' % name, text, re.S)
        if m is None:
            if optional:
                return None
            raise ValueError(f"{path}: no DataArray {name}")
        return np.array(m.group(1).split(), dtype=float)

    points = array("Points").reshape(-1, 3)
    conn = array("connectivity").astype(int)
    offsets = array("offsets").astype(int)
    if not np.all(np.diff(np.concatenate([[0], offsets])) == 3):
        raise ValueError(f"{path}: not a triangle mesh")
    if with_body:
        body = array("body", optional=True)
        body = body.astype(int) if body is not None else np.zeros(len(points), int)
        return points, conn.reshape(-1, 3), body
    return points, conn.reshape(-1, 3)


def snapshots(folder):
    return sorted(Path(folder).glob("snapshot_*.vtp"))


def triangle_areas(points, tris):
    """The area of each triangle."""
    a, b, c = points[tris[:, 0]], points[tris[:, 1]], points[tris[:, 2]]
    return 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)


def surface_moments(points, tris):
    """(centroid, covariance) of the surface itself: the area-weighted first and second moments
    of its flat triangles, exactly (the integral of x x^T over a triangle of area A and vertices
    a, b, c is A (a a^T + b b^T + c c^T + s s^T) / 12 with s = a + b + c)."""
    a, b, c = points[tris[:, 0]], points[tris[:, 1]], points[tris[:, 2]]
    w = triangle_areas(points, tris)
    s = a + b + c
    total = w.sum()
    centroid = (w[:, None] * s).sum(axis=0) / (3 * total)
    second = sum(np.einsum("i,ij,ik->jk", w, v, v) for v in (a, b, c, s)) / (12 * total)
    return centroid, second - np.outer(centroid, centroid)


def measures(points, tris, radius):
    """offset and roundness of one cell's surface (see the module's description)."""
    c, cov = surface_moments(points, tris)
    offset = math.hypot(c[1], c[2]) / radius
    yz = np.linalg.eigvalsh(cov[1:, 1:])
    roundness = math.sqrt(max(yz[0], 0.0) / yz[1])
    return offset, roundness


def area(points, tris):
    return float(triangle_areas(points, tris).sum())


MEASURES_FILE = "shape_measures.json"


def shape_history(folder, t_end):
    """(t (s), rows (offset, roundness), D_r (um)) of a finished run: measured on its snapshots
    (evenly spaced over [0, t_end]) and kept in the run folder's shape_measures.json, which is
    committed with the run; the snapshots are not, so a fresh checkout reads that file instead.
    None when neither is there."""
    folder = Path(folder)
    snaps = snapshots(folder)
    if snaps:
        shapes = (read_vtp(p) for p in snaps)
        points, tris = next(shapes)  # as placed: the cell's area at rest
        D_r = math.sqrt(area(points, tris) / math.pi)
        rows = [measures(points, tris, DIAMETER / 2)] + [measures(*shape, DIAMETER / 2) for shape in shapes]
        m = np.array(rows).reshape(-1, 2)
        t = np.linspace(0, t_end, len(snaps))
        record = {"D_r_um": D_r, "t_s": t.tolist(), "offset": m[:, 0].tolist(), "roundness": m[:, 1].tolist()}
        tmp = folder / (MEASURES_FILE + ".tmp")
        tmp.write_text(json.dumps(record, indent=1) + "\n")
        os.replace(tmp, folder / MEASURES_FILE)
        return t, m, D_r
    record = study_runner.read_json(folder / MEASURES_FILE)
    if not isinstance(record, dict):
        return None
    m = np.column_stack([record["offset"], record["roundness"]])
    return np.array(record["t_s"]), m, float(record["D_r_um"])


def roundness_drift(travelled, roundness):
    """How much the roundness changes per 10 tube diameters travelled: the slope of its
    least-squares line against the distance travelled (in D), times 10."""
    if len(travelled) < 2:
        return 0.0
    return 10.0 * float(np.polyfit(travelled, roundness, 1)[0])


def classify(offset, roundness, offset_range):
    """The shape's name from its measures over the last quarter of the run, in the words of
    Fedosov, Peltomaki & Gompper (2014) and Guckenberger et al. (2018): centred (offset < 0.1) and
    round across the flow (roundness > 0.9, axial symmetry) is a parachute; centred but not round
    (two-fold rather than axial symmetry) is a croissant; off the axis is a slipper; a shape whose
    offset still moves by more than 0.05 of the radius is not steady yet."""
    if offset_range > 0.05:
        return "not steady"
    if offset < 0.1:
        return "parachute" if roundness > 0.9 else "croissant"
    return "slipper"


# ----------------------------------------------------------------------------- pictures

def draw(ax, points, tris, view):
    """The cell seen along -y (side) or along +x (front), shaded by the light from the viewer."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    c = points.mean(axis=0)
    p = points.copy()
    p[:, 0] -= c[0]  # the cell's x about its centroid; y, z about the tube axis
    tri = p[tris]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    light = np.array([0.3, -1.0, 0.4]) if view == "side" else np.array([-1.0, 0.3, 0.4])
    light /= np.linalg.norm(light)
    shade = 0.35 + 0.65 * np.abs(n @ light)
    col = Poly3DCollection(tri, facecolors=np.outer(shade, [0.85, 0.2, 0.2]), edgecolors="none")
    ax.add_collection3d(col)
    r = DIAMETER / 2
    t = np.linspace(0, 2 * np.pi, 100)
    if view == "side":
        for z in (-r, r):
            ax.plot([-6, 6], [r, r], [z, z], color="0.4", lw=1)
        ax.view_init(elev=0, azim=-90)
    else:
        ax.plot(np.full_like(t, -6), r * np.cos(t), r * np.sin(t), color="0.4", lw=1)
        ax.view_init(elev=0, azim=180)
    ax.set_xlim(-6, 6)
    ax.set_ylim(-r, r)
    ax.set_zlim(-r, r)
    ax.set_box_aspect((12, 2 * r, 2 * r))
    ax.set_axis_off()


def picture(path, folder, title):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    points, tris = read_vtp(snapshots(folder)[-1])
    fig = plt.figure(figsize=(8, 3.6))
    for k, view in enumerate(("side", "front")):
        ax = fig.add_subplot(1, 2, k + 1, projection="3d")
        draw(ax, points, tris, view)
        ax.set_title("side (flow to the right)" if view == "side" else "along the flow", fontsize=9)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def history(path, rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(7, 3))
    for rate, t, m in rows:
        for k, (ax, name) in enumerate(zip(axes, ("offset / (D/2)", "roundness"))):
            ax.plot(t * rate, m[:, k], ".-", lw=1, label=f"v/D = {fmt_g(rate)} 1/s")
            ax.set_xlabel("t v / D (tube diameters travelled)")
            ax.set_ylabel(name)
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ----------------------------------------------------------------------------- main

def main(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rates", default=",".join(fmt_g(r) for r in RATES),
                    help="pseudo-shear rates v/D, 1/s, comma-separated")
    ap.add_argument("--travel", type=float, default=TRAVEL_DIAMETERS,
                    help="tube diameters the cell-free mean velocity covers in a run (sets t_end)")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--bendlab", default="build/release/bendlab")
    ap.add_argument("--work", default=str(ROOT / "studies" / "tube_shapes"))
    ap.add_argument("--doc", default=str(ROOT / "docs" / "results" / "tube_shapes.md"))
    ap.add_argument("--binary-commit", default=None, help="the commit whose bendlab made the runs (for the document)")
    ap.add_argument("--list", action="store_true", help="print the runs and their state; run nothing")
    ap.add_argument("--doc-only", action="store_true", help="write the document from the finished runs; run nothing")
    args = ap.parse_args(argv[1:])
    rates = study_runner.number_list(args.rates, "--rates", lambda r: r > 0, "rate must be positive")

    if not (args.travel > 0 and math.isfinite(args.travel)):
        raise SystemExit(f"error: --travel must be positive: {args.travel}")
    runs = [ShapeRun(r, t_end_of(r, args.travel)) for r in rates]
    work = Path(args.work)
    bendlab = study_runner.bendlab_binary(args.bendlab) if not args.doc_only else None
    runner = study_runner.Runner(bendlab, work, jobs=args.jobs)
    if args.list:
        return runner.list(runs, "tube shapes")
    if not args.doc_only:
        runner.run_all(runs)

    doc = Path(args.doc)
    fig_dir = doc.parent / doc.stem
    fig_dir.mkdir(parents=True, exist_ok=True)
    L = ["# One red blood cell in a tube: parachute, croissant and slipper", ""]
    L += study_runner.generated_by(study_runner.invocation(Path(__file__), argv[1:]))
    L += [f"from {study_runner.source_commit() or 'an unknown commit'} on {study_runner.machine()}, "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}"
          + (f"; the runs were made by the bendlab of commit {args.binary_commit}" if args.binary_commit else "")
          + ".", ""]
    L += [f"One cell of the flow command's red blood cell (docs/conventions.md §6) in a tube of D = {fmt_g(DIAMETER)} um, "
          f"periodic over {fmt_g(LENGTH)} um, dx = {fmt_g(DX)} um, tau = {fmt_g(TAU)}, placed by seed {SEED} "
          "(off the axis, at a random orientation); each run lasts until the cell-free mean velocity has "
          f"covered {fmt_g(args.travel)} tube diameters. The measures are those of scripts/tube_shapes.py's "
          "description, over the last quarter of the run's snapshots (mean, and the range in brackets). "
          "The names are those of Fedosov, Peltomaki & Gompper, Soft Matter 10:4258 (2014) and Guckenberger "
          "et al., Soft Matter 14:2032 (2018), arXiv:1711.06986, given by scripts/tube_shapes.py's classify(): centred "
          "(offset < 0.1) and round across the flow (roundness > 0.9) is a parachute; centred but two-fold "
          "rather than axially symmetric is a croissant; off the axis is a slipper; an offset still moving by "
          "more than 0.05 over the last quarter is not steady.", ""]
    L += ["| v / D (1/s) | gamma* | t_end (s) | offset / (D/2) | roundness | roundness drift per 10 D | shape |",
          "| --- | --- | --- | --- | --- | --- | --- |"]
    hist = []
    drifts = []
    chi = None
    pictures = []
    for r in runs:
        folder = work / r.name
        state, info = runner.state(r)
        if state != "done":
            said = f"failed: {info}" if state == "failed" else "not finished"
            L.append(f"| {fmt_g(r.rate)} | | {fmt_g(r.t_end)} | {said} | | | |")
            continue
        measured = shape_history(folder, r.t_end)
        if measured is None:
            L.append(f"| {fmt_g(r.rate)} | | {fmt_g(r.t_end)} | finished, but neither its snapshots nor its "
                     f"{MEASURES_FILE} are here | | | |")
            continue
        t, m, D_r = measured
        chi = D_r / DIAMETER
        gamma_star = r.rate * PLASMA_VISCOSITY * (D_r * 1e-6) ** 3 / BENDING_MODULUS
        hist.append((r.rate, t, m))
        last = m[len(m) - max(1, len(m) // 4):]
        mean = last.mean(axis=0)
        cells = [f"{mean[k]:.3g} [{last[:, k].min():.3g}, {last[:, k].max():.3g}]" for k in range(2)]
        shape = classify(*mean, offset_range=float(np.ptp(last[:, 0])))
        drift = roundness_drift(t[len(t) - len(last):] * r.rate, last[:, 1])  # t v / D: diameters travelled
        drifts.append((r.rate, drift, float(mean[1])))
        L.append(f"| {fmt_g(r.rate)} | {gamma_star:.3g} | {fmt_g(r.t_end)} | {' | '.join(cells)} | {drift:+.3f} "
                 f"| {shape} |")
        png = fig_dir / f"{r.name}.png"
        if snapshots(folder):
            picture(png, folder, f"v/D = {fmt_g(r.rate)} 1/s: {shape}")
        elif not png.exists():
            print(f"note: no snapshots of {r.name} here and no picture made before: {study_runner.rel(png)} is missing")
        pictures.append((r, png, shape, gamma_star))
    L.append("")
    if hist:
        history(fig_dir / "history.png", hist)
        L += [f"![the measures against the distance travelled]({fig_dir.name}/history.png)", ""]
    for r, png, shape, gamma_star in pictures:
        if png.exists():
            L += [f"![v/D = {fmt_g(r.rate)} 1/s]({fig_dir.name}/{png.name})", ""]
    if chi is not None:
        L += ["## Where the runs lie", "",
              f"Fedosov, Peltomaki & Gompper (2014) map the shapes on the confinement chi = D_r / D, with "
              f"D_r = sqrt(A / pi) from the cell's area A at rest (here D_r = {chi * DIAMETER:.3g} um, "
              f"chi = {chi:.3g}), and the rate gamma* = (v / D) eta D_r^3 / kappa_B (eta = {PLASMA_VISCOSITY:g} Pa s, "
              f"kappa_B = {BENDING_MODULUS:g} J); the runs above sit at:", ""]
        for r, png, shape, gamma_star in pictures:
            L.append(f"- v/D = {fmt_g(r.rate)} 1/s (mean velocity {fmt_g(r.rate * DIAMETER * 1e-3)} mm/s): "
                     f"(chi, gamma*) = ({chi:.3g}, {gamma_star:.3g}), {shape}.")
        L.append("")
        names = {shape for _, _, shape, _ in pictures}
        found = ", ".join(f"{fmt_g(r.rate)} 1/s: {shape}" for r, _, shape, _ in pictures)
        worst = max(abs(d) for _, d, _ in drifts)
        near = [f"{fmt_g(rate)} 1/s" for rate, d, rnd in drifts if abs(rnd - 0.9) < abs(d)]
        L += [f"Found ({found}). "
              f"Over the last quarter of each run the roundness still moves, by up to {worst:.2g} per 10 diameters "
              "(the drift column: the slope of its least-squares line); "
              + (f"a name whose roundness lies closer to the parachute's threshold 0.9 than that could change in a "
                 f"longer run: {', '.join(near)}. " if near else "no roundness lies that close to the threshold 0.9. ")
              + ("A slipper appears at no rate of this tube: every steady shape is centred. "
                 if "slipper" not in names else "")
              + "Both papers place the axisymmetric parachute at strong confinement and high velocity, as here; "
              "Guckenberger et al. find croissants and slippers coexisting in a microchannel of about the cell's "
              "size at low velocities (below about 1 mm/s), the shape chosen by where and how the cell starts, so "
              "a run from one placement (seed "
              f"{SEED}) shows one of the two.", ""]
    doc.write_text("\n".join(L))
    print(f"wrote {study_runner.rel(doc)} and {study_runner.rel(fig_dir)}/")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
