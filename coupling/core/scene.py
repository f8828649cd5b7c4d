"""Coupled scenes: the mechanics sections plus [tribology], [circuit], [coupling], [output].

A scene names only what it needs, and only that is built:
- mechanics sections only: the impact solver alone (no ngspice);
- [circuit] with [circuit.schedule]: a prescribed make/break schedule, no mechanics;
- mechanics + [tribology] + [circuit]: the co-simulation.

Each key is a field of the dataclass its section maps onto, declared there with its
default, unit and meaning (``scene_key``: mech's, circuit's and the coupling sections'
below), and listed in docs/scene_keys.md, which ``python -m coupling.app.keys_doc`` writes
from those fields. [circuit]'s keys are the fields of the dataclasses its template builds
(template_classes), named as the keys; [tribology] chooses the contact laws
(docs/tribology.md).

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
from dataclasses import field
from pathlib import Path
from typing import Any

from mech.parameters import HISTORY_ROWS_MAX, LENGTH_MAX, T_END_MAX, Friction, MechScene, SolverOptions
from mech.recorder import DENSE_BYTES, MEMORY_LIMIT, history_memory
from mech.scene import SCENE_SECTIONS as MECH_SECTIONS
from mech.scene import read_toml
from mech.scene import scene_from_dict as mech_scene_from_dict
from mech.validation import (
    check_bool, check_choice, check_file, check_keys, check_nonnegative, check_positive, check_range, check_whole,
    internal,
    scene_key,
)
from mech.frozen import frozen
from coupling.core.policy import (
    COIL_POINT_FRACTION, COIL_STEP_POINTS, COIL_TIME_SCALE_FRACTION, GAP_CHANGE_FRACTION, TIME_SCALE_FRACTION,
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
# coupling.gap_change_fraction at most: a step may carry the armature past its landing (the
# mechanics find the stop exactly), not over many times the gap
GAP_CHANGE_MAX = 10.0
COIL_STEP_POINTS_MAX = 64  # (ngspice's points cost ~10-30 us each; more buys nothing the audit can see)


def _table(where: str, value) -> dict:
    if not isinstance(value, dict):
        raise ValueError(f"{where}: expected a table of keys, got {value!r}")
    return value


@frozen
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
    time_scale_fraction, coil_time_scale_fraction, gap_change_fraction: the step rules
    (coupling.core.policy, docs/coupling.md "Step lengths" and "The coil's steps"): a macro
    step extrapolates the loop current, the coil's flux, over at most that fraction of its
    time scale, and lets the working gap change by at most that fraction of itself.
    coil_step_points, coil_point_fraction: in a coil-driven run ngspice takes at least that
    many points per macro step, and while the coil's flux changes its steps are at most that
    fraction of the coil's time constant L/R (at the rest gap): the coil flux's integration
    error, second order in ngspice's step, is what the coil's energy audit measures.
    """

    scheme: str = scene_key("mechanics_first", unit="-", doc='or "jacobi"')
    macro_step: float = scene_key(2e-6, unit="s", doc="exchange interval while a tip touches")
    max_macro_step: float | None = scene_key(1e-4, unit="s", doc="while both tips are free")
    align_events: bool = scene_key(True, unit="-", doc="end a macro step at each make/break")
    onset_penetration: float = scene_key(10e-9, unit="m", doc="conduction ramps in over this penetration")
    time_scale_fraction: float = scene_key(
        TIME_SCALE_FRACTION, unit="-",
        doc="a macro step extrapolates the loop current over at most this fraction of its time scale; (0, 1]")
    coil_time_scale_fraction: float = scene_key(
        COIL_TIME_SCALE_FRACTION, unit="-",
        doc="the same for the coil's flux (psi^2 for a flux-tube magnet); (0, 1]")
    gap_change_fraction: float = scene_key(
        GAP_CHANGE_FRACTION, unit="-",
        doc="while the armature moves, a macro step lets the working gap change by at most this fraction of itself; "
            "(0, 10]")
    coil_step_points: int = scene_key(
        COIL_STEP_POINTS, unit="-",
        doc="in a coil-driven run ngspice takes at least this many points per macro step; 1 .. 64")
    coil_point_fraction: float = scene_key(
        COIL_POINT_FRACTION, unit="-",
        doc="while the coil's flux changes, ngspice's steps are at most this fraction of the coil's time constant "
            "L/R; (0, 1]")

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
        for name in ("time_scale_fraction", "coil_time_scale_fraction", "coil_point_fraction"):
            check_range(f"coupling.{name}", getattr(self, name), 0.0, 1.0, closed_high=True)
        check_range("coupling.gap_change_fraction", self.gap_change_fraction, 0.0, GAP_CHANGE_MAX, closed_high=True)
        check_whole("coupling.coil_step_points", self.coil_step_points, 1, COIL_STEP_POINTS_MAX)

    @property
    def free_step(self) -> float:
        return self.macro_step if self.max_macro_step is None or self.scheme == "jacobi" else self.max_macro_step


