"""The exchange between mechanics and circuit: links that join a block of one to a block of
the other over named channels.

A link owns what crosses the seam for one pair of blocks, both ways:
- into the circuit, as input channels (``circuit.Stepper.inputs``): functions of time
  read from the mechanics' dense output over the macro step just integrated;
- into the mechanics, as drives (``mech.ImpactSolver.advance``): values at the step's
  start and end, linear in between, extrapolated from the circuit's last points;
- the signal the step rules watch (``coupling.core.policy``) and the waveform columns it
  adds to the result.

``ContactLink``: a circuit contact (a ``circuit.ContactBlock``, by its label) fed by one or
more contact points of the mechanics: its conductance G_F(F_n(t)) from the contact law
(summed over the points, which touch the same fixed contact), its gap (the nearer
point's height, for an arc that grows with it) and, back, mu(I) from the loop current.
A circuit of several contacts (a bridge) has one link per contact, each fed by the
contact pair of its fixed contact (coupling.core.arrangement).
"""

from __future__ import annotations

import math
from bisect import bisect_right
from itertools import compress
from operator import lt, not_

import numpy as np
from mech.gauss import LEGGAUSS

from coupling.core.policy import BEND_FRACTION, TAIL_POINTS, end_derivatives, end_rate, time_scale

CONTACT_EVENTS = ("contact_start", "contact_end")
# the step rules' floor of the coil's signal (psi^2 or psi), as a fraction of its value at the
# coil's rated current: changes far below the rated force do not shorten the steps (the
# coil's ringing after an unsuppressed release, at a thousandth of its rated flux)
FLUX_FLOOR = 1.0


def gap_time(room: float, speed: float, accel: float) -> float:
    """s: the time a gap takes to close by ``room`` (m) from ``speed`` (m/s) at ``accel``
    (m/s^2), both magnitudes: the root of speed t + accel t^2 / 2 = room, in the form without
    cancellation. At rest and unaccelerated: inf."""
    if room <= 0.0:
        return 0.0
    root = speed + math.sqrt(speed * speed + 2.0 * accel * room)
    return 2.0 * room / root if root > 0.0 else math.inf


def conduction_onset(penetration: float, onset: float) -> float:
    """Fraction (0..1) of the law's conductance a contact point carries at penetration y (m).

    s = 3 x^2 - 2 x^3, x = y / onset, for 0 <= y < onset; 1 beyond; 0 out of contact. Over
    the first `onset` metres (default 10 nm, a surface-roughness scale: 10 ns at 1 m/s) the
    continuum Hertz and Holm laws do not hold, and G_F ~ y^0.4 has an unbounded derivative
    at y = 0 that ngspice's truncation-error control chases below its minimum step at tight
    RELTOL (measured: a relay with a snubber aborted at the first make at RELTOL 1e-6).
    With the ramp G ~ y^2.4 near touchdown: twice differentiable.
    """
    if penetration <= 0.0:
        return 0.0
    if onset <= 0.0 or penetration >= onset:
        return 1.0
    x = penetration / onset
    return x * x * (3.0 - 2.0 * x)


def contact_intervals(seg, touching_at_start) -> list[list[tuple[float, float]]]:
    """Per contact point, the contact intervals inside the segment as its events delimit them."""
    intervals = []
    for i in range(len(touching_at_start)):
        start = seg.t_start if touching_at_start[i] else None
        spans = []
        for e in seg.events:
            if e["tip"] != i:
                continue
            if e["kind"] == "contact_start":
                start = e["time"]
            elif e["kind"] == "contact_end" and start is not None:
                spans.append((start, e["time"]))
                start = None
        if start is not None:
            spans.append((start, seg.t_end))
        intervals.append(spans)
    return intervals


# macro steps whose armature samples and received work ``CoilLink`` evaluates at once, and
# dense steps of the armature's travel it holds for them at most (a bar at nanosecond steps
# can have a million in one macro step: 64 B each, the memory stays a few MB)
BATCH_STEPS = 256
BATCH_PIECES = 1 << 16

# Gauss-Legendre on [0, 1] (nodes, weights) of RECEIVED_NODES points: the quadrature of the
# armature's drive work (``received_work``), exact for polynomials of degree 7 in time;
# mech.gauss's rule on [-1, 1] mapped (x -> (x + 1) / 2, w -> w / 2: numpy.polynomial is
# not imported at a run's start)
RECEIVED_NODES = 4
GAUSS_NODES = tuple(0.5 * (x + 1.0) for x in LEGGAUSS[RECEIVED_NODES][0])
GAUSS_WEIGHTS = tuple(0.5 * w for w in LEGGAUSS[RECEIVED_NODES][1])


