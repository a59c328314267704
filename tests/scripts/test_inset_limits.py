"""The zoom inset of the D(gamma t) figures (scripts/inset_limits.py): its vertical range spans
the curves with bending in the inset's time window, with a small margin, and leaves out the
no-bending curve and a far-off bending curve."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "scripts"))
from inset_limits import inset_ylim  # noqa: E402

T = np.linspace(0.0, 10.0, 201)


def relax(level, rate=2.0, wiggle=0.0):
    """A curve rising from 0 to `level`, with a small oscillation of amplitude `wiggle`."""
    return level * (1.0 - np.exp(-rate * T)) + wiggle * np.sin(3.0 * T)


def figure14_like():
    """The shape of figure 14 at G = 0.05: no bending near 0.27, the methods near 0.133."""
    return [("none", T, relax(0.2711)),
            ("B", T, relax(0.1336)), ("C", T, relax(0.1334, wiggle=2e-4)),
            ("D", T, relax(0.1342)), ("E", T, relax(0.1331))]


def in_window(y, t0=5.0, t1=10.0):
    return y[(T >= t0) & (T <= t1)]


def test_limits_span_the_bending_curves_and_exclude_the_no_bending_curve():
    curves = figure14_like()
    lo, hi, left_out = inset_ylim(curves, (5.0, 10.0))
    bending = np.concatenate([in_window(y) for k, _, y in curves if k != "none"])
    none = in_window(curves[0][2])
    assert lo < bending.min() and hi > bending.max()
    assert none.min() > hi  # the no-bending curve lies wholly outside the inset
    assert left_out == ["none"]
    # Zoomed: the range is the methods' spread with a small margin, not the gap to 0.27.
    spread = bending.max() - bending.min()
    assert hi - lo == pytest.approx(1.3 * spread, rel=1e-12)
    assert hi - lo < 0.05 * (none.min() - bending.min())


def test_no_bending_curve_below_the_methods_is_excluded_too():
    curves = [("none", T, relax(0.05)), ("B", T, relax(0.2)), ("C", T, relax(0.201))]
    lo, hi, left_out = inset_ylim(curves, (5.0, 10.0))
    assert in_window(curves[0][2]).max() < lo
    assert left_out == ["none"]


def test_only_the_window_counts():
    # Before gamma t = 5 the curves pass through every value from 0; the inset ignores that.
    curves = figure14_like()
    lo, hi, _ = inset_ylim(curves, (5.0, 10.0))
    assert lo > 0.13
    lo2, hi2, _ = inset_ylim(curves, (0.0, 10.0))
    assert lo2 < 0.0 + 0.01


def test_far_off_bending_curve_is_left_to_the_main_axes():
    # G = 0.2: Method A 20 % above the cluster of the other methods.
    curves = [("none", T, relax(0.5231)), ("A", T, relax(0.2514)),
              ("B", T, relax(0.2063)), ("C", T, relax(0.2057)), ("D", T, relax(0.2071))]
    lo, hi, left_out = inset_ylim(curves, (5.0, 10.0))
    assert left_out == ["none", "A"]
    assert hi < in_window(curves[1][2]).min()
    assert lo < 0.2057 * 0.9999 and hi > 0.2071
    # Without the outlier rule A stays in the range (the no-bending curve still does not).
    lo, hi, left_out = inset_ylim(curves, (5.0, 10.0), outlier=None)
    assert left_out == ["none"] and hi > 0.2514 and hi < 0.5


def test_flat_curves_get_a_visible_range_and_no_curve_gives_none():
    curves = [("none", T, np.full_like(T, 0.3)), ("C", T, np.full_like(T, 0.2))]
    lo, hi, _ = inset_ylim(curves, (5.0, 10.0))
    assert lo < 0.2 < hi and hi - lo == pytest.approx(4e-4)
    assert inset_ylim([("none", T, relax(0.3))], (5.0, 10.0)) is None
    assert inset_ylim([("C", T, relax(0.2))], (20.0, 30.0)) is None
