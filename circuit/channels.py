"""Input channels that ngspice's compiled callbacks evaluate without Python.

An input channel (an EXTERNAL voltage source, ``Stepper.advance(inputs=...)``) is any
function of time; these two are callables too, and anywhere a function is accepted they
may be given instead. With the compiled callbacks (circuit/callbacks.c) their values are
computed in C; with the Python callbacks their ``function`` is called. Both give the same
bits: a ``ConstantChannel``'s value is a number, and a ``TableChannel``'s C evaluation
does the operations its Python ``function`` does, in the same order (the caller that
builds one vouches for that; tests/circuit/test_compiled_callbacks_runs.py holds
coupling's coil gap to it).
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

# (numpy's float64 as a dtype object: the type np.float64 is converted at each call, ~0.15 us,
# and a coil's table is made at every macro step)
_FLOAT64 = np.dtype(np.float64)


class ConstantChannel:
    """An input channel of one value (finite and >= 0, checked by the Stepper)."""

    __slots__ = ("value", "function")

    def __init__(self, value: float):
        number = self.value = float(value)
        self.function = lambda t: number  # (the Python callbacks' route)

    def __call__(self, t: float) -> float:
        return self.value


class TableChannel:
    """An input channel given as a piecewise polynomial of time, clipped at zero:

    value(t) = max(offset - scale * p(u), 0.0), u = t clamped to [lo, hi] (after the left
    limits of ``windows``); p(u) = ``start`` if there are no pieces or u <= lo, else, with
    k = min(bisect_left(ends, u), n - 1), th = (u - t0[k]) / h[k] and t1 = 1 - th,
    p(u) = c0 + th * (c1 + t1 * (c2 + th * (c3 + t1 * c4))), c = coefficients[k] (a 4th
    order dense output's interpolant, as a solver's dense step writes it).

    ``function``: the same channel in Python, operation for operation (the Python callbacks
    call it, and so do the compiled ones for a value that is not finite and >= 0, which
    raises the channel's error there). ``windows``: (lows, highs, befores), the left limits
    at breakpoints as ``circuit.contact.left_limited`` takes them (a time in [lows[i],
    highs[i]] is read at befores[i]), or None.
    """

    __slots__ = ("function", "lo", "hi", "start", "offset", "scale", "ends", "t0", "h", "coefficients", "windows")

    def __init__(self, function: Callable[[float], float], lo: float, hi: float, start: float,
                 ends, t0, h, coefficients, offset: float = 0.0, scale: float = -1.0, windows=None):
        self.function = function
        self.lo, self.hi, self.start = float(lo), float(hi), float(start)
        self.offset, self.scale = float(offset), float(scale)
        self.ends = np.ascontiguousarray(ends, dtype=_FLOAT64)
        n = len(self.ends)
        self.t0 = np.ascontiguousarray(t0, dtype=_FLOAT64)
        self.h = np.ascontiguousarray(h, dtype=_FLOAT64)
        self.coefficients = np.ascontiguousarray(coefficients, dtype=_FLOAT64).reshape(n, 5)
        if self.t0.shape != (n,) or self.h.shape != (n,):
            raise ValueError(f"TableChannel: ends, t0 and h must have one value per piece ({n})")
        if not (math.isfinite(self.lo) and math.isfinite(self.hi) and self.lo <= self.hi):
            raise ValueError(f"TableChannel: [lo, hi] = [{lo!r}, {hi!r}] is not a time span")
        if windows is not None:
            windows = tuple(np.ascontiguousarray(w, dtype=_FLOAT64) for w in windows)
            if len(windows) != 3 or not (windows[0].shape == windows[1].shape == windows[2].shape
                                         and windows[0].ndim == 1):
                raise ValueError("TableChannel: windows must be (lows, highs, befores) of one length")
        self.windows = windows

    def __call__(self, t: float) -> float:
        return self.function(t)

    def with_windows(self, function: Callable[[float], float], lows, highs, befores) -> "TableChannel":
        """This channel read as its left limits at breakpoints (``function``: that in Python)."""
        return TableChannel(function, self.lo, self.hi, self.start, self.ends, self.t0, self.h, self.coefficients,
                            self.offset, self.scale, (lows, highs, befores))
