"""The shape measures of scripts/tube_shapes.py on shapes whose answer is known: an axisymmetric
cup on the axis (offset 0, roundness 1), the same cup moved off the axis and turned, a
cup flattened across the flow, the surface moments against an exact quadrature, a mesh whose vertices
crowd on one side (the measures are the surface's), and the reading of a .vtp as the flow command writes it."""
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
import tube_shapes  # noqa: E402


def revolution(profile, n_theta=24, n_phi=12):
    """A closed triangulated surface of revolution about the x-axis: profile(phi) -> (x, r) for
    phi in [0, pi], the poles at phi = 0 and pi on the axis."""
    pts = [(profile(0.0)[0], 0.0, 0.0)]
    for i in range(1, n_phi):
        x, r = profile(math.pi * i / n_phi)
        for k in range(n_theta):
            t = 2 * math.pi * k / n_theta
            pts.append((x, r * math.cos(t), r * math.sin(t)))
    pts.append((profile(math.pi)[0], 0.0, 0.0))
    ring = lambda i, k: 1 + (i - 1) * n_theta + k % n_theta  # noqa: E731
    last = len(pts) - 1
    tris = [(0, ring(1, k), ring(1, k + 1)) for k in range(n_theta)]
    for i in range(1, n_phi - 1):
        for k in range(n_theta):
            tris += [(ring(i, k), ring(i + 1, k), ring(i + 1, k + 1)), (ring(i, k), ring(i + 1, k + 1), ring(i, k + 1))]
    tris += [(last, ring(n_phi - 1, k + 1), ring(n_phi - 1, k)) for k in range(n_theta)]
    return np.array(pts), np.array(tris)


def cup():
    """An oblate cup symmetric about the x-axis: x short, (y, z) a circle of radius 3."""
    return revolution(lambda phi: (1.2 * math.cos(phi) + 0.5 * math.sin(phi) ** 2, 3 * math.sin(phi)))


def cigar():
    """A prolate body symmetric about the x-axis: x long (half-length 4), radius 1.5."""
    return revolution(lambda phi: (4 * math.cos(phi), 1.5 * math.sin(phi)))


def turned(points, degrees, shift):
    a = math.radians(degrees)
    rot = np.array([[math.cos(a), 0, -math.sin(a)], [0, 1, 0], [math.sin(a), 0, math.cos(a)]])  # about y
    return (points - points.mean(axis=0)) @ rot.T + np.asarray(shift)


def test_centred_axisymmetric_cup_is_a_parachute():
    offset, roundness = tube_shapes.measures(*cup(), radius=5.0)
    assert abs(offset) < 1e-12
    assert abs(roundness - 1) < 1e-12
    assert tube_shapes.classify(offset, roundness, offset_range=0.0) == "parachute"


def test_offset_of_a_moved_and_turned_cup_is_a_slipper():
    points, tris = cup()
    moved = turned(points, 30, [7.0, 1.2, -1.6])
    offset, roundness = tube_shapes.measures(moved, tris, radius=5.0)
    # the vertex mean and the surface centroid of the cup differ along its axis, which the turn by
    # 30 deg about y tilts into z: the offset is that of the surface centroid
    c, _ = tube_shapes.surface_moments(moved, tris)
    assert abs(offset - math.hypot(c[1], c[2]) / 5.0) < 1e-12
    assert abs(offset - 0.4) < 0.05  # |(1.2, -1.6)| = 2, up to that shift
    assert roundness < 0.99
    assert tube_shapes.classify(offset, roundness, offset_range=0.0) == "slipper"
    assert tube_shapes.classify(offset, roundness, offset_range=0.2) == "not steady"


def test_centred_cup_flattened_across_the_flow_is_a_croissant():
    points, tris = cup()
    points[:, 2] *= 0.7
    offset, roundness = tube_shapes.measures(points, tris, radius=5.0)
    assert offset < 1e-12
    assert abs(roundness - 0.7) < 0.05  # z squeezed by 0.7: about 0.7 (the triangles' areas change too)
    assert tube_shapes.classify(offset, roundness, offset_range=0.0) == "croissant"


def test_surface_moments_of_a_cigar_are_exact_for_its_flat_triangles():
    # the edge-midpoint rule, A/3 times the sum over the three edge midpoints, integrates every
    # quadratic exactly over a triangle: the closed form must agree to round-off
    points, tris = cigar()
    c, cov = tube_shapes.surface_moments(points, tris)
    total, first, second = 0.0, np.zeros(3), np.zeros((3, 3))
    for t in tris:
        a, b, d = points[t]
        w = 0.5 * np.linalg.norm(np.cross(b - a, d - a))
        for m in ((a + b) / 2, (b + d) / 2, (d + a) / 2):
            first += w / 3 * m
            second += w / 3 * np.outer(m, m)
        total += w
    assert np.allclose(c, first / total, rtol=0, atol=1e-12)
    assert np.allclose(cov, second / total - np.outer(first, first) / total**2, rtol=0, atol=1e-12)


