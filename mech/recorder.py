"""The run's history: one row per accepted step, written by whichever stepper advances it.

Both steppers (the compiled DOPRI5 loop, mech.integrator, and solve_ivp, mech.scipy_backend)
write the rows of a segment from ``n`` on and the solver then ``commit``s them with the
regimes they were integrated in; the solver's own single points (the start, a hold at
rest) go through ``append``. The buffers grow by doubling, so a long run costs amortised
O(1) per row; ``truncate`` drops the rows after a checkpoint.

Memory in proportion to what is kept, not to the steps taken: once ``row_limit`` rows are
recorded, ``reserve`` asks the solver (``on_full``) to ``thin`` the older rows before the
buffers grow again (mech.solver.ImpactSolver keeps every event and regime change and one
row per interval of a uniform time grid). The dense output (``keep_dense``) covers only the
rows since the last ``release_dense``: a co-simulation samples what it needs of a macro
step and releases it, so that buffer holds one macro step's steps, not the run's.
"""

from __future__ import annotations

import numpy as np

from .kernel_layout import A_FN, CONTACT_ROWS, NAUX

# bytes a run may take for its history (with the growth of its buffers and the copy a
# result makes): a scene whose solver.history_rows would need more is refused before it
# runs (docs/scene_keys.md, "Bounds"; coupling adds its waveforms to the same bound)
MEMORY_LIMIT = 4 * 2**30
# bytes of dense output kept beyond what the rows since the last release need (a stepper
# fills the buffer to here before it returns, as it fills the row buffer)
DENSE_BYTES = 64 * 2**20
# A stepper returns when its room is full, and a return restarts its step-size control, so
# where it returns changes the trajectory (within the tolerance). The room ends where a
# buffer that only doubled would be full, 4096 x 2^k rows, and past CHUNK rows every CHUNK
# rows: counted in rows ever recorded, a thinned run returns where an unthinned one does
# and integrates the same steps; the buffer needs only CHUNK rows besides those it keeps.
CHUNK = 16384


def row_bytes(state_size: int, n_extra: int = 0, dense: bool = False, contact_rows: int = CONTACT_ROWS) -> int:
    """Bytes of one history row (t, state, aux, peak force, regimes, extra states) of a model
    of ``contact_rows`` contact rows, and with ``dense`` of one row of dense output (start,
    length, 5 x state coefficients)."""
    base = 8 * (1 + state_size + contact_rows * (NAUX + 2) + n_extra)
    return base + (8 * (2 + 5 * state_size) if dense else 0)


def history_memory(state_size: int, rows: int, n_extra: int = 0, contact_rows: int = CONTACT_ROWS) -> int:
    """Bytes the history of ``rows`` rows may take at its peak: the buffer of those rows and
    a stepper's room (CHUNK) while it doubles (old and new, up to twice that) plus the
    result's copy of the rows."""
    return (2 * (rows + CHUNK) + rows) * row_bytes(state_size, n_extra, contact_rows=contact_rows)