@frozen
class OutputOptions:
    """What a run writes besides summary.json: csv, parquet, plots (PNG), history (mechanics CSV),
    html (waveforms.html, the interactive waveform page).

    history_resolution, history_max_rows: history.csv keeps the records on either side of
    every event and regime change and, of the rest, one per interval of
    max(history_resolution, run length / history_max_rows) (s; both 0: every record the run
    kept, at most [solver] history_rows besides those); docs/coupling.md, "Outputs".
    """

    csv: bool = scene_key(True, unit="-", doc="waveforms.csv")
    parquet: bool = scene_key(True, unit="-", doc="waveforms.parquet")
    # PNGs on request only: drawing them costs more than a run
    plots: bool = scene_key(
        False, unit="-", doc="PNG plots (`switchsim run --plots`, or `switchsim plot DIR` afterwards)")
    history: bool = scene_key(True, unit="-", doc="mechanics history.csv")
    html: bool = scene_key(True, unit="-", doc="waveforms.html (interactive)")
    history_resolution: float = scene_key(
        1e-6, unit="s", doc="history.csv rows at most this close, besides event rows")
    history_max_rows: int = scene_key(
        50_000, unit="-",
        doc="and at most this many of them (0: every row the run kept, see `[solver] history_rows`); at most 1e7")

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


@frozen
class TribologySpec:
    """The contact laws (mu(I), gamma, R_c(F_n, I)), where they came from, and the fit if any;
    its fields declare [tribology]'s keys (TRIBOLOGY_KEYS)."""

    # coupling.laws.tribology.ContactLaws: the keys but feedback choose them together (one of
    # source / fit / data, or mu and resistance), so they are rows of this one field, declared
    # as circuit.validation.scene_key(keys=...) declares a field several keys set
    laws: Any = field(metadata={"unit": "-", "doc": "", "keys": (
        ("source", "-", '"illustrative": the shipped, not measured, fit'),
        ("fit", "path", "a fit.json from `switchsim fit`"),
        ("data", "path", "a tribometer CSV, fitted on the fly"),
        ("mu", "N^gamma", "a number (Coulomb, with a material `resistance`) or an inline mu-law table"),
        ("resistance", "-", '`{law = "holm" | "constant", ...}` (docs/contact_materials.md) or an inline '
                            "fitted-law table (docs/tribology.md)"))})
    source: str = internal()  # where the laws came from, in words (not the key source)
    feedback: bool = scene_key(True, unit="-", doc="mu follows the contact current")
    fit: Any = internal(None)  # coupling.laws.tribology.TribometerFit, when the laws come from a fit


