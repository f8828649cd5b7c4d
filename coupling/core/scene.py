"""Coupled scenes: the mechanics sections plus [tribology], [circuit], [coupling], [output].

A scene names only what it needs, and only that is built:
- mechanics sections only: the impact solver alone (no ngspice);
- [circuit] with [circuit.schedule]: a prescribed make/break schedule, no mechanics;
- mechanics + [tribology] + [circuit]: the co-simulation.

    [tribology]   source = "illustrative" | fit = "fit.json" | data = "data.csv"
                  | inline [tribology.mu] and [tribology.resistance] tables (docs/tribology.md)
                  feedback = true (mu follows the contact current; false: mu = mu(0))
    [circuit]     template = "resistive" | "inductive" | "capacitive" | "current_source" | "netlist"
                  | "mcu_input" (voltage, pull, pull_resistance, series_resistance,
                  input_capacitance, logic_low, logic_high, contact_capacitance, leakage_conductance)
                  | "short_circuit" (resistive, shorted at fault_time: fault_resistance, fault_rise)
                  | "bridge" (resistive, its switch a double-break bridge: two contacts in series,
                  named as the scene's two electrical [[fixed]] contacts)
                  | "changeover" (form C: the supply on the moving contact, its NO and NC throws
                  each with its own resistive load: load_resistance, nc_load_resistance; the
                  scene's electrical [[fixed]] contacts named NO and NC)
                  voltage, source_resistance (voltage templates) | current, compliance_voltage,
                  output_capacitance, output_resistance (current_source), wiring_resistance,
                  wiring_inductance, load_resistance, load_inductance, load_capacitance,
                  bleed_resistance, contact_capacitance, leakage_conductance,
                  snubber = {resistance, capacitance} (both), flyback = true | {...},
                  arc = true | false | {min_voltage, min_current, ...}, netlist = "file.cir",
                  params = {NAME = number} (new values of the netlist's .param definitions),
                  load_probe, max_step, reltol, abstol, vntol, chgtol, method, temperature,
                  wall_timeout (each key one dataclass field; omitted: that field's default),
                  probes = ["v(node)", "v(n1,n2)", "i(element)"] (recorded as waveform columns)
    [circuit.schedule]  make = [...], break = [...], closed_resistance, opening_speed
                        (s, s, ohm, m/s: the gap for an arc whose voltage grows with it)
    [coupling]    scheme = "mechanics_first" | "jacobi", macro_step, max_macro_step (s),
                  align_events = true, onset_penetration (m)
    [output]      csv, parquet, plots, history, html = true | false, history_resolution (s),
                  history_max_rows
    [metrics]     settle_window (s), make_guard (s), arc_toggle_limit (coupling.core.metrics),
                  logic = { node = "v(pin)", low, high } (V; coupling.core.logic)
    [duty]        materials = ["moving", "fixed"], moving_node, repulsion, conductor_radius,
                  transition_gap, transfer_fraction, erosion_coefficient, weld_margin,
                  melt_fraction, cap_height, life = {gap_range, min_force, max_resistance,
                  stop_on_weld} (coupling.core.duty; docs/contact_duty.md)

SI units everywhere. File paths are relative to the scene file. Every error names the
file, the section and key as written and says what is allowed, before any solver starts.

This module holds no value checks of its own: it maps each TOML section 1:1 onto its
dataclass (mech's, circuit's, or the coupling sections' below, which use mech/validation.py),
checks the structure (sections, key names, which sections go together, files) and reports
the dataclasses' errors in the scene's words (docs/scene_keys.md, "Where values are checked").
"""

from __future__ import annotations

import copy
import dataclasses
import re
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

from mech.parameters import HISTORY_ROWS_MAX, LENGTH_MAX, T_END_MAX, Friction, MechScene, SolverOptions
from mech.recorder import DENSE_BYTES, MEMORY_LIMIT, history_memory
from mech.scene import SCENE_SECTIONS as MECH_SECTIONS
from mech.scene import read_toml
from mech.scene import scene_from_dict as mech_scene_from_dict
from mech.validation import (
    check_bool, check_choice, check_file, check_keys, check_nonnegative, check_positive, check_whole,
)

COUPLING_SECTIONS = ("tribology", "circuit", "coupling", "output", "metrics", "duty", "coil", "magnet")
# macro steps a coupled run may take at most (t_end / macro_step, every step in contact):
# each costs a mechanics advance and an ngspice step (~0.1-1 ms), so 1e6 is minutes to an
# hour; a 1e-9 s macro step over 5 ms (5e6) is refused before it starts
MACRO_STEPS_MAX = 1_000_000
# waveform points per macro step and bytes per point and column, for the memory estimate:
# ngspice lands at least once per step (the default relay: about 2), and a point is held by
# ngspice's vectors, the result's columns and the files written from them
POINTS_PER_MACRO_STEP = 4
WAVE_COPIES = 3
MECH_WAVE_COLUMNS = 8  # normal_force_0/1, penetration_0/1, normal_force, gap, mu (+1 spare)
MACRO_STEP_LOG_BYTES = 152  # the friction coefficient's log, one entry per macro step
TEMPLATES = ("resistive", "inductive", "capacitive", "current_source", "netlist", "mcu_input", "short_circuit",
             "bridge", "changeover")
SCHEMES = ("mechanics_first", "jacobi")


def _table(where: str, value) -> dict:
    if not isinstance(value, dict):
        raise ValueError(f"{where}: expected a table of keys, got {value!r}")
    return value


@dataclass(frozen=True)
class CouplingOptions:
    """How mechanics and circuit exchange data (SI).

    scheme: "mechanics_first" (default: the mechanics advances a macro step first, its
    dense trajectory drives the circuit continuously, the current is extrapolated
    linearly into mu(I)) or "jacobi" (both advance on the other's values held at the
    step start, for comparison).
    macro_step: s, exchange interval while a tip is in contact (and for jacobi always).
    max_macro_step: s, exchange interval while both tips are free (nothing to exchange
    then but the contact onset, which the mechanics finds exactly); None = macro_step.
    align_events: end a macro step exactly at each contact make/break (mechanics_first).
    onset_penetration: m, penetration over which a tip's conduction ramps in smoothly
    (coupling.core.exchange.conduction_onset): the continuum Hertz/Holm laws do not hold below
    the surface-roughness scale, and G ~ y^0.4 has an unbounded derivative at touchdown
    that ngspice's truncation-error control cannot follow at tight RELTOL.
    """

    scheme: str = "mechanics_first"
    macro_step: float = 2e-6
    max_macro_step: float | None = 1e-4
    align_events: bool = True
    onset_penetration: float = 10e-9

    def __post_init__(self):
        check_choice("coupling.scheme", self.scheme, SCHEMES)
        check_positive("coupling.macro_step", self.macro_step, high=T_END_MAX)
        if self.max_macro_step is not None:
            check_positive("coupling.max_macro_step", self.max_macro_step, high=T_END_MAX)
            if self.max_macro_step < self.macro_step:
                raise ValueError(f"coupling.max_macro_step = {self.max_macro_step!r}: must be >= "
                                 f"coupling.macro_step = {self.macro_step!r}")
        check_bool("coupling.align_events", self.align_events)
        check_nonnegative("coupling.onset_penetration", self.onset_penetration, high=LENGTH_MAX)

    @property
    def free_step(self) -> float:
        return self.macro_step if self.max_macro_step is None or self.scheme == "jacobi" else self.max_macro_step


