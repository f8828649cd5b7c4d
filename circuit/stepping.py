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
from typing import Callable, Iterable, Mapping, NamedTuple

import numpy as np

from .channels import ConstantChannel
from .contact import Conductance, checked_breakpoints, left_limited, snapped
from .deck import CircuitLike, arc_states, build_deck, input_sources
from .errors import ConductanceError, GapError, SessionBusyError
from .names import GROUND
from .ngspice import NgspiceSession, get_session
from .options import SimulationOptions
from .probes import COLUMNS, probe_columns

_FIXED = -2  # (a scalar of _plan_scalars read from no vector)

#: The gap distance d(t) >= 0 (m) as a function of time (s).
Gap = Callable[[float], float]


class StepResult(NamedTuple):
    """One macro step. Scalars are the values at ``t_end`` (SI: s, V, A): those of the
    circuit's first contact as attributes, every contact's in ``values`` (keyed by result
    column: contact_voltage, contact_current, arc_current with the contact's suffix, and
    load_current).

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
    values: dict = {}
    columns: tuple = COLUMNS  # the circuit's result columns (Probes.column_names)
    # ``reader``'s values as a list of floats (the same doubles, the caller's own list), for a
    # caller that works on the step's few points as floats
    floats: Callable[[str], list] | None = None
    # ``floats`` of several columns in one call: a tuple of column names -> a list of their
    # lists (SI: s, V, A, Wb as the columns are), each the caller's own
    float_columns: Callable[[tuple], list] | None = None

    def arrays(self) -> dict[str, np.ndarray]:
        return {name: self.reader(name) for name in self.columns}

    def frame(self):
        """``arrays()`` as a pandas DataFrame."""
        import pandas as pd

        return pd.DataFrame(self.arrays())


class Stepper:
    """Step a switch circuit through a transient of length ``t_end`` (s).

    circuit: a ``SwitchCircuit``, a ``NetlistCircuit`` or a PySpice ``Circuit`` with one
        or more contacts (``add_contact``).
    options: ``SimulationOptions`` (max internal step, tolerances, wall-clock limit).

    ``inputs``: the circuit's input channels, each a quantity Python gives ngspice as a
    function of time at every step: per contact "<label>.conductance" (S) and, when its
    arc model depends on the gap distance (``ArcModel.column_gradient`` or
    ``breakdown_gradient`` > 0), "<label>.gap" (m); a contact's label is "contact" (the
    unnamed one) or "contact_<name>". ``uses_gap``: True if any contact needs its gap.

    Holds this process's ngspice until ``close()`` (or the end of a ``with`` block);
    another Stepper or run meanwhile raises SessionBusyError.
    """

    def __init__(self, circuit: CircuitLike, t_end: float, options: SimulationOptions | None = None):
        self.options = options if options is not None else SimulationOptions()
        if not isinstance(self.options, SimulationOptions):
            raise TypeError(f"options must be a SimulationOptions, got {type(self.options).__name__}")
        lines, self.probes = build_deck(circuit, t_end, self.options)
        self._arcs = arc_states(self.probes)
        self.inputs = input_sources(self.probes)
        self._errors = {}
        for c in self.probes.contacts:
            which = "contact" if not c.name else f"contact {c.name}"
            self._errors[c.conductance_source] = _error(ConductanceError, f"{which} conductance", "S")
            if c.gap_source is not None:
                self._errors[c.gap_source] = _error(GapError, f"{which} gap", "m")
        for c in self.probes.coils:
            self._errors[c.gap_source] = _error(GapError, f"{c.label} gap", "m")
        self.uses_gap = any(c.gap_source is not None for c in self.probes.contacts)
        self.t_end = float(t_end)
        self.deck = tuple(lines)
        # s: the run's fixed lengths, from the options and t_end (asked at every macro step)
        self._sliver = self.options.sliver(self.t_end)
        self._min_break = self.options.min_break(self.t_end)
        self._end_tolerance = self.options.end_tolerance(self.t_end)
        self._tol = 1e-12 * self.t_end  # s: how far past t_end a macro step's end is taken as t_end
        # the first contact's suffix (its scalars are StepResult's attributes), None without one
        self._first = self.probes.contacts[0].suffix if self.probes.contacts else None
        self._session: NgspiceSession | None = None
        self._t = 0.0
        self._started = False
        self._finished = False
        self._failure: BaseException | None = None
        self._final: dict[str, np.ndarray] | None = None  # the columns kept at close
        self._rejections: list[tuple[float, bool]] | None = None  # ngspice's rejected steps, kept at close
        self._steps = 0
        self._length = 0
        self._ngspice_seconds = 0.0
        names = ["time"]
        for c in self.probes.contacts:
            names += [c.current_vector, c.node_a, c.node_b]
        names.append(self.probes.load_current)
        names += [c.arc_current_vector for c in self.probes.contacts]
        names += [c.load_vector for c in self.probes.contacts]
        for c in self.probes.coils:
            names += [c.current_vector, c.node_p, c.node_n, c.flux_node]
        self._last_names = tuple(dict.fromkeys(n.lower() for n in names if n and n.lower() not in GROUND))
        self._scalar_plan = self._plan_scalars()
        self._columns = self.probes.column_names  # (a property that builds its tuple: once, not per step)
        # the columns that are one ngspice vector as it stands, by its (lower-case) name
        self._direct = {column: name.lower() for column in self._columns
                        if (name := self.probes.vector_of(column)) is not None}
        session = get_session()
        with session.exclusive():
            session.claim(self)
            try:
                session.load(list(lines))
                session.set_arcs(self._arcs)
            except BaseException:
                session.release(self)
                raise
        self._session = session

    # -- stepping --

    def advance(
        self, t_next: float, conductance: Conductance | float | None = None, breakpoints: Iterable[float] = (),
        gap: Gap | float | None = None, *, inputs: Mapping[str, Conductance | float] | None = None,
        max_step: float = math.inf, restart: bool = False,
    ) -> StepResult:
        """Integrate from the current time to ``t_next`` (s).

        inputs: every input channel (``self.inputs``) -> its value over [t_current, t_next]:
            a function of time only (ngspice calls it at Newton iterations and rejected
            trial points too), a ``TableChannel`` (a piecewise polynomial that the compiled
            callbacks evaluate without Python), or a constant. A conductance (S) is exactly 0 for an open
            contact; a gap (m) is the distance d(t) >= 0. A circuit with one contact may
            give ``conductance`` and ``gap`` instead.
        max_step: s, ngspice's steps within this macro step at most this long (besides the
            options' max_step for the whole run): a caller that knows a state changes fast
            over the step (a coil's flux) asks for points in it.
        breakpoints: make/break instants (s) in (t_current, t_next]; ngspice lands on
            each, and every input is read as its left limit there (the pre-event state).
        restart: a make/break at the current time itself (within a sliver after it, where no
            step can land): ngspice restarts there (order 1, a short first step), as at a
            breakpoint.
        gap: required when the arc model depends on the gap (``uses_gap``; without it
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
        if not max_step > 0.0:  # (also NaN)
            raise ValueError(f"max_step = {max_step!r} s: must be > 0 (inf: no bound)")
        tol = self._tol
        if not (t_next > t0 and t_next <= self.t_end + tol):
            raise ValueError(
                f"t_next = {t_next!r} s: must satisfy {t0!r} < t_next <= t_end = {self.t_end!r} s"
            )
        final = t_next >= self.t_end - tol
        if final:
            t_next = self.t_end
        functions = self._input_functions(conductance, gap, inputs)
        # (most macro steps have no make or break: an empty list or tuple is taken as it is,
        # and below no left limits or landings are worked out for none, ~1.5 us a step)
        points = () if type(breakpoints) in (list, tuple) and not breakpoints else \
            checked_breakpoints(breakpoints, t0, t_next)
        if not session.lock.acquire(blocking=False):
            raise SessionBusyError("ngspice is in use by another thread of this process")
        try:
            if not self._started:
                # The operating point: an arc path closed at t = 0 is armed.
                for arc in self._arcs.values():
                    arc.start(float(functions[arc.conductance_source](0.0)) > 0.0)
            span = t_next - t0
            merge = self._sliver  # (no sliver step after a breakpoint)
            # (without breakpoints left_limited returns each function as it is)
            session.set_channels({source: left_limited(f, points, span, t_next, merge)
                                  for source, f in functions.items()} if points else functions, self._errors)
            landings = snapped(points, t_next, t_next - t0, merge) if points else []
            if self._started and (restart or (landings and landings[0] - t0 <= self._min_break)):
                # ngspice drops a breakpoint within CKTminBreak after its current time
                # (measured at TMAX 1 us: 4e-11 s after it dropped, 1e-10 s landed), so a make
                # 2.6e-17 s after a macro time accumulated as t + H had its 10 ns ramp taken in
                # one step. A breakpoint at the current time itself makes ngspice restart there
                # (order 1, short first step), as it would at the make.
                session.set_breakpoint(session.last_time())
            for b in landings:
                session.set_breakpoint(b)
            for arc in self._arcs.values():
                arc.add_breakpoints(landings)
            first_index = max(self._length - 1, 0)
            clock = _time.perf_counter()
            try:
                session.transient(None if final else t_next, not self._started, self.options.wall_timeout, self.t_end,
                                  self._end_tolerance, max_step)
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
        first = self._first
        read, floats, float_columns = self._reader(first_index, last_index)
        # (by position, in the fields' order: keywords cost a macro step ~0.4 us more)
        return StepResult(
            t0,  # t_start
            landed,  # t_end
            math.nan if first is None else scalars["contact_voltage" + first],  # contact_voltage
            math.nan if first is None else scalars["contact_current" + first],  # contact_current
            scalars["load_current"],  # load_current
            math.nan if first is None else scalars["arc_current" + first],  # arc_current
            last_index - first_index - 1,  # points
            read,  # reader
            scalars,  # values
            self._columns,  # columns
            floats,  # floats
            float_columns,  # float_columns
        )

    def _input_functions(self, conductance, gap, inputs) -> dict[str, Conductance]:
        """Every input channel's source -> its function of time, checked (ValueError/TypeError
        naming the channel before anything runs)."""
        channels = self.inputs
        if (conductance is None and gap is None and inputs is not None and len(inputs) == len(channels)
                and all(map(channels.__contains__, inputs))):  # every channel given by name: nothing to add
            # (a function or channel is taken as it is, as _as_function would: no message built for it)
            return {channels[name]: value if callable(value) else _as_function(value, *_what(name))
                    for name, value in inputs.items()}
        given = dict(inputs or {})
        if conductance is not None or gap is not None:
            if len(self.probes.contacts) != 1:
                raise ValueError(f"this circuit has {len(self.probes.contacts)} contacts: give each its input "
                                 f"channels, advance(t_next, inputs={{...}}) with {', '.join(self.inputs)}")
            single = self.probes.contacts[0]
            if conductance is not None:
                given.setdefault(f"{single.label}.conductance", conductance)
            if gap is not None and single.gap_source is not None:
                given.setdefault(f"{single.label}.gap", gap)
        unknown = sorted(set(given) - set(self.inputs))
        if unknown:
            raise ValueError(f"inputs {', '.join(unknown)}: this circuit's input channels are {', '.join(self.inputs)}")
        missing = [name for name in self.inputs if name not in given]
        for name in missing:
            block = next((c for c in self.probes.contacts if f"{c.label}.gap" == name), None)
            if block is not None:
                arc = block.arc
                raise ValueError(
                    f"the arc model depends on the gap ({arc.gap_terms}): pass the gap distance d(t) >= 0 "
                    f"in m, advance(t_next, conductance, breakpoints, gap=function_of_time_or_number)"
                    + ("" if len(self.probes.contacts) == 1 else f" (input {name})"))
            raise TypeError(f"advance() needs the input {name} (a function of time or a number)")
        if gap is not None and not self.uses_gap:
            _as_function(gap, "gap", "m")  # checked, then ignored: no arc uses it
        return {self.inputs[name]: _as_function(value, *_what(name)) for name, value in given.items()}

    def _read_last(self, session: NgspiceSession) -> tuple[int, float, dict[str, float]]:
        """Points so far, the last time (s) and the last contact/load values (V, A)."""
        length, last = session.last_values(self._last_names)
        # (the plan of _plan_scalars: the dict's keys built once, not per macro step)
        scalars = {key: fixed if a == _FIXED else (last[a] if a >= 0 else 0.0) - (last[b] if b >= 0 else 0.0)
                   for key, a, b, fixed in self._scalar_plan}
        return length, last[0], scalars

    def _plan_scalars(self) -> tuple[tuple[str, int, int, float], ...]:
        """Each scalar of a step (``StepResult.values``) as (key, a, b, fixed): the value
        ``fixed`` where a is _FIXED, else the last value of ``_last_names[a]`` minus that of
        ``_last_names[b]``, an index -1 standing for ground (0 V)."""
        index = {name: k for k, name in enumerate(self._last_names)}

        def node(name: str) -> int:
            return -1 if name.lower() in GROUND else index[name.lower()]

        def vector(key: str, name: str | None, otherwise: float) -> tuple[str, int, int, float]:
            return (key, index[name.lower()], -1, 0.0) if name else (key, _FIXED, -1, otherwise)

        p = self.probes
        plan = [vector("load_current", p.load_current, math.nan)]
        for c in p.contacts:
            plan.append(("contact_voltage" + c.suffix, node(c.node_a), node(c.node_b), 0.0))
            plan.append(vector("contact_current" + c.suffix, c.current_vector, math.nan))
            plan.append(vector("arc_current" + c.suffix, c.arc_current_vector, 0.0))
            if c.load_vector is not None:
                plan.append(vector("load_current" + c.suffix, c.load_vector, math.nan))
        for c in p.coils:
            plan.append(vector("coil_current" + c.suffix, c.current_vector, math.nan))
            plan.append(("coil_voltage" + c.suffix, node(c.node_p), node(c.node_n), 0.0))
            plan.append(vector("coil_flux_linkage" + c.suffix, c.flux_node, math.nan))
        return tuple(plan)

    def _reader(self, start: int, stop: int) -> tuple[Callable[[str], np.ndarray], Callable[[str], list],
                                                      Callable[[tuple], list]]:
        # the step's vectors, each read from ngspice once however many columns and callers
        # ask (a coupled step's callers read time three times); each call returns its own copy.
        # ``floats``: a column as a list of floats, a vector of ngspice's read straight into
        # one (cffi's unpack: a macro step's two or three points cost ~1 us instead of the
        # ~4 us of a numpy array made, copied and converted; the same doubles)
        vectors: dict[str, np.ndarray] = {}
        columns: dict[str, np.ndarray] = {}
        lists: dict[str, list] = {}
        probes, direct = self.probes, self._direct

        def vector(name: str) -> np.ndarray:
            values = vectors.get(name)
            if values is None:
                values = vectors[name] = self._active().vector(name, start, stop)
            return values

        def read(column: str) -> np.ndarray:
            if self._final is not None:
                return self._final[column][start:stop].copy()
            self._active()
            values = columns.get(column)
            if values is None:
                name = direct.get(column)
                values = columns[column] = (vector(name) if name is not None
                                            else probes.columns(vector, (column,))[column])
            return values.copy()

        def listed(column: str, session):
            # (the column's list of floats, kept for the step, and the session if it was
            # asked for: ``float_columns`` checks the owner once for all its columns)
            values = lists.get(column)
            if values is None:
                name = direct.get(column)
                if self._final is not None or name is None or column in columns:
                    values = read(column).tolist()
                else:
                    if session is None:
                        session = self._active()
                    values = session.floats(name, start, stop)
                lists[column] = values
            return values, session

        def floats(column: str) -> list:
            return listed(column, None)[0][:]

        def float_columns(names: tuple) -> list:
            # (a coupled macro step reads two columns: one call, one owner's check)
            out = []
            session = None
            for column in names:
                values, session = listed(column, session)
                out.append(values[:])
            return out

        return read, floats, float_columns

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
    def rejections(self) -> tuple[np.ndarray, np.ndarray]:
        """Every step ngspice rejected in this run: (the accepted time it was retried from, s;
        True where Newton failed to converge, False where ngspice's truncation-error test
        rejected it). docs/circuit.md, "What ngspice does after the arc's chop"."""
        found = self._rejections if self._rejections is not None else (
            self._session.rejections if self._session is not None and self._started else [])
        return (np.array([t for t, _ in found], dtype=float), np.array([n for _, n in found], dtype=bool))

    @property
    def stats(self) -> dict[str, float]:
        """Macro steps, accepted ngspice points, conductance and gap evaluations (and a coil's gap,
        with a coil), seconds inside ngspice, arc state changes (the steps ngspice rejected:
        ``rejections``)."""
        points = len(self._final["time"]) if self._final is not None else (self._active().length() if self._started else 0)
        calls = self._session.channel_calls if self._session is not None else {}
        conductances = {c.conductance_source.lower() for c in self.probes.contacts}
        gaps = {c.gap_source.lower() for c in self.probes.contacts if c.gap_source}
        coils = {c.gap_source.lower() for c in self.probes.coils}
        out = {"steps": self._steps, "points": points,
               "conductance_calls": sum(n for s, n in calls.items() if s in conductances),
               "gap_calls": sum(n for s, n in calls.items() if s in gaps),
               "ngspice_seconds": self._ngspice_seconds,
               "arc_switches": sum(arc.switches for arc in self._arcs.values())}
        if coils:
            out["coil_gap_calls"] = sum(n for s, n in calls.items() if s in coils)
        return out

    def results(self, extra: tuple[str, ...] = (), probes=()):
        """``result_columns(extra, probes)`` as a pandas DataFrame."""
        import pandas as pd

        return pd.DataFrame(self.result_columns(extra, probes))

    def result_columns(self, extra: tuple[str, ...] = (), probes=()) -> dict[str, np.ndarray]:
        """The whole run so far: the circuit's columns (``probes.column_names``, SI) plus raw ngspice vectors named in ``extra``
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
                out = {name: np.empty(0) for name in self.probes.column_names}
            n = len(out["time"])
            for name in names:
                out.setdefault(name, np.full(n, np.nan))
            return out
        session = self._active()
        if not self._started:
            return {name: np.empty(0) for name in self.probes.column_names + names}
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
                    self._rejections = list(session.rejections)
                with session.exclusive():
                    session.clear()
        finally:
            session.release(self)
            self._session = None

    def __enter__(self) -> "Stepper":
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()


def _error(kind: type, what: str, unit: str) -> Callable[[float, float], Exception]:
    """The error for an input value that is not finite and >= 0."""
    return lambda t, value: kind(f"{what} at t = {t!r} s is {value!r} {unit}; it must be finite and >= 0")


def _what(channel: str) -> tuple[str, str]:
    """(what an input is, its unit) for messages: ("conductance", "S") or ("gap", "m")."""
    return ("gap", "m") if channel.endswith(".gap") else ("conductance", "S")


def _as_function(value: Conductance | float, what: str = "conductance", unit: str = "S") -> Conductance:
    if callable(value):
        return value
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        number = float(value)
        if not (0.0 <= number < math.inf):
            raise ValueError(f"{what} = {value!r} {unit}: must be finite and >= 0")
        return ConstantChannel(number)
    raise TypeError(f"{what} must be a function of time or a number ({unit}), got {type(value).__name__}")

