#!/usr/bin/python3
"""Method S's accuracy with the 6-point (default) and the 3-point Gauss rule on the MT1 red blood
cell, 320-20480 triangles: the Helfrich energy E_B (exact 48.47346) and the max/average errors of
n, H, K and f (eq. 17), beside shared/spec/METHOD_S.md section 5 (computed with the 6-point rule),
and the sphere energy E/(8 pi) at 5120 triangles. The 3-point rule halves the cost of S's assembly.

    PYTHONPATH=build/release/python OMP_NUM_THREADS=1 /usr/bin/python3 scripts/method_s_quadrature.py

Prints a table (a few minutes on one core: 20480 triangles dominate).
"""
import math

import bendlab

SPEC_F = {320: (0.32, 0.141), 1280: (0.36, 0.049), 5120: (1.7, 0.060), 20480: (8.5, 0.072)}


def main():
    rbc = bendlab.surface("rbc")
    print("triangles gauss E_B | n max/avg | H max/avg | K max/avg | f max/avg | f max / spec")
    for level in (2, 3, 4, 5):
        mesh = bendlab.sphere_mesh("mt1", level)
        mesh = mesh.with_positions(rbc.map_from_unit_sphere(mesh.vertices))
        n = 20 * 4 ** level
        for gauss in ("6", "3"):
            method = bendlab.Method("S", gauss=gauss)
            errors = bendlab.node_errors(rbc, mesh.vertices, method.compute(mesh))
            cells = []
            for q in ("n", "H", "K", "f"):
                s = bendlab.summarize(errors[q])
                cells.append(f"{s['max']:.3g}/{s['average']:.3g}")
            f_max = bendlab.summarize(errors["f"])["max"]
            print(f"{n} {gauss} {method.energy(mesh):.6f} | " + " | ".join(cells) +
                  f" | {f_max / SPEC_F[n][0]:.2f}", flush=True)
    sphere = bendlab.sphere_mesh("mt1", 4)
    for gauss in ("6", "3"):
        print(f"sphere 5120, gauss {gauss}: E/(8 pi) = {bendlab.Method('S', gauss=gauss).energy(sphere) / (8 * math.pi):.7f}")


if __name__ == "__main__":
    main()
