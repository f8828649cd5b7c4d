"""Runs through ngspice's compiled callbacks (circuit/callbacks.c: the sources and the step
control) against runs through its Python callbacks: the same waveforms to the bit, the
same errors and wall-clock aborts, the same channel calls; a TableChannel's C values
against its Python function at random times; a session without the compiled library runs
on the Python route; an arc's gap held while the arc is out and its contact open, on both
routes, without changing a bit.

The route is chosen when a Stepper loads its circuit: SWITCHSIM_PYTHON_CALLBACKS=1 forces
the Python callbacks (compiled_callbacks.FORCE_PYTHON).
"""

from __future__ import annotations

import math
import random
import struct
import time
from bisect import bisect_left

import numpy as np
import pytest

from circuit import (
    ArcModel,
    ConductanceError,
    ContactSchedule,
    DCSource,
    GapError,
    InductiveLoad,
    SimulationOptions,
    SimulationTimeout,
    Stepper,
    SwitchCircuit,
    TableChannel,
    Wiring,
    compiled_callbacks,
    get_session,
    ngspice,
)

V_S, R_S = 24.0, 0.05
SPEED, T_BREAK, T_END = 2.0, 0.1e-3, 0.6e-3
ARC = ArcModel(min_voltage=12.0, min_current=0.4, resistance=0.05, column_gradient=2e3)
BREAK = ContactSchedule(((0.0, T_BREAK),), closed_resistance=0.01)
OPTIONS = SimulationOptions(max_step=1e-6)
MACRO = 0.05e-3


# arcs whose accepted points the compiled step callback answers where only the arc's filter
# moves (lit and closed, out and unarmed), and arcs it leaves to ArcState.accepted at
# every point: one out after the break with a breakdown to test, the Ayrton arc
ARCS = {
    "linear": ARC,
    "breakdown": ArcModel(min_voltage=12.0, min_current=0.4, resistance=0.05, column_gradient=2e3,
                          breakdown_voltage=30.0, breakdown_gradient=1e5),
    "ayrton": ArcModel(min_voltage=12.0, min_current=0.4, column_gradient=2e3, characteristic="ayrton",
                       ayrton_c=2.0, ayrton_d=1e3),
}


def circuit(arc: ArcModel = ARC) -> SwitchCircuit:
    return SwitchCircuit(DCSource(V_S, R_S), InductiveLoad(12.0, 1e-3), wiring=Wiring(0.0, 0.0),
                         contact_capacitance=100e-12, arc=arc)


def bits(x: float) -> bytes:
    return struct.pack("<d", x)


def python_twin(lo, hi, start, ends, t0, h, coefficients, offset, scale):
    """A TableChannel's value written as plain Python float arithmetic (its definition)."""
    ends, t0, h, rows = ends.tolist(), t0.tolist(), h.tolist(), coefficients.tolist()
    n = len(ends)

    def value(s: float) -> float:
        s = lo if s < lo else (hi if s > hi else s)
        if not ends or s <= lo:
            q = start
        else:
            k = min(bisect_left(ends, s), n - 1)
            c0, c1, c2, c3, c4 = rows[k]
            th = (s - t0[k]) / h[k]
            t1 = 1.0 - th
            q = c0 + th * (c1 + t1 * (c2 + th * (c3 + t1 * c4)))
        return max(offset - scale * q, 0.0)

    return value


def gap_table(lo: float, hi: float, pieces: int = 3, seed: int = 0, bad: float | None = None) -> TableChannel:
    """The gap SPEED (t - T_BREAK), 0 before the break, as quartic pieces over [lo, hi] with
    small curvature terms (so that every coefficient counts); ``bad``: a value put in."""
    rng = random.Random(seed)
    edges = np.linspace(lo, hi, pieces + 1)
    t0, h, ends = edges[:-1], np.diff(edges), edges[1:]
    y = SPEED * (edges - T_BREAK)
    coefficients = np.array([[y[k], y[k + 1] - y[k]] + [rng.uniform(-1e-7, 1e-7) for _ in range(3)]
                             for k in range(pieces)])
    if bad is not None:
        coefficients[-1, 0] = bad
    start = float(y[0])
    twin = python_twin(lo, hi, start, ends, t0, h, coefficients, 0.0, -1.0)
    return TableChannel(twin, lo, hi, start, ends, t0, h, coefficients, offset=0.0, scale=-1.0)


