"""Bounce and break metrics as pure functions of the contact's closed intervals and waveforms.

Definitions (SI: s, V, A, J), documented for users in docs/coupling.md ("Bounce metrics"):

- closed intervals: when the contact conducts metallically (merged, sorted). A run
  *starts closed* when the first interval begins at the run's start.
- make: the start of a closed interval after the run's start; break: the end of a closed
  interval before the run's end.
- opening: the open interval from a break to the next make (a *bounce* opening), or to
  the end of the run (the *final* opening, the contact ends open).
- final closure: the last closed interval when the contact is closed at the end of the run.
  The contact is *settled* when the final closure has lasted at least ``settle_window``
  by the end of the run. ``settle_time`` = start of the final closure - first make
  (None when not settled: the run ends open, or the final closure is shorter than the
  settle window; ``settle_note`` then says which).
- bounce window: first make to the start of the last closure (the last make). When the
  run ends open, that last closure's break and the final opening are reported on their
  own (``final_opening``): a single make that opens for good has no bounce window.
- voltage peaks are taken over the openings (break to next make, or to the end of the
  run): while the contact is closed its voltage is I R_c. Right after a make R_c falls
  from infinity (Holm's law at a vanishing force), so for nanoseconds the contact still
  shows most of the open-circuit voltage, and whether a sample lands there is up to
  ngspice's step (on the free drop at RELTOL 1e-6 one did, 0.1 ns after the first make
  at 23.9 V; at 1e-4 none): a peak taken after the make would measure the sampling.
- make-instant samples: at a make ngspice keeps the left limit (the open contact) and may
  put one or more samples within femtoseconds after it that still show the open-circuit
  voltage. Samples with make <= t <= make + guard (``make_guard``, default
  max(1e-12 s, 1e-9 t_end)) produce no voltage metric.
- the arc burns where |arc current| > ARC_BURNING_CURRENT (1 mA: an extinguished gap's
  1 nS leakage stays below it up to 1 MV); arc durations and arc energies count only the
  sample intervals whose left sample burns (``burning_steps``).
"""

from __future__ import annotations

import math

import numpy as np

from mech.validation import check_nonnegative, check_whole, scene_key
from mech.frozen import frozen

from coupling.core.logic import LogicInput

ARC_BURNING_CURRENT = 1e-3  # A
DEFAULT_SETTLE_WINDOW = 1e-3  # s
DEFAULT_ARC_TOGGLE_LIMIT = 50  # arc on/off changes in one run above which a warning is given


@frozen
class MetricSettings:
    """The scene's [metrics] section (SI).

    settle_window: s, how long the contact must stay closed at the end of the run to count
        as settled (default 1 ms).
    make_guard: s or None, samples this close after a make produce no voltage metric
        (None: max(1e-12 s, 1e-9 t_end)).
    arc_toggle_limit: more arc on/off changes than this in one run give a warning.
    logic: a Schmitt-trigger input on a node (coupling.core.logic.LogicInput), or None.
    """

    settle_window: float = scene_key(
        DEFAULT_SETTLE_WINDOW, unit="s", doc="closed this long at the end of the run = settled")
    make_guard: float | None = scene_key(
        None, unit="s",
        doc="samples this close after a make give no voltage metric; omitted: max(1e-12, 1e-9 t_end)")
    arc_toggle_limit: int = scene_key(
        DEFAULT_ARC_TOGGLE_LIMIT, unit="-", doc="more arc on/off changes give a warning")
    logic: LogicInput | None = scene_key(
        None, unit="-",
        doc='a Schmitt-trigger input on a node: `{ node = "v(pin)", low = 0.99, high = 2.31 }` (a voltage probe '
            "of the circuit, recorded if `[circuit] probes` does not; thresholds in V, low < high); summary.json "
            '`logic` (docs/coupling.md, "Digital inputs"). Omitted: none, but with template "mcu_input" the pin '
            "`v(pin)` at `logic_low` / `logic_high` (a table given there may set any of the three)")

    def __post_init__(self):
        check_nonnegative("metrics.settle_window", self.settle_window)
        if self.make_guard is not None:
            check_nonnegative("metrics.make_guard", self.make_guard)
        check_whole("metrics.arc_toggle_limit", self.arc_toggle_limit)
        if self.logic is not None and not isinstance(self.logic, LogicInput):
            raise ValueError(f"metrics.logic = {self.logic!r}: expected a LogicInput (the scene builds it from "
                             "its table) or None")

    def guard(self, t_end: float) -> float:
        """s: the make guard for a run of length t_end."""
        return self.make_guard if self.make_guard is not None else max(1e-12, 1e-9 * t_end)


