"""The waveform panels of a run, specified once and drawn by both waveforms.png
(coupling.app.plots) and waveforms.html (coupling.app.waveview), so the two show the same
quantities, units and axis ranges.

A panel is one axis: its quantity and unit (coupling.app.quantities), the columns it draws
and the rule that scales it (``SCALES``). ``PANELS`` lists them in drawing order; a new
panel (a coil's current, an armature's position) is one more entry; a circuit of several
contacts adds a panel of every contact's metallic current and one of every contact's
resistance (one trace per contact, open samples left out).
``axis`` turns a panel's rule and the samples in view into the numbers both writers use:
limits, samples clipped at the top (marked there with their peak), and for the contact
resistance the band above the axis where an open contact is drawn.

Rules (docs/coupling.md, "Plots"):
- ``voltage``: in the bounce window, to the bounce's peak and the open-circuit voltage
  before the first make (a fly-off spike is clipped and marked); over the whole run, to
  the largest value.
- ``spikes``: to 1.15 x the 99.5th percentile of |y| of the panel's first trace (the loop
  current, not a re-ignition spike); samples beyond are clipped and marked with their peak.
- ``linear``: every value in view.
- ``log``: every positive value in view, log scale.
- ``resistance``: log scale over the closed contact's range: from half its least value to
  ten times the value it stays below for 99 % of its closed time (each sample weighted by
  the time it stands for). The conduction onsets of a make or break, where the contact
  force goes through zero and R_c towards infinity within nanoseconds to microseconds,
  are above that range: marked at the top with their peak. Samples without conduction
  (R_c infinite) are drawn in a band above the axis marked "open", never as a number.
"""

from __future__ import annotations

import fnmatch
import math
from dataclasses import dataclass, field

import numpy as np

from mech.frozen import frozen
from coupling.app.quantities import WAVEFORM, Quantity


SCALES = ("voltage", "spikes", "linear", "log", "resistance")
WHEN = ("present", "finite", "nonzero")


@frozen
class Trace:
    """One curve of a panel: a waveform column (or a glob over columns, e.g. "v(*"; the
    column is then the label), its legend label and colour (hex: matplotlib and plotly
    read it). ``when``: "present" (the column exists), "finite" (every sample finite: a
    load current without a load probe is NaN), "nonzero" (some sample not 0: an arc that
    burns, a contact point that touches; one that never does is not drawn as if it did).
    ``dashed``: a reference drawn behind the others (the loop current)."""

    column: str
    label: str = ""
    color: str | None = None
    when: str = "present"
    dashed: bool = False

    def __post_init__(self):
        if self.when not in WHEN:
            raise ValueError(f"Trace({self.column!r}).when = {self.when!r}: allowed {', '.join(WHEN)}")


@frozen
class Panel:
    """One axis: ``quantity`` (its name and SI unit: the axis label), the traces, the scale
    rule (a key of SCALES), and for the PNG a display unit with its factor from SI (the
    page shows SI with prefixes on the ticks)."""

    key: str
    quantity: Quantity
    traces: tuple
    scale: str = "linear"
    png_unit: tuple = field(default=(None, 1.0))

    def __post_init__(self):
        if self.scale not in SCALES:
            raise ValueError(f"Panel({self.key!r}).scale = {self.scale!r}: allowed {', '.join(SCALES)}")


# Derived series: name -> (needed columns, function of the column mapping)
DERIVED = {
    "abs_voltage": (("contact_voltage",), lambda c: np.abs(c["contact_voltage"])),
    "arc_power": (("contact_voltage", "arc_current"), lambda c: np.abs(c["contact_voltage"] * c["arc_current"])),
}