def use_route(monkeypatch, python: bool) -> None:
    """The next circuit load runs on the Python callbacks (``python``) or the compiled ones."""
    if python:
        monkeypatch.setenv(compiled_callbacks.FORCE_PYTHON, "1")
    else:
        monkeypatch.delenv(compiled_callbacks.FORCE_PYTHON, raising=False)


@pytest.fixture(params=["compiled", "python"])
def route(request, monkeypatch):
    use_route(monkeypatch, request.param == "python")
    return request.param


def stepped(table: bool, constant_after: float | None = None, arc: ArcModel = ARC) -> tuple[dict, dict, bool]:
    """A break with an arc, the gap a TableChannel (or its Python function), the contact's
    conductance a function, then (``constant_after``) a constant: columns, stats, route."""
    with Stepper(circuit(arc), T_END, OPTIONS) as stepper:
        compiled = get_session()._compiled is not None
        t = 0.0
        while not stepper.finished:
            t_next = min(t + MACRO, T_END)
            gap = gap_table(t, t_next, seed=int(t / MACRO))
            conductance = BREAK if constant_after is None or t < constant_after else 0.0
            stepper.advance(t_next, conductance, BREAK.breakpoints(t, t_next), gap=gap if table else gap.function,
                            max_step=3e-7 if 0.1e-3 <= t < 0.2e-3 else math.inf)  # (the pause's own bound)
            t = t_next
        columns = stepper.result_columns()
        columns["rejected_from"], columns["rejected_newton"] = stepper.rejections  # (the sync callback's log)
        return columns, stepper.stats, compiled


def same(a: dict, b: dict) -> bool:
    return a.keys() == b.keys() and all(np.asarray(a[k]).tobytes() == np.asarray(b[k]).tobytes() for k in a)


def test_both_routes_give_the_same_waveforms_to_the_bit(monkeypatch):
    results = {}
    for name in ("compiled", "python"):
        use_route(monkeypatch, name == "python")
        results[name] = stepped(table=True, constant_after=0.3e-3)
    (columns_c, stats_c, compiled), (columns_p, stats_p, python) = results["compiled"], results["python"]
    assert compiled and not python
    assert same(columns_c, columns_p)
    assert stats_c["gap_calls"] == stats_p["gap_calls"] > 0
    assert stats_c["conductance_calls"] == stats_p["conductance_calls"] > 0
    assert np.any(columns_c["arc_current"] != 0.0)  # the arc burned: its source was read


@pytest.mark.parametrize("kind", sorted(ARCS))
def test_every_arc_kind_runs_to_the_same_bits_on_both_routes(kind, monkeypatch):
    """The arc's state at every accepted point, whichever callback decided it, is Python's
    (the waveforms and the rejected steps' log, to the bit)."""
    results = []
    for python in (False, True):
        use_route(monkeypatch, python)
        results.append(stepped(table=True, arc=ARCS[kind]))
    (compiled, _, on_c), (python, _, on_python) = results
    assert on_c and not on_python
    assert same(compiled, python)
    assert np.any(compiled["arc_current"] != 0.0)


def test_rejected_steps_beyond_the_compiled_log_are_kept_in_order(monkeypatch, tmp_path):
    """The compiled step callback logs rejected steps in a buffer that Python empties into its
    list; a full buffer hands that redo to Python, which empties it first. With room for two,
    the log is the Python route's, entry for entry."""
    monkeypatch.setattr(ngspice, "REJECTIONS_LOGGED", 2)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))  # (a library of its own: its state made afresh)
    use_route(monkeypatch, False)
    compiled, _, on_c = stepped(table=True)
    use_route(monkeypatch, True)
    python, _, _ = stepped(table=True)
    assert on_c and len(compiled["rejected_from"]) > 2 * 2
    assert same(compiled, python)


def test_a_table_channel_runs_as_its_python_function(route):
    with_table, _, _ = stepped(table=True)
    with_function, _, _ = stepped(table=False)
    assert same(with_table, with_function)


def test_without_the_compiled_library_the_session_runs_the_python_callbacks(monkeypatch):
    use_route(monkeypatch, False)
    compiled, _, on_c = stepped(table=True)
    monkeypatch.setattr(compiled_callbacks, "load", lambda root=None: None)  # (a failed build)
    python, _, on_c_after = stepped(table=True)
    assert on_c and not on_c_after
    assert same(compiled, python)


