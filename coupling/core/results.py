"""The outcome of a run: mechanics result, circuit waveforms, bounce metrics, warnings, files and plots.

Bounce metrics (``bounce`` in summary.json) are computed by coupling.core.metrics from the
closed intervals of the contact (mechanics: the union of the tips' contact intervals, for
contacts in series their intersection, coupling.core.arrangement;
prescribed schedule: its intervals) and the waveform; every key is defined in
docs/coupling.md ("Bounce metrics"). Warnings (``warnings``) come from
coupling.core.diagnostics.
"""

from __future__ import annotations

import enum
import math
from dataclasses import field
from pathlib import Path

import numpy as np

from mech.frozen import record
from mech.results import REGIME_NAMES

from coupling.core.metrics import MetricSettings, merge_intervals
from coupling.core.metrics import bounce_metrics as _bounce_metrics
from coupling.core.metrics import operations as _operations


OPENING_COLUMNS = ("start", "end", "open_duration", "reclosed", "kind", "current_at_break", "peak_voltage",
                   "arc_duration", "arc_energy")


def _num(v):
    if v is None:
        return None
    v = float(v)
    return v if math.isfinite(v) else None


def contact_waves(waveforms: dict | None, suffix: str) -> dict | None:
    """One contact's columns of a circuit of several, under the unsuffixed names the metrics
    read (time, contact_voltage, contact_current, arc_current; SI), without a load current:
    its loop current is then its own metallic plus arc current (a changeover's throws each
    carry their own)."""
    if waveforms is None:
        return None
    return {"time": waveforms["time"], **{name: waveforms[name + suffix] for name in
                                          ("contact_voltage", "contact_current", "arc_current")}}


def bounce_metrics(intervals, t_end: float, waveforms: dict | None, closed_at_end: bool,
                   settings: MetricSettings | None = None) -> dict:
    """The bounce summary (coupling.core.metrics.bounce_metrics) from closed intervals and a waveform frame."""
    if waveforms is None or not len(waveforms["time"]):
        return _bounce_metrics(intervals, t_end, closed_at_end, settings=settings)
    arc = waveforms.get("arc_current")
    loop = waveforms.get("load_current")
    if loop is None or not np.all(np.isfinite(loop)):  # no load probe: metallic + arc current
        loop = waveforms["contact_current"] + (arc if arc is not None else 0.0)
    return _bounce_metrics(intervals, t_end, closed_at_end, waveforms["time"],
                           waveforms["contact_voltage"], loop, arc, settings=settings)


class RunStatus(str, enum.Enum):
    """How a run ended, one value of four (a ``str``: ``result.status == "ok"`` reads as it says).

    ok: finished and physically sound; unsound: finished, but a soundness bound is violated
    (``CoupledResult.problems``; the command line exits 3); failed: stopped by an error
    (``message``; exit 1); interrupted: stopped by Ctrl-C (exit 130). A failed or interrupted
    run keeps what it computed up to ``stopped_at``."""

    OK = "ok"
    UNSOUND = "unsound"
    FAILED = "failed"
    INTERRUPTED = "interrupted"

    def __str__(self) -> str:
        return self.value


