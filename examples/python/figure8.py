#!/usr/bin/python3
"""Figure 8 of the paper from Python: |f| against the polar angle on the MT1 RBC, every method.

    /usr/bin/python3 examples/python/figure8.py [--triangles 5120] [--out figure8.png]

Needs the bendlab module on the path: an installed bendlab, or PYTHONPATH=build/release/python.
The force density of every registered method (kappa_B = 1) at the nodes of the MT1 mesh mapped onto
the red blood cell of eq. (15), against the polar angle of eq. (16), with the exact |f| as a line.
"""
import argparse

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import bendlab  # noqa: E402


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--triangles", type=int, default=5120, help="MT1 mesh size (320, 1280, 5120, ...)")
    p.add_argument("--out", default="figure8.png", help="output image")
    a = p.parse_args()

    level = bendlab.level_with_triangles("mt1", a.triangles)
    if level < 0:
        p.error(f"--triangles {a.triangles}: MT1 meshes have 20 * 4^k triangles")
    rbc = bendlab.surface("rbc")
    sphere = bendlab.sphere_mesh("mt1", level)
    mesh = sphere.with_positions(rbc.map_from_unit_sphere(sphere.vertices))
    x = mesh.vertices
    theta = np.arccos(np.clip(x[:, 2] / np.linalg.norm(x, axis=1), -1, 1))  # eq. (16)

    names = [m["name"] for m in bendlab.methods()] if hasattr(bendlab, "methods") else list("ABCDE") + ["ED"]
    fig, ax = plt.subplots(figsize=(7, 4.5))
    markers = "os^vDP*x"
    for k, name in enumerate(names):
        r = bendlab.Method(name).compute(mesh, kappa_b=1.0)
        ax.plot(theta, np.linalg.norm(r.force_density, axis=1), markers[k % len(markers)], ms=2.5, label=name)
    # The exact |f| along a meridian.
    t = np.linspace(0, np.pi, 2001)
    meridian = rbc.map_from_unit_sphere(np.column_stack([np.sin(t), np.zeros_like(t), np.cos(t)]))
    exact = np.abs(rbc.evaluate(np.ascontiguousarray(meridian))["f_normal"])
    theta_exact = np.arccos(np.clip(meridian[:, 2] / np.linalg.norm(meridian, axis=1), -1, 1))
    ax.plot(theta_exact, exact, "k--", lw=1.2, label="exact")
    ax.set_xlabel(r"polar angle $\theta$")
    ax.set_ylabel(r"$|\mathbf{f}|$  ($\kappa_B = 1$)")
    ax.set_yscale("symlog", linthresh=1)
    ax.set_title(f"Figure 8: force density on the MT1 RBC, {mesh.num_faces} triangles")
    ax.legend(ncol=4, fontsize=8)
    fig.tight_layout()
    fig.savefig(a.out, dpi=130)
    print(f"figure8: wrote {a.out}")


if __name__ == "__main__":
    main()