def merge_intervals(intervals) -> list[tuple[float, float]]:
    """Union of closed intervals (s), sorted."""
    out: list[list[float]] = []
    for a, b in sorted((float(a), float(b)) for a, b in intervals):
        if out and a <= out[-1][1]:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([a, b])
    return [(a, b) for a, b in out]


def intersection(a, b) -> list[tuple[float, float]]:
    """The intersection of two unions of intervals (s), as sorted disjoint intervals."""
    a, b = merge_intervals(a), merge_intervals(b)
    out, i, j = [], 0, 0
    while i < len(a) and j < len(b):
        lo, hi = max(a[i][0], b[j][0]), min(a[i][1], b[j][1])
        if hi > lo:
            out.append((lo, hi))
        if a[i][1] < b[j][1]:
            i += 1
        else:
            j += 1
    return out


def make_instants(intervals, t_start: float, tol: float) -> list[float]:
    """s: the makes, interval starts after t_start (tolerance tol)."""
    return [a for a, _ in merge_intervals(intervals) if a > t_start + tol]


def openings_of(intervals, t_start: float, t_end: float, tol: float) -> list[tuple[float, float, bool]]:
    """Open intervals after the contact was first closed: (break, end, reclosed) with end the
    next make, or t_end and reclosed False for the final opening."""
    iv = merge_intervals(intervals)
    out = []
    for k, (_, b) in enumerate(iv):
        if b >= t_end - tol:
            break
        if k + 1 < len(iv):
            out.append((b, iv[k + 1][0], True))
        else:
            out.append((b, t_end, False))
    return out


def make_instant_mask(t: np.ndarray, makes, guard: float) -> np.ndarray:
    """True for samples with make < t <= make + guard for some make: the closing transient,
    where R_c falls from infinity and the contact still shows the open-circuit voltage for
    as long as ngspice's first steps happen to fall there. The sample at the make itself is
    the open contact's left limit, the last voltage of the opening the make ends: not
    masked (an RC that charges through the opening peaks there)."""
    t = np.asarray(t, float)
    mask = np.zeros(len(t), bool)
    for m in makes:
        mask |= (t > m) & (t <= m + guard)
    return mask


def trapezoid(t: np.ndarray, y: np.ndarray) -> float:
    """Integral of y over t, trapezoidal rule (0 for fewer than two samples)."""
    if len(t) < 2:
        return 0.0
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(t)))


def _peak(v: np.ndarray, mask: np.ndarray) -> float | None:
    return float(np.max(np.abs(v[mask]))) if mask.any() else None


def _left_value(t: np.ndarray, y: np.ndarray, at: float, guard: float) -> float | None:
    """y just before ``at``: the first sample within guard of it (ngspice keeps the left limit
    at a breakpoint), else the last sample before it."""
    k = int(np.searchsorted(t, at - guard, side="left"))
    if k < len(t) and t[k] <= at + guard:
        return float(y[k])
    return float(y[k - 1]) if k >= 1 else None


