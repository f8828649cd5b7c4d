"""The run's history: one row per accepted step, written by whichever stepper advances it.

Both steppers (the compiled DOPRI5 loop, mech.integrator, and solve_ivp, mech.scipy_backend)
write the rows of a segment from ``n`` on and the solver then ``commit``s them with the
regimes they were integrated in; the solver's own single points (the start, a hold at
rest) go through ``append``. The buffers grow by doubling, so a long run costs amortised
O(1) per row; ``truncate`` drops the rows after a checkpoint.
"""

from __future__ import annotations

import numpy as np

from .kernel_layout import A_FN, NAUX


class Recorder:
    """Growable buffers of the history (all SI, one row per record):

    - t (s), y (state), aux (2, NAUX) per contact point, fmax (2,) the largest normal force
      (N) sampled over the step that ends at the row, regime (2,) per contact point, ext
      (the extra states of a coupled model, mech.solver.CoupledStates);
    - with ``keep_dense``, each row's dense output: the step's start (s), length (s) and
      its 5 x N DOPRI5 coefficients (mech.integrator.dense_eval).
    """

    def __init__(self, state_size: int, n_extra: int = 0, capacity: int = 4096, keep_dense: bool = False):
        if capacity < 2:
            raise ValueError(f"capacity = {capacity!r}: at least 2 rows")
        self.n = 0
        self.capacity = capacity
        self.keep_dense = keep_dense
        self.t = np.empty(capacity)
        self.y = np.empty((capacity, state_size))
        self.aux = np.empty((capacity, 2, NAUX))
        self.fmax = np.empty((capacity, 2))
        self.regime = np.empty((capacity, 2), dtype=np.int64)
        self.ext = np.empty((capacity, n_extra))
        dcap = capacity if keep_dense else 1
        self.dense_t0 = np.empty(dcap)
        self.dense_h = np.empty(dcap)
        self.dense_coef = np.empty((dcap, 5, state_size))

    def reserve(self, rows: int) -> None:
        """Make room for ``rows`` more rows after ``n`` (and one spare)."""
        while self.n + rows + 1 > self.capacity:
            self._grow()

    def _grow(self) -> None:
        cap = 2 * self.capacity
        n = self.n

        def grown(a):
            b = np.empty((cap,) + a.shape[1:], dtype=a.dtype)
            b[:n] = a[:n]
            return b

        self.t, self.y, self.aux, self.fmax = grown(self.t), grown(self.y), grown(self.aux), grown(self.fmax)
        self.regime, self.ext = grown(self.regime), grown(self.ext)
        if self.keep_dense:
            self.dense_t0, self.dense_h, self.dense_coef = (grown(self.dense_t0), grown(self.dense_h),
                                                            grown(self.dense_coef))
        self.capacity = cap

    def free_rows(self) -> tuple[tuple, tuple]:
        """Views of the rows from ``n`` on, for a stepper to write into: (t, y, aux, fmax) and
        the dense output (t0, h, coef) (a one-row scratch when dense output is not kept)."""
        n = self.n
        records = (self.t[n:], self.y[n:], self.aux[n:], self.fmax[n:])
        if self.keep_dense:
            return records, (self.dense_t0[n:], self.dense_h[n:], self.dense_coef[n:])
        return records, (self.dense_t0, self.dense_h, self.dense_coef)

    def commit(self, rows: int, regime: np.ndarray) -> None:
        """Count the ``rows`` a stepper wrote after ``n`` as recorded, in ``regime``."""
        self.regime[self.n:self.n + rows] = regime
        self.n += rows

    def append(self, t: float, y: np.ndarray, aux: np.ndarray, regime: np.ndarray, ext: np.ndarray) -> None:
        """Record one point (a zero-length step: its dense output is the state itself)."""
        self.reserve(1)
        k = self.n
        self.t[k] = t
        self.y[k] = y
        self.aux[k] = aux
        self.fmax[k] = aux[:, A_FN]
        self.regime[k] = regime
        self.ext[k] = ext
        if self.keep_dense:
            self.dense_t0[k] = t
            self.dense_h[k] = 1.0
            self.dense_coef[k] = 0.0
            self.dense_coef[k, 0] = y
        self.n += 1

    def truncate(self, n: int) -> None:
        """Drop the rows from ``n`` on (a return to a checkpoint)."""
        if not 0 <= n <= self.n:
            raise ValueError(f"n = {n!r}: must lie in [0, {self.n}]")
        self.n = n

    @property
    def last_aux(self) -> np.ndarray:
        """(2, NAUX) of the last row (a view)."""
        return self.aux[self.n - 1]

    def columns(self, start: int = 0, stop: int | None = None) -> dict:
        """Copies of rows [start, stop) by name: t, states, aux, peak_force, regimes, extra_states."""
        s = slice(start, self.n if stop is None else stop)
        return dict(t=self.t[s].copy(), states=self.y[s].copy(), aux=self.aux[s].copy(),
                    peak_force=self.fmax[s].copy(), regimes=self.regime[s].copy(), extra_states=self.ext[s].copy())

    def dense(self, start: int = 0, stop: int | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Copies of the dense output (t0, h, coef) of rows [start, stop) (keep_dense only)."""
        if not self.keep_dense:
            raise ValueError("dense output is recorded only with keep_dense=True")
        s = slice(start, self.n if stop is None else stop)
        return self.dense_t0[s].copy(), self.dense_h[s].copy(), self.dense_coef[s].copy()