@frozen
class CircuitSpec:
    """The circuit, its ngspice options, and an optional prescribed contact schedule."""

    circuit: Any = internal()  # circuit.SwitchCircuit | circuit.NetlistCircuit, ...: its fields are [circuit] keys
    options: Any = internal()  # circuit.SimulationOptions: likewise
    schedule: Any = scene_key(  # circuit.ContactSchedule | None
        None, unit="-", doc="`[circuit.schedule]`: a prescribed contact, no mechanics")
    template: str = scene_key(
        "resistive", unit="-",
        doc='"inductive", "capacitive", "current_source", "netlist", "mcu_input" (a switch read by a '
            'microcontroller pin: docs/circuit.md section 6), "short_circuit" (resistive, the load shorted at '
            '`fault_time`: a fault current through the closed contact), "bridge" (resistive or R-L with '
            "`load_inductance`, a contactor's motor or coil, its switch a double-break bridge: two contacts in series, each its own circuit contact named as the scene's two "
            "electrical `[[fixed]]` contacts, which it needs; docs/circuit.md section 6), \"changeover\" (form C: "
            "the supply on the moving contact, its NO and NC throws each with its own load, resistive or R-L "
            "(`load_inductance`, `nc_load_inductance`); each its own "
            "circuit contact fed by the electrical `[[fixed]]` contact named \"NO\" or \"NC\", which it needs; "
            'docs/coupling.md, "A changeover")')
    probes: tuple = scene_key(  # circuit.probes.UserProbe
        (), unit="-", doc='`["v(node)", "v(n1,n2)", "i(element)"]`: extra waveform columns')
    netlist: str | None = scene_key(
        None, unit="path", doc='template "netlist": your netlist with one `XCONTACT a b` line, or one '
        "`XCONTACT_<name> a b` line per electrical `[[fixed]]` contact of that name (in series, one chain: a bridge, "
        "closed while all touch; otherwise independent contacts, each closed while it touches: named NO and NC, a "
        "changeover)")


@frozen
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
    schedule_t_end: float | None = None  # s: a schedule scene's run length ([solver] t_end, its one key there)

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
        return self.mech.solver.t_end if self.mech is not None else self.schedule_t_end

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
    feedback = check_bool("tribology.feedback", table.get("feedback", _field_default(TribologySpec, "feedback")))
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


# --- [circuit]: each key one field of a circuit dataclass, named as the key ----------------
# A template builds the dataclasses of template_classes; each flat [circuit] key is the field
# of that name (declared with circuit.validation.scene_key), the sub-tables snubber, flyback,
# arc and schedule the fields of theirs, and an omitted key takes its field's default. The
# dataclasses name the keys in their errors themselves ("circuit.voltage = ...").

# [circuit] keys that are sub-tables, each its own dataclass (named: asked for only when given)
_PARTS = {"snubber": "Snubber", "flyback": "FlybackDiode", "arc": "ArcModel"}


def template_classes(template: str) -> tuple:
    """The circuit dataclasses a template builds, whose fields are its [circuit] keys (besides
    the CircuitSpec's and the ngspice options' keys): (source, wiring, load, switch) or one."""
    import circuit as ck

    if template == "netlist":
        return (ck.NetlistCircuit,)
    if template == "mcu_input":
        return (ck.McuInput,)
    # (by name: only the chosen classes are asked for, so a run imports only their families,
    # circuit/templates/__init__.py)
    source = "CurrentSource" if template == "current_source" else "DCSource"
    load = {"inductive": "InductiveLoad", "capacitive": "CapacitiveLoad"}.get(template, "ResistiveLoad")
    switch = {"short_circuit": "ShortCircuit", "bridge": "BridgeCircuit",
              "changeover": "ChangeoverCircuit"}.get(template, "SwitchCircuit")
    return tuple(getattr(ck, name) for name in (source, "Wiring", load, switch))


def key_fields(cls) -> list[str]:
    """The fields of ``cls`` that scene keys of the same name set (declared scene_key)."""
    return [f.name for f in dataclasses.fields(cls) if "unit" in f.metadata and "keys" not in f.metadata]


def section_keys(cls) -> list[str]:
    """Every scene key of ``cls``'s section it takes: its key fields and the keys a field of
    several stands for (ContactSchedule's make and break)."""
    return key_fields(cls) + [row[0] for f in dataclasses.fields(cls) for row in f.metadata.get("keys", ())]


TRIBOLOGY_KEYS = tuple(section_keys(TribologySpec))


def template_keys(template: str) -> set:
    """The [circuit] keys a template uses (besides template, schedule, probes and the ngspice options)."""
    keys = set().union(*(key_fields(cls) for cls in template_classes(template)))
    return keys | {"netlist"} if template == "netlist" else keys