PANELS = (
    Panel("voltage", WAVEFORM["contact_voltage"], (Trace("contact_voltage", "contact voltage", "#1f77b4"),),
          "voltage"),
    Panel("abs_voltage", WAVEFORM["abs_voltage"], (Trace("abs_voltage", "|contact voltage|", "#1f77b4"),), "log"),
    Panel("current", WAVEFORM["current"], (Trace("load_current", "load (loop)", "#8c8c8c", "finite", dashed=True),
                                           Trace("contact_current", "contact (metallic)", "#d62728"),
                                           Trace("arc_current", "arc", "#ff7f0e", "nonzero")), "spikes"),
    Panel("resistance", WAVEFORM["contact_resistance"],
          (Trace("contact_resistance", "contact resistance", "#9467bd"),), "resistance"),
    # a circuit of several contacts (a bridge, a changeover): each contact's own, one trace each
    Panel("contact_currents", WAVEFORM["current"], (Trace("contact_current_*"),), "spikes"),
    Panel("contact_resistances", WAVEFORM["contact_resistance"], (Trace("contact_resistance_*"),), "log"),
    Panel("force", WAVEFORM["normal_force"], (Trace("normal_force_0", "contact point 0", "#2ca02c", "nonzero"),
                                              Trace("normal_force_1", "contact point 1", "#bcbd22", "nonzero")),
          "linear"),
    Panel("gap", WAVEFORM["gap"], (Trace("gap", "gap", "#8c564b"),), "linear", ("um", 1e6)),
    Panel("arc_power", WAVEFORM["arc_power"], (Trace("arc_power", "arc power", "#ff7f0e", "nonzero"),), "spikes"),
    # the relay's coil and armature: the current with its dip at pull-in, the coil's voltage
    # (its spike at switch-off, which the suppression sets), the force and the travel
    Panel("coil_current", WAVEFORM["coil_current"], (Trace("coil_current", "coil current", "#17becf"),), "linear",
          ("mA", 1e3)),
    Panel("coil_voltage", WAVEFORM["coil_voltage"], (Trace("coil_voltage", "coil voltage", "#1f77b4"),), "linear"),
    Panel("magnetic_force", WAVEFORM["magnetic_force"],
          (Trace("magnetic_force", "magnetic force", "#e377c2"),), "linear"),
    Panel("armature", WAVEFORM["armature_position"],
          (Trace("armature_position", "armature travel", "#7f7f7f"),), "linear", ("mm", 1e3)),
    Panel("probe_voltage", WAVEFORM["probe_voltage"], (Trace("v(*"),), "linear"),
    Panel("probe_current", WAVEFORM["probe_current"], (Trace("i(*"),), "linear"),
)


def columns_of(result) -> dict:
    """The run's waveform columns (name -> float array), the derived series added."""
    cols = getattr(result, "waveform_columns", None)
    if cols is None:
        w = result.waveforms
        cols = {c: w[c].to_numpy() for c in w.columns}
    cols = {k: np.asarray(v, dtype=float) for k, v in cols.items()}
    for name, (needs, make) in DERIVED.items():
        if all(n in cols for n in needs):
            cols[name] = make(cols)
    return cols


def _drawn(trace: Trace, values: np.ndarray) -> bool:
    if trace.when == "finite":
        return bool(np.all(np.isfinite(values)))
    if trace.when == "nonzero":
        return bool(np.any(np.isfinite(values) & (values != 0.0)))
    return True


def panel_traces(panel: Panel, cols: dict) -> list[tuple[str, str, str | None]]:
    """(column, label, colour) of the panel's traces this run has and draws."""
    out = []
    for tr in panel.traces:
        if any(ch in tr.column for ch in "*?["):
            names = sorted(c for c in cols if fnmatch.fnmatchcase(c.lower(), tr.column.lower()))
            out += [(c, c, tr.color) for c in names]
        elif tr.column in cols and _drawn(tr, cols[tr.column]):
            out.append((tr.column, tr.label or tr.column, tr.color))
    return out


def dashed(panel: Panel, column: str) -> bool:
    """Whether the panel draws ``column`` as a dashed reference behind the others."""
    return any(tr.dashed and tr.column == column for tr in panel.traces)


def panel_of(column: str) -> Panel | None:
    """The panel that draws ``column`` (a waveform column), or None."""
    for panel in PANELS:
        for tr in panel.traces:
            if tr.column == column or fnmatch.fnmatchcase(column.lower(), tr.column.lower()):
                return panel
    return None


def merged(panel: Panel, runs: list) -> list[Axis]:
    """One axis for several runs of one panel (a sweep's overlay): ``runs`` holds each run's
    (t, series); the limits span every run's own (the open band keeps its share of the
    height), and each run's clipped and open samples are those against these limits."""
    own = [axis(panel, t, series, np.ones(len(t), bool)) for t, series in runs]
    lo, hi = min(a.lo for a in own), max(a.hi for a in own)
    out = []
    for a, (t, series) in zip(own, runs):
        if a.band is not None:
            r = series[0][1]
            finite = np.isfinite(r) & (r > 0.0)
            above = np.flatnonzero(finite & (r > hi))
            clipped = [(series[0][0], above, float(np.max(r[above])))] if len(above) else []
            top = hi * (hi / lo) ** (OPEN_BAND / (1.0 - OPEN_BAND))
            out.append(Axis(lo, hi, True, clipped, np.flatnonzero(~finite), top))
        else:
            out.append(Axis(lo, hi, a.log, _beyond(series, np.ones(len(t), bool), lo, hi)))
    return out


