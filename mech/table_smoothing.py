"""Smooth time tables: a force or a clamp's travel given by a few points, interpolated by
monotone cubics instead of straight lines (``interpolation = "pchip"``).

A table is linear between its points in the mechanics (a force's rate, a clamp's velocity
piecewise constant), so each point is a jump of rate or velocity, and a jump rings the
bar's modes: a clamp travel along an S-curve given by 16 points made 5 spurious re-closures
at the break that 300 points did not. A smooth table is the monotone piecewise-cubic
Hermite interpolant (PCHIP: it keeps the data's shape, no overshoot) with zero slopes at
its ends, where the table is held constant, sampled densely: the mechanics still reads a
linear table, whose jumps are now those of a curve with a continuous rate (they fall as the
square of the spacing). SI units as the table's.
"""

from __future__ import annotations

import numpy as np

from .armature import pchip_slopes

INTERPOLATIONS = ("linear", "pchip")
SUBDIVISIONS = 16  # samples per segment of the user's table


def held_pchip_slopes(x, y) -> np.ndarray:
    """PCHIP slopes through (x, y) with zero slope at both ends (the table is constant
    outside [x_0, x_n]; zero end slopes keep the interpolant monotone where the data is)."""
    d = pchip_slopes(x, y)
    d[0] = d[-1] = 0.0
    return d


def smooth_samples(times, values, subdivisions: int = SUBDIVISIONS) -> tuple[np.ndarray, np.ndarray]:
    """(times, values) of the held PCHIP through the table, ``subdivisions`` samples per
    segment (the table's own points among them). values: (n,) or (n, k), each column
    interpolated on its own. A table of fewer than three points is returned as it is (two
    points: a line, held at both ends)."""
    t = np.asarray(times, dtype=float)
    v = np.asarray(values, dtype=float)
    if len(t) < 3:
        return t, v
    cols = v.reshape(len(t), -1)
    s = np.linspace(0.0, 1.0, subdivisions + 1)[:-1]
    h = np.diff(t)
    dense_t = np.concatenate([t[:-1, None] + h[:, None] * s[None, :], t[-1:, None]], axis=None)
    out = np.empty((len(dense_t), cols.shape[1]))
    # the cubic Hermite basis on each segment at the local coordinates s
    h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
    h01, h11 = -2 * s**3 + 3 * s**2, s**3 - s**2
    for j in range(cols.shape[1]):
        y = cols[:, j]
        d = held_pchip_slopes(t, y)
        seg = (h00[None, :] * y[:-1, None] + h10[None, :] * (h * d[:-1])[:, None]
               + h01[None, :] * y[1:, None] + h11[None, :] * (h * d[1:])[:, None])
        out[:, j] = np.concatenate([seg.ravel(), y[-1:]])
    return dense_t, out.reshape((len(dense_t),) + v.shape[1:])