def burning_steps(i_arc: np.ndarray) -> np.ndarray:
    """Per sample interval (len(i_arc) - 1 of them): True where the arc burns over it, i.e.
    its left sample's |i| > ARC_BURNING_CURRENT. The one definition arc_duration and
    arc_energy share: an extinguished gap's 1 nS leakage counts in neither."""
    burning = np.abs(np.asarray(i_arc, float)) > ARC_BURNING_CURRENT
    return burning[:-1]


def arc_duration(t: np.ndarray, i_arc: np.ndarray, start: float, end: float) -> float:
    """s: time the arc burns (``burning_steps``) within [start, end]."""
    sel = (t >= start) & (t <= end)
    ts = t[sel]
    if len(ts) < 2:
        return 0.0
    return float(np.sum(np.diff(ts)[burning_steps(i_arc[sel])]))


def arc_energy(t: np.ndarray, v: np.ndarray, i_arc: np.ndarray, start: float = -math.inf,
               end: float = math.inf) -> float:
    """J: the arc's energy, the trapezoid of |v i_arc| over the sample intervals within
    [start, end] where it burns (``burning_steps``, as ``arc_duration``): an open gap's
    leakage current through the arc branch is not an arc."""
    sel = (t >= start) & (t <= end)
    ts = t[sel]
    if len(ts) < 2:
        return 0.0
    power = np.abs(v[sel] * i_arc[sel])
    steps = 0.5 * (power[1:] + power[:-1]) * np.diff(ts)
    return float(np.sum(steps[burning_steps(i_arc[sel])]))


def arc_toggles(i_arc: np.ndarray) -> int:
    """Number of arc ignitions and extinctions seen in the samples."""
    burning = np.abs(np.asarray(i_arc)) > ARC_BURNING_CURRENT
    return int(np.count_nonzero(burning[1:] != burning[:-1]))


def opening_table(t, v, i_loop, i_arc, openings, makes, guard) -> list[dict]:
    """One row per opening: start, end (s; the next make, or the end of the run), open_duration
    (s), reclosed, kind ("bounce" or "final"), current_at_break (A, the loop current i_loop at
    the break: what the opening contact interrupts), peak_voltage (V, largest |v| in [start, end],
    the left limit at the make that ends it included), arc_duration (s), arc_energy (J)."""
    excluded = make_instant_mask(t, makes, guard)
    rows = []
    for start, end, reclosed in openings:
        sel = (t >= start) & (t <= end)
        rows.append(dict(
            start=start, end=end, open_duration=end - start, reclosed=reclosed,
            kind="bounce" if reclosed else "final",
            current_at_break=_left_value(t, i_loop, start, guard),
            peak_voltage=_peak(v, sel & ~excluded),
            arc_duration=arc_duration(t, i_arc, start, end) if i_arc is not None else 0.0,
            arc_energy=arc_energy(t, v, i_arc, start, end) if i_arc is not None else 0.0,
        ))
    return rows


