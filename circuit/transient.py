"""One-shot transient runs: a contact given as G(t) or a schedule, and the PWL reference form."""

from __future__ import annotations

import numbers
from typing import TYPE_CHECKING, Iterable, Union

import numpy as np

from .contact import Conductance
from .deck import CircuitLike, arc_states, build_deck, circuit_netlist
from .ngspice import get_session
from .options import SimulationOptions
from .schedule import ContactSchedule
from .stepping import Gap, Stepper

if TYPE_CHECKING:  # pandas is imported by the DataFrame's maker, on use
    import pandas


def run_transient(
    circuit: CircuitLike,
    contact: ContactSchedule | Conductance | float,
    t_end: float,
    *,
    options: SimulationOptions | None = None,
    breakpoints: Iterable[float] = (),
    extra: tuple[str, ...] = (),
    gap: Gap | float | None = None,
    probes=(),
) -> pandas.DataFrame:
    """Run 0..t_end (s) with the contact conductance from Python; returns the waveform (SI columns).

    contact: a ``ContactSchedule`` (its ramp corners become breakpoints), a function
        G(t) in S (pass its make/break instants as ``breakpoints``), or a constant in S.
    extra: raw ngspice vectors to add as columns (e.g. 'load', 'vsource#branch', 'arc_gap').
    gap: the gap distance d(t) >= 0 in m (function of time or constant) for an arc
        model that depends on it (``ArcModel.column_gradient``/``breakdown_gradient``);
        None: a schedule's own ``gap`` if it has an ``opening_speed``. Missing while
        needed: ValueError before anything runs.
    probes: user probes (``circuit.probes.check_probes``) recorded as extra columns.
    """
    points = set(float(b) for b in breakpoints)
    if isinstance(contact, ContactSchedule):
        points.update(contact.breakpoints(0.0, t_end))
        if gap is None and contact.opening_speed is not None:
            gap = contact.gap
        contact = contact.conductance
    _require_gap(circuit, gap, "run_transient(..., gap=function_of_time_or_number)")
    with Stepper(circuit, t_end, options) as stepper:
        stepper.advance(t_end, contact, sorted(p for p in points if 0.0 < p <= t_end), gap=gap)
        return stepper.results(extra, probes)


def _single_contact(circuit: CircuitLike, how: str):
    """The circuit's one contact (a block); a one-shot run drives exactly one."""
    contacts = circuit_netlist(circuit)[1].contacts
    if len(contacts) != 1:
        raise ValueError(f"a one-shot run drives a circuit's one contact; this one has {len(contacts)} "
                         f"({', '.join(c.label for c in contacts)}): step it with Stepper.advance(..., inputs={{...}})")
    return contacts[0]


def _require_gap(circuit: CircuitLike, gap: object, how: str) -> None:
    arc = _single_contact(circuit, how).arc
    if gap is None and arc is not None and arc.uses_gap:
        raise ValueError(
            f"the arc model depends on the gap ({arc.gap_terms}): pass the gap distance d(t) >= 0 in m, {how}"
        )


GapVertices = Union[tuple[np.ndarray, np.ndarray], float]


def run_pwl_reference(
    circuit: CircuitLike,
    schedule: ContactSchedule,
    t_end: float,
    *,
    options: SimulationOptions | None = None,
    resistance_step: float | None = None,
    extra: tuple[str, ...] = (),
    gap: GapVertices | None = None,
) -> pandas.DataFrame:
    """The same run with the schedule written into the netlist as a PWL conductance source.

    No Python in ngspice's loop: the reference that the callback and stepping forms are
    checked against. ngspice sets breakpoints at the PWL vertices itself.
    resistance_step: sampling step (s) of a closed-resistance function (constant: unused).
    gap: for an arc model that depends on the gap, the gap as PWL vertices (times s,
        distances m) or a constant (m); None: the schedule's own ``gap`` (its
        ``opening_speed``), written exactly as a PWL. Missing while needed: ValueError.
    """
    if not isinstance(schedule, ContactSchedule):
        raise TypeError(f"run_pwl_reference needs a ContactSchedule, got {type(schedule).__name__}")
    options = options if options is not None else SimulationOptions()
    drive = schedule.pwl_points(t_end, resistance_step)
    gap_drive = _gap_vertices(gap, schedule, t_end)
    _require_gap(circuit, gap_drive, "run_pwl_reference(..., gap=(times, distances)) or a schedule "
                 "with opening_speed")
    contact = _single_contact(circuit, "run_pwl_reference")
    drives = {f"{contact.label}.conductance": drive}
    if gap_drive is not None and contact.gap_source is not None:
        drives[f"{contact.label}.gap"] = gap_drive
    lines, probes = build_deck(circuit, t_end, options, drives)
    arcs = arc_states(probes)
    for arc in arcs.values():
        arc.start(float(drive[1][0]) > 0.0)
        arc.add_breakpoints(drive[0])  # ngspice lands on the PWL vertices
    session = get_session()
    owner = _Run()
    with session.exclusive():
        session.claim(owner)
        try:
            session.load(lines)
            session.set_arcs(arcs)
            session.transient(None, True, options.wall_timeout, t_end, options.end_tolerance(t_end))
            return probes.frame(session.vector, tuple(extra))
        finally:
            session.clear()
            session.release(owner)


def _gap_vertices(gap: GapVertices | None, schedule: ContactSchedule, t_end: float):
    """PWL vertices of the gap (times s, distances m), or None if there is none."""
    if gap is None:
        return schedule.gap_pwl_points(t_end) if schedule.opening_speed is not None else None
    if callable(gap):
        raise TypeError("run_pwl_reference: the gap must be PWL vertices (times s, distances m) or a number (m), "
                        "not a function (use run_transient for a gap function)")
    if isinstance(gap, numbers.Real) and not isinstance(gap, bool):
        value = float(gap)
        if not (0.0 <= value < np.inf):
            raise ValueError(f"gap = {gap!r} m: must be finite and >= 0")
        return np.array([0.0, float(t_end)]), np.array([value, value])
    times, values = gap
    return np.asarray(times, dtype=float), np.asarray(values, dtype=float)


class _Run:
    """Owner token of a one-shot run (the session tracks its owner by weak reference)."""