def panels_for(cols: dict, keys=None) -> list[tuple[Panel, list]]:
    """(panel, its traces) for every panel of PANELS with something to draw (``keys``: only those)."""
    out = []
    for panel in PANELS:
        if keys is not None and panel.key not in keys:
            continue
        traces = panel_traces(panel, cols)
        if traces:
            out.append((panel, traces))
    return out


@dataclass
class Axis:
    """A panel's axis as both writers draw it (SI). ``lo``/``hi``: the data range (log:
    positive); ``top``: the axis top (``hi``, or the top of the open band above it);
    ``clipped``: (column, sample indices above ``hi``, their peak); ``open``: the sample
    indices drawn in the open band."""

    lo: float
    hi: float
    log: bool = False
    clipped: list = field(default_factory=list)
    open: np.ndarray | None = None
    top: float | None = None

    def __post_init__(self):
        if self.top is None:
            self.top = self.hi

    @property
    def band(self) -> tuple[float, float] | None:
        """(bottom, top) of the open band, or None."""
        return (self.hi, self.top) if self.open is not None else None


def sample_weights(t: np.ndarray) -> np.ndarray:
    """s: the time each sample stands for (half the spacing to each neighbour)."""
    if len(t) < 2:
        return np.ones(len(t))
    dt = np.diff(t)
    return 0.5 * (np.r_[dt, 0.0] + np.r_[0.0, dt])


def quantile(values: np.ndarray, q: float) -> float:
    """``np.quantile(values, q)`` (its default, linear interpolation between order statistics,
    the same arithmetic) of finite values, without the import of numpy.ma that np.quantile
    makes (~10 ms of a run's start)."""
    a = np.sort(np.asarray(values, dtype=float))
    v = (len(a) - 1) * q
    if v >= len(a) - 1:
        return float(a[-1])
    i = max(math.floor(v), 0)
    gamma = v - i
    diff = a[i + 1] - a[i]
    return float(a[i + 1] - diff * (1.0 - gamma) if gamma >= 0.5 else a[i] + diff * gamma)


def weighted_quantile(values: np.ndarray, weights: np.ndarray, q: float) -> float:
    """The value below which the fraction q of the total weight lies."""
    order = np.argsort(values)
    cum = np.cumsum(weights[order])
    if cum[-1] <= 0.0:
        return quantile(values, q)
    return float(values[order][min(np.searchsorted(cum, q * cum[-1]), len(order) - 1)])


def closed_mask(t: np.ndarray, intervals) -> np.ndarray:
    """Samples inside the contact's closed intervals (s)."""
    out = np.zeros(len(t), bool)
    for a, b in intervals:
        out |= (t >= a) & (t <= b)
    return out


OPEN_BAND = 0.14  # the open band's share of the resistance axis height
RESISTANCE_QUANTILE, RESISTANCE_HEADROOM = 0.99, 10.0


def resistance_axis(t, r, sel, intervals) -> Axis:
    """The ``resistance`` rule (module docstring): samples ``sel`` in view, ``intervals`` the
    closed intervals."""
    finite = np.isfinite(r) & (r > 0.0)
    use = sel & finite & closed_mask(t, intervals)
    if not use.any():
        use = sel & finite
    if use.any():
        typical = weighted_quantile(r[use], sample_weights(t)[use], RESISTANCE_QUANTILE)
        lo = 0.5 * float(np.min(r[use]))
        hi = max(RESISTANCE_HEADROOM * typical, 4.0 * lo)
    else:  # never conducts: only the band has something to show
        lo, hi = 1e-3, 1.0
    above = np.flatnonzero(sel & finite & (r > hi))
    clipped = [("contact_resistance", above, float(np.max(r[above])))] if len(above) else []
    return Axis(lo, hi, log=True, clipped=clipped, open=np.flatnonzero(sel & ~finite),
                top=hi * (hi / lo) ** (OPEN_BAND / (1.0 - OPEN_BAND)))