def common_keys() -> set:
    """The [circuit] keys of every template: the CircuitSpec's and the ngspice options'."""
    import circuit as ck

    return (set(key_fields(CircuitSpec)) - {"netlist"}) | set(key_fields(ck.SimulationOptions))


def circuit_keys() -> frozenset:
    """Every key [circuit] may hold."""
    return frozenset(common_keys().union(*(template_keys(t) for t in TEMPLATES)))


def __getattr__(name: str):
    if name == "CIRCUIT_KEYS":  # (built on first use: reading them imports circuit)
        return circuit_keys()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _kwargs(table: dict, cls, skip=_PARTS) -> dict:
    """The keyword arguments of ``cls`` that ``table`` gives: its key fields present (``skip``:
    the sub-tables, built on their own)."""
    return {k: table[k] for k in key_fields(cls) if k in table and k not in skip}


def _part(table: dict, name: str):
    """A sub-table (snubber, flyback, arc): false/absent -> None, true -> defaults, a table -> its fields."""
    value = table.get(name)
    if value is None or value is False:
        return None
    import circuit

    cls = getattr(circuit, _PARTS[name])
    if value is True:
        if name == "snubber":
            raise ValueError("circuit.snubber = true: give its resistance (ohm) and capacitance (F), "
                             "e.g. snubber = {resistance = 100.0, capacitance = 100e-9}")
        return cls()
    if not isinstance(value, dict):
        raise ValueError(f"circuit.{name} = {value!r}: expected true, false or a table of keys")
    allowed = key_fields(cls)
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

    table = _table("[circuit]", table)
    named = table.get("template", "resistive")
    usable = template_keys(named) | common_keys() if named in TEMPLATES else set()  # (else refused below)
    # (a table whose keys all belong to its own template passes the check against every
    # template's keys: those, which import the netlist reader, ~3 ms, are looked at only
    # when a key is not its template's, for the same error as before)
    if not set(table) <= usable:
        table = check_keys("[circuit]", table, circuit_keys())
    template = check_choice("circuit.template", named, TEMPLATES)
    if "voltage" in table and "current" in table:
        raise ValueError("circuit.voltage and circuit.current both name a source: give one, current "
                         "(A) with template = \"current_source\", or voltage (V) with a voltage-source template")
    stray = sorted(set(table) - usable)
    if stray:
        hint = {"netlist": " (put it in the netlist)",
                "current_source": " (a current source: current, compliance_voltage, output_capacitance, "
                                  "output_resistance)"}.get(template, "")
        if template not in ("netlist", "current_source") and set(stray) & set(key_fields(ck.CurrentSource)):
            hint = " (a current source needs template = \"current_source\")"
        raise ValueError(f"circuit.{', circuit.'.join(stray)} do(es) not apply to template {template!r}"
                         f"{hint}; its keys: {', '.join(sorted(template_keys(template)))}")
    try:
        options = ck.SimulationOptions(**_kwargs(table, ck.SimulationOptions))
        arc = _part(table, "arc")
        if template == "netlist":
            if "netlist" not in table:
                raise ValueError("template \"netlist\" needs netlist = \"file.cir\" (with one 'XCONTACT a b' line)")
            if device is not None:
                from coupling.core.device import drive_keys

                ignored = [k for k in drive_keys() if k in device.coil]
                if ignored:
                    raise ValueError(f"coil.{', coil.'.join(ignored)} do(es) not apply with circuit.template = "
                                     "\"netlist\": the netlist drives its XCOIL line (put the supply, the driver and "
                                     "the suppression in the netlist); [coil] takes resistance and turns")
            path = _input_file("circuit.netlist", table["netlist"], base_dir)
            coil = {} if device is None else dict(coil_resistance=device.resistance,
                                                  coil_current=device.current_law())
            circ = ck.NetlistCircuit.from_file(path, arc=arc, contact_current_factor=current_factor,
                                               **_kwargs(table, ck.NetlistCircuit), **coil)
        elif template == "mcu_input":
            if device is not None:
                raise ValueError("[coil] with circuit.template = \"mcu_input\": the coil's drive joins a switch "
                                 "template (resistive, inductive, capacitive, current_source) or a netlist")
            circ = ck.McuInput(contact_current_factor=current_factor, **_kwargs(table, ck.McuInput))
        else:
            source, wiring, load, switch = template_classes(template)
            names = {}
            if template == "bridge":
                if "schedule" in table:
                    raise ValueError("circuit.schedule with template = \"bridge\": a bridge's two contacts are "
                                     "driven by the mechanics' [[fixed]] contacts, not by a schedule")
                names = dict(contact_names=_bridge_names(mech))
            if template == "changeover":
                if "schedule" in table:
                    raise ValueError("circuit.schedule with template = \"changeover\": its NO and NC contacts are "
                                     "driven by the mechanics' [[fixed]] contacts, not by a schedule")
                names = dict(contact_names=_changeover_names(mech))
            circ = switch(source=source(**_kwargs(table, source)), load=load(**_kwargs(table, load)),
                          wiring=wiring(**_kwargs(table, wiring)), snubber=_part(table, "snubber"),
                          flyback=_part(table, "flyback"), arc=arc,
                          contact_current_factor=current_factor, coil=None if device is None else device.drive(),
                          **_kwargs(table, switch), **names)
        schedule = None
        if "schedule" in table:
            st = check_keys("circuit.schedule", _table("circuit.schedule", table["schedule"]),
                            section_keys(ck.ContactSchedule))
            if "make" not in st or "break" not in st:
                raise ValueError("circuit.schedule needs make = [...] and break = [...] (s)")
            schedule = ck.ContactSchedule.from_events(st["make"], st["break"], **_kwargs(st, ck.ContactSchedule))
    except TypeError as err:  # a value of a type no check foresaw
        raise ValueError(str(err)) from None
    probes = ()
    if "probes" in table:  # validated against the deck's nodes and elements
        from circuit.deck import build_deck
        from circuit.probes import check_probes

        probes = check_probes(table["probes"], build_deck(circ, 1.0, options)[0], "[circuit] probes")
    return CircuitSpec(circ, options, schedule, template, probes, table.get("netlist"))


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

    mech = schedule_t_end = None
    if schedule_given:  # [solver] t_end alone: the run's length, checked as the key's field would
        t_end = solver_table.get("t_end", _field_default(SolverOptions, "t_end"))
        schedule_t_end = check_positive("solver.t_end", t_end, high=T_END_MAX)
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
    if circuit_table is not None and device is not None and mech is not None and mech.bar is None:
        circuit = _actuator_circuit(circuit_table, device)
    elif circuit_table is not None:
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
                  coupling=coupling, output=output, name=name, metrics=metrics, duty=duty,
                  schedule_t_end=schedule_t_end)
    check_work(scene)
    return scene


