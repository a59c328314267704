"""The wrinkle measure of scripts/small_g_study.py: a smooth capsule shape (an ellipsoid, the
small-deformation shape) has no normal displacement from its smooth fit, and a ripple of known
amplitude and degree added to it comes back with that amplitude and at that degree."""
import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
import small_g_study as sg  # noqa: E402


def sphere_points(n=2562):
    """Nearly uniform points on the unit sphere (Fibonacci lattice), as many as mt1:5120's vertices."""
    k = np.arange(n) + 0.5
    z = 1 - 2 * k / n
    phi = math.pi * (1 + 5 ** 0.5) * k
    s = np.sqrt(1 - z * z)
    return np.column_stack([s * np.cos(phi), s * np.sin(phi), z])


def ellipsoid(p, axes=(1.08, 0.97, 0.95), centre=(0.3, -0.1, 0.2)):
    """Points of an ellipsoid (tilted in the x-z plane), radially from the unit-sphere points p."""
    a = np.asarray(axes)
    c, s = math.cos(0.6), math.sin(0.6)
    rot = np.array([[c, 0, -s], [0, 1, 0], [s, 0, c]])
    q = p @ rot.T
    r = 1.0 / np.sqrt(np.sum((q / a) ** 2, axis=1))
    return (p * r[:, None]) + np.asarray(centre)


def test_a_smooth_ellipsoid_has_no_wrinkles():
    x = ellipsoid(sphere_points())
    rms, largest = sg.roughness(x)
    assert rms < 2e-4 and largest < 1e-3  # the degree-8 fit of a 12 % ellipsoid
    sp = sg.spectrum(x, 26)
    assert sg.high_degree_rms(sp) < 1e-5


def test_a_ripple_is_measured_with_its_amplitude_and_degree():
    p = sphere_points()
    x = ellipsoid(p)
    theta = np.arccos(p[:, 2])
    amp, l = 0.01, 22
    # A zonal ripple of degree 22 (a Legendre polynomial, orthogonal to the smooth fit), along the normal.
    from scipy.special import eval_legendre
    ripple = amp * eval_legendre(l, np.cos(theta))
    c = x - x.mean(axis=0)
    n = c / np.linalg.norm(c, axis=1)[:, None]
    rms, largest = sg.roughness(x + ripple[:, None] * n)
    expected = amp / math.sqrt(2 * l + 1)  # rms of P_l over the sphere
    assert rms == pytest.approx(expected, rel=0.1)
    sp = sg.spectrum(x + ripple[:, None] * n, 26)
    assert max(range(10, 27, 2), key=lambda k: sp[k]) == l