def bounce_metrics(intervals, t_end: float, closed_at_end: bool, t=None, v=None, i_loop=None, i_arc=None,
                   settings: MetricSettings | None = None, t_start: float = 0.0) -> dict:
    """The ``bounce`` section of summary.json (module docstring; every key in docs/coupling.md).

    intervals: closed intervals (s); closed_at_end: the contact's state at t_end; t, v,
    i_loop, i_arc: the waveform (s, V, A, A; None: no circuit metrics); i_loop is the
    loop current through the contact branch (the load current; or the metallic plus the arc
    current when there is no load probe): the current at a break is read from it.
    """
    settings = settings or MetricSettings()
    guard = settings.guard(t_end)
    iv = merge_intervals(intervals)
    tol = guard
    starts_closed = bool(iv) and iv[0][0] <= t_start + tol
    makes = make_instants(iv, t_start, tol)
    openings = openings_of(iv, t_start, t_end, tol)
    if not closed_at_end and iv and iv[-1][1] >= t_end - tol:
        closed_at_end = True  # the intervals say it (a schedule closed up to t_end)
    out: dict = dict(
        initial_state="closed" if starts_closed else "open",
        final_state="closed" if closed_at_end else "open",
        first_make=makes[0] if makes else None,
        last_make=makes[-1] if makes else None,
        bounces=sum(1 for o in openings if o[2]),
        total_bounce_time=(makes[-1] - makes[0]) if makes else 0.0,
        settle_window=settings.settle_window,
        settled=False, settle_time=None, settle_note=None,
        peak_contact_voltage=None, peak_bounce_voltage=None, peak_final_opening_voltage=None,
        arc_energy=0.0, arc_toggles=0, openings=[], final_opening=None,
    )
    if closed_at_end and iv:
        final_start = iv[-1][0]
        held = t_end - final_start
        if held >= settles(settings.settle_window):
            out["settled"] = True
            out["settle_time"] = final_start - makes[0] if makes else 0.0
        else:
            out["settle_note"] = (f"not settled: the final closure has lasted {held * 1e3:.4g} ms of the "
                                  f"{settings.settle_window * 1e3:.4g} ms settle window at the end of the run "
                                  "(run longer: [solver] t_end)")
    elif iv:
        out["settle_note"] = "not settled: the run ends open (no settle time)"
    else:
        out["settle_note"] = "the contact never closed"
    first = first_make_operation(iv, t_end, settings, t_start)
    if first is not None:  # a run that makes and breaks: the top-level keys are its first make's
        out.update(first_make=first["time"], last_make=first["time"] + first["bounce_time"],
                   bounces=first["bounces"], total_bounce_time=first["bounce_time"], settled=first["settled"],
                   settle_time=first["settle_time"], settle_note=None if first["settled"] else out["settle_note"])
    if t is None or v is None or len(t) == 0:
        return out
    t = np.asarray(t, float)
    v = np.asarray(v, float)
    i_loop = np.asarray(i_loop, float) if i_loop is not None else np.zeros_like(t)
    i_arc = np.asarray(i_arc, float) if i_arc is not None else None
    rows = opening_table(t, v, i_loop, i_arc, openings, makes, guard)
    out["openings"] = rows
    # The voltage peaks are the openings' (module docstring): a closed contact's is I R_c.
    out["peak_contact_voltage"] = max((r["peak_voltage"] for r in rows if r["peak_voltage"] is not None),
                                      default=None)
    bounce_end = math.inf if first is None else first["time"] + first["bounce_time"]
    out["peak_bounce_voltage"] = max((r["peak_voltage"] for r in rows if r["reclosed"] and r["end"] <= bounce_end
                                      and r["peak_voltage"] is not None), default=None)
    if rows and not rows[-1]["reclosed"]:
        last = rows[-1]
        out["peak_final_opening_voltage"] = last["peak_voltage"]
        out["final_opening"] = dict(break_time=last["start"], current_at_break=last["current_at_break"],
                                    arc_duration=last["arc_duration"], arc_energy=last["arc_energy"],
                                    peak_voltage=last["peak_voltage"])
    if i_arc is not None:
        out["arc_energy"] = arc_energy(t, v, i_arc)
        out["arc_toggles"] = arc_toggles(i_arc)
    return out


def first_make_operation(intervals, t_end: float, settings: MetricSettings, t_start: float = 0.0) -> dict | None:
    """The first operation's make when the run also breaks (an operation with a break, or a
    later episode): the top-level bounce keys then describe that make alone, as a user
    expects, not the make and the break mixed. None for a run that only makes (its keys
    stay those of the whole run)."""
    ops = operations(intervals, t_end, settings=settings, t_start=t_start)
    if not ops or "make" not in ops[0] or not any("break" in op for op in ops):
        return None
    return ops[0]["make"]


def settles(window: float) -> float:
    """The settle criterion with a relative round-off allowance (a final closure of exactly
    the window counts)."""
    return window * (1.0 - 1e-12)


# --- operations: what each make and each break of a run did -------------------------------