class GainIntegral:
    """G(q) = the integral of the mechanics' gain table from its first knot to q (N/Wb^2 m, or
    what the drive needs times m or rad): the exact antiderivative of mech.armature.gain_at
    on the table (3, count) of positions, gains and the slopes the mechanics uses (the
    model's ``again``): each interval's cubic Hermite piece integrated in closed form, the
    end's tangent line beyond the ends; no table (count 0, gain 1): G(q) = q."""

    def __init__(self, table: np.ndarray):
        self.count = int(table.shape[1])
        self.x = [float(v) for v in table[0]]
        self.y = [float(v) for v in table[1]]
        self.m = [float(v) for v in table[2]]
        self.at_knot = [0.0]  # G at each knot
        for k in range(self.count - 1):
            h = self.x[k + 1] - self.x[k]
            self.at_knot.append(self.at_knot[-1] + h * (0.5 * (self.y[k] + self.y[k + 1])
                                                         + h * (self.m[k] - self.m[k + 1]) / 12.0))
        # per interval what __call__ takes from it, the products h m as __call__ formed them
        # (the same doubles): one lookup instead of a dozen, six calls a macro step
        self._intervals = [(self.x[k], self.x[k + 1] - self.x[k], self.at_knot[k], self.y[k],
                            (self.x[k + 1] - self.x[k]) * self.m[k], self.y[k + 1],
                            (self.x[k + 1] - self.x[k]) * self.m[k + 1]) for k in range(self.count - 1)]
        self._arrays = None  # (``many``'s: made at its first call)

    def many(self, q: np.ndarray) -> np.ndarray:
        """``__call__`` at each of ``q`` (a float64 array), element by element with its
        operations in its order (the same doubles), for a batch of samples at once."""
        q = np.asarray(q, dtype=np.float64)
        if self.count == 0:
            return q.copy()
        table = self._arrays
        if table is None:
            columns = zip(*self._intervals) if self._intervals else [()] * 7
            table = self._arrays = (np.array(self.x), *(np.array(column, dtype=np.float64) for column in columns))
        x, x_lo, h, g_lo, y_lo, hm_lo, y_hi, hm_hi = table
        inner = np.zeros_like(q)
        if self.count > 1:  # (one knot: every q is at or beyond an end)
            k = np.clip(np.searchsorted(x, q, side="right") - 1, 0, self.count - 2)
            x_lo, h, g_lo, y_lo, hm_lo, y_hi, hm_hi = (a[k] for a in (x_lo, h, g_lo, y_lo, hm_lo, y_hi, hm_hi))
            s = (q - x_lo) / h
            s2 = s * s
            s3 = s2 * s
            s4 = s3 * s
            inner = g_lo + h * (y_lo * (s - s3 + 0.5 * s4) + hm_lo * (0.5 * s2 - 2.0 * s3 / 3.0 + 0.25 * s4)
                                + y_hi * (s3 - 0.5 * s4) + hm_hi * (0.25 * s4 - s3 / 3.0))
        d = q - self.x[0]
        below = d * (self.y[0] + 0.5 * self.m[0] * d)
        d = q - self.x[-1]
        above = self.at_knot[-1] + d * (self.y[-1] + 0.5 * self.m[-1] * d)
        return np.where(q <= self.x[0], below, np.where(q >= self.x[-1], above, inner))

    def __call__(self, q: float) -> float:
        if self.count == 0:
            return q
        x, y, m = self.x, self.y, self.m
        if q <= x[0]:
            d = q - x[0]
            return d * (y[0] + 0.5 * m[0] * d)
        if q >= x[-1]:  # (the last knot: count - 1)
            d = q - x[-1]
            return self.at_knot[-1] + d * (y[-1] + 0.5 * m[-1] * d)
        x_lo, h, g_lo, y_lo, hm_lo, y_hi, hm_hi = self._intervals[bisect_right(x, q) - 1]
        s = (q - x_lo) / h
        s2 = s * s
        s3 = s2 * s
        s4 = s3 * s
        # the integrals from 0 to s of the Hermite basis h00, h10, h01, h11 (hm: h m at the ends)
        return g_lo + h * (y_lo * (s - s3 + 0.5 * s4) + hm_lo * (0.5 * s2 - 2.0 * s3 / 3.0 + 0.25 * s4)
                           + y_hi * (s3 - 0.5 * s4) + hm_hi * (0.25 * s4 - s3 / 3.0))


def received_work(armature, t0: float, t1: float, drive0: float, drive1: float, gain_integral, cuts=(),
                  travel=None) -> float:
    """J: the work a drive did on the armature over [t0, t1] (s), the integral of
    F(t) dq/dt dt with F = drive(t) gain(q(t)): the drive linear in time from drive0 at t0 to
    drive1 at t1 (N, or Wb^2: what mech's "armature.force" channel holds), gain the
    mechanics' gain table, ``gain_integral`` its antiderivative G (``GainIntegral``);
    armature(t) -> (q, dq/dt) (m, or rad for a clapper, whose drive is then N m).

    By parts, W = drive1 (G(q1) - G(q0)) - slope x the integral of G(q(t)) - G(q0) dt: exact
    for a constant drive whatever the path, and what is left to a quadrature has no dq/dt in
    it, which the bar's vibration carries through the card (a 4-point Gauss-Legendre of
    F dq/dt per macro step left the default relay's received work 1.4e-4 off the mechanics'
    own quadrature). Gauss-Legendre of RECEIVED_NODES points on each piece between the
    ``cuts`` (s: the mechanics' events, where dq/dt has a kink: a stop or the card).
    ``travel``: optionally, times -> [q] at once, the same q as ``armature``'s (mech's
    Segment.travel: one call for a piece's nodes instead of one each)."""
    span = t1 - t0
    if span <= 0.0:
        return 0.0
    q1 = armature(t1)[0]  # (first: the segment's armature caches its last time, often the end)
    q0 = armature(t0)[0]
    g0 = gain_integral(q0)
    work = drive1 * (gain_integral(q1) - g0)
    slope = (drive1 - drive0) / span
    if slope == 0.0:
        return work
    inner = sorted(c for c in cuts if t0 < c < t1) if cuts else ()
    edges = [t0, *inner, t1]
    total = 0.0
    for k in range(len(edges) - 1):
        a, h = edges[k], edges[k + 1] - edges[k]
        piece = 0.0
        nodes = [a + x * h for x in GAUSS_NODES]
        for q, w in zip(travel(nodes) if travel is not None else [armature(s)[0] for s in nodes], GAUSS_WEIGHTS):
            if q != q0:  # (an armature that has not moved adds nothing)
                piece += w * (gain_integral(q) - g0)
        total += h * piece
    return work - slope * total


