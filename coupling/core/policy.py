"""The co-simulation's step rules, pure (no solver, no ngspice): where a macro step ends and
how an exchanged signal (the loop current behind mu(I)) is extrapolated over it.

Times in s, currents in A. ``end_rate`` gives a signal's rate and time scale from the
circuit's last points; ``StepPolicy`` turns them into the next step.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from mech.frozen import frozen

PROBE_TIME = 1e-4  # s: the step right after a current jump is H^2 / PROBE_TIME (O(H^2): second order)
# A step extrapolates the current over at most this fraction of its local time scale
# |dI/dt|/|d2I/dt2|: an exponential overshoots by ~(1 - e^-x - x)... ~x^2/2 of its remaining
# change over x time constants, ~12 % at 0.5.
TIME_SCALE_FRACTION = 0.5
# The coil's flux is extrapolated over at most this fraction of its time scale: its error, ~x^2/2
# of the change over x time scales, is then ~0.5 %, and the armature's force follows the
# flux squared (measured on the default relay: operate time within 0.3 % of a 10x finer run)
COIL_TIME_SCALE_FRACTION = 0.1
# While the armature moves, a macro step lets the working gap change by at most this fraction
# of itself: the coil's flux equation holds the gap, and its force 1/g^2, over the step
GAP_CHANGE_FRACTION = 1.0
# In a coil-driven run ngspice's steps are bounded twice. Its flux increments are second order
# in its own step, and its truncation control let them be a macro step long (up to t_end / 50
# through the coil's rise): the default relay's coil audit was left at 8.9e-4 of the energy
# into the coil and its operate time ~6 us early (docs/coupling.md, "The coil's steps").
# At least this many points per macro step: the circuit's error then falls with the macro
# step, in the coupling's order ...
COIL_STEP_POINTS = 2
# ... and, while the coil's flux changes, steps of at most this fraction of the coil's time
# constant L/R (at the rest gap, unsaturated): 80 points a time constant
COIL_POINT_FRACTION = 0.0125
# The coil's curvature time scale |rate / curvature| is taken no shorter than this fraction of
# sqrt(2 (|psi^2| + rated psi^2) / |curvature|), the time the curvature alone takes to move
# psi^2 by its size plus its rated value (CoilLink.observe): the first vanishes where psi^2 is
# stationary, though psi^2 then hardly moves. At a quarter it leaves an exponential above a
# seventh of the rated value to |rate / curvature| (its time constant), as before
BEND_FRACTION = 0.25
# a step in which the seated armature leaves its stop ends this fraction of the way there
# (StepPolicy.approach_end): the extrapolated drive decides the unseat only from close by
APPROACH_FRACTION = 0.5
CHANGE_FRACTION = 1e-3  # the time-scale rule applies only where a step would change the current by more
CURRENT_FLOOR = 1e-3  # A: floor of |I| in the cautious time scale |I|/|dI/dt|
GROWTH_CAP = 4.0  # macro steps: the longest step in a closed contact with a steady current
TAIL_POINTS = 8  # circuit points kept across macro steps for the slope and its curvature


@frozen
class StepPolicy:
    """The co-simulation's step rules, pure (no solver, no ngspice): where a macro step ends
    and how the loop current is extrapolated over it. Times in s, currents in A.

    - ``base_end``: a macro step while a tip touches (or right after a jump), the longer
      ``free_step`` while both are free; no sliver step (< 1e-3 H) left before t_end. While
      a contact stays closed and the current steady (``previous``: the last step's length
      when it made or broke nothing and the current moved less than the change rule of
      ``plan`` allows), the step doubles per step up to ``growth_cap`` macro steps: the
      mechanics find a make or break inside a long step and the step is cut there
      (``aligned_end``), ngspice reads the mechanics' conductance at its own points, and
      every step stays proportional to H, so the coupling keeps its order. A settled
      contact under a slow force (the default relay after its bounces) then takes a
      quarter of the macro steps.
    - ``plan`` (scheme mechanics_first): right after a make/break the current has jumped
      and is known only at the jump, so a short probe step H^2 / probe_time with the current
      held (zero-order hold: O(H^2) error, still second order); otherwise a Taylor step
      with the circuit's own slope, no longer than time_scale_fraction of the current's
      time scale where the step would change it by more than change_fraction of
      (|I| + current_floor).
    - ``extrapolate``: I(t + s) = I + slope min(s, horizon): linear, but not beyond the
      current's time scale (an exponential approach extrapolated over its time constant
      lands on its asymptote).
    - ``aligned_end``: where a step that saw a make/break at t_e is cut: at t_e inside it,
      at t + probe when t_e is at its start, else not cut (None); "at" a step's start or
      end is within ``resolution`` (the circuit's shortest step) or 1e-9 macro steps of it.
    - ``approach_end``: where a step in which the seated armature left its stop is cut:
      halfway there while the unseat is more than H ahead, else H past it.
    """

    macro_step: float
    free_step: float
    probe_time: float = PROBE_TIME
    time_scale_fraction: float = TIME_SCALE_FRACTION
    change_fraction: float = CHANGE_FRACTION
    current_floor: float = CURRENT_FLOOR
    growth_cap: float = GROWTH_CAP
    gap_change_fraction: float = GAP_CHANGE_FRACTION
    circuit_points: int = 1
    point_fraction: float = math.inf
    # s: the circuit's shortest step (circuit.SimulationOptions.sliver, 1000 times ngspice's
    # smallest): a make/break nearer a step's start or end counts as there
    resolution: float = 0.0

    def __post_init__(self):
        for name in ("macro_step", "free_step", "probe_time", "time_scale_fraction", "current_floor", "growth_cap",
                     "gap_change_fraction"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"StepPolicy.{name} = {value!r}: must be a finite number > 0")
        if self.free_step < self.macro_step:
            raise ValueError(f"StepPolicy.free_step = {self.free_step!r}: must be >= macro_step = {self.macro_step!r}")
        if isinstance(self.circuit_points, bool) or not isinstance(self.circuit_points, int) or self.circuit_points < 1:
            raise ValueError(f"StepPolicy.circuit_points = {self.circuit_points!r}: must be a whole number >= 1")
        if not self.point_fraction > 0:  # (inf: no such bound)
            raise ValueError(f"StepPolicy.point_fraction = {self.point_fraction!r}: must be > 0")
        if not (math.isfinite(self.change_fraction) and self.change_fraction >= 0):
            raise ValueError(f"StepPolicy.change_fraction = {self.change_fraction!r}: must be a finite number >= 0")
        if not (math.isfinite(self.resolution) and self.resolution >= 0):
            raise ValueError(f"StepPolicy.resolution = {self.resolution!r}: must be a finite number >= 0")

    @classmethod
    def from_options(cls, options, resolution: float = 0.0) -> "StepPolicy":
        """The contact current's rules from a scene's CouplingOptions (macro_step, free_step,
        time_scale_fraction); ``resolution``: the circuit's shortest step (s)."""
        return cls(macro_step=float(options.macro_step), free_step=float(options.free_step),
                   time_scale_fraction=float(options.time_scale_fraction), resolution=float(resolution))

    def for_coil(self, options, floor: float) -> "StepPolicy":
        """The coil's rules: the same steps, its own time-scale fraction and gap rule from the
        scene's CouplingOptions, ``floor`` the watched signal's floor (Wb^2 or Wb)."""
        return replace(self, current_floor=floor, time_scale_fraction=float(options.coil_time_scale_fraction),
                       gap_change_fraction=float(options.gap_change_fraction),
                       circuit_points=int(options.coil_step_points),
                       point_fraction=float(options.coil_point_fraction))

    @property
    def probe(self) -> float:
        """s: the short step that fetches the current right after a make/break (H^2 / probe_time)."""
        return self.macro_step ** 2 / self.probe_time

    def base_end(self, t: float, t_end: float, touching: bool, previous: float = 0.0) -> float:
        """s: the end of the next step before the current is looked at; ``previous``: the
        length (s) of the step before when the contact stayed closed over it with a steady
        current (0: it did not, see ``steady``)."""
        step = self.free_step
        if touching:
            step = self.macro_step
            if previous > 0.0:
                step = min(self.free_step, self.growth_cap * self.macro_step, max(self.macro_step, 2.0 * previous))
        t_next = min(t + step, t_end)
        if t_end - t_next < 1e-3 * self.macro_step:
            t_next = t_end  # no sliver step at the end
        return t_next

    def plan(self, t: float, t_next: float, t_end: float, *, touching: bool, jumped: bool, current: float,
             rate: float, scale: float, curvature: float = 0.0) -> tuple[float, float]:
        """(end of the step in s, slope in A/s to extrapolate the current with) for a step from t
        proposed to end at t_next, given the current (A), its rate dI/dt (A/s) and time scale (s).
        ``curvature`` (A/s^2): where the slope alone keeps the change rule but the parabola does
        not (a stationary point: a ringing coil's psi^2 at an extremum or a zero of psi, or at
        its switch-on), the step is at most time_scale_fraction of sqrt(2 (|I| + floor) /
        |curvature|), the time the curvature alone takes to change the signal by its size."""
        if jumped:
            return min(t + self.probe, t_end), 0.0
        if touching and not self.steady(current, rate, t_next - t):
            t_next = min(t_next, t + max(self.probe, self.time_scale_fraction * scale))
        elif touching and curvature and not self.steady(current, rate, t_next - t, curvature):
            bend = math.sqrt(2.0 * (abs(current) + self.current_floor) / abs(curvature))
            t_next = min(t_next, t + max(self.probe, self.time_scale_fraction * bend))
        return t_next, rate

    def circuit_step(self, t: float, t_next: float, time_constant: float = math.inf) -> float:
        """s: the longest circuit step inside the macro step [t, t_next]: the step over
        ``circuit_points``, and ``point_fraction`` of ``time_constant`` (s; inf: none, as
        where the coil's flux is steady); inf: ngspice's own steps (landing on t_next). The
        first bound is proportional to the macro step, so the circuit's error falls with it in
        the coupling's order; the second does not come and go with the macro step either (a
        bound that did, the change rule over the step, made the convergence under halved
        steps erratic)."""
        step = math.inf if self.circuit_points == 1 else (t_next - t) / self.circuit_points
        return min(step, self.point_fraction * time_constant)

    def steady(self, current: float, rate: float, span: float, curvature: float = 0.0) -> bool:
        """True if the current (A) at rate dI/dt (A/s), and along the parabola of ``curvature``
        (A/s^2), moves by no more than the change rule of ``plan`` allows over ``span`` (s)."""
        return abs(rate) * span + 0.5 * abs(curvature) * span * span <= self.change_fraction * (
            abs(current) + self.current_floor)

    @staticmethod
    def extrapolate(current: float, slope: float, elapsed: float, horizon: float = math.inf,
                    curvature: float = 0.0) -> float:
        """A: the current ``elapsed`` s after a point where it is ``current`` with ``slope`` (and
        second derivative ``curvature``, per s^2: along that parabola), not beyond ``horizon``."""
        e = min(elapsed, horizon)
        return current + slope * e + 0.5 * curvature * e * e

    def approach_end(self, t: float, t_next: float, event: float) -> float | None:
        """s: where to end a step [t, t_next] in which the mechanics found the seated armature
        leaving its stop at ``event`` (with the drive extrapolated over the step): halfway
        there while it is more than a macro step ahead, else a macro step past it; None: keep
        the step (it ends before that)."""
        lead = event - t
        if lead > self.macro_step:
            return t + APPROACH_FRACTION * lead
        if t_next > event + self.macro_step:
            return event + self.macro_step
        return None

    @property
    def guard(self) -> float:
        """s: how near a step's start or end a make/break counts as there: 1e-9 macro steps,
        at least ``resolution``."""
        return max(1e-9 * self.macro_step, self.resolution)

    def aligned_end(self, t: float, t_next: float, event: float) -> float | None:
        """s: where to end a step [t, t_next] in which the first make/break is at ``event``; None: keep it."""
        # (the mechanics locate an event to ~1e-9 of their own step, and ngspice cannot take
        # a sliver of a step: an event found 5e-15 s after a step cut at it asked for a
        # 5e-15 s step, and with a 10 mH load behind a flyback diode ngspice's Newton failed
        # on it until "timestep too small")
        guard = self.guard
        if t + guard < event < t_next - guard:
            return event
        if event <= t + guard and t_next - t > self.probe * (1.0 + 1e-9):
            return t + self.probe  # it happened at the step start: only a short step past it
        return None


def end_derivatives(t: Sequence[float], i: Sequence[float], span: float) -> tuple[float, float | None]:
    """(dI/dt, d2I/dt2) of a circuit signal at the last of its points (t, i), from differences
    over at least 1e-3 of ``span`` (s) so that a sliver landing step does not dominate: the
    last chord's slope (the derivative at the chord's middle) and the change of slope from
    the chord before (a parabola's curvature, exactly); (0, None) without two finite points,
    (dI/dt, None) without a third."""
    if len(t) < 2 or not all(map(math.isfinite, i[-3:])):  # (map: no generator per call, twice a macro step)
        return 0.0, None
    # (the shortest difference and the points it needs looked up once: the same doubles)
    least = 1e-3 * span
    t_last, t_k = t[-1], t[-2]
    k = len(t) - 2
    while k > 0 and t_last - t_k < least:
        k -= 1
        t_k = t[k]
    dt = t_last - t_k
    if dt <= 0:
        return 0.0, None
    i_k = i[k]
    rate = float((i[-1] - i_k) / dt)
    j = k - 1
    while j > 0 and t_k - t[j] < least:
        j -= 1
    if j < 0 or t_k <= t[j]:
        return rate, None
    t_j = t[j]
    previous = (i_k - i[j]) / (t_k - t_j)
    return rate, 2.0 * (rate - previous) / (t_last - t_j)


def end_rate(t: Sequence[float], i: Sequence[float], span: float) -> tuple[float, float]:
    """(dI/dt in A/s, its time scale |dI/dt| / |d2I/dt2| in s) of the loop current at the last
    of the circuit points (t, i) (several steps' worth: a short step may hold only one or
    two), from ``end_derivatives``; (0, inf) without enough points. For an exponential
    approach the time scale is its time constant wherever the current is on it; for a ramp
    it is infinite."""
    rate, curvature = end_derivatives(t, i, span)
    return rate, time_scale(rate, curvature, i[-1] if rate != 0.0 else 0.0)


def time_scale(rate: float, curvature: float | None, last: float) -> float:
    """s: |rate / curvature| (``end_derivatives``' pair at a signal's last point ``last``);
    with no curvature known the cautious |last| + CURRENT_FLOOR over |rate|; inf where
    either vanishes."""
    if curvature is None:
        # too few points for a curvature: the cautious scale |I|/|dI/dt|
        return (abs(float(last)) + CURRENT_FLOOR) / abs(rate) if rate != 0.0 else math.inf
    if curvature == 0.0:
        return math.inf
    return float(abs(rate / curvature))
