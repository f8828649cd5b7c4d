"""A digital input's view of a node voltage: a Schmitt trigger's edges, as pure functions of (t, v).

The scene's ``[metrics] logic = { node = "v(pin)", low = 0.99, high = 2.31 }`` (SI: V)
puts a Schmitt-trigger input on a node: its level turns high only when the voltage rises
above ``high`` and low only when it falls below ``low``; in between it keeps the level it
had (the hysteresis), so a ripple that stays between the thresholds gives no edge. Its
summary (``logic`` in summary.json, ``logic_metrics``; documented in docs/coupling.md,
"Digital inputs"):

- ``initial_level``: the level at the first sample: "high" above ``high``, "low" below
  ``low``; between them the input's earlier state is unknown, and the nearer threshold's
  side is taken (v >= (low + high) / 2: high);
- ``edges`` (with ``rising_edges``, ``falling_edges``): the level changes seen; each at
  the instant the voltage crosses the threshold, interpolated linearly between the two
  samples around the crossing (``edge_table``: time, direction, since_previous);
- ``first_edge``, ``last_edge`` (s): the level is stable from ``last_edge`` to the end of
  the run; ``edge_burst`` = last_edge - first_edge (s), how long the input chatters: what a
  software debounce would have to wait out;
- ``final_level`` and ``stable_margin`` (V): from the last edge on (without edges: over
  the whole run), how close the voltage came to the threshold that would switch the level
  back, v - low for a high level, high - v for a low one: a near miss shows as a small
  margin. The edge itself counts (the voltage is at the threshold it crossed there, a
  margin of high - low), so a voltage that goes on moving away from the other threshold
  gives the hysteresis whatever the samples; only a later dip gives less.
"""

from __future__ import annotations

import math

import numpy as np

from mech.validation import check_keys
from mech.frozen import frozen

#: The keys of ``[metrics] logic``.
LOGIC_KEYS = ("node", "low", "high")