def pieces_travel(segments: list[tuple], which: np.ndarray, times: np.ndarray) -> np.ndarray:
    """The armature's travel q (m or rad) at ``times`` (s), each in the segment
    ``segments[which[i]]``: (t_start, *mech's Segment.armature_pieces()), that is (t_start, q
    at t_start, ends, t0, h, coefficients). The arithmetic of Segment.travel element by
    element (the same doubles), for many segments' samples at once. The segments follow one
    another in time (each starts where the one before ended), so a time after its segment's
    start finds its dense step among all segments' step ends."""
    which = np.asarray(which, dtype=np.intp)
    times = np.asarray(times, dtype=np.float64)
    if not segments:
        return np.array([])[which]
    # (the segments' fields as columns in one pass: zip in C, no comprehension per field)
    starts, at_start, ends, t0, h, c = zip(*segments)
    starts, at_start = np.array(starts)[which], np.array(at_start)[which]
    counts = np.array(list(map(len, ends)), dtype=np.intp)
    if not counts.sum():
        return at_start
    offsets = np.concatenate(([0], np.cumsum(counts)[:-1]))
    ends, t0, h, c = np.concatenate(ends), np.concatenate(t0), np.concatenate(h), np.concatenate(c)
    own, count = offsets[which], counts[which]
    # (min(bisect_left(its ends, t), n - 1) in its own segment; the earlier segments' ends all
    # lie before a time after its segment's start, the later ones' after it)
    k = own + np.clip(np.searchsorted(ends, times, side="left") - own, 0, np.maximum(count - 1, 0))
    k = np.minimum(k, len(ends) - 1)  # (a segment without steps: any index, its start is taken)
    th = (times - t0[k]) / h[k]
    t1 = 1.0 - th
    c = c[k]
    q = c[:, 0] + th * (c[:, 1] + t1 * (c[:, 2] + th * (c[:, 3] + t1 * c[:, 4])))
    return np.where((count == 0) | (times <= starts), at_start, q)


def _kept(times: list[float], *series: list[float]) -> tuple[list[float], ...]:
    """(times, *series) without the points no later than the one before them (a step's first
    point is the previous step's last): a Tail's filter. The lists are its caller's fresh
    slices, and are changed in place."""
    # (later[k - 1]: times[k] is later than times[k - 1], t_k - t_(k-1) > 0 for doubles; the
    # mask and the points it drops found in C (map, compress) and deleted, no Python frame
    # per point: ~1 us less a call, once or twice a macro step)
    later = list(map(lt, times, times[1:]))
    if all(later):  # (every point kept; none or one point)
        return (times, *series)
    lists = (times, *series)
    if later.count(False) == 1:  # (the usual one: a step's first point, the last one's repeat)
        k = later.index(False) + 1
        for values in lists:
            del values[k]
        return lists
    for k in reversed(list(compress(range(1, len(times)), map(not_, later)))):
        for values in lists:
            del values[k]
    return lists


class Tail:
    """The last points of a circuit signal, kept across macro steps for its rate and time
    scale (``end_rate``); points before a jump say nothing of the signal after it.

    Kept as lists of floats: a macro step adds one to three points, and numpy's per-call
    overhead on arrays of eight cost more than the arithmetic (the same double arithmetic)."""

    def __init__(self):
        self.t: list[float] = []
        self.v: list[float] = []

    def observe(self, t: np.ndarray, v: np.ndarray, jumped: bool) -> None:
        self.observe_floats(t.tolist(), v.tolist(), jumped)

    def observe_floats(self, t: list[float], v: list[float], jumped: bool) -> None:
        """``observe`` on the step's points as lists of floats (a caller that has them as
        lists already: the coil's two tails share the step's times)."""
        # (the last TAIL_POINTS of each: new lists, whose head is deleted in place)
        times, values = self.t + t, self.v + v
        del times[:-TAIL_POINTS], values[:-TAIL_POINTS]
        times, values = _kept(times, values)
        if jumped:
            times, values = times[-1:], values[-1:]
        self.t, self.v = times, values

    def observe_pair(self, other: "Tail", t: list[float], v: list[float], w: list[float]) -> None:
        """``observe_floats(t, v, False)`` on this tail and ``other.observe_floats(t, w, False)``
        on a tail that has seen the same times (the coil's psi^2 and psi): which points are
        kept depends on the times alone, so it is worked out once (~3 us of a coil macro step)."""
        # (the last TAIL_POINTS of each: new lists, whose head is deleted in place)
        times, values, others = self.t + t, self.v + v, other.v + w
        del times[:-TAIL_POINTS], values[:-TAIL_POINTS], others[:-TAIL_POINTS]
        times, values, others = _kept(times, values, others)
        # (one list for both tails' times: a tail replaces its lists, never changes them)
        self.t, self.v = times, values
        other.t, other.v = times, others

    def rate(self, span: float) -> tuple[float, float]:
        """(d/dt in units per s, time scale in s) at the last point (``end_rate``)."""
        return end_rate(self.t, self.v, span)

    def derivatives(self, span: float) -> tuple[float, float | None]:
        """(d/dt per s, d2/dt2 per s^2 or None) at the last point (``end_derivatives``)."""
        return end_derivatives(self.t, self.v, span)


#: A: below this supply current a contact's share of it is not taken (both throws open)
SHARE_FLOOR = 1e-9


