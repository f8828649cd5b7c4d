"""The outcome of a run: mechanics result, circuit waveforms, bounce metrics, files and plots.

Bounce metrics (``bounce`` in summary.json), from the closed intervals of the contact
(mechanics: the union of both tips' contact intervals; prescribed schedule: its
intervals), SI units:
    first_make, last_make      s, first and last closing instant
    bounces                    re-closures after the first make (makes - 1)
    total_bounce_time          s, last_make - first_make
    final_state                "closed" or "open" at the end of the run
    peak_contact_voltage       V, largest |contact voltage| after the first make
    arc_energy                 J, integral of |contact voltage x arc current| dt
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd


def _num(v):
    if v is None:
        return None
    v = float(v)
    return v if math.isfinite(v) else None


def merge_intervals(intervals) -> list[tuple[float, float]]:
    """Union of closed intervals (s), sorted."""
    out: list[list[float]] = []
    for a, b in sorted(intervals):
        if out and a <= out[-1][1]:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([a, b])
    return [(a, b) for a, b in out]


def bounce_metrics(intervals, t_end: float, waveforms: pd.DataFrame | None, closed_at_end: bool) -> dict:
    """The bounce summary (see the module docstring) from closed intervals and the waveform."""
    iv = merge_intervals(intervals)
    out = dict(first_make=None, last_make=None, bounces=0, total_bounce_time=0.0,
               final_state="closed" if closed_at_end else "open", peak_contact_voltage=None, arc_energy=0.0)
    if iv:
        out.update(first_make=iv[0][0], last_make=iv[-1][0], bounces=len(iv) - 1,
                   total_bounce_time=iv[-1][0] - iv[0][0])
    if waveforms is not None and len(waveforms):
        t = waveforms.time.to_numpy()
        v = waveforms.contact_voltage.to_numpy()
        # strictly after the first make: at the make instant itself ngspice still has the
        # open contact (left limit at the breakpoint), i.e. the full supply voltage
        mask = t > iv[0][0] if iv else np.ones(len(t), bool)
        out["peak_contact_voltage"] = float(np.max(np.abs(v[mask]))) if mask.any() else None
        if "arc_current" in waveforms:
            p = np.abs(v * waveforms.arc_current.to_numpy())
            out["arc_energy"] = float(np.sum(0.5 * (p[1:] + p[:-1]) * np.diff(t)))
    return out


@dataclass
class CoupledResult:
    """What a run produced. mechanics: mech.ImpactResult or None; waveforms: DataFrame
    (time, contact_voltage, contact_current, load_current, contact_resistance,
    contact_conductance, arc_current, normal_force[_i], penetration_i, mu; SI) or None."""

    scene: object
    mechanics: object | None
    waveforms: pd.DataFrame | None
    stats: dict
    status: str = "ok"
    accuracy: dict | None = None  # summary.accuracy of run(scene, check=True) (coupling/accuracy.py)
    _cache: dict = field(default_factory=dict, repr=False)

    @property
    def closed_intervals(self) -> list[tuple[float, float]]:
        """Intervals (s) during which the contact is closed."""
        if self.mechanics is not None:
            c = self.mechanics.contacts
            return merge_intervals(zip(c.t_start, c.t_end))
        sched = self.scene.circuit.schedule
        return [(a, min(b, self.scene.t_end)) for a, b in sched.intervals if a < self.scene.t_end]

    @property
    def bounce(self) -> dict:
        if self.scene.circuit is None:
            return {}
        if self.mechanics is not None:
            c = self.mechanics.contacts
            closed_at_end = bool((~c.complete).any()) if len(c) else False
        else:
            closed_at_end = self.scene.circuit.schedule.is_closed(self.scene.t_end)
        return bounce_metrics(self.closed_intervals, self.scene.t_end, self.waveforms, closed_at_end)

    @property
    def summary(self) -> dict:
        """summary.json: the mechanics keys (contacts, restitution, energy, solver, flags),
        bounce, run statistics and status."""
        out: dict = {"scene": getattr(self.scene, "name", "scene"), "kind": self.scene.kind,
                     "status": self.status}
        if self.mechanics is not None:
            out.update(self.mechanics.to_summary())
            flag = jacobi_step_flag(self)
            if flag:
                out["flags"] = list(out.get("flags", [])) + [flag]
        if self.scene.circuit is not None:
            out["bounce"] = {k: (_num(v) if isinstance(v, float) else v) for k, v in self.bounce.items()}
        if self.scene.tribology is not None:
            out["tribology"] = {"source": self.scene.tribology.source,
                                "feedback": self.scene.tribology.feedback,
                                "laws": self.scene.tribology.laws.to_dict()}
        out["run"] = _jsonable(self.stats)
        if self.accuracy is not None:
            out["accuracy"] = _jsonable(self.accuracy)
        return out

    def save(self, out_dir) -> Path:
        """Write summary.json, the waveforms (CSV, parquet), the mechanics tables and PNG plots,
        as the scene's [output] asks."""
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        opts = self.scene.output
        (out / "summary.json").write_text(json.dumps(self.summary, indent=2))
        if self.waveforms is not None:
            if opts.csv:
                self.waveforms.to_csv(out / "waveforms.csv", index=False)
            if opts.parquet:
                self.waveforms.to_parquet(out / "waveforms.parquet", index=False)
        if self.mechanics is not None:
            if opts.history:
                self.mechanics.history.to_csv(out / "history.csv", index=False)
            self.mechanics.contacts.to_csv(out / "contacts.csv", index=False)
            self.mechanics.phases.to_csv(out / "phases.csv", index=False)
            self.mechanics.event_table.to_csv(out / "events.csv", index=False)
        if opts.plots:
            from .plots import save_plots

            save_plots(self, out)
        return out


def jacobi_step_flag(result) -> str | None:
    """A warning when the jacobi scheme's macro step is longer than half a contact: it holds
    the conductance of the step start over the whole step, so a contact shorter than the
    step is seen at one instant or not at all (measured in docs/accuracy.md, part 5: at a
    200 us step on the default scene the arc energy came out 1e-9 J instead of 0.02 J)."""
    scene = result.scene
    if scene.kind != "coupled" or scene.coupling.scheme != "jacobi" or result.mechanics is None:
        return None
    c = result.mechanics.contacts
    c = c[c.complete]
    if not len(c):
        return None
    shortest = float((c.t_end - c.t_start).min())
    h = scene.coupling.macro_step
    if shortest >= 2.0 * h:
        return None
    return (f"coupling.macro_step = {h:g} s is longer than half the shortest contact ({shortest:.3g} s): the "
            "jacobi scheme holds the contact conductance over each step and misses most of such a contact; "
            "use scheme = \"mechanics_first\" or a macro step below half the contact")


def _jsonable(value):
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return _num(value)
    return value