@dataclass(frozen=True)
class OutputOptions:
    """What a run writes besides summary.json: csv, parquet, plots (PNG), history (mechanics CSV),
    html (waveforms.html, the interactive waveform page).

    history_resolution, history_max_rows: history.csv keeps the records on either side of
    every event and regime change and, of the rest, one per interval of
    max(history_resolution, run length / history_max_rows) (s; both 0: every record the run
    kept, at most [solver] history_rows besides those); docs/coupling.md, "Outputs".
    """

    csv: bool = True
    parquet: bool = True
    plots: bool = False  # PNGs on request (`switchsim run --plots`, `switchsim plot DIR`): drawing them costs more than a run
    history: bool = True
    html: bool = True
    history_resolution: float = 1e-6
    history_max_rows: int = 50_000

    def __post_init__(self):
        for name in ("csv", "parquet", "plots", "history", "html"):
            check_bool(f"output.{name}", getattr(self, name))
        check_nonnegative("output.history_resolution", self.history_resolution, high=T_END_MAX)
        check_whole("output.history_max_rows", self.history_max_rows, 0, HISTORY_ROWS_MAX,
                    note=" (0: every record the run kept)")

    def history_interval(self, duration: float) -> float:
        """s: the history's resolution for a run of ``duration`` s (0: every record)."""
        budget = duration / self.history_max_rows if self.history_max_rows else 0.0
        return max(self.history_resolution, budget)


@dataclass(frozen=True)
class TribologySpec:
    """The contact laws (mu(I), gamma, R_c(F_n, I)), where they came from, and the fit if any."""

    laws: Any  # coupling.laws.tribology.ContactLaws
    source: str
    feedback: bool = True
    fit: Any = None  # coupling.laws.tribology.TribometerFit, when the laws come from a fit


@dataclass(frozen=True)
class CircuitSpec:
    """The circuit, its ngspice options, and an optional prescribed contact schedule."""

    circuit: Any  # circuit.SwitchCircuit | circuit.NetlistCircuit
    options: Any  # circuit.SimulationOptions
    schedule: Any = None  # circuit.ContactSchedule | None
    template: str = "resistive"
    probes: tuple = ()  # circuit.probes.UserProbe: [circuit] probes = ["v(node)", "i(element)"]


@dataclass(frozen=True)
class Scene:
    """A validated scene. ``raw`` is the TOML document it was built from; ``set`` edits it."""

    raw: dict
    base_dir: Path
    mech: MechScene | None
    tribology: TribologySpec | None
    circuit: CircuitSpec | None
    coupling: CouplingOptions = field(default_factory=CouplingOptions)
    output: OutputOptions = field(default_factory=OutputOptions)
    name: str = "scene"
    metrics: Any = None  # coupling.core.metrics.MetricSettings
    duty: Any = None  # coupling.core.duty.DutySettings, when the scene has [duty]

    @property
    def kind(self) -> str:
        """'mechanics', 'circuit' (prescribed schedule) or 'coupled'."""
        if self.circuit is None:
            return "mechanics"
        if self.mech is None:
            return "circuit"
        return "coupled"

    @property
    def t_end(self) -> float:
        """s: length of the run ([solver] t_end)."""
        if self.mech is not None:
            return self.mech.solver.t_end
        return SolverOptions(**self.raw.get("solver", {})).t_end  # a schedule scene: [solver] t_end alone

    def set(self, key: str, value) -> "Scene":
        """A new scene with ``key`` set to value, re-validated: "section.key",
        "section.sub.key", an entry of a list by its index ("rivet[0].mass", "force[1].value",
        "magnet.iron[1].length", "initial.velocity[2]"), a netlist's parameter
        ("circuit.params.RF"). An index names an entry the scene has (no entry is added).

        Example: ``scene.set("initial.angle_deg", 45).set("circuit.load_resistance", 6.0)``.
        """
        return self.update({key: value})

    def update(self, changes: dict) -> "Scene":
        """A new scene with several "section.key" values set at once, validated once (for
        keys that only make sense together, e.g. initial.resting with initial.angle_deg = 0).

        Setting one of several exclusive alternatives drops the others the scene had (unless
        they are set in the same call): ``update({"bar.width": 0.02, "bar.thickness": 3e-4})``
        turns a round bar (bar.diameter) into a rectangular one in one call; likewise
        bar.diameter back, and tribology.source / fit / data (ALTERNATIVES)."""
        raw = set_keys(self.raw, changes, self.name)
        _drop_replaced_alternatives(raw, changes)
        return scene_from_dict(raw, base_dir=self.base_dir, name=self.name)

    def unset(self, *keys: str) -> "Scene":
        """A new scene without these "section.key" entries (their defaults apply), validated."""
        raw = copy.deepcopy(self.raw)
        for key in keys:
            node, last = _walk(raw, key, self.name, create=False)
            if isinstance(node, list):
                node.pop(last)  # "rivet[1]": the entry goes, the ones after it move up
            elif node is not None:
                node.pop(last, None)
        return scene_from_dict(raw, base_dir=self.base_dir, name=self.name)

    def __reduce__(self):
        # A scene travels between processes as its document (one ngspice per process:
        # parallel sweeps need separate processes); it is rebuilt and validated there.
        return (_rebuild_scene, (copy.deepcopy(self.raw), str(self.base_dir), self.name))

    def without(self, *sections: str) -> "Scene":
        """A new scene without these top-level sections, e.g. ``without("circuit", "coupling")``
        for the mechanics alone."""
        raw = copy.deepcopy(self.raw)
        for section in sections:
            raw.pop(section, None)
        return scene_from_dict(raw, base_dir=self.base_dir, name=self.name)


# ------------------------------------------------------------------------------------


TRIBOLOGY_KEYS = ("source", "fit", "data", "mu", "resistance", "feedback")