def _error(run) -> tuple[type, str]:
    with pytest.raises(Exception) as caught:
        run()
    return type(caught.value), str(caught.value)


def test_a_bad_value_raises_the_same_one_line_error_on_both_routes(monkeypatch):
    def bad_conductance():
        with Stepper(circuit(), T_END, OPTIONS) as stepper:
            stepper.advance(0.2e-3, lambda t: -1.0 if t > 0.05e-3 else 1.0, gap=0.0)

    def bad_table():
        with Stepper(circuit(), T_END, OPTIONS) as stepper:
            stepper.advance(0.2e-3, BREAK, BREAK.breakpoints(0.0, 0.2e-3), gap=gap_table(0.0, 0.2e-3, bad=math.nan))

    def infinite_table():  # (a table's value is clipped at zero: only NaN or inf can be bad)
        with Stepper(circuit(), T_END, OPTIONS) as stepper:
            stepper.advance(0.2e-3, BREAK, BREAK.breakpoints(0.0, 0.2e-3), gap=gap_table(0.0, 0.2e-3, bad=math.inf))

    for run, kind, pattern in ((bad_conductance, ConductanceError, "conductance at t = "),
                               (bad_table, GapError, " is nan m; it must be finite and >= 0"),
                               (infinite_table, GapError, " is inf m; it must be finite and >= 0")):
        errors = []
        for python in (False, True):
            use_route(monkeypatch, python)
            errors.append(_error(run))
        assert errors[0] == errors[1]
        assert errors[0][0] is kind and pattern in errors[0][1] and "\n" not in errors[0][1], errors[0]


def test_the_wall_clock_limit_aborts_a_run_with_no_python_channel_on_both_routes(monkeypatch):
    """Constant inputs and no arc: on the compiled route no step of the run enters Python
    until the deadline has passed."""
    plain = SwitchCircuit(DCSource(V_S, R_S), InductiveLoad(12.0, 1e-3), wiring=Wiring(0.0, 0.0))
    for python in (False, True):
        use_route(monkeypatch, python)
        started = time.monotonic()
        with Stepper(plain, 10.0, SimulationOptions(max_step=1e-7, wall_timeout=0.1)) as stepper:
            assert (get_session()._compiled is None) == python
            with pytest.raises(SimulationTimeout, match="wall-clock limit"):
                stepper.advance(10.0, 1.0)
        assert time.monotonic() - started < 5.0


def test_the_c_table_equals_its_python_definition_at_random_times_bit_for_bit(monkeypatch):
    use_route(monkeypatch, False)
    library = compiled_callbacks.load()
    assert library is not None
    rng = random.Random(7)
    for seed in range(20):
        lo = rng.uniform(0.0, 1e-3)
        hi = lo + rng.uniform(1e-9, 1e-4)
        table = gap_table(lo, hi, pieces=rng.randint(1, 6), seed=seed)
        times = [rng.uniform(lo - 0.1 * (hi - lo), hi + 0.1 * (hi - lo)) for _ in range(200)]
        times += [lo, hi, *table.ends.tolist(), *table.t0.tolist(), math.nextafter(lo, -1.0), math.nextafter(hi, 2.0)]
        assert [bits(v) for v in compiled_callbacks.table_values(library, table, times)] == \
            [bits(table.function(t)) for t in times]
        # read as left limits at breakpoints (circuit.contact.left_limited's windows)
        from circuit.contact import left_limited

        breaks = sorted(rng.uniform(lo, hi) for _ in range(2))
        limited = left_limited(table, breaks, hi - lo, hi)
        assert isinstance(limited, TableChannel) and limited.windows is not None
        times += [b + d for b in breaks for d in (-1e-12 * b, 0.0, 1e-13 * b, 2e-12 * b)]
        assert [bits(v) for v in compiled_callbacks.table_values(library, limited, times)] == \
            [bits(limited.function(t)) for t in times]
    empty = TableChannel(lambda s: 0.5, 0.0, 1.0, 0.5, [], [], [], np.empty((0, 5)))
    assert compiled_callbacks.table_values(library, empty, [0.0, 0.5, 2.0]) == [0.5, 0.5, 0.5]


