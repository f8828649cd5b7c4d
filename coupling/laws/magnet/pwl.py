"""Odd piecewise-linear functions y(x) = sign(x) f(|x|) and their exact integrals: the form
in which every magnet of this package gives its coil current as a function of the flux
linkage, because ngspice's ``pwl(x, x0,y0, x1,y1, ...)`` evaluates the same thing.

A function is given by its points for x >= 0, starting at (0, 0), x strictly increasing;
beyond the last point it goes on along its last segment, as ngspice's pwl does
(src/spicelib/parser/ptfuncs.c, PTpwl: the end segments are extended linearly). The value
on a segment is y0 + (y1 - y0) (x - x0) / (x1 - x0), computed in that order, as PTpwl does,
so that Python and ngspice agree to round-off.
"""

from __future__ import annotations

import numpy as np


def number(value: float) -> str:
    """A finite float as ngspice reads it back exactly: Python's shortest round-trip repr
    (digits, '.', 'e', '-' only: nothing ngspice could take for a scale suffix)."""
    value = float(value)
    if not np.isfinite(value):
        raise ValueError(f"a magnet's expression needs finite numbers, got {value!r}")
    return repr(value)


class OddPwl:
    """y(x) = sign(x) f(|x|), f piecewise linear through ``(xs[j], ys[j])`` with xs[0] = 0,
    ys[0] = 0, xs strictly increasing and ys strictly increasing (so it can be inverted);
    linear beyond the last point with the last segment's slope."""

    __slots__ = ("xs", "ys", "_cum")

    def __init__(self, xs, ys):
        xs = np.asarray(xs, dtype=float)
        ys = np.asarray(ys, dtype=float)
        if xs.ndim != 1 or xs.shape != ys.shape or xs.size < 2 or xs[0] != 0.0 or ys[0] != 0.0:
            raise ValueError("OddPwl: needs >= 2 points starting at (0, 0)")
        if not (np.all(np.diff(xs) > 0.0) and np.all(np.diff(ys) > 0.0)):
            raise ValueError("OddPwl: x and y must increase strictly")
        self.xs, self.ys = xs, ys
        # integral of f from 0 to each point: the trapezoid is exact on a linear segment
        self._cum = np.concatenate(([0.0], np.cumsum(np.diff(xs) * (ys[:-1] + ys[1:]) / 2.0)))

    def _segment(self, a):
        return np.clip(np.searchsorted(self.xs, a, side="right") - 1, 0, self.xs.size - 2)

    def _f(self, a, k):
        x0, x1, y0, y1 = self.xs[k], self.xs[k + 1], self.ys[k], self.ys[k + 1]
        return y0 + (y1 - y0) * (a - x0) / (x1 - x0)

    def __call__(self, x):
        """y(x), odd in x."""
        x = np.asarray(x, dtype=float)
        a = np.abs(x)
        return np.sign(x) * self._f(a, self._segment(a))

    def integral(self, x):
        """The integral of y from 0 to x (even in x): exact, piecewise quadratic."""
        a = np.abs(np.asarray(x, dtype=float))
        k = self._segment(a)
        return self._cum[k] + (a - self.xs[k]) * (self.ys[k] + self._f(a, k)) / 2.0

    def inverse(self, y):
        """x with y(x) = y (odd): f is strictly increasing, so the root is one and explicit."""
        y = np.asarray(y, dtype=float)
        b = np.abs(y)
        k = np.clip(np.searchsorted(self.ys, b, side="right") - 1, 0, self.ys.size - 2)
        x0, x1, y0, y1 = self.xs[k], self.xs[k + 1], self.ys[k], self.ys[k + 1]
        return np.sign(y) * (x0 + (x1 - x0) * (b - y0) / (y1 - y0))

    @property
    def initial_slope(self) -> float:
        """dy/dx at x = 0."""
        return float((self.ys[1] - self.ys[0]) / (self.xs[1] - self.xs[0]))

    def expression(self, x: str) -> str:
        """The ngspice B-source expression of y(x) for an expression ``x``: one pwl over the
        mirrored points, odd by construction and linear through 0 (no kink there)."""
        xs = np.concatenate((-self.xs[:0:-1], self.xs))
        ys = np.concatenate((-self.ys[:0:-1], self.ys))
        pairs = ", ".join(f"{number(a)},{number(b)}" for a, b in zip(xs, ys))
        return f"pwl(({x}), {pairs})"


def union(arrays) -> np.ndarray:
    """The sorted distinct values of ``arrays`` together: np.unique's result, without the
    import of numpy.ma that np.unique makes (~10 ms of a run's start)."""
    xs = np.sort(np.concatenate(arrays))
    return xs[np.concatenate(([True], xs[1:] != xs[:-1]))] if xs.size else xs


def merged(functions) -> OddPwl:
    """The sum of odd piecewise-linear functions as one: its points are the union of theirs
    (a sum of functions linear between the union's points is linear there, and beyond the
    last one), so the merged function equals the sum exactly, up to round-off."""
    functions = list(functions)
    xs = union([f.xs for f in functions])
    ys = sum(f(xs) for f in functions)
    ys[0] = 0.0
    return OddPwl(xs, ys)


class Linear:
    """y = slope x: a term without breakpoints."""

    __slots__ = ("slope",)

    xs = np.array([0.0])

    def __init__(self, slope: float):
        self.slope = float(slope)

    def __call__(self, x):
        return self.slope * np.asarray(x, dtype=float)

    def integral(self, x):
        x = np.asarray(x, dtype=float)
        return self.slope * x * x / 2.0

    @property
    def initial_slope(self) -> float:
        return self.slope

    def expression(self, x: str) -> str:
        """slope * x as a one-segment pwl: ngspice computes 0 + (slope - 0) (x - 0) / (1 - 0),
        exactly slope * x, and reads the numbers of a pwl's point list in full (measured:
        benchmarks/magnet_ngspice.py), while plain constants may lose digits."""
        return f"pwl(({x}), 0.0,0.0, 1.0,{number(self.slope)})"