def episodes(intervals, window: float) -> list[list[tuple[float, float]]]:
    """The closed intervals (s) grouped into switching episodes: consecutive intervals whose
    openings are shorter than ``window`` (s) belong together (bounces at a make, chatter at a
    break); an opening of at least ``window`` ends an episode."""
    groups: list[list[tuple[float, float]]] = []
    for a, b in merge_intervals(intervals):
        if groups and a - groups[-1][-1][1] < settles(window):
            groups[-1].append((a, b))
        else:
            groups.append([(a, b)])
    return groups


def _current_window(t, i, start, end) -> tuple[float, float]:
    """(peak |i| in A, integral of i^2 dt in A^2 s) over [start, end]."""
    sel = (t >= start) & (t <= end)
    if not sel.any():
        return 0.0, 0.0
    return float(np.max(np.abs(i[sel]))), trapezoid(t[sel], i[sel] ** 2)


def _arc_end(t, i_arc, start: float, stop: float = math.inf) -> float | None:
    """s: where the arc that burns after ``start`` goes out (its last burning sample's
    successor), looking no later than ``stop`` (the contact's next make: arcs of a later
    operation are not this break's); ``stop`` when it burns up to there, None when it still
    burns at the run's last sample."""
    if i_arc is None:
        return start
    sel = (t >= start) & (t < stop)
    ts, burning = t[sel], np.abs(i_arc[sel]) > ARC_BURNING_CURRENT
    if not len(ts) or not burning.any():
        return start
    if burning[-1]:
        return None if math.isinf(stop) else stop
    last = int(np.flatnonzero(burning)[-1])
    return float(ts[last + 1])


def _more_arc_time(t, i_arc, i_min: float | None) -> float | None:
    """s: how much longer a still-burning arc needs to reach I_min at the rate its current
    falls over the run's last tenth of burning (None: it does not fall, no estimate)."""
    burning = np.flatnonzero(np.abs(i_arc) > ARC_BURNING_CURRENT)
    if len(burning) < 3 or i_min is None:
        return None
    first = t[burning[0]]
    sel = t >= t[-1] - 0.1 * (t[-1] - first)
    ts, ia = t[sel], np.abs(i_arc[sel])
    if len(ts) < 2 or ts[-1] <= ts[0]:
        return None
    rate = (ia[-1] - ia[0]) / (ts[-1] - ts[0])
    if rate >= 0.0:
        return None
    return max(ia[-1] - i_min, 0.0) / -rate