def _volts(key: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{key} = {value!r}: expected a finite number of volts")
    return float(value)


@frozen
class LogicInput:
    """``[metrics] logic``: a Schmitt-trigger input on one node (SI: V).

    node: the waveform column it reads, a probe text of the circuit (``"v(pin)"``,
        ``"v(n1,n2)"``); the scene records it as a probe if ``[circuit] probes`` does not.
    low, high: the thresholds, V, low < high.
    """

    node: str
    low: float
    high: float

    def __post_init__(self) -> None:
        if not isinstance(self.node, str) or not self.node.strip():
            raise ValueError(f"metrics.logic.node = {self.node!r}: expected a node voltage such as \"v(pin)\"")
        low, high = _volts("metrics.logic.low", self.low), _volts("metrics.logic.high", self.high)
        if low >= high:
            raise ValueError(f"metrics.logic.low = {low:g} V must be below metrics.logic.high = {high:g} V "
                             "(the Schmitt thresholds: low < high)")
        object.__setattr__(self, "low", low)
        object.__setattr__(self, "high", high)

    @classmethod
    def from_table(cls, table, defaults: dict | None = None) -> "LogicInput":
        """From the scene's ``logic`` table, missing keys taken from ``defaults`` (a
        template's pin and thresholds); a key neither gives: ValueError naming it."""
        if not isinstance(table, dict):
            raise ValueError(f"metrics.logic = {table!r}: expected a table such as "
                             "{ node = \"v(pin)\", low = 0.99, high = 2.31 }")
        check_keys("metrics.logic", table, LOGIC_KEYS)
        values = {**(defaults or {}), **table}
        missing = [k for k in LOGIC_KEYS if k not in values]
        if missing:
            raise ValueError(f"metrics.logic needs {', '.join(missing)} (node = \"v(pin)\": a node of the circuit; "
                             "low, high: the Schmitt thresholds in V)")
        return cls(**values)


def schmitt_levels(v: np.ndarray, low: float, high: float, initial: int | None = None) -> np.ndarray:
    """The Schmitt trigger's level (1 high, 0 low) after each sample of v (V).

    A sample above ``high`` sets 1, below ``low`` sets 0, one in between keeps the level
    before it; before the first sample the level is ``initial`` (None: 1 if v[0] >= the
    thresholds' midpoint, else 0)."""
    v = np.asarray(v, float)
    if initial is None:
        initial = int(len(v) > 0 and v[0] >= 0.5 * (low + high))
    decided = np.where(v > high, 1, np.where(v < low, 0, -1))
    index = np.arange(len(v))
    last = np.maximum.accumulate(np.where(decided >= 0, index, -1)) if len(v) else index
    return np.where(last >= 0, decided[np.maximum(last, 0)], initial)


def schmitt_edges(t, v, low: float, high: float, initial: int | None = None) -> list[tuple[float, str]]:
    """The edges (time s, "rising" | "falling") a Schmitt input with thresholds low < high (V)
    sees on the samples (t, v); each edge's time is where the straight line between the
    two samples around it crosses the threshold. Non-finite samples are skipped."""
    t, v = np.asarray(t, float), np.asarray(v, float)
    keep = np.isfinite(t) & np.isfinite(v)
    t, v = t[keep], v[keep]
    levels = schmitt_levels(v, low, high, initial)
    changes = np.flatnonzero(levels[1:] != levels[:-1]) + 1
    edges = []
    for k in changes:
        # the sample before a change is on the far side of the threshold crossed (or on it)
        rising = bool(levels[k])
        level = high if rising else low
        t0, t1, v0, v1 = t[k - 1], t[k], v[k - 1], v[k]
        when = t1 if t1 == t0 else t0 + (level - v0) / (v1 - v0) * (t1 - t0)
        edges.append((float(when), "rising" if rising else "falling"))
    if len(v) and initial is not None and levels[0] != initial:  # the first sample itself switched
        edges.insert(0, (float(t[0]), "rising" if levels[0] else "falling"))
    return edges


def logic_metrics(t, v, logic: LogicInput) -> dict:
    """The ``logic`` section of summary.json for the samples (t s, v V) of ``logic.node``
    (module docstring)."""
    t, v = np.asarray(t, float), np.asarray(v, float)
    keep = np.isfinite(t) & np.isfinite(v)
    t, v = t[keep], v[keep]
    out: dict = dict(node=logic.node, low=logic.low, high=logic.high, initial_level=None, final_level=None,
                     edges=0, rising_edges=0, falling_edges=0, first_edge=None, last_edge=None, edge_burst=None,
                     stable_margin=None, edge_table=[])
    if not len(t):
        return out
    levels = schmitt_levels(v, logic.low, logic.high)
    edges = schmitt_edges(t, v, logic.low, logic.high)
    name = {1: "high", 0: "low"}
    out["initial_level"] = name[int(levels[0])]
    out["final_level"] = name[int(levels[-1])]
    rows, previous = [], None
    for when, direction in edges:
        rows.append(dict(time=when, direction=direction, since_previous=None if previous is None else when - previous))
        previous = when
    out["edge_table"] = rows
    out["edges"] = len(edges)
    out["rising_edges"] = sum(1 for _, d in edges if d == "rising")
    out["falling_edges"] = len(edges) - out["rising_edges"]
    if edges:
        out["first_edge"], out["last_edge"] = edges[0][0], edges[-1][0]
        out["edge_burst"] = edges[-1][0] - edges[0][0]
        after = v[int(np.flatnonzero(levels[1:] != levels[:-1])[-1]) + 1:]
        # the edge itself, where the voltage stood at the threshold it crossed: the first
        # sample after it is wherever ngspice's step put it (the tactile switch's margin
        # moved from 1.43 to 1.59 V between two step sequences of the same run)
        after = np.append(after, logic.high if levels[-1] else logic.low)
    else:
        after = v
    out["stable_margin"] = float(np.min(after - logic.low) if levels[-1] else np.min(logic.high - after))
    return out