def resistance_ticks(axis: Axis) -> list[tuple[float, str | None]]:
    """(value, None) ticks on a resistance axis's data range -- decades, or 1-2-5 steps when
    it spans less than two decades, none right under the band -- and (band middle, "open")."""
    lo, hi, top = axis.lo, axis.hi, axis.top
    mid = float(np.sqrt(hi * top))
    below = hi / (mid / lo) ** 0.08
    exps = range(int(np.floor(np.log10(lo))), int(np.ceil(np.log10(hi))) + 1)
    ticks = [10.0 ** e for e in exps if lo <= 10.0 ** e <= below]
    if len(ticks) < 2:
        ticks = [m * 10.0 ** e for e in exps for m in (1, 2, 5) if lo <= m * 10.0 ** e <= below]
    return [(v, None) for v in ticks] + [(mid, "open")]


def _spikes_axis(series, sel, floor=1e-12) -> Axis:
    ref = series[0][1][sel]
    a = np.abs(ref[np.isfinite(ref)])
    top = max(1.15 * quantile(a, 99.5 / 100) if len(a) else 0.0, floor)
    lows = [np.nanmin(y[sel]) for _, y in series if sel.any() and np.isfinite(y[sel]).any()]
    lo = -0.1 * top if lows and min(lows) < 0.0 else 0.0
    return Axis(lo, top, clipped=_beyond(series, sel, lo, top))


def _beyond(series, sel, lo, hi) -> list:
    """(column, indices, peak) of each trace's samples outside (lo, hi); the peak is the
    sample farthest out, with its sign."""
    out = []
    for column, y in series:
        idx = np.flatnonzero(sel & np.isfinite(y) & ((y > hi) | (y < lo)))
        if len(idx):
            out.append((column, idx, float(y[idx][np.argmax(np.abs(y[idx]))])))
    return out


def _linear_axis(series, sel) -> Axis:
    vals = np.concatenate([y[sel][np.isfinite(y[sel])] for _, y in series]) if sel.any() else np.array([])
    if not len(vals):
        return Axis(0.0, 1.0)
    lo, hi = min(float(vals.min()), 0.0), max(float(vals.max()), 0.0)
    span = hi - lo if hi > lo else max(abs(hi), 1e-12)
    return Axis(lo - 0.04 * span if lo < 0.0 else lo - 0.02 * span, hi + 0.06 * span)


def _log_axis(series, sel) -> Axis:
    vals = np.concatenate([y[sel] for _, y in series]) if sel.any() else np.array([])
    vals = vals[np.isfinite(vals) & (vals > 0.0)]
    if not len(vals):
        return Axis(1e-6, 1.0, log=True)
    lo = max(float(vals.min()), 1e-300)
    return Axis(lo / 2.0, max(float(vals.max()) * 2.0, lo * 10.0), log=True)


def _voltage_axis(t, series, sel, bounce, whole_run) -> Axis:
    v = series[0][1]
    if whole_run or not bounce:
        top = max(float(np.nanmax(np.abs(v[sel]))) if sel.any() else 1.0, 1.0) * 1.08
    else:
        # the bounce's own peak, and the open-circuit voltage before the first make
        peak = bounce.get("peak_bounce_voltage") or 0.0
        first = bounce.get("first_make")
        k = int(np.searchsorted(t, first, side="left")) - 1 if first is not None else -1
        top = 1.15 * max(peak, float(abs(v[k])) if k >= 0 else 0.0, 1.0)
    low = np.nanmin(v[sel] if sel.any() else v)
    lo = -0.08 * top if low > -0.08 * top else -top
    return Axis(lo, top, clipped=[] if whole_run or not bounce else _beyond(series[:1], sel, lo, top))


def axis(panel: Panel, t: np.ndarray, series: list, sel: np.ndarray, *, bounce=None, whole_run=True,
         closed_intervals=()) -> Axis:
    """The panel's axis for the samples ``sel`` in view; ``series``: (column, values) of its
    drawn traces; ``bounce`` the run's bounce metrics (the voltage rule), ``closed_intervals``
    the contact's (s; the resistance rule)."""
    if panel.scale == "resistance":
        return resistance_axis(t, series[0][1], sel, closed_intervals)
    if panel.scale == "voltage":
        return _voltage_axis(t, series, sel, bounce, whole_run)
    if panel.scale == "spikes":
        return _spikes_axis(series, sel)
    if panel.scale == "log":
        return _log_axis(series, sel)
    return _linear_axis(series, sel)

