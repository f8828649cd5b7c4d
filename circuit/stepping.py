"""Co-simulation stepping: advance one ngspice transient macro step by macro step.

For each macro step [t_n, t_next] the caller supplies the contact conductance as a
Python function of time, G(t) >= 0 in S, and the make/break instants inside the step.
ngspice integrates to exactly t_next (its steps are shortened to land there, without the
order reset a breakpoint causes) and pauses; the contact and load quantities are read
back. One run is one ngspice transient, so results do not depend on the macro step
except through G and the breakpoints. Repeated runs are bit-identical. With an arc model
whose voltage grows with the gap (``ArcModel.column_gradient`` > 0, or
``breakdown_gradient``) the gap distance d(t) >= 0 in m is supplied the same way
(``gap=``).

Example::

    circuit = SwitchCircuit(DCSource(24.0), InductiveLoad(24.0, 10e-3), arc=ArcModel())
    with Stepper(circuit, t_end=2e-3, options=SimulationOptions(max_step=1e-6)) as stepper:
        t = 0.0
        while t < 2e-3:
            t_next = min(t + 2e-6, 2e-3)
            step = stepper.advance(t_next, conductance=lambda s: schedule(s),
                                   breakpoints=schedule.breakpoints(t, t_next))
            current = step.contact_current          # A, at t_next
            t = t_next
        waveform = stepper.results()                # pandas DataFrame, whole run
        columns = stepper.result_columns()          # the same as numpy arrays (no pandas)
"""

from __future__ import annotations

import math
import numbers
import time as _time
from typing import Callable, Iterable, NamedTuple

import numpy as np

from .contact import Conductance, checked_breakpoints, left_limited, snapped
from .deck import CircuitLike, arc_state, build_deck, circuit_arc
from .errors import SessionBusyError
from .ngspice import NgspiceSession, get_session
from .options import SimulationOptions
from .probes import COLUMNS, probe_columns

#: The gap distance d(t) >= 0 (m) as a function of time (s).
Gap = Callable[[float], float]


class StepResult(NamedTuple):
    """One macro step. Scalars are the values at ``t_end`` (SI: s, V, A).

    ``arrays()`` / ``frame()`` give every accepted ngspice point of the closed interval
    [t_start, t_end] (the first point is the previous step's last). Immutable; a
    NamedTuple because one is made per macro step, thousands per run.
    """

    t_start: float
    t_end: float
    contact_voltage: float
    contact_current: float
    load_current: float
    arc_current: float
    points: int  # accepted ngspice points in (t_start, t_end]
    reader: Callable[[str], np.ndarray]

    def arrays(self) -> dict[str, np.ndarray]:
        return {name: self.reader(name) for name in COLUMNS}

    def frame(self):
        """``arrays()`` as a pandas DataFrame."""
        import pandas as pd

        return pd.DataFrame(self.arrays())