def _input_file(key: str, value, base_dir: Path) -> Path:
    """The file a scene key names, relative to the scene's folder (mech.validation.check_file)."""
    if not isinstance(value, str) or not value:
        raise ValueError(f"{key} = {value!r}: expected a file name (a string), relative to the scene's folder")
    return check_file(f"{key} = {value!r}", base_dir / value)


def _tribology(table: dict, base_dir: Path) -> TribologySpec:
    """[tribology]; ``resistance = { law = "holm" | "constant", ... }`` takes R_c from
    contact materials (coupling.laws.materials) instead of a fit, with mu from the fit or
    ``mu = number`` (Coulomb, gamma = 0)."""
    table = check_keys("[tribology]", _table("[tribology]", table), TRIBOLOGY_KEYS)
    feedback = check_bool("tribology.feedback", table.get("feedback", True))
    resistance = table.get("resistance")
    if not (isinstance(resistance, dict) and "law" in resistance):
        return _tribology_fitted(table, base_dir, feedback)
    from coupling.laws.materials import resistance_law_from_table
    from coupling.laws.tribology import ContactLaws, MuLaw

    law = resistance_law_from_table(resistance, "tribology.resistance")
    rest = {k: v for k, v in table.items() if k != "resistance"}
    mu = rest.get("mu")
    fitted = [k for k in ("source", "fit", "data") if k in rest]
    if isinstance(mu, (int, float)) and not isinstance(mu, bool):
        if fitted:
            raise ValueError(f"tribology.mu = {mu!r} and tribology.{fitted[0]} both give mu; remove one")
        mu = check_positive("tribology.mu", mu)  # Coulomb's coefficient
        mu_law = MuLaw(0.0, "constant", (("mu0", mu),), (0.0, 1e6))
        return TribologySpec(ContactLaws(mu_law, law), f"materials ({law.name}), mu = {mu:g}", feedback)
    if "mu" in rest and not fitted:
        mu_law = MuLaw.from_dict(_table("tribology.mu", rest["mu"]), "tribology.mu")
        return TribologySpec(ContactLaws(mu_law, law), f"materials ({law.name}), inline mu", feedback)
    if not fitted:
        raise ValueError(f"[tribology]: resistance = {{ law = {resistance['law']!r} }} gives R_c only; give mu too: "
                         "mu = 0.3 (Coulomb), or source/fit/data for the fitted mu(I)")
    spec = _tribology_fitted(rest, base_dir, feedback)
    return TribologySpec(ContactLaws(spec.laws.mu_law, law), f"{spec.source} (mu); materials ({law.name}) (R_c)",
                         spec.feedback, spec.fit)


def _tribology_fitted(table: dict, base_dir: Path, feedback: bool) -> TribologySpec:
    from coupling.laws.tribology import ContactLaws, TribometerFit, default_fit, fit_tribometer, read_tribometer_csv

    given = [k for k in ("source", "fit", "data") if k in table] + (["inline mu/resistance"] if (
        "mu" in table or "resistance" in table) else [])
    if len(given) != 1:
        raise ValueError("[tribology]: give exactly one of source = \"illustrative\", fit = \"fit.json\", "
                         "data = \"data.csv\", or inline [tribology.mu] and [tribology.resistance] tables "
                         f"(found {', '.join(given) or 'none'})")
    if "source" in table:
        if table["source"] != "illustrative":
            raise ValueError(f"tribology.source = {table['source']!r}: the only built-in source is \"illustrative\" "
                             "(the shipped, not measured, dataset); for your data use fit = or data =")
        fit = default_fit()
        return TribologySpec(fit.laws, "illustrative (not measured)", feedback, fit)
    if "fit" in table:
        path = _input_file("tribology.fit", table["fit"], base_dir)
        fit = TribometerFit.from_json(path)
        return TribologySpec(fit.laws, f"fit file {path.name}", feedback, fit)
    if "data" in table:
        path = _input_file("tribology.data", table["data"], base_dir)
        fit = fit_tribometer(read_tribometer_csv(path))
        return TribologySpec(fit.laws, f"fit of {path.name}", feedback, fit)
    if "mu" not in table or "resistance" not in table:
        raise ValueError("[tribology]: inline laws need both [tribology.mu] and [tribology.resistance]")
    laws = ContactLaws.from_dict({"mu": table["mu"], "resistance": table["resistance"]}, "tribology")
    return TribologySpec(laws, "inline laws", feedback)


# --- [circuit]: scene keys mapped 1:1 onto the circuit dataclasses ------------------------
# Each flat [circuit] key is one field of one dataclass; an omitted key takes that field's
# default (the dataclasses are the only source of defaults). Sub-tables snubber, flyback,
# arc and schedule map their keys onto the fields of the same name. Errors raised by a
# dataclass ("DCSource.voltage = ...") are reported in the scene's words ("circuit.voltage").

_VOLTAGE_SOURCE = {"voltage": "voltage", "source_resistance": "internal_resistance"}
_CURRENT_SOURCE = {"current": "current", "compliance_voltage": "compliance_voltage",
                   "output_capacitance": "output_capacitance", "output_resistance": "output_resistance"}
_WIRING = {"wiring_resistance": "resistance", "wiring_inductance": "inductance"}
_LOADS = {
    "resistive": {"load_resistance": "resistance"},
    "inductive": {"load_resistance": "resistance", "load_inductance": "inductance"},
    "capacitive": {"load_resistance": "resistance", "load_capacitance": "capacitance",
                   "bleed_resistance": "bleed_resistance"},
    "current_source": {"load_resistance": "resistance"},
    "short_circuit": {"load_resistance": "resistance"},
    "bridge": {"load_resistance": "resistance"},
    "changeover": {"load_resistance": "resistance"},
}
_FAULT = {"fault_time": "fault_time", "fault_resistance": "fault_resistance", "fault_rise": "fault_rise"}
_CHANGEOVER = {"nc_load_resistance": "nc_load_resistance"}
_TEMPLATE_CIRCUIT = {"contact_capacitance": "contact_capacitance", "leakage_conductance": "leakage_conductance"}
_NETLIST = {"netlist": None, "load_probe": "load_probe", "leakage_conductance": "leakage_conductance",
            "params": "params"}
_PARTS = ("snubber", "flyback", "arc")
_OPTION_KEYS = ("max_step", "reltol", "abstol", "vntol", "chgtol", "method", "temperature", "wall_timeout")
_MCU_INPUT = {k: k for k in ("voltage", "pull", "pull_resistance", "series_resistance", "input_capacitance",
                              "logic_low", "logic_high", "contact_capacitance", "leakage_conductance")}
_SCHEDULE = {"make": "intervals", "break": "intervals", "closed_resistance": "closed_resistance",
             "edge_time": "edge_time", "opening_speed": "opening_speed"}