def _actuator_circuit(table: dict, device) -> CircuitSpec:
    """An armature alone (no [bar]): its circuit is the coil's drive; [circuit] may set only
    ngspice's options (a contact template's contact would never be driven)."""
    import circuit as ck

    table = _table("[circuit]", table)
    allowed = set(key_fields(ck.SimulationOptions))
    stray = sorted(set(table) - allowed)
    if stray:
        raise ValueError(f"circuit.{', circuit.'.join(stray)}: an armature alone (no [bar]) has no contact, its "
                         f"circuit is the coil's drive ([coil]); [circuit] may set only ngspice's options: "
                         f"{', '.join(sorted(allowed))}")
    try:
        options = ck.SimulationOptions(**_kwargs(table, ck.SimulationOptions))
    except TypeError as err:  # a value of a type no check foresaw
        raise ValueError(str(err)) from None
    return CircuitSpec(device.drive(), options, template="coil")


def _field_default(cls, name: str):
    """The default of ``cls``'s field ``name``: the default of the key it is."""
    return next(f.default for f in dataclasses.fields(cls) if f.name == name)


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
    # (a path beside this package, as coupling.laws.tribology's data: importlib.resources,
    # the same text, cost ~2.5 ms of the default run's start, its readers importing zipfile)
    return (Path(__file__).parent.parent / "scenes" / f"{name}.toml").read_text(encoding="utf-8")


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