class Stepper:
    """Step a switch circuit through a transient of length ``t_end`` (s).

    circuit: a ``SwitchCircuit``, a ``NetlistCircuit`` or a PySpice ``Circuit`` with a
        contact (``add_contact``).
    options: ``SimulationOptions`` (max internal step, tolerances, wall-clock limit).

    ``uses_gap``: True if the circuit's arc model depends on the gap distance
    (``ArcModel.column_gradient`` or ``breakdown_gradient`` > 0): every ``advance`` then
    needs ``gap``.

    Holds this process's ngspice until ``close()`` (or the end of a ``with`` block);
    another Stepper or run meanwhile raises SessionBusyError.
    """

    def __init__(self, circuit: CircuitLike, t_end: float, options: SimulationOptions | None = None):
        self.options = options if options is not None else SimulationOptions()
        if not isinstance(self.options, SimulationOptions):
            raise TypeError(f"options must be a SimulationOptions, got {type(self.options).__name__}")
        lines, self.probes = build_deck(circuit, t_end, self.options, "external")
        self._arc = arc_state(circuit, self.probes)
        model = circuit_arc(circuit)
        self.uses_gap = model is not None and model.uses_gap
        self._arc_model = model
        self.t_end = float(t_end)
        self.deck = tuple(lines)
        self._session: NgspiceSession | None = None
        self._t = 0.0
        self._started = False
        self._finished = False
        self._failure: BaseException | None = None
        self._final: dict[str, np.ndarray] | None = None  # the columns kept at close
        self._steps = 0
        self._length = 0
        self._ngspice_seconds = 0.0
        p = self.probes
        names = ["time", p.contact_current, p.node_a, p.node_b, p.load_current, p.arc_current]
        self._last_names = tuple(dict.fromkeys(n.lower() for n in names if n and n.lower() not in ("0", "gnd")))
        session = get_session()
        with session.exclusive():
            session.claim(self)
            try:
                session.load(list(lines))
                session.set_arc(self._arc)
            except BaseException:
                session.release(self)
                raise
        self._session = session

    # -- stepping --

    def advance(
        self, t_next: float, conductance: Conductance | float, breakpoints: Iterable[float] = (),
        gap: Gap | float | None = None,
    ) -> StepResult:
        """Integrate from the current time to ``t_next`` (s).

        conductance: G(t) in S for t in [t_current, t_next], a function of time only
            (ngspice calls it at Newton iterations and rejected trial points too), exactly
            0 for an open contact; or a constant.
        breakpoints: make/break instants (s) in (t_current, t_next]; ngspice lands on
            each, and uses the left limit of G there (the pre-event state).
        gap: the gap distance d(t) >= 0 in m on [t_current, t_next], a function of time
            only (called like G: Newton iterations, rejected trials, left limit at the
            breakpoints), or a constant. Required when the arc model depends on the gap
            (``uses_gap``: ``column_gradient`` or ``breakdown_gradient`` > 0; without it
            ValueError before anything runs); otherwise ignored (a number is still checked).
        """
        session = self._active()
        if self._failure is not None:
            raise RuntimeError(
                f"this Stepper failed at t = {self._t!r} s ({type(self._failure).__name__}); start a new one"
            ) from self._failure
        t0 = self._t
        t_next = float(t_next)
        if self._finished:
            raise ValueError(f"the run is finished (t_end = {self.t_end!r} s)")
        tol = 1e-12 * self.t_end
        if not (t_next > t0 and t_next <= self.t_end + tol):
            raise ValueError(
                f"t_next = {t_next!r} s: must satisfy {t0!r} < t_next <= t_end = {self.t_end!r} s"
            )
        final = t_next >= self.t_end - tol
        if final:
            t_next = self.t_end
        source = _as_function(conductance)
        gap_source = self._gap_function(gap)
        points = checked_breakpoints(breakpoints, t0, t_next)
        if not session.lock.acquire(blocking=False):
            raise SessionBusyError("ngspice is in use by another thread of this process")
        try:
            if not self._started and self._arc is not None:
                # The operating point: an arc path closed at t = 0 is armed.
                self._arc.start(float(source(0.0)) > 0.0)
            span = t_next - t0
            session.set_source(
                left_limited(source, points, span, t_next),
                None if gap_source is None else left_limited(gap_source, points, span, t_next),
            )
            landings = snapped(points, t_next, t_next - t0)
            if self._started and landings and landings[0] - t0 <= self.options.min_break(self.t_end):
                # ngspice drops a breakpoint within CKTminBreak after its current time
                # (measured at TMAX 1 us: 4e-11 s after it dropped, 1e-10 s landed), so a make
                # 2.6e-17 s after a macro time accumulated as t + H had its 10 ns ramp taken in
                # one step. A breakpoint at the current time itself makes ngspice restart there
                # (order 1, short first step), as it would at the make.
                session.set_breakpoint(session.last_time())
            for b in landings:
                session.set_breakpoint(b)
            if self._arc is not None:
                self._arc.add_breakpoints(landings)
            first_index = max(self._length - 1, 0)
            clock = _time.perf_counter()
            try:
                session.transient(None if final else t_next, not self._started, self.options.wall_timeout, self.t_end,
                                  self.options.end_tolerance(self.t_end))
            except BaseException as exc:
                self._failure = exc
                raise
            finally:
                self._started = True
                self._ngspice_seconds += _time.perf_counter() - clock
            last_index, landed, scalars = self._read_last(session)
            self._length = last_index
        finally:
            session.lock.release()
        self._t = t_next
        self._finished = final
        self._steps += 1
        return StepResult(
            t_start=t0,
            t_end=landed,
            points=last_index - first_index - 1,
            reader=self._reader(first_index, last_index),
            **scalars,
        )

    def _gap_function(self, gap: Gap | float | None) -> Gap | None:
        """The gap as a function of time if the arc model uses it (None otherwise)."""
        if gap is None:
            if self.uses_gap:
                arc = self._arc_model
                raise ValueError(
                    f"the arc model depends on the gap (column_gradient = {arc.column_gradient:g} V/m, "
                    f"breakdown_gradient = {arc.breakdown_gradient:g} V/m): pass the gap distance d(t) >= 0 "
                    "in m, advance(t_next, conductance, breakpoints, gap=function_of_time_or_number)"
                )
            return None
        function = _as_function(gap, "gap", "m")
        return function if self.uses_gap else None

    def _read_last(self, session: NgspiceSession) -> tuple[int, float, dict[str, float]]:
        """Points so far, the last time (s) and the last contact/load values (V, A)."""
        length, values = session.last_values(self._last_names)
        last = dict(zip(self._last_names, values))
        p = self.probes

        def node(name: str) -> float:
            return 0.0 if name.lower() in ("0", "gnd") else last[name.lower()]

        scalars = {
            "contact_voltage": node(p.node_a) - node(p.node_b),
            "contact_current": last[p.contact_current.lower()],
            "load_current": last[p.load_current.lower()] if p.load_current else math.nan,
            "arc_current": last[p.arc_current.lower()] if p.arc_current else 0.0,
        }
        return length, last["time"], scalars

    def _reader(self, start: int, stop: int) -> Callable[[str], np.ndarray]:
        def read(column: str) -> np.ndarray:
            if self._final is not None:
                return self._final[column][start:stop].copy()
            session = self._active()
            return self.probes.columns(lambda name: session.vector(name, start, stop), (column,))[column]

        return read

    # -- state --

    @property
    def time(self) -> float:
        """Time reached, s."""
        return self._t

    @property
    def finished(self) -> bool:
        return self._finished

    @property
    def contact_current(self) -> float:
        """Latest contact current, A (metallic conduction, positive from node a to node b)."""
        return self._latest("contact_current")

    @property
    def contact_voltage(self) -> float:
        """Latest contact voltage V(a) - V(b), V."""
        return self._latest("contact_voltage")

    @property
    def load_current(self) -> float:
        return self._latest("load_current")

    @property
    def arc_current(self) -> float:
        return self._latest("arc_current")

    def _latest(self, column: str) -> float:
        if self._final is not None:
            values = self._final[column]
            return float(values[-1]) if len(values) else math.nan
        if not self._started:
            return math.nan
        return self._read_last(self._active())[2][column]

    @property
    def stats(self) -> dict[str, float]:
        """Macro steps, accepted ngspice points, conductance and gap evaluations, seconds inside ngspice, arc state changes."""
        points = len(self._final["time"]) if self._final is not None else (self._active().length() if self._started else 0)
        calls = self._session.source_calls if self._session is not None else 0
        gap_calls = self._session.gap_calls if self._session is not None else 0
        return {"steps": self._steps, "points": points, "conductance_calls": calls, "gap_calls": gap_calls,
                "ngspice_seconds": self._ngspice_seconds, "arc_switches": self._arc.switches if self._arc else 0}

    def results(self, extra: tuple[str, ...] = (), probes=()):
        """``result_columns(extra, probes)`` as a pandas DataFrame."""
        import pandas as pd

        return pd.DataFrame(self.result_columns(extra, probes))

    def result_columns(self, extra: tuple[str, ...] = (), probes=()) -> dict[str, np.ndarray]:
        """The whole run so far: columns ``COLUMNS`` (SI) plus raw ngspice vectors named in ``extra``
        and the user probes (``circuit.probes.check_probes``: v(node), i(element)) as columns
        named by their text, name -> numpy array; after ``close()`` the probes' columns are
        NaN (ngspice's vectors are gone: ask for them before)."""
        names = tuple(extra) + tuple(p.text for p in probes)
        if self._session is None or (self._final is not None and not extra):
            # closed (e.g. a run that failed and is being written as it stood): the columns
            # kept at close, none if it never started; raw vectors and probes asked for
            # afterwards are gone (NaN)
            if self._final is not None:
                out = {k: v.copy() for k, v in self._final.items()}
            else:
                out = {name: np.empty(0) for name in COLUMNS}
            n = len(out["time"])
            for name in names:
                out.setdefault(name, np.full(n, np.nan))
            return out
        session = self._active()
        if not self._started:
            return {name: np.empty(0) for name in COLUMNS + names}
        out = self.probes.columns(session.vector)
        for name in extra:
            out[name] = session.vector(name.lower())
        out.update(probe_columns(probes, lambda n: session.vector(n.lower()), self.deck))
        return out

    def vector(self, name: str) -> np.ndarray:
        """Any raw ngspice vector of the run (node name, 'element#branch'), while open."""
        return self._active().vector(name.lower())

    # -- lifetime --

    def _active(self) -> NgspiceSession:
        session = self._session
        if session is None:
            raise RuntimeError("this Stepper is closed")
        owner = session.owner() if session.owner is not None else None
        if owner is not self:
            raise SessionBusyError("this Stepper's ngspice was taken over by another run")
        return session

    def close(self) -> None:
        """Keep the results, then free ngspice for the next run."""
        session = self._session
        if session is None:
            return
        try:
            owner = session.owner() if session.owner is not None else None
            if owner is self:
                if self._started and self._final is None:
                    try:
                        self._final = self.probes.columns(session.vector)
                    except KeyError:
                        self._final = None
                with session.exclusive():
                    session.clear()
        finally:
            session.release(self)
            self._session = None

    def __enter__(self) -> "Stepper":
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()


def _as_function(value: Conductance | float, what: str = "conductance", unit: str = "S") -> Conductance:
    if callable(value):
        return value
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        number = float(value)
        if not (0.0 <= number < math.inf):
            raise ValueError(f"{what} = {value!r} {unit}: must be finite and >= 0")
        return lambda t: number
    raise TypeError(f"{what} must be a function of time or a number ({unit}), got {type(value).__name__}")