class ContactLink:
    """A circuit contact fed by contact points of the mechanics (SI units).

    label: the circuit contact's label ("contact", or "contact_<name>"); its input
        channels are "<label>.conductance" (S) and, when its arc needs it, "<label>.gap" (m).
    points: the mechanics' contact points that conduct into it (in parallel).
    laws: the contact laws (``coupling.laws.tribology.ContactLaws``): R_c(F_n) and mu(I).
    onset: m, the penetration over which a point's conduction ramps in (``conduction_onset``).
    feedback: mu follows the current (False: mu = mu(0) throughout).
    load_column: the contact's own load current ("load_current_<name>": a changeover's
        throw, in its own branch), or None where the supply's current runs through it (one
        contact, contacts in series). The coupling extrapolates one current, the supply's;
        a contact in its own branch takes its ``share`` of it at each step's start (its
        own over the supply's), so that while both throws of a make-before-break changeover
        are closed each one's mu(I) follows its own current, not their sum.
    """

    def __init__(self, label: str, points: tuple[int, ...], laws, onset: float, feedback: bool = True,
                 load_column: str | None = None):
        self.label = label
        self.points = tuple(points)
        self.laws = laws
        self.onset = onset
        self.feedback = feedback
        self.load_column = load_column
        self.share = 1.0  # of the supply's current through this contact (observe)
        self.tail = Tail()
        self.mu_log: list[tuple[float, float, float, float]] = []

    # -- into the mechanics --

    def mu(self, current: float) -> float:
        """N^gamma: the friction coefficient at the loop current (A)."""
        return float(self.laws.mu(current)) if self.feedback else float(self.laws.mu(0.0))

    def drives(self, mech, mu_start: float, mu_end: float) -> dict:
        """The mechanics' drives this link sets over a step: ``mu.<i>`` of each of its contact
        points the model has (N^gamma, at the step's start and end)."""
        names = mech.drive_names
        return {f"mu.{i}": (mu_start, mu_end) for i in self.points if f"mu.{i}" in names}

    def repulsion(self, mech, duty, current_at, t: float, t_end: float) -> dict:
        """The drives ``repulsion.<i>`` of its contact points over the step [t, t_end] (N at the
        step's start and end), empty without [duty] repulsion (``duty``: the scene's
        coupling.core.duty.DutySettings or None).

        Holm's force of each point's share of the loop current ``current_at(s)`` (A, extrapolated
        as mu's is), at the plastic a-spot of the point's normal force at the step's start; the
        current split between the points by their conductances then. A point open at the step's
        start gets 0 for the step (it has no spot): a point that makes within a step feels its
        repulsion from the next one on, which also ends the chatter a repulsion above the
        closing force would keep up at an open contact (docs/mechanics.md, "Drive channels")."""
        if duty is None or not duty.repulsion:
            return {}
        names = mech.drive_names
        contact = mech.contact_now()
        law = self.laws.resistance_law.scalar_force_conductance
        g = {i: law(contact[i, 2]) * conduction_onset(contact[i, 0], self.onset) for i in self.points}
        total = sum(g.values())
        ends = (current_at(t), current_at(t_end))
        out = {}
        for i in self.points:
            if f"repulsion.{i}" in names:
                share = g[i] / total if total > 0.0 else 0.0
                out[f"repulsion.{i}"] = tuple(duty.repulsion_force(share * current, contact[i, 2]) for current in ends)
        return out

    # -- into the circuit --

    def inputs(self, seg, touching_at_start, gap_wanted: bool) -> dict:
        """The contact's input channels over the segment: G_F(F_n(t)) summed over its points,
        S, and the gap, m, both from the dense output.

        Each point conducts only inside its contact intervals as the mechanics' events
        delimit them, the same instants ngspice gets as breakpoints: the interpolant may
        show a round-off penetration just before a located make.
        """
        intervals = contact_intervals(seg, touching_at_start)
        force = self.laws.resistance_law.scalar_force_conductance
        onset = self.onset
        points = self.points
        lo, hi = seg.t_start, seg.t_end

        first_two = points == (0, 1)  # the one circuit contact: the compiled tip_forces' nearest gap
        near = max(points) < 2  # rows tip_forces gives (F_0, F_1, gap, y_0, y_1), else pair_forces'
        # ngspice calls these at every new trial time (thousands of times a run): plain loops
        # over the few intervals, no generator per call
        spans = [span for i in points for span in intervals[i]]  # any point's
        touching = [(i, intervals[i]) for i in points if intervals[i]]
        tip_forces, pair_forces = seg.tip_forces, seg.pair_forces

        def gap(s: float) -> float:
            """m: the arc's length, the smaller point height; 0 while a point touches."""
            s = lo if s < lo else (hi if s > hi else s)
            for a, b in spans:
                if a <= s <= b:
                    return 0.0
            if first_two:
                return tip_forces(s)[2]
            rows = pair_forces(s)
            return float(min(rows[i, 2] for i in points))

        out = {}
        if gap_wanted:
            # a point that touches throughout makes the gap 0 throughout: a constant, which
            # ngspice's compiled callbacks answer without Python (a closed contact's steps)
            closed = any(a <= lo and hi <= b for a, b in spans)
            out[f"{self.label}.gap"] = 0.0 if closed else gap
        if not touching:
            out[f"{self.label}.conductance"] = 0.0  # open throughout: no conductance callback needed
            return out

        def g(s: float) -> float:
            s = lo if s < lo else (hi if s > hi else s)
            total = 0.0
            forces = None
            for i, spans_i in touching:
                for a, b in spans_i:
                    if a <= s <= b:
                        break
                else:
                    continue  # point i is open at s
                if near:
                    if forces is None:
                        forces = tip_forces(s)
                    total += force(forces[i]) * conduction_onset(forces[3 + i], onset)
                else:
                    row = pair_forces(s)[i]
                    total += force(float(row[0])) * conduction_onset(float(row[1]), onset)
            return total

        out[f"{self.label}.conductance"] = g
        return out

    def held_inputs(self, contact: np.ndarray, gap_wanted: bool) -> dict:
        """The input channels held at the values of the contact state ``contact`` (rows: points;
        columns: penetration m, ..., normal force N), as the Jacobi scheme takes them."""
        force = self.laws.resistance_law.scalar_force_conductance
        g = sum(force(contact[i, 2]) * conduction_onset(contact[i, 0], self.onset) for i in self.points)
        out = {f"{self.label}.conductance": g}
        if gap_wanted:
            out[f"{self.label}.gap"] = float(max(0.0, -np.max(contact[list(self.points), 0])))
        return out

    # -- back from the circuit --

    def current(self, step) -> float:
        """A: the current that sets mu(I): the loop (load) current, a smooth state of the
        circuit (the metallic contact current also carries the parasitic capacitance's
        discharge spikes at each make); the contact's own current when the circuit has no
        load probe."""
        current = float(step.values["load_current"])
        if np.isfinite(current):
            return current
        suffix = self.label[len("contact"):]
        return float(step.values["contact_current" + suffix])

    def observe(self, step, jumped: bool) -> None:
        """Keep the circuit's last points of the current (for its rate and time scale), and
        the contact's share of it at the step's end (``load_column``)."""
        self.tail.observe_floats(step.floats("time"), step.floats("load_current"), jumped)
        if self.load_column is not None:
            own, supply = float(step.values[self.load_column]), float(step.values["load_current"])
            # (both open, the supply's current is leakage: the share is then of no consequence)
            self.share = own / supply if np.isfinite(own) and abs(supply) > SHARE_FLOOR else 1.0

    def own(self, current: float) -> float:
        """A: this contact's part of the supply's current ``current`` (A): its ``share``."""
        return self.share * current

    # -- results --

    def mu_series(self, times: np.ndarray) -> np.ndarray:
        """The friction coefficient the mechanics used (N^gamma), linear within each macro step."""
        if not self.mu_log:
            return np.full(len(times), self.mu(0.0))
        log = np.array(self.mu_log)
        k = np.clip(np.searchsorted(log[:, 1], times), 0, len(log) - 1)
        t0, t1, m0, m1 = log[k].T
        frac = np.where(t1 > t0, (times - t0) / np.where(t1 > t0, t1 - t0, 1.0), 0.0)
        return m0 + (m1 - m0) * np.clip(frac, 0.0, 1.0)