@record
class CoupledResult:
    """What a run produced. mechanics: mech.ImpactResult or None; waveform_columns: name ->
    numpy array (time, contact_voltage, contact_current, load_current, contact_resistance,
    contact_conductance, arc_current, normal_force[_i], penetration_i, gap, mu, the
    probes; SI, equal lengths) or None; ``waveforms`` is the same as a pandas DataFrame,
    built on first use (writing and judging a run need no pandas)."""

    scene: object
    mechanics: object | None
    waveform_columns: dict | None
    stats: dict
    status: RunStatus = RunStatus.OK
    message: str = ""  # why it failed, was interrupted or is unsound ("" when ok)
    stopped_at: float | None = None  # s: where a failed or interrupted run stopped
    accuracy: dict | None = None  # summary.accuracy of run(scene, check=True) (coupling/app/accuracy.py)
    soundness: dict | None = None  # what judge() measured: extremes, bounds and problems (coupling.core.soundness)
    # J: the work the mechanics received from the coil's drive (coupling.core.exchange.CoilLink.receive), None
    # without a coil; the relay's energy audit sets the magnet's work against it (coupling.core.relay)
    armature_received: float | None = None
    _cache: dict = field(default_factory=dict, repr=False)

    def __post_init__(self):
        self.status = RunStatus(self.status)

    @property
    def problems(self) -> list[str]:
        """One line per violated soundness bound (empty when sound, or not judged)."""
        return list((self.soundness or {}).get("problems", []))

    def judge(self) -> "CoupledResult":
        """Judge the finished run's soundness (coupling.core.soundness.assess): an ok run with a
        violated bound becomes unsound, its message naming each problem. Done where a run is
        made (``coupling.run``), so the API, the command line and sweep rows carry the same
        status. Returns the result itself."""
        from coupling.core.soundness import assess

        self.soundness = assess(self)
        if self.problems and self.status is RunStatus.OK:
            self.status = RunStatus.UNSOUND
            self.message = "; ".join(self.problems)
        return self

    @property
    def waveforms(self):
        """pandas DataFrame of ``waveform_columns`` (None without waveforms)."""
        if self.waveform_columns is None:
            return None
        if "waveforms" not in self._cache:
            import pandas as pd

            self._cache["waveforms"] = pd.DataFrame(self.waveform_columns)
        return self._cache["waveforms"]

    @property
    def closed_intervals(self) -> list[tuple[float, float]]:
        """Intervals (s) during which the contact is closed (contacts in series, a bridge: while
        every one touches; coupling.core.arrangement)."""
        if self.mechanics is not None:
            from coupling.core.arrangement import switch_closed

            return switch_closed(self.scene, self.mechanics.contact_columns)[0]
        sched = self.scene.circuit.schedule
        return [(a, min(b, self.scene.t_end)) for a, b in sched.intervals if a < self.scene.t_end]

    @property
    def closed_at_end(self) -> bool:
        """Whether the contact is closed when the run ends (a contact still going on)."""
        if self.mechanics is not None:
            from coupling.core.arrangement import switch_closed

            return switch_closed(self.scene, self.mechanics.contact_columns)[1]
        return bool(self.scene.circuit.schedule.is_closed(self.scene.t_end))

    @property
    def contact_closed(self) -> dict:
        """Per circuit contact of a circuit of several: its name -> (closed intervals s, closed
        at the end), each the union of its own contact pairs' (coupling.core.arrangement);
        {} for one contact or without mechanics."""
        if self.mechanics is None or self.scene.circuit is None:
            return {}
        from coupling.core.arrangement import contact_closed

        return contact_closed(self.scene, self.mechanics.contact_columns)

    @property
    def contact_results(self) -> dict:
        """Per circuit contact of a circuit of several (summary.json ``per_contact``): its
        name -> {"closed_intervals": its own (s), "bounce": its bounce metrics, "operations":
        its operations}, from its own closed intervals and its own columns
        (``contact_waves``: its current is its own metallic plus arc current); {} for one
        contact."""
        closed = self.contact_closed
        if not closed:
            return {}
        if "contact_results" not in self._cache:
            settings = getattr(self.scene, "metrics", None)
            model = getattr(self.scene.circuit.circuit, "arc", None)
            out = {}
            for block in self.scene.circuit.circuit.contacts:
                intervals, at_end = closed[block.name]
                w = contact_waves(self.waveform_columns, block.suffix)
                bounce = bounce_metrics(intervals, self.scene.t_end, w, at_end, settings)
                if w is None or not len(w["time"]):
                    ops = _operations(intervals, self.scene.t_end, settings=settings)
                else:
                    loop = w["contact_current"] + w["arc_current"]
                    ops = _operations(intervals, self.scene.t_end, w["time"], w["contact_voltage"], loop,
                                      w["contact_current"], w["arc_current"], settings,
                                      min_arc_current=None if model is None else model.min_current)
                out[block.name] = {"closed_intervals": [list(iv) for iv in intervals], "bounce": bounce,
                                   "operations": ops}
            self._cache["contact_results"] = out
        return self._cache["contact_results"]

    @property
    def changeover(self) -> dict | None:
        """A changeover's transfer times and break-before-make (summary.json ``changeover``;
        coupling.core.arrangement.changeover_metrics), None for any other circuit."""
        from coupling.core.arrangement import changeover_metrics, changeover_names

        names = changeover_names(getattr(self.scene.circuit, "circuit", None)) if self.scene.circuit else None
        if names is None or not self.contact_results:
            return None
        if "changeover" not in self._cache:
            closed, res, w = self.contact_closed, self.contact_results, self.waveform_columns
            no, nc = ({"intervals": closed[n][0], "operations": res[n]["operations"],
                       "time": None if w is None else w["time"],
                       "arc_current": None if w is None else w[f"arc_current_{n}"]} for n in names)
            self._cache["changeover"] = dict(normally_open=names[0], normally_closed=names[1],
                                             **changeover_metrics(no, nc))
        return self._cache["changeover"]

    def contact_opening_columns(self, name: str) -> dict:
        """The per-opening table of one contact of several (``contact_results``; openings_<name>.csv)."""
        rows = self.contact_results[name]["bounce"].get("openings", [])
        return {k: [r.get(k) for r in rows] for k in OPENING_COLUMNS}

    @property
    def has_contact(self) -> bool:
        """True when the circuit holds a contact (an actuator's coil drive alone holds none)."""
        return self.scene.circuit is not None and bool(getattr(self.scene.circuit.circuit, "contacts", (1,)))

    @property
    def bounce(self) -> dict:
        if not self.has_contact:
            return {}
        key = "bounce"
        if key not in self._cache:
            self._cache[key] = bounce_metrics(self.closed_intervals, self.scene.t_end, self.waveform_columns,
                                              self.closed_at_end, getattr(self.scene, "metrics", None))
        return self._cache[key]

    @property
    def logic(self) -> dict | None:
        """The digital input's view of ``[metrics] logic``'s node (coupling.core.logic.logic_metrics),
        or None without it."""
        settings = getattr(getattr(self.scene, "metrics", None), "logic", None)
        if settings is None or self.waveform_columns is None:
            return None
        if "logic" not in self._cache:
            from coupling.core.logic import logic_metrics

            waves = self.waveform_columns
            self._cache["logic"] = logic_metrics(waves["time"], waves[settings.node], settings)
        return self._cache["logic"]

    @property
    def operations(self) -> list[dict]:
        """The run as a sequence of operations, each a ``make`` and/or a ``break``
        (coupling.core.metrics.operations; summary.json ``operations``, docs/coupling.md)."""
        if not self.has_contact:
            return []
        if "operations" not in self._cache:
            w = self.waveform_columns
            settings = getattr(self.scene, "metrics", None)
            if w is None or not len(w["time"]) or "contact_voltage" not in w:
                ops = _operations(self.closed_intervals, self.scene.t_end, settings=settings)
            else:
                arc = w.get("arc_current")
                loop = w.get("load_current")
                if loop is None or not np.all(np.isfinite(loop)):  # no load probe: metallic + arc current
                    loop = w["contact_current"] + (arc if arc is not None else 0.0)
                model = getattr(getattr(self.scene.circuit, "circuit", None), "arc", None)
                ops = _operations(self.closed_intervals, self.scene.t_end, w["time"], w["contact_voltage"], loop,
                                  w["contact_current"], arc, settings,
                                  min_arc_current=None if model is None else model.min_current)
                if getattr(self.scene, "duty", None) is not None:  # what each did to the contact
                    from coupling.core.duty import operation_duty

                    ops = operation_duty(self, ops)
                else:  # the held closure's force and R_c, a datasheet's figures
                    from coupling.core.duty import held_closures

                    ops = held_closures(self, ops)
            self._cache["operations"] = ops
        return self._cache["operations"]

    @property
    def relay(self) -> dict | None:
        """What the relay's coil and armature did (coupling.core.relay; summary.json ``relay``),
        None without a coil."""
        w = self.waveform_columns
        if w is None or "magnetic_force" not in w or not len(w["time"]):
            return None
        if "relay" not in self._cache:
            from coupling.core.device import device
            from coupling.core.relay import relay_metrics

            spec = device(self.scene.raw)
            self._cache["relay"] = relay_metrics(w, self.operations, self.coil_drive, spec.magnet,
                                                 self.mechanics.events, spec.resistance,
                                                 received=self.armature_received)
        return self._cache["relay"]

    @property
    def coil_drive(self):
        """The circuit's CoilDrive (its on_time and off_time, s), or None: no coil, or a
        netlist's coil (its drive is the user's own circuit)."""
        from circuit.coil_drive import CoilDrive

        circ = getattr(self.scene.circuit, "circuit", None)
        return circ if isinstance(circ, CoilDrive) else getattr(circ, "coil", None)

    @property
    def opening_columns(self) -> dict:
        """The per-opening table of ``bounce`` (openings.csv) as lists: start, end, open_duration,
        reclosed, kind, current_at_break, peak_voltage, arc_duration, arc_energy (SI)."""
        rows = self.bounce.get("openings", [])
        return {k: [r.get(k) for r in rows] for k in OPENING_COLUMNS}

    @property
    def openings(self):
        """pandas DataFrame of ``opening_columns``."""
        import pandas as pd

        return pd.DataFrame(self.bounce.get("openings", []), columns=list(OPENING_COLUMNS))

    @property
    def warnings(self) -> list[str]:
        """One-line warnings about physically doubtful states of the run (coupling.core.diagnostics)."""
        if "warnings" not in self._cache:
            from coupling.core.arrangement import changeover_warnings
            from coupling.core.diagnostics import run_warnings

            lines = run_warnings(self)
            co = self.changeover
            if co is not None:
                lines = lines + changeover_warnings(co, (co["normally_open"], co["normally_closed"]))
            self._cache["warnings"] = lines
        return self._cache["warnings"]

    @property
    def summary(self) -> dict:
        """summary.json: the mechanics keys (contacts, restitution, energy, solver, flags),
        bounce, run statistics and status."""
        out: dict = {"scene": getattr(self.scene, "name", "scene"), "kind": self.scene.kind,
                     "status": self.status.value}
        if self.message:
            out["message"] = self.message
        if self.stopped_at is not None:
            out["stopped_at"] = self.stopped_at
        if self.mechanics is not None:
            out.update(self.mechanics.to_summary())
            refined = self.stats.get("modes_refined")
            if refined and "solver" in out:  # run again with the count its impacts asked for
                out["solver"] = dict(out["solver"], modes_rule=refined["rule"] + " (refined after a first run: "
                                     + refined["first"] + ")")
            flag = jacobi_step_flag(self)
            if flag:
                out["flags"] = list(out.get("flags", [])) + [flag]
        if self.has_contact:
            out["bounce"] = _jsonable(self.bounce)
            out["operations"] = _jsonable(self.operations)
            if self.contact_results:
                from coupling.core.arrangement import is_series

                out["arrangement"] = "series" if is_series(self.scene.circuit.circuit) else "independent"
                out["per_contact"] = _jsonable(self.contact_results)
            if self.changeover is not None:
                out["changeover"] = _jsonable(self.changeover)
        if self.scene.circuit is not None:
            if self.relay is not None:
                out["relay"] = _jsonable(self.relay)
            if getattr(self.scene, "duty", None) is not None:
                from coupling.core.duty import duty_totals

                out["duty"] = _jsonable(duty_totals(self.scene.duty, self.operations))
            if self.logic is not None:
                out["logic"] = _jsonable(self.logic)
        if self.scene.tribology is not None:
            out["tribology"] = {"source": self.scene.tribology.source,
                                "feedback": self.scene.tribology.feedback,
                                "laws": self.scene.tribology.laws.to_dict()}
        out["warnings"] = list(self.warnings)
        out["run"] = _jsonable(self.stats)
        if self.soundness is not None:
            out["soundness"] = _jsonable(self.soundness)
        if self.accuracy is not None:
            out["accuracy"] = _jsonable(self.accuracy)
        return out

    def save(self, out_dir, *, overwrite: bool = False) -> Path:
        """Write the result folder ``out_dir`` as ``switchsim run --out`` does, by the same
        writer (coupling.app.output; imported here, when called: results are made in the core,
        folders written by the application): whole or not at all, summary.json last; a folder
        holding other files is refused unless ``overwrite`` (then replaced whole). Returns it."""
        from coupling.app.output import save_result

        return save_result(self, out_dir, overwrite=overwrite)


def event_columns(events: list[dict]) -> dict:
    """events.csv's columns: every key any event has, in order of first appearance (blank where an event lacks it)."""
    keys = list(dict.fromkeys(k for ev in events for k in ev))
    return {k: [ev.get(k) for ev in events] for k in keys}


def jacobi_step_flag(result) -> str | None:
    """A warning when the jacobi scheme's macro step is longer than half a contact: it holds
    the conductance of the step start over the whole step, so a contact shorter than the
    step is seen at one instant or not at all (measured in docs/accuracy.md, part 5: at a
    200 us step on the default scene the arc energy came out 1e-9 J instead of 0.02 J)."""
    scene = result.scene
    if scene.kind != "coupled" or scene.coupling.scheme != "jacobi" or result.mechanics is None:
        return None
    c = result.mechanics.contact_columns
    done = c["complete"]
    if not done.any():
        return None
    shortest = float((c["t_end"][done] - c["t_start"][done]).min())
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