def template_keys(template: str) -> set:
    """The [circuit] keys a template uses (besides template, schedule and the ngspice options)."""
    if template == "netlist":
        return set(_NETLIST) | {"arc"}
    if template == "mcu_input":
        return set(_MCU_INPUT)
    source = _CURRENT_SOURCE if template == "current_source" else _VOLTAGE_SOURCE
    fault = set(_FAULT) if template == "short_circuit" else set(_CHANGEOVER) if template == "changeover" else set()
    parts = set(_PARTS) - {"flyback"} if template == "changeover" else set(_PARTS)  # (resistive throws)
    return set(source) | set(_WIRING) | set(_LOADS[template]) | set(_TEMPLATE_CIRCUIT) | parts | fault


CIRCUIT_KEYS = frozenset({"template", "schedule", "probes", *_OPTION_KEYS}.union(*(template_keys(t) for t in TEMPLATES)))


def circuit_key_names(ck) -> dict:
    """'Class.field' of every dataclass behind [circuit] -> the scene key that sets it."""
    names = {}
    for cls, keys in ((ck.DCSource, _VOLTAGE_SOURCE), (ck.CurrentSource, _CURRENT_SOURCE), (ck.Wiring, _WIRING),
                      (ck.ResistiveLoad, _LOADS["resistive"]), (ck.InductiveLoad, _LOADS["inductive"]),
                      (ck.CapacitiveLoad, _LOADS["capacitive"]), (ck.SwitchCircuit, _TEMPLATE_CIRCUIT),
                      (ck.NetlistCircuit, _NETLIST), (ck.McuInput, _MCU_INPUT), (ck.ShortCircuit, _FAULT),
                      (ck.BridgeCircuit, _TEMPLATE_CIRCUIT), (ck.ChangeoverCircuit, _TEMPLATE_CIRCUIT),
                      (ck.ChangeoverCircuit, _CHANGEOVER)):
        names.update({f"{cls.__name__}.{name}": f"circuit.{key}" for key, name in keys.items() if name})
    for part, cls in zip(_PARTS, (ck.Snubber, ck.FlybackDiode, ck.ArcModel)):
        names[f"SwitchCircuit.{part}"] = names[f"NetlistCircuit.{part}"] = f"circuit.{part}"
        names.update({f"{cls.__name__}.{f.name}": f"circuit.{part}.{f.name}" for f in dataclasses.fields(cls)})
    names.update({f"SimulationOptions.{k}": f"circuit.{k}" for k in _OPTION_KEYS})
    names.update({f"ContactSchedule.{name}": f"circuit.schedule.{'make/break' if name == 'intervals' else key}"
                  for key, name in _SCHEDULE.items()})
    names["SwitchCircuit.load"] = "circuit.template"
    for cls in ("ShortCircuit", "BridgeCircuit", "ChangeoverCircuit"):  # each a SwitchCircuit
        names.update({f"{cls}.{k.split('.', 1)[1]}": v for k, v in list(names.items())
                      if k.startswith("SwitchCircuit.")})
    names["CircuitSpec.probes"] = "circuit.probes"  # what to record, beside the circuit itself
    return names


def _in_scene_words(err: Exception, names: dict) -> str:
    """The message of a dataclass's error with every 'Class.field' it names replaced by its scene key."""
    return re.sub(r"\b[A-Z]\w*\.\w+", lambda m: names.get(m.group(0), m.group(0)), str(err))


def _fields(table: dict, keys: dict) -> dict:
    """The dataclass keyword arguments of the scene keys present in ``table`` (scene key -> field)."""
    return {name: table[key] for key, name in keys.items() if key in table and name}


def _part(table: dict, name: str, cls):
    """A sub-table (snubber, flyback, arc): false/absent -> None, true -> defaults, a table -> its fields."""
    value = table.get(name)
    if value is None or value is False:
        return None
    if value is True:
        if name == "snubber":
            raise ValueError("circuit.snubber = true: give its resistance (ohm) and capacitance (F), "
                             "e.g. snubber = {resistance = 100.0, capacitance = 100e-9}")
        return cls()
    if not isinstance(value, dict):
        raise ValueError(f"circuit.{name} = {value!r}: expected true, false or a table of keys")
    allowed = [f.name for f in dataclasses.fields(cls)]
    check_keys(f"circuit.{name}", value, allowed)
    if name == "snubber" and len(value) != 2:
        missing = sorted(set(allowed) - set(value))
        raise ValueError("circuit.snubber needs both resistance (ohm) and capacitance (F); "
                         f"missing: {', '.join(missing)}")
    return cls(**value)


def _bridge_names(mech) -> tuple[str, str]:
    """The bridge template's two contact names: the scene's two electrical [[fixed]] contacts'."""
    from circuit.names import BLOCK_NAME

    fixed = list(getattr(mech, "fixed", ()) or ()) if mech is not None else []
    names = mech.fixed_names() if fixed else ()
    electrical = [(k, names[k]) for k, fx in enumerate(fixed) if fx.electrical]
    if len(electrical) != 2:
        have = f"{len(electrical)} ({', '.join(n for _, n in electrical)})" if fixed else "none ([block] or no bar)"
        raise ValueError(f"circuit.template = \"bridge\" needs two electrical [[fixed]] contacts, the bridge's two "
                         f"(each struck by its own contact point); this scene has {have}")
    for k, name in electrical:
        if not BLOCK_NAME.fullmatch(name):
            raise ValueError(f"fixed[{k}].name = {name!r}: a bridge's contact is named in the circuit by its fixed "
                             "contact's name, a letter then up to 15 letters or digits")
    return tuple(n for _, n in electrical)


def _changeover_names(mech) -> tuple[str, str]:
    """The changeover template's (NO, NC) contact names: the scene's electrical [[fixed]]
    contacts named NO and NC (ignoring case), as written."""
    fixed = list(getattr(mech, "fixed", ()) or ()) if mech is not None else []
    names = mech.fixed_names() if fixed else ()
    electrical = {names[k].lower(): names[k] for k, fx in enumerate(fixed) if fx.electrical}
    if "no" not in electrical or "nc" not in electrical:
        have = ", ".join(electrical.values()) or "none" if fixed else "none ([block] or no bar)"
        raise ValueError("circuit.template = \"changeover\" needs two electrical [[fixed]] contacts named \"NO\" (struck "
                         "when operated) and \"NC\" (the blade's rest); this scene's electrical fixed contacts: " + have)
    return electrical["no"], electrical["nc"]


