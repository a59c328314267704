"""Vertical range of a zoom inset on D(gamma t) curves: the range of the curves with bending in
the inset's time window plus a small margin, so that the inset magnifies where the bending
methods differ (a few tenths of a percent) instead of spanning the no-bending curve too.

Used by scripts/shear_study.py (figures 13/14); tested by tests/scripts/test_inset_limits.py."""
import numpy as np


def inset_ylim(curves, window, exclude=("none",), margin=0.15, outlier=0.05):
    """Choose the inset's (bottom, top) for `curves` seen in the time window `window` = (t0, t1).

    curves: iterable of (key, t, y), t and y array-like of one curve.
    exclude: keys left to the main axes whatever their values (the no-bending reference).
    margin: padding above and below, as a fraction of the kept curves' range in the window.
    outlier: a curve whose mean in the window lies further than this fraction from the median of
        the kept curves' means is left out too (Method A at G = 0.2 sits 20 % above the others and
        would stretch the zoom over the gap); None keeps every curve not in `exclude`.

    Returns (bottom, top, left_out): left_out lists the keys not spanned by the range, in the
    order given (the excluded keys that had points in the window, then the outliers). Returns
    None when no kept curve has a point in the window.
    """
    t0, t1 = window
    inside, left_out = [], []
    for key, t, y in curves:
        t, y = np.asarray(t, float), np.asarray(y, float)
        sel = (t >= t0) & (t <= t1) & np.isfinite(y)
        if not sel.any():
            continue
        if key in exclude:
            left_out.append(key)
            continue
        inside.append((key, y[sel]))
    if not inside:
        return None
    if outlier is not None and len(inside) >= 3:
        med = float(np.median([v.mean() for _, v in inside]))
        scale = abs(med) if med != 0 else 1.0
        kept = [(k, v) for k, v in inside if abs(v.mean() - med) <= outlier * scale]
        if kept:  # two equal groups far apart leave no cluster: keep them all
            left_out += [k for k, v in inside if abs(v.mean() - med) > outlier * scale]
            inside = kept
    lo = min(float(v.min()) for _, v in inside)
    hi = max(float(v.max()) for _, v in inside)
    span = hi - lo
    # A flat set of curves still gets a visible range: 0.1 % of its level.
    pad = margin * span if span > 0 else 1e-3 * max(abs(hi), 1e-12)
    return lo - pad, hi + pad, left_out