class Recorder:
    """Growable buffers of the history (all SI, one row per record):

    - t (s), y (state), aux (contact_rows, NAUX) per contact row, fmax (contact_rows,) the
      largest normal force (N) sampled over the step that ends at the row (after thinning:
      since the kept row before), regime (contact_rows,), ext (the extra states of a coupled model,
      mech.solver.CoupledStates);
    - with ``keep_dense``, each row's dense output from row ``dense_base`` on: the step's
      start (s), length (s) and its 5 x N DOPRI5 coefficients (mech.integrator.dense_eval),
      row k at index k - dense_base.

    row_limit: rows before ``reserve`` calls ``on_full`` (None: grow without limit);
    on_full() may thin the rows (the buffers grow if that left too little room);
    on_commit(start, rows) sees every committed batch of rows (the solver's checks).
    """

    def __init__(self, state_size: int, n_extra: int = 0, capacity: int = 4096, keep_dense: bool = False,
                 row_limit: int | None = None, contact_rows: int = CONTACT_ROWS):
        if capacity < 2:
            raise ValueError(f"capacity = {capacity!r}: at least 2 rows")
        self.n = 0
        self.capacity = capacity
        self.dropped = 0  # rows thinned away: n + dropped rows were recorded
        self.room_end = capacity  # where a stepper's room ends, in rows recorded (CHUNK)
        self.keep_dense = keep_dense
        self.row_limit = row_limit
        self.thin_at = row_limit if row_limit is not None else 0
        self.on_full = None
        self.on_commit = None
        self.t = np.empty(capacity)
        self.y = np.empty((capacity, state_size))
        self.aux = np.empty((capacity, contact_rows, NAUX))
        self.fmax = np.empty((capacity, contact_rows))
        self.regime = np.empty((capacity, contact_rows), dtype=np.int64)
        self.ext = np.empty((capacity, n_extra))
        self.dense_base = 0
        dcap = capacity if keep_dense else 1
        self.dense_t0 = np.empty(dcap)
        self.dense_h = np.empty(dcap)
        self.dense_coef = np.empty((dcap, 5, state_size))
        self._buffers = self._dense_buffers = ()  # free_window's tuples of the buffers
        # the dense rows DENSE_BYTES hold (state_size is fixed: _ensure reads this at every segment)
        self._dense_rows_max = DENSE_BYTES // (8 * (2 + 5 * state_size))

    @property
    def recorded(self) -> int:
        """Rows recorded so far, those thinned away included."""
        return self.n + self.dropped

    def reserve(self, rows: int) -> None:
        """Make room for ``rows`` more rows after ``n`` (and one spare) and for a stepper's
        room up to ``room_end``: past ``row_limit`` rows by thinning (``on_full``) first,
        by growing where that freed too little."""
        # (the room's test inline, ``recorded`` as a sum: reserve runs at every segment,
        # and the room is extended once in thousands of them)
        if self.n + self.dropped + rows + 1 > self.room_end:
            self._extend_room(rows)
        if (self.on_full is not None and self.row_limit is not None and self.n >= self.row_limit
                and (self.n + self.room_end - self.recorded > self.capacity or self.n >= self.thin_at)):
            self.on_full()
            # (a stepper that grows the buffer itself, solve_ivp's, fills no room: try again
            # once half a room more is kept)
            self.thin_at = self.n + CHUNK // 2
        self._ensure(rows)

    def _extend_room(self, rows: int) -> None:
        while self.recorded + rows + 1 > self.room_end:
            self.room_end += self.room_end if self.room_end < CHUNK else CHUNK

    def make_room(self, rows: int) -> None:
        """Make room for ``rows`` more rows by growing only, never thinning: for a stepper,
        inside a segment whose first row the solver has noted."""
        self._ensure(rows)

    def _ensure(self, rows: int) -> None:
        """Grow (never thin) until ``rows`` more rows and one spare fit, and the stepper's
        room to ``room_end``, dense output too.

        The dense buffer spans the stepper's room up to DENSE_BYTES, and beyond that what
        the current rows need: a stepper then returns more often, each time the dense
        buffer is full (the rows since the last release are all kept)."""
        n = self.n
        recorded = n + self.dropped  # (self.recorded, read once: no property call a segment)
        if recorded + rows + 1 > self.room_end:
            self._extend_room(rows)
        need = n + self.room_end - recorded
        if need > self.capacity:
            cap = self.capacity
            while cap < need:
                cap *= 2
            if self.row_limit is not None and self.n >= self.row_limit:
                cap = need  # past the limit (thinning freed too little): no more than needed
            self.grow(cap)
        if self.keep_dense:
            used = n - self.dense_base
            span = used + self.room_end - recorded
            size = max(min(span, self._dense_rows_max), used + rows + 1)
            if size > len(self.dense_t0):
                cap = len(self.dense_t0)
                while cap < size:
                    cap *= 2
                cap = min(cap, span)
                self._within_limit(0, cap)
                self.dense_t0 = _grown(self.dense_t0, cap, used)
                self.dense_h = _grown(self.dense_h, cap, used)
                self.dense_coef = _grown(self.dense_coef, cap, used)

    def _within_limit(self, rows: int, dense_rows: int) -> None:
        """Raise MemoryError before the buffers would hold more than a run may take
        (MEMORY_LIMIT): ``rows`` more history rows and ``dense_rows`` more rows of dense
        output beside the buffers there are and their copies (as history_memory counts the
        peak). The solver then ends the run with its partial result.
        A scene's history_rows bound the rows a run keeps, but not those of one stretch
        whose dense output is all kept (a coupled macro step): a bar whose highest mode
        needs nanosecond steps filled the machine's memory there (observed: 18 GB in a
        minute) until the system killed the process, and nothing was kept."""
        state, extra, contacts = self.y.shape[1], self.ext.shape[1], self.aux.shape[1]
        per_row = row_bytes(state, extra, contact_rows=contacts)
        dense = row_bytes(state, extra, dense=True, contact_rows=contacts) - per_row
        # (the buffers now, the grown ones, and the copies a segment and the result take)
        need = (2 * self.capacity + rows) * per_row + (2 * len(self.dense_t0) + dense_rows) * dense
        if need > MEMORY_LIMIT:
            raise MemoryError(
                f"the mechanics' history would take {need / 2**30:.3g} GiB, more than the "
                f"{MEMORY_LIMIT / 2**30:g} GiB a run may take ({self.recorded} steps recorded, {self.n} held): "
                "its steps are far below the scene's time scales (the highest mode's stability limit: fewer "
                "modes, bar.modes) or its run is too long (solver.t_end)")

    def grow(self, cap: int) -> None:
        """Make room for ``cap`` history rows (the rows held kept; numpy's MemoryError, when
        it cannot allocate them, propagates: the solver ends the run with its partial result)."""
        self._within_limit(cap, 0)
        n = self.n
        self.t, self.y, self.aux = _grown(self.t, cap, n), _grown(self.y, cap, n), _grown(self.aux, cap, n)
        self.fmax, self.regime, self.ext = _grown(self.fmax, cap, n), _grown(self.regime, cap, n), _grown(self.ext, cap, n)
        self.capacity = cap

    def free_rows(self) -> tuple[tuple, tuple]:
        """Views of the rows from ``n`` on, for a stepper to write into: (t, y, aux, fmax) and
        the dense output (t0, h, coef) (a one-row scratch when dense output is not kept).
        Both views are equally long, so a stepper that fills one never overruns the other."""
        n = self.n
        room = min(self.capacity - n, self.room_end - n - self.dropped)  # (the property read inline)
        if self.keep_dense:
            d = n - self.dense_base
            dense_room = min(room, len(self.dense_t0) - d)
            if dense_room >= 0:  # (always, after reserve: the records cut once, not cut and cut again)
                end = n + dense_room
                return ((self.t[n:end], self.y[n:end], self.aux[n:end], self.fmax[n:end]),
                        (self.dense_t0[d:d + dense_room], self.dense_h[d:d + dense_room],
                         self.dense_coef[d:d + dense_room]))
        records = (self.t[n:n + room], self.y[n:n + room], self.aux[n:n + room], self.fmax[n:n + room])
        if self.keep_dense:
            room = min(room, len(self.dense_t0) - d)
            records = tuple(a[:room] for a in records)
            return records, (self.dense_t0[d:d + room], self.dense_h[d:d + room], self.dense_coef[d:d + room])
        return records, (self.dense_t0, self.dense_h, self.dense_coef)

    def free_window(self) -> tuple:
        """``free_rows`` as the buffers and where their views start: ((t, y, aux, fmax), (t0,
        h, coef), first, dense_first, room); free_rows' views are the buffers' ``room`` rows
        from ``first`` (the dense buffers' from ``dense_first``; a cut past the one-row
        scratch, when the dense output is not kept, ends at its end). The tuples are the
        same objects while the buffers are the same arrays: the compiled stepper's argument
        check (mech.aot) then passes them by identity, where free_rows' seven new views were
        checked one by one at every segment (~1.5 us, and ~1 us to cut them)."""
        bufs = self._buffers
        if not (bufs and bufs[0] is self.t and bufs[1] is self.y and bufs[2] is self.aux and bufs[3] is self.fmax):
            bufs = self._buffers = (self.t, self.y, self.aux, self.fmax)
        dense = self._dense_buffers
        if not (dense and dense[0] is self.dense_t0 and dense[1] is self.dense_h and dense[2] is self.dense_coef):
            dense = self._dense_buffers = (self.dense_t0, self.dense_h, self.dense_coef)
        n = self.n
        room = min(self.capacity - n, self.room_end - n - self.dropped)  # (as free_rows)
        if not self.keep_dense:
            return bufs, dense, n, 0, room
        d = n - self.dense_base
        dense_room = min(room, len(self.dense_t0) - d)
        if dense_room >= 0:  # (always, after reserve)
            return bufs, dense, n, d, dense_room
        rows, dense_rows = self.free_rows()  # (otherwise free_rows' own cut, as views)
        return rows, dense_rows, 0, 0, len(rows[0])

    def commit(self, rows: int, regime: np.ndarray) -> None:
        """Count the ``rows`` a stepper wrote after ``n`` as recorded, in ``regime``."""
        start = self.n
        self.regime[start:start + rows] = regime
        self.n += rows
        if self.on_commit is not None and rows:
            self.on_commit(start, rows)

    def append(self, t: float, y: np.ndarray, aux: np.ndarray, regime: np.ndarray, ext: np.ndarray) -> None:
        """Record one point (a zero-length step: its dense output is the state itself)."""
        self._ensure(1)
        k = self.n
        self.t[k] = t
        self.y[k] = y
        self.aux[k] = aux
        self.fmax[k] = aux[:, A_FN]
        self.regime[k] = regime
        self.ext[k] = ext
        if self.keep_dense:
            d = k - self.dense_base
            self.dense_t0[d] = t
            self.dense_h[d] = 1.0
            self.dense_coef[d] = 0.0
            self.dense_coef[d, 0] = y
        self.n += 1

    def truncate(self, n: int) -> None:
        """Drop the rows from ``n`` on (a return to a checkpoint)."""
        if not self.dense_base <= n <= self.n:
            raise ValueError(f"n = {n!r}: must lie in [{self.dense_base}, {self.n}]")
        self.n = n

    def release_dense(self) -> None:
        """Forget the dense output of every row so far (the next rows' fill the buffer from
        its start): what the caller needed of it has been sampled."""
        self.dense_base = self.n

    def thin(self, keep: np.ndarray) -> int:
        """Drop the rows k < len(keep) where ``keep[k]`` is False, moving the later rows down;
        each kept row's peak force becomes the largest over the rows dropped before it (back
        to the kept row before). ``keep`` must keep its last row and may not reach into rows
        with dense output. Returns the number of rows dropped."""
        floor = len(keep)
        if floor == 0 or not keep[-1]:
            raise ValueError("thin: the last row of the thinned range must be kept")
        if self.keep_dense and floor > self.dense_base:
            raise ValueError(f"thin: rows from {self.dense_base} on carry dense output; release it first")
        idx = np.flatnonzero(keep)
        m = len(idx)
        dropped = floor - m
        if not dropped:
            return 0
        starts = np.concatenate(([0], idx[:-1] + 1))
        peak = np.maximum.reduceat(self.fmax[:floor], starts, axis=0)
        n = self.n
        for a in (self.t, self.y, self.aux, self.regime, self.ext):
            a[:m] = a[idx]
            a[m:n - dropped] = a[floor:n]
        self.fmax[:m] = peak
        self.fmax[m:n - dropped] = self.fmax[floor:n]
        self.n = n - dropped
        self.dropped += dropped
        self.dense_base -= dropped if self.keep_dense else 0
        return dropped

    @property
    def last_aux(self) -> np.ndarray:
        """(contact_rows, NAUX) of the last row (a view)."""
        return self.aux[self.n - 1]

    def columns(self, start: int = 0, stop: int | None = None) -> dict:
        """Copies of rows [start, stop) by name: t, states, aux, peak_force, regimes, extra_states."""
        s = slice(start, self.n if stop is None else stop)
        return dict(t=self.t[s].copy(), states=self.y[s].copy(), aux=self.aux[s].copy(),
                    peak_force=self.fmax[s].copy(), regimes=self.regime[s].copy(), extra_states=self.ext[s].copy())

    def dense(self, start: int = 0, stop: int | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Copies of the dense output (t0, h, coef) of rows [start, stop) (keep_dense only;
        rows from ``dense_base`` on)."""
        if not self.keep_dense:
            raise ValueError("dense output is recorded only with keep_dense=True")
        stop = self.n if stop is None else stop
        if start < self.dense_base:
            raise ValueError(f"rows before {self.dense_base} have no dense output any more (released)")
        s = slice(start - self.dense_base, stop - self.dense_base)
        return self.dense_t0[s].copy(), self.dense_h[s].copy(), self.dense_coef[s].copy()


def _grown(a: np.ndarray, cap: int, used: int) -> np.ndarray:
    """A copy of ``a`` with ``cap`` rows, its first ``used`` rows kept."""
    b = np.empty((cap,) + a.shape[1:], dtype=a.dtype)
    b[:used] = a[:used]
    return b
