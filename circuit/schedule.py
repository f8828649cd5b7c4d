"""Prescribed make/break schedules of the contact: usable as G(t) with breakpoints, or as a PWL source.

A schedule is a list of closed intervals ``(t_make, t_break)``. While closed the contact
has the closed resistance (constant, or a function of the time since make); at each
make and each break the conductance ramps linearly over ``edge_time``::

    G(t) = w(t) / R_closed(t - t_make),  w: 0 -> 1 on [t_make, t_make + edge],
                                          1 -> 0 on [t_break - edge, t_break]

Optionally (``opening_speed`` v, m/s) the schedule also gives a simple gap distance
d(t) >= 0 (m) for an arc model that depends on it: 0 while closed, opening at v after
each break and closing at v towards the next make (a triangle, apex halfway), opening
at v for ever after the last break, and closing at v towards the first make::

    d(t) = v min(t - t_break, t_next_make - t)   in each open interval

Example, a make at 0.1 ms followed by bounces::

    schedule = ContactSchedule.from_events(
        make=[0.1e-3, 0.3e-3, 0.55e-3], brk=[0.25e-3, 0.5e-3], closed_resistance=0.01)
    schedule(0.2e-3)            # 100.0 S
    schedule.breakpoints()      # every ramp corner, for Stepper.advance / ngspice
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass
from typing import Callable, ClassVar, Sequence

import numpy as np

from .validation import check_range, scene_key

Resistance = Callable[[float], float]


@dataclass(frozen=True)
class ContactSchedule:
    """Prescribed contact states. SI units.

    intervals: closed intervals ((t_make, t_break), ...), s, increasing and disjoint;
        t_make <= 0 means closed from the start (no make ramp), t_break = inf never opens.
    closed_resistance: ohm while closed; a float, or a function of the time since
        make (s) -> ohm (e.g. a film resistance decaying as the force builds up).
    edge_time: duration of the linear conductance ramp at each make and break, s
        (0: ideal jumps; a PWL description needs edge_time > 0).
    opening_speed: m/s, or None (default): the speed of the simple gap d(t) (``gap``,
        module docstring), for an arc model whose voltage grows with the gap.
    """

    SECTION: ClassVar[str] = "circuit.schedule"
    intervals: tuple[tuple[float, float], ...] = scene_key(keys=(
        ("make", "s", "make instants"),
        ("break", "s", "break instants (as many as makes, or one fewer: ends closed)")))
    closed_resistance: float | Resistance = scene_key(0.01, unit="ohm")
    edge_time: float = scene_key(10e-9, unit="s", doc="conductance ramp at each edge")
    opening_speed: float | None = scene_key(
        None, unit="m/s", doc="the gap for an arc whose voltage grows with it; omitted: no gap")

    def __post_init__(self) -> None:
        name = self.SECTION
        check_range(name, "edge_time", self.edge_time, "s", 0.0, 1e-3)
        if self.opening_speed is not None:
            check_range(name, "opening_speed", self.opening_speed, "m/s", 0.0, 1e3, low_open=True)
            if not self.intervals:
                raise ValueError(f"{name}.opening_speed: the gap needs at least one closed interval "
                                 "(it is measured from the breaks and makes)")
        if not callable(self.closed_resistance):
            check_range(name, "closed_resistance", self.closed_resistance, "ohm", 1e-9, 1e9, low_open=True)
        try:
            pairs = tuple((float(a), float(b)) for a, b in self.intervals)
        except (TypeError, ValueError):
            raise ValueError(f"{name}.make/break: intervals {self.intervals!r} must be pairs (t_make, t_break) in s") from None
        object.__setattr__(self, "intervals", pairs)
        previous_break = -math.inf
        for i, (make, brk) in enumerate(pairs):
            if math.isnan(make) or math.isnan(brk) or math.isinf(make):
                raise ValueError(f"{name}.make/break[{i}] = {(make, brk)!r}: t_make must be finite, t_break a number or inf")
            if make < previous_break or (i > 0 and make <= 0):
                raise ValueError(
                    f"{name}.make/break[{i}] = {(make, brk)!r}: intervals must increase and not overlap "
                    f"(previous break at {previous_break!r} s)"
                )
            ramps = (0.0 if make <= 0 else self.edge_time) + (0.0 if math.isinf(brk) else self.edge_time)
            if brk - make < ramps or brk <= max(make, 0.0):
                raise ValueError(
                    f"{name}.make/break[{i}] = {(make, brk)!r}: a closed interval must last at least "
                    f"its ramps ({ramps!r} s) and end after it starts"
                )
            previous_break = brk
        # Lookup tables for the hot paths (G(t) runs inside ngspice's Newton loop).
        object.__setattr__(self, "_makes", [m for m, _ in pairs])
        corners: set[float] = set()
        for make, brk in pairs:
            if make > 0:
                corners.update((make, make + self.edge_time))
            if not math.isinf(brk):
                corners.update((brk - self.edge_time, brk))
        if self.opening_speed is not None:
            # The gap's apexes: halfway between a break and the next make.
            corners.update(0.5 * (brk + make) for (_, brk), (make, _) in zip(pairs[:-1], pairs[1:]))
        object.__setattr__(self, "_corners", sorted(corners))

    @classmethod
    def from_events(cls, make: Sequence[float], brk: Sequence[float], **fields) -> "ContactSchedule":
        """From make instants and break instants (s); one more make than breaks leaves it closed.
        ``fields``: closed_resistance, edge_time, opening_speed (omitted: the field's default)."""
        if any(isinstance(v, (str, bytes, dict)) or not hasattr(v, "__len__") for v in (make, brk)):
            raise ValueError(f"{cls.SECTION}.make = {make!r}, {cls.SECTION}.break = {brk!r}: expected lists of times (s)")
        make, brk = list(make), list(brk)
        if len(brk) not in (len(make), len(make) - 1):
            raise ValueError(
                f"{cls.SECTION}.make/break: {len(make)} makes need {len(make)} or {len(make) - 1} breaks, got {len(brk)}"
            )
        ends = brk + [math.inf] * (len(make) - len(brk))
        return cls(tuple(zip(make, ends)), **fields)

    # -- as a function of time --

    def _closed_conductance(self, since_make: float) -> float:
        if callable(self.closed_resistance):
            r = float(self.closed_resistance(since_make))
            if not (r > 0.0 and math.isfinite(r)):
                raise ValueError(f"closed_resistance({since_make!r} s) = {r!r} ohm: must be finite and > 0")
            return 1.0 / r
        return 1.0 / self.closed_resistance

    def conductance(self, t: float) -> float:
        """G(t), S. Right-continuous at ideal jumps (edge_time = 0)."""
        i = bisect.bisect_right(self._makes, t) - 1
        if i < 0:
            return 0.0
        make, brk = self.intervals[i]
        if t >= brk:
            return 0.0
        e = self.edge_time
        weight = 1.0
        if make > 0 and e > 0 and t < make + e:
            weight = (t - make) / e
        if not math.isinf(brk) and e > 0 and t > brk - e:
            weight = min(weight, (brk - t) / e)
        return weight * self._closed_conductance(t - make)

    __call__ = conductance

    def gap(self, t: float) -> float:
        """The simple gap distance d(t), m (module docstring); needs ``opening_speed``."""
        v = self.opening_speed
        if v is None:
            raise ValueError("ContactSchedule.gap: set opening_speed (m/s) for the schedule to give a gap")
        i = bisect.bisect_right(self._makes, t) - 1
        if i < 0:
            return v * (self.intervals[0][0] - t)  # closing towards the first make
        brk = self.intervals[i][1]
        if t <= brk:
            return 0.0
        if i + 1 < len(self.intervals):
            return v * min(t - brk, self.intervals[i + 1][0] - t)
        return v * (t - brk)

    def breakpoints(self, t_start: float = 0.0, t_end: float = math.inf) -> tuple[float, ...]:
        """Every ramp corner in (t_start, t_end], s: where G(t) has a kink or a jump (with
        ``opening_speed`` also the gap's apexes, where d(t) turns)."""
        corners = self._corners
        return tuple(corners[bisect.bisect_right(corners, t_start) : bisect.bisect_right(corners, t_end)])

    def is_closed(self, t: float) -> bool:
        return self.conductance(t) > 0.0

    # -- as a PWL --

    def pwl_points(self, t_end: float, resistance_step: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Times (s) and conductances (S) of a PWL description on [0, t_end].

        Exact for a constant closed resistance. A resistance function is sampled every
        ``resistance_step`` s while closed (required then), linear in G in between.
        """
        if self.edge_time <= 0:
            raise ValueError("ContactSchedule.edge_time = 0: a PWL description needs edge_time > 0 (ramps)")
        if callable(self.closed_resistance):
            if resistance_step is None or not resistance_step > 0:
                raise ValueError("pwl_points: a closed_resistance function needs resistance_step > 0 (s)")
        times = {0.0, float(t_end)}
        times.update(self.breakpoints(0.0, t_end))
        if callable(self.closed_resistance):
            for make, brk in self.intervals:
                lo, hi = max(make, 0.0), min(brk, t_end)
                if hi > lo:
                    times.update(np.arange(lo, hi, resistance_step).tolist())
        grid = np.array(sorted(t for t in times if 0.0 <= t <= t_end))
        # With ramps, G is continuous, so its value at each corner is the PWL vertex.
        values = np.array([self.conductance(t) for t in grid])
        return grid, values

    def gap_pwl_points(self, t_end: float) -> tuple[np.ndarray, np.ndarray]:
        """Times (s) and gap distances (m) of a PWL description of ``gap`` on [0, t_end] (exact)."""
        times = {0.0, float(t_end)}
        times.update(self.breakpoints(0.0, t_end))
        grid = np.array(sorted(t for t in times if 0.0 <= t <= t_end))
        return grid, np.array([self.gap(t) for t in grid])