def _circuit(table: dict, base_dir: Path, current_factor: str | None, device=None, mech=None):
    """[circuit] as its CircuitSpec; with the relay's ``device`` ([coil], [magnet]) the coil
    and its drive join the template's circuit (a netlist places it with an XCOIL line); the
    bridge template takes its contacts' names from the mechanics' (``mech``) [[fixed]]."""
    import circuit as ck

    table = check_keys("[circuit]", _table("[circuit]", table), CIRCUIT_KEYS)
    template = check_choice("circuit.template", table.get("template", "resistive"), TEMPLATES)
    if "voltage" in table and "current" in table:
        raise ValueError("circuit.voltage and circuit.current both name a source: give one, current "
                         "(A) with template = \"current_source\", or voltage (V) with a voltage-source template")
    usable = template_keys(template) | {"template", "schedule", "probes", *_OPTION_KEYS}
    stray = sorted(set(table) - usable)
    if stray:
        hint = {"netlist": " (put it in the netlist)",
                "current_source": " (a current source: current, compliance_voltage, output_capacitance, "
                                  "output_resistance)"}.get(template, "")
        if template not in ("netlist", "current_source") and set(stray) & set(_CURRENT_SOURCE):
            hint = " (a current source needs template = \"current_source\")"
        raise ValueError(f"circuit.{', circuit.'.join(stray)} do(es) not apply to template {template!r}"
                         f"{hint}; its keys: {', '.join(sorted(template_keys(template)))}")
    try:
        options = ck.SimulationOptions(**{k: table[k] for k in _OPTION_KEYS if k in table})
        arc = _part(table, "arc", ck.ArcModel)
        if template == "netlist":
            if "netlist" not in table:
                raise ValueError("template \"netlist\" needs netlist = \"file.cir\" (with one 'XCONTACT a b' line)")
            path = _input_file("circuit.netlist", table["netlist"], base_dir)
            coil = {} if device is None else dict(coil_resistance=device.resistance,
                                                  coil_current=device.current_law())
            circ = ck.NetlistCircuit.from_file(path, arc=arc, contact_current_factor=current_factor,
                                               **_fields(table, _NETLIST), **coil)
        elif template == "mcu_input":
            if device is not None:
                raise ValueError("[coil] with circuit.template = \"mcu_input\": the coil's drive joins a switch "
                                 "template (resistive, inductive, capacitive, current_source) or a netlist")
            circ = ck.McuInput(contact_current_factor=current_factor, **_fields(table, _MCU_INPUT))
        else:
            if template == "current_source":
                source = ck.CurrentSource(**_fields(table, _CURRENT_SOURCE))
                load = ck.ResistiveLoad(**_fields(table, _LOADS[template]))
            else:
                source = ck.DCSource(**_fields(table, _VOLTAGE_SOURCE))
                load = {"resistive": ck.ResistiveLoad, "inductive": ck.InductiveLoad, "capacitive": ck.CapacitiveLoad,
                        "short_circuit": ck.ResistiveLoad, "bridge": ck.ResistiveLoad,
                        "changeover": ck.ResistiveLoad}[template](**_fields(table, _LOADS[template]))
            cls, fault = (ck.ShortCircuit, _fields(table, _FAULT)) if template == "short_circuit" else (
                ck.SwitchCircuit, {})
            if template == "bridge":
                if "schedule" in table:
                    raise ValueError("circuit.schedule with template = \"bridge\": a bridge's two contacts are "
                                     "driven by the mechanics' [[fixed]] contacts, not by a schedule")
                cls, fault = ck.BridgeCircuit, dict(contact_names=_bridge_names(mech))
            if template == "changeover":
                if "schedule" in table:
                    raise ValueError("circuit.schedule with template = \"changeover\": its NO and NC contacts are "
                                     "driven by the mechanics' [[fixed]] contacts, not by a schedule")
                cls, fault = ck.ChangeoverCircuit, dict(contact_names=_changeover_names(mech),
                                                        **_fields(table, _CHANGEOVER))
            circ = cls(source=source, load=load, wiring=ck.Wiring(**_fields(table, _WIRING)),
                       snubber=_part(table, "snubber", ck.Snubber), flyback=_part(table, "flyback", ck.FlybackDiode),
                       arc=arc, contact_current_factor=current_factor, coil=None if device is None else device.drive(),
                       **_fields(table, _TEMPLATE_CIRCUIT), **fault)
        schedule = None
        if "schedule" in table:
            st = check_keys("circuit.schedule", _table("circuit.schedule", table["schedule"]), _SCHEDULE)
            if "make" not in st or "break" not in st:
                raise ValueError("circuit.schedule needs make = [...] and break = [...] (s)")
            schedule = ck.ContactSchedule.from_events(st["make"], st["break"], **_fields(st, {
                k: k for k in ("closed_resistance", "edge_time", "opening_speed")}))
    except (TypeError, ValueError) as err:  # TypeError: a value of a type no check foresaw
        raise ValueError(_in_scene_words(err, circuit_key_names(ck))) from None
    probes = ()
    if "probes" in table:  # validated against the deck's nodes and elements
        from circuit.deck import build_deck
        from circuit.probes import check_probes

        probes = check_probes(table["probes"], build_deck(circ, 1.0, options)[0], "[circuit] probes")
    return CircuitSpec(circ, options, schedule, template, probes)


def scene_from_dict(doc: dict, *, base_dir: Path | str = ".", name: str = "scene") -> Scene:
    """Validate a parsed scene document completely and build the Scene. Every error names
    the scene (``name``, its file) first."""
    try:
        return _build(doc, Path(base_dir), name)
    except (ValueError, FileNotFoundError) as err:
        message = str(err)
        if message.startswith(f"{name}:"):
            raise
        raise type(err)(f"{name}: {message}") from None