class CoilLink:
    """The relay's coil in the circuit and its armature in the mechanics, joined by the magnet
    (SI units; coupling.laws.magnet).

    Into the circuit: the coil's input channel "<label>.gap", the magnet's working air gap
    g = rest_gap - lever * q(t) (m) along the armature's motion q (m for a plunger, rad for
    a clapper; ``lever``: m of pole-face travel per unit of q), from the mechanics' dense
    output. Into the mechanics: the drive "armature.force". A magnet whose force separates
    as F = psi^2 h(g) (every flux-tube magnet: its iron carries the whole coil flux) drives
    with psi^2 (Wb^2), extrapolated from the circuit's last points (to the step's end with
    their last slope and curvature; linear in time over the step), and the mechanics
    multiplies it by the table ``gain(q) = lever h(g(q))`` (N/Wb^2 or N m/Wb^2) along its
    own exact path; any other magnet (a table) drives with F(psi, g) itself at the step's
    ends, the gap at the end predicted from the armature's speed.
    """

    def __init__(self, label: str, magnet, rest_gap: float, lever: float = 1.0, switch_times=(),
                 floor: float = 0.0):
        self.label = label
        self.floor = float(floor)  # Wb^2 or Wb: the signal's floor in the step rules (FLUX_FLOOR of the rated)
        self.switch_times = tuple(sorted(float(s) for s in switch_times))
        self.magnet = magnet
        self.rest_gap = float(rest_gap)
        self.lever = float(lever)
        from coupling.laws.magnet import FluxTubeMagnet

        # a flux-tube magnet's iron carries the whole coil flux: W = W_iron(psi) + psi^2 R(g) / (2 N^2)
        self.separable = isinstance(magnet, FluxTubeMagnet)
        self.tail = Tail()
        # the circuit's step rule: the coil's time constant L/R at the rest gap (s), the flux
        # linkage's floor (Wb: FLUX_FLOOR of the rated), its last points and rate (Wb/s)
        self.time_constant = math.inf
        self.flux_floor = 0.0
        self.flux_tail = Tail()
        self.flux_rate = 0.0
        # the watched signal (``signal``: psi^2 or psi) at the last step's end, its rate (per s),
        # time scale (s) and the slope the step rules chose to extrapolate it with
        self.value, self.rate, self.scale, self.slope = 0.0, 0.0, math.inf, 0.0
        self.horizon = math.inf  # s: how far the drive is extrapolated along the slope (``drives``)
        self.curvature = 0.0  # its second derivative (per s^2) there, from the last three points
        self.bound_by = "curvature"  # the rule that set ``scale``: "curvature", "size" or "gap"
        self.gap_scale = math.inf  # s: the gap rule's time scale (inf: the armature does not move)
        self.left_seat = -math.inf  # s: when the armature last left its seat
        self._flux_column = "coil_flux_linkage" + label[len("coil"):]
        self._observed = ("time", self._flux_column)  # (the step's columns ``observe`` reads)
        self._gap_channel = f"{label}.gap"  # (the input channel's name, made once: asked at every step)
        self.q_times: list[float] = []  # the circuit's points (s) ...
        self._q: list[float] = []  # ... and the armature's travel there (m or rad; ``q``)
        self._sampled = False
        # J: the work the mechanics received from the drive "armature.force" so far
        # (``receive``), against which the magnet's work as the circuit sees it is audited
        self._received = 0.0
        # The travel at the circuit's points and the received work wait for BATCH_STEPS macro
        # steps, then are evaluated for them all at once (``_flush``): each step's armature
        # pieces (``inputs``: (t_start, *Segment.armature_pieces())), its points and its work's
        # inputs. The same doubles as step by step; ~11 us less a plunger macro step.
        self._segments: list[tuple] = []
        self._pieces = 0  # dense steps the pending segments hold
        self._step_segment: tuple | None = None  # (the step's Segment, its index in _segments)
        self._pending_q: list[tuple[int, list[float]]] = []
        self._pending_work: list[tuple] = []
        self._gain_integral = None  # GainIntegral of the mechanics' gain table, built at the first step,
        self._drive_row = -1  # ... and the mechanics' drive row of "armature.force" ...
        self._drive_columns = (0, 0, 0)  # ... and the drive's value, slope and t0 columns (kernel_layout D_*)
        self._table_channel = None  # circuit.channels.TableChannel, once the first step asks (``inputs``)

    def next_switch(self, t: float) -> float:
        """s: the coil drive's next switching instant after t (its driver's PWL vertices: on,
        off and their edges), inf without one. The coil's voltage jumps there, which the
        flux linkage's extrapolation cannot see: a macro step ends at each."""
        k = bisect_right(self.switch_times, t * (1.0 + 1e-12) + 1e-15)  # (the first later one: they are sorted)
        return self.switch_times[k] if k < len(self.switch_times) else math.inf

    def gap(self, q: float) -> float:
        """m: the working air gap at the armature's position q."""
        return self.rest_gap - self.lever * q

    def gain_table(self, travel: float, points: int = 201) -> tuple[np.ndarray, np.ndarray]:
        """(q, lever h(g(q))): the mechanics' gain table over the armature's travel [0, travel],
        denser towards the pole where h changes fastest."""
        closed = self.rest_gap - self.lever * travel
        gaps = closed + (self.rest_gap - closed) * np.linspace(0.0, 1.0, points) ** 2
        q = np.sort((self.rest_gap - gaps) / self.lever)
        return q, self.lever * np.asarray(self.magnet.force(1.0, self.rest_gap - self.lever * q), dtype=float)

    def signal(self, psi):
        """What the step rules watch and extrapolate: the drive's flux part, psi^2 (Wb^2) for a
        separable magnet (the force itself up to the gain: a clamped coil's flux falling
        through zero, or ringing at a thousandth of its rated value, moves it by nothing),
        psi (Wb) otherwise."""
        return psi * psi if self.separable else psi

    def drives(self, t: float, end: float, arm: tuple[float, float], policy) -> dict:
        """The armature's drive over [t, end], its flux part extrapolated from the circuit's last
        points by the step rules (``policy.extrapolate`` with this link's slope and time scale;
        psi^2 kept >= 0); the armature's (q, q_dot) at t in ``arm`` (a table magnet's gap at the
        end predicted from them)."""
        s0 = policy.extrapolate(self.value, self.slope, 0.0, self.horizon)
        # the step's end with the last chord's slope and the curvature of the last three
        # points (none after a jump, whose slope is 0: the zero-order hold): the drive stays
        # linear in time over the step, a secant of that parabola instead of the chord's
        # tangent line (the plunger's bounces at the pole 14 times nearer the reference, its
        # current at 50 ms 24 times; docs/coupling.md "The coil's steps"; the chord's lag
        # of half its length behind the end's slope, corrected, did worse on the operate
        # times: -1.6 against -1.1 us on the default relay)
        s1 = policy.extrapolate(self.value, self.slope, end - t, self.horizon,
                                self.curvature if self.slope != 0.0 else 0.0)
        if self.separable:
            return {"armature.force": (max(s0, 0.0), max(s1, 0.0))}
        q, q_dot = arm
        g0, g1 = self.gap(q), self.gap(q + q_dot * (end - t))
        return {"armature.force": (self.lever * float(self.magnet.force(s0, g0)),
                                   self.lever * float(self.magnet.force(s1, g1)))}

    def flux_changing(self, change_fraction: float) -> bool:
        """True if the flux linkage, at its rate at the last step's end, moves by more than
        ``change_fraction`` of (|psi| + its floor) over the coil's time constant (the step rules'
        change rule on psi itself: psi^2 starts from zero with zero slope when the coil is
        switched on)."""
        psi = self.flux_tail.v[-1] if self.flux_tail.v else 0.0
        return abs(self.flux_rate) * self.time_constant > change_fraction * (abs(psi) + self.flux_floor)

    def inputs(self, seg) -> dict:
        """The coil's gap channel over the segment, from the armature's dense output."""
        lo, hi = seg.t_start, seg.t_end
        working_gap, armature = self.gap, seg.armature  # (bound once: called per trial time)

        def gap(s: float) -> float:
            s = lo if s < lo else (hi if s > hi else s)
            return max(working_gap(armature(s)[0]), 0.0)

        pieces = seg.armature_pieces()
        if pieces is None:
            return {f"{self.label}.gap": gap}
        # the same gap as a table of the dense output's pieces, which ngspice's compiled
        # callbacks evaluate with gap's own operations (rest_gap - lever * q, then max(., 0))
        TableChannel = self._table_channel
        if TableChannel is None:  # (looked up once a run, not by an import statement per macro step)
            from circuit.channels import TableChannel  # (circuit is imported when a run starts)

            self._table_channel = TableChannel
        start, ends, t0, h, coefficients = pieces
        self._segments.append((lo, start, ends, t0, h, coefficients))
        self._pieces += len(ends)
        self._step_segment = (seg, len(self._segments) - 1)
        return {self._gap_channel: TableChannel(gap, lo, hi, start, ends, t0, h, coefficients,
                                                offset=self.rest_gap, scale=self.lever)}

    def _segment_index(self, seg) -> int | None:
        """The index in ``_segments`` of the pieces ``inputs`` kept of ``seg``, or None (a
        segment it did not see: sampled at once)."""
        step = self._step_segment
        return step[1] if step is not None and step[0] is seg else None

    def flux(self, step) -> float:
        """Wb: the coil's flux linkage at the step's end."""
        return float(step.values[self._flux_column])

    def observe(self, step, seg, policy) -> None:
        """After a step: the flux linkage at its end, its rate and time scale from the circuit's
        last points (differences over at least 1e-3 of the policy's macro step; for the step
        rules no shorter than BEND_FRACTION of the curvature's own time to move it by its size
        plus the rated value), bounded by the change-by-its-size and gap rules
        (``policy.gap_change_fraction``; ``bound_by`` names the rule that set it; ``horizon``:
        the same without that floor), and the armature's travel at the step's circuit points
        (for the result's columns)."""
        # (as floats once for both tails: psi * psi is the same double product as numpy's)
        t_list, psi_list = step.float_columns(self._observed)
        self.tail.observe_pair(self.flux_tail, t_list, [p * p for p in psi_list] if self.separable else psi_list,
                               psi_list)
        self.flux_rate = self.flux_tail.derivatives(policy.macro_step)[0]
        self.value = self.signal(self.flux(step))
        self.rate, curvature = self.tail.derivatives(policy.macro_step)
        self.curvature = curvature or 0.0
        curve = time_scale(self.rate, curvature, self.tail.v[-1] if self.rate != 0.0 else 0.0)
        # what the drive is extrapolated over (policy.extrapolate's horizon): the time scales
        # as they are; what the step rules take: the curvature's no shorter than BEND_FRACTION
        # of the time the curvature alone takes to move the signal by its size plus the rated
        # value. |rate / curvature| vanishes wherever psi^2 is stationary (a zero of psi as a
        # released coil rings, an extremum as the armature bounces), though psi^2 hardly
        # moves there: the default relay's steps fell geometrically to the probe step
        # (0.25 us) at each of the ringing's zeros, 120 macro steps in 0.35 ms
        # (docs/coupling.md, "The coil's steps")
        plain = curve
        if curvature:
            curve = max(curve, BEND_FRACTION * math.sqrt(2.0 * (abs(self.value) + self.floor) / abs(curvature)))
        scales = [(curve, "curvature")]
        if self.rate != 0.0:
            # not beyond the time it takes to change by its own size (plus the floor): a signal
            # falling linearly to zero (a clamped coil's release) has no curvature
            scales.append(((abs(self.value) + self.floor) / abs(self.rate), "size"))
        # (the start first: the armature's cache then holds the end, which ``receive`` asks for first)
        q_dot_start = seg.armature(seg.t_start)[1]
        q, q_dot = seg.armature(seg.t_end)[:2]
        span = seg.t_end - seg.t_start
        speed = self.lever * abs(float(q_dot))  # m/s of the working gap
        # m/s^2: the armature's acceleration over the step (its velocity change)
        accel = self.lever * abs(float(q_dot) - float(q_dot_start)) / span if span > 0.0 else 0.0
        self.gap_scale = math.inf
        if speed > 0.0 or accel > 0.0:
            # nor beyond the time the gap takes to change by its own size: the coil's flux
            # equation holds the gap, and its force 1/g^2, while the armature flies (the flux
            # itself changes little then: at 240 us steps the default relay's coil audit left
            # 3e-3 of its energy to ngspice's coarse points); at its speed and acceleration,
            # for an armature leaving its stop has no speed yet
            self.gap_scale = gap_time(policy.gap_change_fraction * max(self.gap(float(q)), 0.0), speed, accel)
            scales.append((self.gap_scale, "gap"))
        self.scale, self.bound_by = min(scales)
        horizon = plain  # (the curvature's without its floor, and the other rules')
        for scale, _ in scales[1:]:
            if scale < horizon:
                horizon = scale
        self.horizon = horizon
        new = t_list[1:] if self._sampled else t_list
        self._sampled = True
        lo, hi = seg.t_start, seg.t_end
        # (a point or two a step: kept as floats, joined into arrays at the end)
        self.q_times.extend(new)
        clamped = [lo if s < lo else (hi if s > hi else s) for s in new]
        index = self._segment_index(seg)
        if index is not None:
            self._pending_q.append((index, clamped))
            return
        self._flush()
        travel = getattr(seg, "travel", None)  # (mech's Segment: at once; a stand-in may give armature alone)
        self._q.extend(travel(clamped) if travel is not None else [seg.armature(s)[0] for s in clamped])

    def receive(self, seg, mech) -> None:
        """After a step: add the work the drive did on the armature over the segment, along the
        mechanics' own solution (``received_work`` on its dense output), with the drive as the
        mechanics held it (``mech.drive``'s armature row, linear over the step, read at the
        segment's ends) and the antiderivative of its gain table (``GainIntegral``)."""
        t0, t1 = seg.t_start, seg.t_end
        if self._gain_integral is None:
            from mech.kernel_layout import D_SLOPE, D_T0, D_VALUE

            self._gain_integral = GainIntegral(mech.model.again)
            self._drive_row = mech.model.armature_drive_row
            # (the drive's columns looked up once a run: an import statement per macro step
            # cost ~0.6 us even with the module loaded)
            self._drive_columns = (D_VALUE, D_SLOPE, D_T0)
        # the kernel's drive_at, on the row's three floats (mech.drives.values_at does every row)
        row = mech.drive[self._drive_row].tolist()
        c_value, c_slope, c_t0 = self._drive_columns
        value, slope, t_ref = row[c_value], row[c_slope], row[c_t0]
        drive0, drive1 = value + slope * (t0 - t_ref), value + slope * (t1 - t_ref)
        cuts = [e["time"] for e in seg.events] if seg.events else ()
        index = self._segment_index(seg)
        if index is None:
            self._flush()
            self._received += received_work(seg.armature, t0, t1, drive0, drive1, self._gain_integral, cuts,
                                            seg.travel)
            return
        self._pending_work.append((index, t0, t1, drive0, drive1, cuts))
        if len(self._pending_work) >= BATCH_STEPS or self._pieces >= BATCH_PIECES:
            self._flush()

    @property
    def received(self) -> float:
        """J: the work the mechanics received from the drive "armature.force" so far."""
        self._flush()
        return self._received

    @property
    def q(self) -> list[float]:
        """m or rad: the armature's travel at the circuit's points ``q_times``."""
        self._flush()
        return self._q

    def _flush(self) -> None:
        """The pending steps' travel samples and received work, all at once: ``received_work``
        and ``Segment.travel`` element by element (``pieces_travel``, ``GainIntegral.many``),
        each step's work added in step order."""
        segments, pending_q, pending_work = self._segments, self._pending_q, self._pending_work
        self._segments, self._pending_q, self._pending_work, self._step_segment = [], [], [], None
        self._pieces = 0
        if not pending_q and not pending_work:
            return
        # every travel the pending steps ask for, in one evaluation: at the circuit's points,
        # and for the received work at each step's end and its quadrature nodes (per piece
        # between the step's events: its start, length and step)
        which = [index for index, step_times in pending_q for _ in step_times]
        times = [t for _, step_times in pending_q for t in step_times]
        samples = len(times)
        piece_step, piece_index, piece_start, piece_length = [], [], [], []
        for k, (index, t0, t1, drive0, drive1, cuts) in enumerate(pending_work):
            which.append(index)
            times.append(t1)
            if t1 - t0 > 0.0 and drive1 != drive0 and (drive1 - drive0) / (t1 - t0) != 0.0:
                if not cuts:  # (the usual step, without events: one piece, [t0, t1])
                    piece_step.append(k)
                    piece_index.append(index)
                    piece_start.append(t0)
                    piece_length.append(t1 - t0)
                    continue
                inner = sorted(c for c in cuts if t0 < c < t1)
                edges = [t0, *inner, t1]
                for j in range(len(edges) - 1):
                    piece_step.append(k)
                    piece_index.append(index)
                    piece_start.append(edges[j])
                    piece_length.append(edges[j + 1] - edges[j])
        a, h = np.array(piece_start), np.array(piece_length)
        nodes = a[:, None] + np.array(GAUSS_NODES)[None, :] * h[:, None]
        # (each piece's segment once per node, in the nodes' order)
        which = np.concatenate([np.array(which, dtype=np.intp),
                                np.repeat(np.array(piece_index, dtype=np.intp), RECEIVED_NODES)])
        q = pieces_travel(segments, which, np.concatenate([times, nodes.ravel()]))
        self._q.extend(q[:samples].tolist())
        if not pending_work:
            return
        steps = len(pending_work)
        starts = np.array([segments[work[0]][1] for work in pending_work])  # q at each step's start
        g = self._gain_integral.many(np.concatenate([q[samples:], starts]))
        g_end, g_nodes, g_start = g[:steps].tolist(), g[steps:-steps].reshape(nodes.shape), g[-steps:]
        sums = []
        if piece_step:
            at = np.array(piece_step, dtype=np.intp)
            q0, g0 = starts[at][:, None], g_start[at][:, None]
            # (received_work skips a node where the armature has not moved: its term, +0.0
            # here, leaves the piece's sum as it was)
            terms = np.where(q[samples + steps:].reshape(nodes.shape) != q0,
                             np.array(GAUSS_WEIGHTS)[None, :] * (g_nodes - g0), 0.0)
            piece = 0.0 + terms[:, 0]
            for j in range(1, RECEIVED_NODES):
                piece = piece + terms[:, j]
            sums = (h * piece).tolist()
        g_start = g_start.tolist()
        # (the sum in a local, stored at the end: the same additions in the same order)
        received, p, count = self._received, 0, len(piece_step)
        for k, (_, t0, t1, drive0, drive1, _cuts) in enumerate(pending_work):
            span = t1 - t0
            if span <= 0.0:
                received += 0.0
                continue
            g0 = g_start[k]
            work = drive1 * (g_end[k] - g0)
            slope = (drive1 - drive0) / span
            if slope == 0.0:
                received += work
                continue
            total = 0.0
            while p < count and piece_step[p] == k:
                total += sums[p]
                p += 1
            received += work - slope * total
        self._received = received

    def columns(self, waves: dict) -> dict:
        """The result's coil columns beside the circuit's (coil_current, coil_voltage,
        coil_flux_linkage): ``armature_position`` (m, the pole face's travel from rest,
        lever x q), ``working_gap`` (m) and ``magnetic_force`` (N, F(psi, g) at the pole)."""
        q = self.travel_series(waves["time"])
        gap = np.maximum(self.gap(q), 0.0)
        psi = waves["coil_flux_linkage" + self.label[len("coil"):]]
        return {"armature_position": self.lever * q, "working_gap": gap,
                "magnetic_force": np.asarray(self.magnet.force(psi, gap), dtype=float)}

    def travel_series(self, times: np.ndarray) -> np.ndarray:
        """m or rad: the armature's travel at ``times`` (s), from its samples at the circuit's points."""
        if not self.q_times:
            return np.zeros(len(times))
        return np.interp(times, np.array(self.q_times), np.array(self.q))
