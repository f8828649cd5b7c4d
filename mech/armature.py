"""The armature's laws: one-sided spring-dashpot stops and card, the return spring, the gain table.

Pure functions (SI units; q in m for a plunger, rad for a clapper) that import nothing of
mech: the kernel (mech.kernel) compiles ``stop_force``, ``return_force`` and
``gain_at``; ``pchip_slopes`` prepares the gain table once, where the model is built.
"""

from __future__ import annotations

import math

import numpy as np


def stop_force(pen: float, pen_rate: float, k: float, c: float) -> float:
    """N (N m): a linear spring-dashpot stop, k pen + c dpen/dt for penetration pen > 0 (m or
    rad), clipped at 0: it only pushes (as the Hertz contact, contact_laws.normal_force)."""
    if pen <= 0.0:
        return 0.0
    f = k * pen + c * pen_rate
    return f if f > 0.0 else 0.0


def return_force(q: float, rate: float, preload: float) -> float:
    """N (N m): the return spring's push towards the rest stop (towards -q): preload at
    q = 0 plus rate x q. Its stored energy is preload q + rate q^2 / 2 (zero at q = 0)."""
    return preload + rate * q


def pchip_slopes(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Slopes of the monotone piecewise-cubic Hermite interpolant through (x, y) (x strictly
    increasing, >= 2 points): Fritsch and Carlson's weighted harmonic mean of the adjacent
    secants inside (zero where they differ in sign or one is zero), the one-sided
    three-point formula at the ends, limited so the interpolant keeps the data's shape
    (the rules of SciPy's PchipInterpolator, Fritsch & Carlson, SIAM J. Numer. Anal. 17
    (1980) 238, and Moler, Numerical Computing with MATLAB, 2004, section 3.4)."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    h = np.diff(x)
    delta = np.diff(y) / h
    d = np.zeros_like(y)
    if len(x) == 2:
        d[:] = delta[0]
        return d
    for k in range(1, len(x) - 1):
        a, b = delta[k - 1], delta[k]
        if a == 0.0 or b == 0.0 or (a > 0.0) != (b > 0.0):
            d[k] = 0.0
        else:
            w1 = 2.0 * h[k] + h[k - 1]
            w2 = h[k] + 2.0 * h[k - 1]
            d[k] = (w1 + w2) / (w1 / a + w2 / b)
    d[0] = _end_slope(h[0], h[1], delta[0], delta[1])
    d[-1] = _end_slope(h[-1], h[-2], delta[-1], delta[-2])
    return d


def _end_slope(h0: float, h1: float, m0: float, m1: float) -> float:
    d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    if math.copysign(1.0, d) != math.copysign(1.0, m0):
        return 0.0
    if math.copysign(1.0, m0) != math.copysign(1.0, m1) and abs(d) > abs(3.0 * m0):
        return 3.0 * m0
    return d


def gain_at(q: float, table: np.ndarray, count: int) -> float:
    """The gain (-, or what the drive needs, e.g. N/Wb^2) at q from the table (3, count):
    positions, gains and their PCHIP slopes (pchip_slopes); the cubic Hermite piece of the
    interval holding q, and beyond the ends the end's tangent line (continuous with its
    slope: q passes the ends by the stops' penetrations only). No table (count 0): 1."""
    if count == 0:
        return 1.0
    if q <= table[0, 0]:
        return table[1, 0] + table[2, 0] * (q - table[0, 0])
    last = count - 1
    if q >= table[0, last]:
        return table[1, last] + table[2, last] * (q - table[0, last])
    lo = 0
    hi = last
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if table[0, mid] <= q:
            lo = mid
        else:
            hi = mid
    h = table[0, hi] - table[0, lo]
    s = (q - table[0, lo]) / h
    s2 = s * s
    s3 = s2 * s
    return ((2.0 * s3 - 3.0 * s2 + 1.0) * table[1, lo] + (s3 - 2.0 * s2 + s) * h * table[2, lo]
            + (-2.0 * s3 + 3.0 * s2) * table[1, hi] + (s3 - s2) * h * table[2, hi])


def gain_table(position, gain) -> np.ndarray:
    """(3, count) float array: positions, gains and PCHIP slopes, the kernel's gain table;
    (3, 0) for no table (gain 1). position strictly increasing (checked by the caller)."""
    if position is None:
        return np.zeros((3, 0))
    x = np.asarray(position, dtype=float)
    y = np.asarray(gain, dtype=float)
    return np.ascontiguousarray(np.vstack([x, y, pchip_slopes(x, y)]))