def _build(doc: dict, base_dir: Path, name: str) -> Scene:
    doc = _table(name, doc)
    check_keys(name, doc, set(MECH_SECTIONS) | set(COUPLING_SECTIONS), kind="section")
    circuit_table = doc.get("circuit")
    schedule_given = isinstance(circuit_table, dict) and "schedule" in circuit_table
    mech_given = [s for s in MECH_SECTIONS if s != "solver" and s in doc]
    solver_table = _table("[solver]", doc.get("solver", {}))

    if schedule_given and (mech_given or set(solver_table) - {"t_end"}):
        raise ValueError("[circuit.schedule] prescribes the contact, so the scene runs no mechanics; "
                         f"remove [{'], ['.join(mech_given or ['solver'])}] (only [solver] t_end may stay) "
                         "or remove [circuit.schedule]")
    if "coupling" in doc and ((circuit_table is None and "coil" not in doc) or schedule_given):
        raise ValueError("[coupling] settings need mechanics and a [circuit] (or a [coil]) to couple")
    from coupling.core.device import device as relay_device

    device = relay_device(doc)
    if device is not None and ("armature" not in doc or schedule_given):
        raise ValueError("[coil] and [magnet] drive an armature: add [armature] (its kind, mass or inertia and "
                         "travel; docs/mechanics.md section 10)")
    contact_spring = "bar" in doc or "block" in doc or "rivet" in doc
    if circuit_table is not None and not schedule_given and "tribology" not in doc and contact_spring:
        raise ValueError("a coupled scene needs [tribology] for R_c(F_n, I) and mu(I): "
                         "source = \"illustrative\" (the shipped, not measured, fit), fit = \"fit.json\" "
                         "or data = \"data.csv\"")
    if schedule_given and "tribology" in doc:
        raise ValueError("[tribology] is unused with [circuit.schedule] (the schedule gives the "
                         "closed resistance); remove one of them")

    tribology = _tribology(doc["tribology"], base_dir) if "tribology" in doc else None

    mech = None
    if schedule_given:
        SolverOptions(**solver_table)  # [solver] t_end alone: the run's length
    else:
        mech_doc = {k: v for k, v in doc.items() if k in MECH_SECTIONS}
        if tribology is not None:
            fr = _table("[friction]", mech_doc.get("friction", {}))
            for key in ("mu", "gamma"):
                if key in fr:
                    raise ValueError(f"friction.{key} and [tribology] both set the friction law; "
                                     f"remove friction.{key} (the laws give gamma and mu(I))")
        mech = mech_scene_from_dict(mech_doc, where=name, extra_sections=COUPLING_SECTIONS)
        if tribology is not None:
            laws = tribology.laws
            fr = mech.friction
            mu_fn = laws.mu if tribology.feedback else (lambda _i, _mu0=float(laws.mu(0.0)): _mu0)
            friction = Friction(mu=lambda current, f=mu_fn: float(f(current)), gamma=float(laws.gamma),
                                model=fr.model, max_ratio=fr.max_ratio,
                                regularization_speed=fr.regularization_speed)
            mech = dataclasses.replace(mech, friction=friction)  # every other section as the scene says
        if device is not None:
            mech = _armature_of(mech, device)

    circuit = None
    if circuit_table is not None:
        # R_c(F, I) = g(|I|)/G_F(F): the current factor goes into ngspice (solved without lag)
        factor = tribology.laws.resistance_law.current_factor_expression("I") if tribology is not None else None
        circuit = _circuit(circuit_table, base_dir, factor, device, mech)
        if mech is not None and mech.bar is not None:  # each circuit contact has its contact pairs
            from coupling.core.arrangement import check_arrangement

            check_arrangement(mech, circuit.circuit)
    elif device is not None:  # an actuator: the coil's drive is the whole circuit
        import circuit as ck

        circuit = CircuitSpec(device.drive(), ck.SimulationOptions(), template="coil")

    coupling, output = (_section(doc, section, cls) for section, cls in (
        ("coupling", CouplingOptions), ("output", OutputOptions)))
    metrics, circuit = _metrics(doc, circuit)
    duty = _duty(doc, mech, tribology, circuit)
    scene = Scene(raw=copy.deepcopy(doc), base_dir=base_dir, mech=mech, tribology=tribology, circuit=circuit,
                  coupling=coupling, output=output, name=name, metrics=metrics, duty=duty)
    check_work(scene)
    return scene


def macro_steps(scene: Scene) -> float:
    """The most macro steps a coupled run takes: t_end / macro_step (every step in contact)."""
    return scene.t_end / scene.coupling.macro_step if scene.kind == "coupled" else 0.0


def memory_estimate(scene: Scene) -> dict:
    """Bytes a run of ``scene`` may take at most, by part, before it starts:

    - history: the mechanics' rows (mech.recorder.history_memory of [solver] history_rows
      rows of the largest state the scene can have: "auto" modes at their cap), and in a
      coupled run the dense output of the current macro step (mech.recorder.DENSE_BYTES);
    - waveforms: the circuit's points, t_end / TMAX plus POINTS_PER_MACRO_STEP per macro
      step (a schedule: per make and break), each column held WAVE_COPIES times, and the
      macro steps' log;
    - total. Events (each a row of events.csv) come on top: they are what a run keeps.
    """
    out = {"history": 0, "waveforms": 0}
    if scene.mech is not None:
        states = _largest_state(scene.mech)
        out["history"] = history_memory(states, scene.mech.solver.history_rows)
        if scene.kind == "coupled":
            out["history"] += DENSE_BYTES
    if scene.circuit is not None:
        t_end = scene.t_end
        points = t_end / scene.circuit.options.tmax(t_end)
        steps = macro_steps(scene)
        if scene.circuit.schedule is not None:
            steps = 2 * len(scene.circuit.schedule.intervals)
        points += POINTS_PER_MACRO_STEP * steps + 2
        from circuit.probes import COLUMNS

        columns = len(COLUMNS) + len(scene.circuit.probes) + (MECH_WAVE_COLUMNS if scene.mech is not None else 0)
        out["waveforms"] = int(points * columns * 8 * WAVE_COPIES + MACRO_STEP_LOG_BYTES * macro_steps(scene))
    out["total"] = out["history"] + out["waveforms"]
    return out


def _largest_state(mech: MechScene) -> int:
    """The longest state vector the scene's model can have: its mode counts ("auto": at the
    cap of mech.mode_count), planar or 3D as mech.model.is_planar decides, with the input-work
    quadratures of a held or loaded bar and a hysteretic spring's state."""
    from mech.kernel_layout import NQ, NQ_FREE, state_sizes
    from mech.mode_count import CAP
    from mech.model import is_planar

    bar = mech.bar
    extra = 8 if mech.armature.present else 0  # the armature's coordinate, speed and quadratures (bounded)
    if bar is None:  # an armature alone
        return extra + NQ
    planar = mech.mount.held or (mech.solver.model != "3d" and is_planar(mech))
    axial = CAP if bar.axial_modes == "auto" else bar.axial_modes
    bending = CAP if bar.bending_modes == "auto" else bar.bending_modes
    n = axial + bending * (1 if planar else 2)
    npos, nvel = state_sizes(n, planar)
    # a force-travel spring with hysteresis carries one state (its stick force)
    hysteresis = sum(1 for s in mech.springs if getattr(s, "release_force", None) is not None)
    return npos + nvel + extra + hysteresis + (NQ if (mech.mount.held or mech.forces or mech.springs) else NQ_FREE)