def test_a_macro_steps_last_values_are_the_stored_points_on_both_routes(monkeypatch):
    """At each pause the step's last values (``StepResult``'s scalars) are read from the point
    SendData gave, not looked up vector by vector: the same doubles as the stored vectors'
    last points, and the step's length theirs, on either callback route."""
    for python in (False, True):
        use_route(monkeypatch, python)
        with Stepper(circuit(), T_END, OPTIONS) as stepper:
            session = get_session()
            t, steps = 0.0, 0
            while not stepper.finished:
                t_next = min(t + MACRO, T_END)
                gap = gap_table(t, t_next, seed=int(t / MACRO))
                step = stepper.advance(t_next, BREAK, BREAK.breakpoints(t, t_next), gap=gap)
                for name in ("contact_current", "load_current", "arc_current"):  # (vectors of ngspice's)
                    assert bits(step.values[name]) == bits(float(step.reader(name)[-1])), (python, t, name)
                # (the column is I/G while the contact conducts: the scalar is the nodes' difference)
                contact = stepper.probes.contacts[0]
                across = float(stepper.vector(contact.node_a)[-1]) - float(stepper.vector(contact.node_b)[-1])
                assert bits(step.values["contact_voltage"]) == bits(across)
                assert step.points == len(step.reader("time")) - 1 and step.t_end == step.reader("time")[-1]
                t, steps = t_next, steps + 1
            assert session._point_plans and all(plan is not None for plan in session._point_plans.values())
        assert steps == round(T_END / MACRO)


def held_or_followed(arc: ArcModel, held: bool) -> tuple[dict, dict, list[float]]:
    """A break whose arc burns, then goes out as its gap (a Python function, its calls
    recorded) opens at 20 m/s; the contact's conductance is the schedule until 0.2 ms and
    then, already open, the constant 0 (``held``: the source callbacks may hold the gap) or
    still the schedule's function, 0 all the same (the gap followed at every new time):
    columns with the rejected steps, stats, the gap's calls (s)."""
    calls = []

    def gap(t: float) -> float:
        calls.append(t)
        return max(0.0, 10.0 * SPEED * (t - T_BREAK))

    with Stepper(circuit(arc), T_END, OPTIONS) as stepper:
        t = 0.0
        while not stepper.finished:
            t_next = min(t + MACRO, T_END)
            conductance = 0.0 if held and t >= 0.2e-3 else BREAK
            stepper.advance(t_next, conductance, BREAK.breakpoints(t, t_next), gap=gap)
            t = t_next
        columns = stepper.result_columns()
        columns["rejected_from"], columns["rejected_newton"] = stepper.rejections
        return columns, stepper.stats, calls


@pytest.mark.parametrize("kind", sorted(ARCS))
def test_an_arcs_gap_is_held_while_the_arc_is_out_and_its_contact_open_with_the_same_bits(kind, route):
    """Once the arc has been out for a whole step, and while its contact's conductance is the
    constant 0 (it cannot arm), ngspice reads its gap nowhere (V(arc_on) = 0 times the gap's
    terms): the source callbacks answer the gap's last value without calling its function,
    and the run is the same to the bit as one that follows the gap at every new time (the
    conductance a function). An arc with a breakdown voltage, which may re-ignite, always
    follows it. ``gap_calls`` counts the function's calls, not the held answers."""
    (columns, stats, calls), (followed, _, followed_calls) = (held_or_followed(ARCS[kind], held)
                                                             for held in (True, False))
    assert same(columns, followed)
    current, times = np.abs(columns["arc_current"]), columns["time"]
    lit = np.nonzero(current > 1e-3)[0]
    out = lit[-1] + 1  # the first point of the arc out (its state changed at the one before)
    assert 0.2e-3 < times[out] < T_END - 0.1e-3  # (the contact open, its conductance given as 0.0)
    assert stats["gap_calls"] == len(calls)
    assert sum(t > times[out] for t in followed_calls) > 1000
    if ARCS[kind].breakdown_voltage is None:
        assert stats["arc_switches"] == 1  # lit from the start, out at the point before ``out``, for good
        assert max(calls) == times[out]  # called up to the first point out, held after it
        assert len(calls) < len(followed_calls) / 10
    else:
        assert calls == followed_calls