def test_measures_do_not_depend_on_where_the_vertices_crowd():
    # splitting the triangles on one side at their centroids adds vertices there but not surface:
    # the surface moments, and so every measure, stay the same (a vertex covariance would move)
    points, tris = cup()
    points = turned(points, 25, [0.0, 0.7, 0.3])
    extra, split = [], []
    for t in tris:
        if points[t, 1].mean() > 0.7:
            m = len(points) + len(extra)
            extra.append(points[t].mean(axis=0))
            split += [(t[0], t[1], m), (t[1], t[2], m), (t[2], t[0], m)]
        else:
            split.append(tuple(t))
    crowded = np.vstack([points, extra])
    assert len(extra) > 50
    before = tube_shapes.measures(points, tris, radius=5.0)
    after = tube_shapes.measures(crowded, np.array(split), radius=5.0)
    assert np.allclose(before, after, rtol=0, atol=1e-9)
    assert abs(crowded.mean(axis=0)[1] - points.mean(axis=0)[1]) > 0.05  # the vertex mean did move


def test_reads_points_and_triangles_of_a_vtp(tmp_path):
    f = tmp_path / "snapshot_00000.vtp"
    f.write_text("""<?xml version="1.0"?>
<VTKFile type="PolyData"><PolyData><Piece NumberOfPoints="4" NumberOfPolys="2">
<PointData Scalars="body"><DataArray type="Float64" Name="body" format="ascii">
0 0 0 0
</DataArray></PointData>
<Points><DataArray type="Float64" Name="Points" NumberOfComponents="3" format="ascii">
0 0 0 1 0 0 0 1 0 0 0 1
</DataArray></Points>
<Polys><DataArray type="Int32" Name="connectivity" format="ascii">
0 1 2 0 1 3
</DataArray><DataArray type="Int64" Name="offsets" format="ascii">
3 6
</DataArray></Polys></Piece></PolyData></VTKFile>
""")
    points, tris = tube_shapes.read_vtp(f)
    assert points.shape == (4, 3) and points[3, 2] == 1
    assert tris.tolist() == [[0, 1, 2], [0, 1, 3]]
    assert abs(tube_shapes.area(points, tris) - 1.0) < 1e-15


def test_roundness_drift_is_the_slope_per_ten_diameters():
    travelled = np.linspace(15, 20, 11)
    assert abs(tube_shapes.roundness_drift(travelled, 0.8 + 0.003 * travelled) - 0.03) < 1e-12
    assert tube_shapes.roundness_drift(travelled[:1], np.array([0.9])) == 0.0


def test_shape_history_is_kept_for_a_checkout_without_snapshots(tmp_path):
    # the measures of the snapshots go to shape_measures.json; without the snapshots (they are not
    # committed) the same history is read back from it
    points, tris = cup()
    for k, shift in enumerate(([0, 0, 0], [0, 1.0, 0], [0, 0.5, 0.5])):
        p = points + np.asarray(shift)
        (tmp_path / f"snapshot_{k:05d}.vtp").write_text(
            '<VTKFile type="PolyData"><PolyData><Piece>\n'
            '<Points><DataArray type="Float64" Name="Points" NumberOfComponents="3" format="ascii">\n'
            + " ".join(f"{v:.17g}" for v in p.ravel()) + "\n</DataArray></Points>\n"
            '<Polys><DataArray type="Int32" Name="connectivity" format="ascii">\n'
            + " ".join(str(i) for i in tris.ravel()) + '\n</DataArray><DataArray type="Int64" Name="offsets" format="ascii">\n'
            + " ".join(str(3 * (i + 1)) for i in range(len(tris))) + "\n</DataArray></Polys></Piece></PolyData></VTKFile>\n")
    t, m, d_r = tube_shapes.shape_history(tmp_path, 0.2)
    assert t.tolist() == [0.0, 0.1, 0.2]
    assert abs(m[1, 0] - 1.0 / 5.0) < 1e-12 and abs(d_r - math.sqrt(tube_shapes.area(points, tris) / math.pi)) < 1e-12
    for f in tmp_path.glob("*.vtp"):
        f.unlink()
    t2, m2, d_r2 = tube_shapes.shape_history(tmp_path, 0.2)
    assert t2.tolist() == t.tolist() and np.array_equal(m2, m) and d_r2 == d_r
    assert tube_shapes.shape_history(tmp_path / "nothing", 0.2) is None