def check_work(scene: Scene) -> None:
    """Refuse, before anything runs, a scene whose macro steps or memory exceed what a run
    may take (MACRO_STEPS_MAX, mech.recorder.MEMORY_LIMIT; docs/scene_keys.md, "Bounds"),
    naming the key that sets the largest part."""
    count = macro_steps(scene)
    if count > MACRO_STEPS_MAX:
        raise ValueError(
            f"coupling.macro_step = {scene.coupling.macro_step!r} s: t_end / macro_step = {count:.3g} macro steps "
            f"(solver.t_end = {scene.t_end!r} s), more than the {MACRO_STEPS_MAX:.0e} a run may take; "
            "use a longer macro step or a shorter t_end")
    est = memory_estimate(scene)
    if est["total"] <= MEMORY_LIMIT:
        return
    if est["history"] >= est["waveforms"]:
        key = f"solver.history_rows = {scene.mech.solver.history_rows}"
        fix = "keep fewer rows (or set the mode counts lower than their cap)"
    else:
        opts = scene.circuit.options
        key = (f"circuit.max_step = {opts.max_step!r} s" if opts.max_step is not None
               and scene.t_end / opts.max_step > POINTS_PER_MACRO_STEP * macro_steps(scene)
               else f"coupling.macro_step = {scene.coupling.macro_step!r} s")
        fix = "use a longer step or a shorter t_end"
    raise ValueError(f"{key}: the run could take {est['total'] / 2**30:.3g} GiB (history "
                     f"{est['history'] / 2**30:.3g}, waveforms {est['waveforms'] / 2**30:.3g}), more than the "
                     f"{MEMORY_LIMIT / 2**30:g} GiB a run may take; {fix}")


def _armature_of(mech: MechScene, device) -> MechScene:
    """The mechanics' armature driven by the magnet: a magnet whose force separates as
    psi^2 h(g) gives the armature its gain table lever h(g(q)) over the travel (the
    coupling then drives it with psi^2, coupling.core.exchange.CoilLink); its gap must stay
    open over the whole travel."""
    from coupling.core.exchange import CoilLink

    arm = mech.armature
    if not arm.present:
        raise ValueError("[coil] and [magnet] drive an armature: give [armature] kind = \"plunger\" or \"clapper\"")
    link = CoilLink("coil", device.magnet, device.rest_gap, device.lever)
    closed = link.gap(arm.travel)
    if not closed > 0.0:
        raise ValueError(f"magnet.rest_gap = {device.rest_gap!r} m with magnet.lever = {device.lever!r} and "
                         f"armature.travel = {arm.travel!r}: the working gap would close to {closed:.3g} m at the pole "
                         "stop; the gap must stay > 0 over the travel (a residual gap: the pole stop before the pole)")
    if not link.separable:
        return mech
    if arm.force_gain is not None:
        raise ValueError("armature.force_gain: the magnet gives the armature its gain (h(g) of its flux-tube "
                         "model); remove armature.force_gain")
    q, gain = link.gain_table(arm.travel)
    return dataclasses.replace(mech, armature=dataclasses.replace(
        arm, force_gain={"position": [float(x) for x in q], "gain": [float(g) for g in gain]}))


def _metrics(doc: dict, circuit: CircuitSpec | None):
    """([metrics] as MetricSettings, the circuit) with its ``logic`` input resolved: an
    mcu_input template gives its pin and thresholds by default, and the node read is added
    to the circuit's probes when they do not record it already."""
    from coupling.core.logic import LogicInput
    from coupling.core.metrics import MetricSettings

    table = dict(check_keys("[metrics]", _table("[metrics]", doc.get("metrics", {})),
                            [f.name for f in dataclasses.fields(MetricSettings)]))
    defaults = None
    if circuit is not None and circuit.template == "mcu_input":
        from circuit.templates import MCU_PIN

        pin = circuit.circuit
        defaults = {"node": f"v({MCU_PIN})", "low": pin.logic_low, "high": pin.logic_high}
    if "logic" not in table and defaults is None:
        return MetricSettings(**table), circuit
    if circuit is None:
        raise ValueError("metrics.logic reads a node voltage of the circuit: it needs a [circuit]")
    logic = LogicInput.from_table(table.get("logic", {}), defaults)
    probe, circuit = _recorded(logic.node, circuit, "metrics.logic.node")
    table["logic"] = dataclasses.replace(logic, node=probe.text)
    return MetricSettings(**table), circuit


def _duty(doc: dict, mech: MechScene | None, tribology: TribologySpec | None, circuit: CircuitSpec | None):
    """[duty] as coupling.core.duty.DutySettings (its defaults from the other sections), or None."""
    if "duty" not in doc:
        return None
    from coupling.core.duty import duty_from_table

    return duty_from_table(_table("[duty]", doc["duty"]), mech, tribology, circuit)


def _recorded(text: str, spec: CircuitSpec, where: str):
    """(the probe recording node voltage ``text``, the circuit spec recording it): an equal
    probe of [circuit] probes, else a new one checked against the circuit's deck."""
    from circuit.deck import build_deck
    from circuit.probes import check_probes, parse_probe

    wanted = parse_probe(text, where)
    if wanted.kind != "v":
        raise ValueError(f"{where} = {text!r}: a logic input reads a node voltage, v(node) or v(node1,node2)")
    for probe in spec.probes:
        if (probe.kind, probe.names) == (wanted.kind, wanted.names):
            return probe, spec
    (probe,) = check_probes([wanted.text], build_deck(spec.circuit, 1.0, spec.options)[0], where)
    return probe, dataclasses.replace(spec, probes=spec.probes + (probe,))


def _section(doc: dict, section: str, cls):
    """A section that is one dataclass, each key one field (an omitted key: the field's default)."""
    table = _table(f"[{section}]", doc.get(section, {}))
    return cls(**check_keys(f"[{section}]", table, [f.name for f in dataclasses.fields(cls)]))


#: Exclusive key groups: (section, alternatives); setting keys of one drops the others.
ALTERNATIVES = (
    ("bar", (("diameter",), ("width", "thickness"))),
    ("tribology", (("source",), ("fit",), ("data",))),
)


def _drop_replaced_alternatives(raw: dict, changes: dict) -> None:
    """Remove the alternatives replaced by ``changes`` ("section.key" -> value) from raw."""
    for section, groups in ALTERNATIVES:
        set_now = {k.split(".", 1)[1] for k in changes if k.startswith(section + ".") and k.count(".") == 1}
        table = raw.get(section)
        if not set_now or not isinstance(table, dict):
            continue
        chosen = [g for g in groups if set_now & set(g)]
        if len(chosen) != 1:
            continue  # none touched, or several at once: validation says what is wrong
        for group in groups:
            if group is not chosen[0]:
                for key in group:
                    if key not in set_now:
                        table.pop(key, None)


_KEY_STEP = re.compile(r"([^.\[\]]+)((?:\[[^\[\]]*\])*)")
_INDEX = re.compile(r"\[([^\[\]]*)\]")


