"""One-shot transient runs: a contact given as G(t) or a schedule, and the PWL reference form."""

from __future__ import annotations

from typing import Iterable

import pandas as pd

from .contact import Conductance
from .deck import CircuitLike, arc_state, build_deck
from .ngspice import get_session
from .options import SimulationOptions
from .schedule import ContactSchedule
from .stepping import Stepper


def run_transient(
    circuit: CircuitLike,
    contact: ContactSchedule | Conductance | float,
    t_end: float,
    *,
    options: SimulationOptions | None = None,
    breakpoints: Iterable[float] = (),
    extra: tuple[str, ...] = (),
) -> pd.DataFrame:
    """Run 0..t_end (s) with the contact conductance from Python; returns the waveform (SI columns).

    contact: a ``ContactSchedule`` (its ramp corners become breakpoints), a function
        G(t) in S (pass its make/break instants as ``breakpoints``), or a constant in S.
    extra: raw ngspice vectors to add as columns (e.g. 'load', 'vsource#branch').
    """
    points = set(float(b) for b in breakpoints)
    if isinstance(contact, ContactSchedule):
        points.update(contact.breakpoints(0.0, t_end))
        contact = contact.conductance
    with Stepper(circuit, t_end, options) as stepper:
        stepper.advance(t_end, contact, sorted(p for p in points if 0.0 < p <= t_end))
        return stepper.results(extra)


def run_pwl_reference(
    circuit: CircuitLike,
    schedule: ContactSchedule,
    t_end: float,
    *,
    options: SimulationOptions | None = None,
    resistance_step: float | None = None,
    extra: tuple[str, ...] = (),
) -> pd.DataFrame:
    """The same run with the schedule written into the netlist as a PWL conductance source.

    No Python in ngspice's loop: the reference that the callback and stepping forms are
    checked against. ngspice sets breakpoints at the PWL vertices itself.
    resistance_step: sampling step (s) of a closed-resistance function (constant: unused).
    """
    if not isinstance(schedule, ContactSchedule):
        raise TypeError(f"run_pwl_reference needs a ContactSchedule, got {type(schedule).__name__}")
    options = options if options is not None else SimulationOptions()
    drive = schedule.pwl_points(t_end, resistance_step)
    lines, probes = build_deck(circuit, t_end, options, drive)
    arc = arc_state(circuit, probes)
    if arc is not None:
        arc.start(float(drive[1][0]) > 0.0)
        arc.add_breakpoints(drive[0])  # ngspice lands on the PWL vertices
    session = get_session()
    owner = _Run()
    with session.exclusive():
        session.claim(owner)
        try:
            session.load(lines)
            session.set_arc(arc)
            session.transient(None, True, options.wall_timeout, t_end, options.end_tolerance(t_end))
            return probes.frame(session.vector, tuple(extra))
        finally:
            session.clear()
            session.release(owner)


class _Run:
    """Owner token of a one-shot run (the session tracks its owner by weak reference)."""
