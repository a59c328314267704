"""The shape measures of scripts/tube_shapes.py on shapes whose answer is known: an axisymmetric
cup on the axis (offset 0, roundness 1, tilt 0), the same cup moved off the axis and turned, and
the reading of a .vtp as the flow command writes it."""
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
import tube_shapes  # noqa: E402


def cup(n_theta=24, n_phi=12):
    """Vertices of an oblate cup symmetric about the x-axis: x short, (y, z) a circle of radius 3."""
    pts = []
    for i in range(1, n_phi):
        phi = math.pi * i / n_phi
        for k in range(n_theta):
            t = 2 * math.pi * k / n_theta
            r = 3 * math.sin(phi)
            pts.append((1.2 * math.cos(phi) + 0.5 * r * r / 9, r * math.cos(t), r * math.sin(t)))
    return np.array(pts)


def test_centred_axisymmetric_cup_is_a_parachute():
    offset, roundness, tilt = tube_shapes.measures(cup(), radius=5.0)
    assert abs(offset) < 1e-12
    assert abs(roundness - 1) < 1e-12
    assert tilt < 1e-6
    assert tube_shapes.classify(offset, roundness, tilt, offset_range=0.0) == "parachute"


def test_offset_and_tilt_of_a_moved_and_turned_cup():
    a = math.radians(30)
    rot = np.array([[math.cos(a), 0, -math.sin(a)], [0, 1, 0], [math.sin(a), 0, math.cos(a)]])  # about y
    c = cup()
    p = (c - c.mean(axis=0)) @ rot.T + np.array([7.0, 1.2, -1.6])
    offset, roundness, tilt = tube_shapes.measures(p, radius=5.0)
    assert abs(offset - 2.0 / 5.0) < 1e-12  # |(1.2, -1.6)| = 2
    assert abs(tilt - 30) < 1e-9
    assert roundness < 0.99
    assert tube_shapes.classify(offset, roundness, tilt, offset_range=0.0) == "slipper"
    assert tube_shapes.classify(offset, roundness, tilt, offset_range=0.2) == "not steady"


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