def key_steps(key) -> list:
    """The steps of a scene key: names (str) and list indices (int), e.g. "rivet[0].mass" ->
    ["rivet", 0, "mass"], "magnet.fixed_gap[1].tube[0].length" -> ["magnet", "fixed_gap", 1,
    "tube", 0, "length"]. A key has at least two steps ("section.key" or "section[i]");
    ValueError (without a prefix) otherwise."""
    if not isinstance(key, str):
        raise ValueError(f"key {key!r}: expected 'section.key', e.g. 'initial.angle_deg' or 'rivet[0].mass'")
    steps: list = []
    for part in key.split("."):
        match = _KEY_STEP.fullmatch(part)
        if match is None:
            raise ValueError(f"key {key!r}: expected 'section.key', e.g. 'initial.angle_deg' or 'rivet[0].mass' "
                             "(names joined by '.', list entries as name[index])")
        steps.append(match.group(1))
        for index in _INDEX.findall(match.group(2)):
            if not index.isdigit():
                raise ValueError(f"key {key!r}: index [{index}]: expected a whole number >= 0 (the first entry "
                                 "is [0])")
            steps.append(int(index))
    if len(steps) < 2:
        raise ValueError(f"key {key!r}: expected 'section.key', e.g. 'initial.angle_deg' or 'rivet[0].mass'")
    return steps


def _shown(steps: list) -> str:
    """The key of ``steps`` as written: names joined by '.', indices in brackets."""
    text = ""
    for step in steps:
        text += f"[{step}]" if isinstance(step, int) else (f".{step}" if text else step)
    return text


def _walk(raw: dict, key: str, where: str, *, create: bool = True) -> tuple:
    """(the table or list holding the key's last step, that step: a name or an index). Tables
    on the way are created when missing (``create``); lists never are, nor their entries:
    an index must name an entry the scene has. Errors say ``where`` first and name the key
    as written."""
    try:
        steps = key_steps(key)
    except ValueError as err:
        raise ValueError(f"{where}: {err}") from None
    node = raw
    for k, step in enumerate(steps):
        here = _shown(steps[:k + 1])
        if isinstance(step, int):
            if not isinstance(node, list):  # checked on the way down; the root is a table
                raise ValueError(f"{where}: key {key!r}: {_shown(steps[:k])} is not a list")
            if step >= len(node):
                entries = f"{len(node)} entr{'y' if len(node) == 1 else 'ies'}"
                at = _shown(steps[:k])
                span = f" (only {at}[0])" if len(node) == 1 else f" ({at}[0] to {at}[{len(node) - 1}])" if node else ""
                raise ValueError(f"{where}: key {key!r}: index [{step}] is beyond {_shown(steps[:k])}, which has "
                                 f"{entries}{span}")
        if k == len(steps) - 1:
            return node, step
        nxt = steps[k + 1]
        if isinstance(step, int):
            child = node[step]
        else:
            child = node.get(step)
            if child is None:
                if isinstance(nxt, int):
                    raise ValueError(f"{where}: key {key!r}: index [{nxt}] is beyond {here}, which has 0 entries "
                                     f"(the scene has no {here})")
                if not create:
                    return None, None
                child = node[step] = {}
        if isinstance(nxt, int):
            if not isinstance(child, list):
                kind = "a table" if isinstance(child, dict) else f"{child!r}"
                raise ValueError(f"{where}: key {key!r}: {here} is {kind}, not a list: an index [{nxt}] "
                                 f"reaches into lists only" + (f"; write {here}.{steps[k + 2]}" if isinstance(
                                     child, dict) and k + 2 < len(steps) else ""))
        elif isinstance(child, list):
            n = len(child)
            raise ValueError(f"{where}: key {key!r}: {here} is a list of {n} entr{'y' if n == 1 else 'ies'} "
                             f"([[{here}]]): name one by its index, {here}[0].{nxt}")
        elif not isinstance(child, dict):
            raise ValueError(f"{where}: key {key!r}: {here} = {child!r} is not a table")
        node = child
    raise AssertionError("unreachable")


def key_value(raw: dict, key: str, where: str):
    """The value a scene document gives ``key`` (any key Scene.set takes), None when it gives
    none; a key that cannot be in a scene is an error as for Scene.set."""
    node, last = _walk(raw, key, where, create=False)
    if node is None:
        return None
    return node[last] if isinstance(node, list) else node.get(last)


def set_keys(raw: dict, changes: dict, where: str) -> dict:
    """A copy of a scene document with each key of ``changes`` ("section.key",
    "rivet[0].mass", "circuit.params.RF", ...) set to its value (tuples as lists)."""
    doc = copy.deepcopy(raw)
    for key, value in changes.items():
        node, last = _walk(doc, key, where)
        node[last] = list(value) if isinstance(value, tuple) else copy.deepcopy(value)
    return doc


def _rebuild_scene(raw: dict, base_dir: str, name: str) -> Scene:
    return scene_from_dict(raw, base_dir=Path(base_dir), name=name)


def load_scene(path) -> Scene:
    """Read and validate a scene TOML file (SI units; paths inside are relative to it)."""
    if isinstance(path, Scene):
        raise TypeError("load_scene() takes the path of a scene TOML file; this is already a Scene: pass it to run()")
    if not (isinstance(path, str) or hasattr(path, "__fspath__")):
        raise TypeError(f"load_scene() takes the path of a scene TOML file (str or pathlib.Path), got "
                        f"{type(path).__name__} {path!r:.60}; the built-in scene is default_scene()")
    path = Path(path)
    return scene_from_dict(read_toml(path), base_dir=path.parent, name=str(path))


BUILTIN_SCENES = ("default", "relay_force", "relay_cycle", "free_drop")


def builtin_scene_text(name: str = "default") -> str:
    """A built-in scene as TOML text: "default" (a relay operated by its coil: make, bounce,
    hold, break), "relay_force" (its contact closed by a given force), "relay_cycle"
    (closed, held and opened by given forces) or "free_drop" (the source paper's bar
    dropped on a block)."""
    if name not in BUILTIN_SCENES:
        raise ValueError(f"built-in scene {name!r}: allowed: {', '.join(BUILTIN_SCENES)}")
    return resources.files("coupling").joinpath(f"scenes/{name}.toml").read_text()


def builtin_scene(name: str = "default") -> Scene:
    """A built-in coupled scene (coupling/scenes/<name>.toml), see builtin_scene_text."""
    doc = tomllib.loads(builtin_scene_text(name))
    return scene_from_dict(doc, base_dir=Path("."), name="default scene" if name == "default" else f"{name} scene")


def default_scene_text() -> str:
    """The built-in default coupled scene (a relay operated by its coil), as TOML text."""
    return builtin_scene_text("default")


def default_scene() -> Scene:
    """The built-in default coupled scene (coupling/scenes/default.toml)."""
    return builtin_scene("default")