def operations(intervals, t_end: float, t=None, v=None, i_loop=None, i_contact=None, i_arc=None,
               settings: MetricSettings | None = None, min_arc_current: float | None = None,
               t_start: float = 0.0) -> list[dict]:
    """The run as a sequence of operations (summary.json ``operations``; docs/coupling.md).

    A switching episode (``episodes``, window = ``settle_window``) whose closure lasts at least
    the settle window holds a make and, unless the run ends closed, a break:
    - make: from the episode's first make through its bounces to the start of the held
      closure (the first closure lasting the window). ``time`` (s), ``bounces`` (openings
      before the held closure), ``bounce_time`` (s, last make - first make of the make
      part), ``settle_time`` (s, start of the held closure - first make; None when it never
      held), ``peak_current`` (A, largest |loop current| from the first make to one settle
      window into the held closure: the inrush), ``i2t`` (A^2 s, integral of the loop
      current squared over the same window), ``arc_energy`` (J, the bounce openings' arcs),
      ``make_energy`` (J, dissipated in the contact and its arcs over the window: integral of
      v (i_contact + i_arc) dt);
    - break: from the first separation after the last held closure through any chatter to
      the arc's end. ``time`` (s), ``current_at_break`` (A, the loop current just before),
      ``arc_duration`` (s, time with |i_arc| > 1 mA), ``arc_energy`` (J), ``peak_voltage``
      (V, the largest |v| from the break to the next make or the run's end: the arc and
      the recovery transient after it), ``complete`` (False when the run ended with the arc still burning; then
      ``more_time_needed`` (s) estimates how much longer it needed to reach I_min, or None).
    An episode that never holds is a make that did not settle; if it then opens, its break
    follows. A run that starts closed begins with a held closure (no make).
    """
    settings = settings or MetricSettings()
    window = settings.settle_window
    guard = settings.guard(t_end)
    have_waves = t is not None and v is not None and len(t) > 0
    if have_waves:
        t, v = np.asarray(t, float), np.asarray(v, float)
        i_loop = np.asarray(i_loop, float) if i_loop is not None else np.zeros_like(t)
        i_contact = np.asarray(i_contact, float) if i_contact is not None else i_loop
        i_arc = np.asarray(i_arc, float) if i_arc is not None else None
        dissipated = v * (i_contact + (i_arc if i_arc is not None else 0.0))
    out = []
    groups = episodes(intervals, window)
    for g, group in enumerate(groups):
        held = [k for k, (a, b) in enumerate(group) if b - a >= settles(window)]
        starts_closed = group[0][0] <= t_start + guard
        ends_closed = group[-1][1] >= t_end - guard
        first_held = held[0] if held else None
        op: dict = {}
        if not starts_closed:
            make_part = group[:first_held + 1] if first_held is not None else group
            makes = [a for a, _ in make_part]
            settle_at = group[first_held][0] if first_held is not None else None
            make = dict(time=makes[0], bounces=len(make_part) - 1, bounce_time=makes[-1] - makes[0],
                        settle_time=None if settle_at is None else settle_at - makes[0],
                        settled=settle_at is not None, peak_current=None, i2t=None, arc_energy=None,
                        make_energy=None)
            if have_waves:
                end = min(t_end, (settle_at + window) if settle_at is not None else make_part[-1][1])
                make["peak_current"], make["i2t"] = _current_window(t, i_loop, makes[0], end)
                sel = (t >= makes[0]) & (t <= end)
                make["make_energy"] = trapezoid(t[sel], dissipated[sel])
                make["arc_energy"] = sum((arc_energy(t, v, i_arc, b, a_next) for (_, b), (a_next, _)
                                          in zip(make_part[:-1], make_part[1:])), 0.0) if i_arc is not None else 0.0
            op["make"] = make
        if not ends_closed:
            last_held = held[-1] if held else len(group) - 1
            brk_time = group[last_held][1]
            brk = dict(time=brk_time, current_at_break=None, arc_duration=None, arc_energy=None,
                       peak_voltage=None, complete=True)
            if have_waves:
                arc_out = _arc_end(t, i_arc, group[-1][1], groups[g + 1][0][0] if g + 1 < len(groups) else math.inf)
                end = t_end if arc_out is None else max(arc_out, group[-1][1])
                brk["current_at_break"] = _left_value(t, i_loop, brk_time, guard)
                if i_arc is not None:
                    brk["arc_duration"] = arc_duration(t, i_arc, brk_time, end)
                    brk["arc_energy"] = arc_energy(t, v, i_arc, brk_time, end)
                else:
                    brk["arc_duration"], brk["arc_energy"] = 0.0, 0.0
                makes_after = [a for a, _ in group[last_held + 1:]]
                excluded = make_instant_mask(t, makes_after, guard)
                # the peak to the next make (or the run's end): after the arc goes out the
                # load loop rings the open contact, the break's recovery voltage (on the
                # default relay three times the arc's), part of what the break puts on the gap
                recovered = groups[g + 1][0][0] if g + 1 < len(groups) else t_end
                brk["peak_voltage"] = _peak(v, (t >= brk_time) & (t <= max(end, recovered)) & ~excluded)
                if arc_out is None:
                    brk["complete"] = False
                    brk["more_time_needed"] = _more_arc_time(t, i_arc, min_arc_current)
            op["break"] = brk
        if op:
            out.append(op)
    return out
