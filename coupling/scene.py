"""Coupled scenes: the mechanics sections plus [tribology], [circuit], [coupling], [output].

A scene names only what it needs, and only that is built:
- mechanics sections only: the impact solver alone (no ngspice);
- [circuit] with [circuit.schedule]: a prescribed make/break schedule, no mechanics;
- mechanics + [tribology] + [circuit]: the co-simulation.

    [tribology]   source = "illustrative" | fit = "fit.json" | data = "data.csv"
                  | inline [tribology.mu] and [tribology.resistance] tables (docs/tribology.md)
                  feedback = true (mu follows the contact current; false: mu = mu(0))
    [circuit]     template = "resistive" | "inductive" | "capacitive" | "netlist"
                  voltage, source_resistance, wiring_resistance, wiring_inductance,
                  load_resistance, load_inductance, load_capacitance, bleed_resistance,
                  contact_capacitance, leakage_conductance, snubber = {resistance, capacitance},
                  flyback = true | {...}, arc = true | false | {min_voltage, min_current, ...},
                  netlist = "file.cir", load_probe, max_step, reltol, method, wall_timeout
    [circuit.schedule]  make = [...], break = [...], closed_resistance, opening_speed
                        (s, s, ohm, m/s: the gap for an arc whose voltage grows with it)
    [coupling]    scheme = "mechanics_first" | "jacobi", macro_step, max_macro_step (s),
                  align_events = true, onset_penetration (m)
    [output]      csv, parquet, plots, history = true | false, history_resolution (s),
                  history_max_rows

SI units everywhere. File paths are relative to the scene file. Every error names the
section and key and says what is allowed, before any solver starts.
"""

from __future__ import annotations

import copy
import difflib
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

from mech.parameters import Friction, MechScene, check_nonnegative, check_positive
from mech.scene import SECTIONS as MECH_SECTIONS
from mech.scene import read_toml
from mech.scene import scene_from_dict as mech_scene_from_dict

COUPLING_SECTIONS = ("tribology", "circuit", "coupling", "output")
TEMPLATES = ("resistive", "inductive", "capacitive", "netlist")
SCHEMES = ("mechanics_first", "jacobi")

_CIRCUIT_KEYS = {
    "template", "voltage", "source_resistance", "wiring_resistance", "wiring_inductance",
    "load_resistance", "load_inductance", "load_capacitance", "bleed_resistance",
    "contact_capacitance", "leakage_conductance", "snubber", "flyback", "arc", "netlist",
    "load_probe", "max_step", "reltol", "method", "wall_timeout", "schedule",
}
_LOAD_KEYS = {
    "resistive": {"load_resistance"},
    "inductive": {"load_resistance", "load_inductance"},
    "capacitive": {"load_resistance", "load_capacitance", "bleed_resistance"},
    "netlist": set(),
}
_ALL_LOAD_KEYS = {"load_resistance", "load_inductance", "load_capacitance", "bleed_resistance"}


def _unknown(where: str, key: str, allowed) -> ValueError:
    close = difflib.get_close_matches(key, list(allowed), n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return ValueError(f"{where}: unknown key {key!r}{hint}; allowed keys: {', '.join(sorted(allowed))}")


def _table(where: str, value) -> dict:
    if not isinstance(value, dict):
        raise ValueError(f"{where}: expected a table of keys, got {value!r}")
    return value


def _bool(where: str, value) -> bool:
    if not isinstance(value, bool):
        raise ValueError(f"{where} = {value!r}: expected true or false")
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
    (coupling.master.conduction_onset): the continuum Hertz/Holm laws do not hold below
    the surface-roughness scale, and G ~ y^0.4 has an unbounded derivative at touchdown
    that ngspice's truncation-error control cannot follow at tight RELTOL.
    """

    scheme: str = "mechanics_first"
    macro_step: float = 2e-6
    max_macro_step: float | None = 1e-4
    align_events: bool = True
    onset_penetration: float = 10e-9

    def __post_init__(self):
        if self.scheme not in SCHEMES:
            raise ValueError(f"coupling.scheme = {self.scheme!r}: allowed values are {', '.join(map(repr, SCHEMES))}")
        check_positive("coupling.macro_step", self.macro_step)
        if self.max_macro_step is not None:
            check_positive("coupling.max_macro_step", self.max_macro_step)
            if self.max_macro_step < self.macro_step:
                raise ValueError(f"coupling.max_macro_step = {self.max_macro_step!r}: must be >= "
                                 f"coupling.macro_step = {self.macro_step!r}")
        if not isinstance(self.align_events, bool):
            raise ValueError(f"coupling.align_events = {self.align_events!r}: expected true or false")
        check_nonnegative("coupling.onset_penetration", self.onset_penetration)

    @property
    def free_step(self) -> float:
        return self.macro_step if self.max_macro_step is None or self.scheme == "jacobi" else self.max_macro_step


@dataclass(frozen=True)
class OutputOptions:
    """What a run writes besides summary.json: csv, parquet, plots (PNG), history (mechanics CSV).

    history_resolution, history_max_rows: history.csv keeps the records on either side of
    every event and regime change and, of the rest, one per interval of
    max(history_resolution, run length / history_max_rows) (s; both 0: every solver step);
    docs/coupling.md, "Outputs".
    """

    csv: bool = True
    parquet: bool = True
    plots: bool = True
    history: bool = True
    history_resolution: float = 1e-6
    history_max_rows: int = 50_000

    def __post_init__(self):
        for name in ("csv", "parquet", "plots", "history"):
            _bool(f"output.{name}", getattr(self, name))
        check_nonnegative("output.history_resolution", self.history_resolution)
        rows = self.history_max_rows
        if isinstance(rows, bool) or not isinstance(rows, int) or rows < 0:
            raise ValueError(f"output.history_max_rows = {rows!r}: expected a whole number >= 0 (0: no limit)")

    def history_interval(self, duration: float) -> float:
        """s: the history's resolution for a run of ``duration`` s (0: every record)."""
        budget = duration / self.history_max_rows if self.history_max_rows else 0.0
        return max(self.history_resolution, budget)


@dataclass(frozen=True)
class TribologySpec:
    """The contact laws (mu(I), gamma, R_c(F_n, I)), where they came from, and the fit if any."""

    laws: Any  # coupling.tribology.ContactLaws
    source: str
    feedback: bool = True
    fit: Any = None  # coupling.tribology.TribometerFit, when the laws come from a fit


@dataclass(frozen=True)
class CircuitSpec:
    """The circuit, its ngspice options, and an optional prescribed contact schedule."""

    circuit: Any  # circuit.SwitchCircuit | circuit.NetlistCircuit
    options: Any  # circuit.SimulationOptions
    schedule: Any = None  # circuit.ContactSchedule | None
    template: str = "resistive"


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
        t_end = _table("[solver]", self.raw.get("solver", {})).get("t_end")
        if t_end is not None:
            return float(t_end)
        return self.mech.solver.t_end if self.mech is not None else MechScene().solver.t_end

    def set(self, key: str, value) -> "Scene":
        """A new scene with ``key`` ("section.key" or "section.sub.key") set to value, re-validated.

        Example: ``scene.set("initial.angle_deg", 45).set("circuit.load_resistance", 6.0)``.
        """
        return self.update({key: value})

    def update(self, changes: dict) -> "Scene":
        """A new scene with several "section.key" values set at once, validated once (for
        keys that only make sense together, e.g. initial.resting with initial.angle_deg = 0)."""
        raw = copy.deepcopy(self.raw)
        for key, value in changes.items():
            node, last = _walk(raw, key)
            node[last] = list(value) if isinstance(value, tuple) else value
        return scene_from_dict(raw, base_dir=self.base_dir, name=self.name)

    def unset(self, *keys: str) -> "Scene":
        """A new scene without these "section.key" entries (their defaults apply), validated."""
        raw = copy.deepcopy(self.raw)
        for key in keys:
            node, last = _walk(raw, key)
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


def _tribology(table: dict, base_dir: Path, where: str) -> TribologySpec:
    from coupling.tribology import ContactLaws, TribometerFit, default_fit, fit_tribometer, read_tribometer_csv

    table = _table(where, table)
    allowed = {"source", "fit", "data", "mu", "resistance", "feedback"}
    for key in table:
        if key not in allowed:
            raise _unknown(where, key, allowed)
    feedback = _bool(f"{where} feedback", table.get("feedback", True))
    given = [k for k in ("source", "fit", "data") if k in table] + (["inline mu/resistance"] if (
        "mu" in table or "resistance" in table) else [])
    if len(given) != 1:
        raise ValueError(f"{where}: give exactly one of source = \"illustrative\", fit = \"fit.json\", "
                         f"data = \"data.csv\", or inline [tribology.mu] and [tribology.resistance] tables "
                         f"(found {', '.join(given) or 'none'})")
    if "source" in table:
        if table["source"] != "illustrative":
            raise ValueError(f"{where} source = {table['source']!r}: the only built-in source is \"illustrative\" "
                             "(the shipped, not measured, dataset); for your data use fit = or data =")
        fit = default_fit()
        return TribologySpec(fit.laws, "illustrative (not measured)", feedback, fit)
    if "fit" in table:
        path = base_dir / str(table["fit"])
        if not path.is_file():
            raise FileNotFoundError(f"{where} fit = {str(table['fit'])!r}: file {str(path)!r} not found")
        fit = TribometerFit.from_json(path)
        return TribologySpec(fit.laws, f"fit file {path.name}", feedback, fit)
    if "data" in table:
        path = base_dir / str(table["data"])
        if not path.is_file():
            raise FileNotFoundError(f"{where} data = {str(table['data'])!r}: file {str(path)!r} not found")
        fit = fit_tribometer(read_tribometer_csv(path))
        return TribologySpec(fit.laws, f"fit of {path.name}", feedback, fit)
    if "mu" not in table or "resistance" not in table:
        raise ValueError(f"{where}: inline laws need both [tribology.mu] and [tribology.resistance]")
    laws = ContactLaws.from_dict({"mu": table["mu"], "resistance": table["resistance"]})
    return TribologySpec(laws, "inline laws", feedback)


def _circuit(table: dict, base_dir: Path, where: str, current_factor: str | None):
    import circuit as ck

    table = _table(where, table)
    for key in table:
        if key not in _CIRCUIT_KEYS:
            raise _unknown(where, key, _CIRCUIT_KEYS)
    template = table.get("template", "resistive")
    if template not in TEMPLATES:
        raise ValueError(f"{where} template = {template!r}: allowed values are {', '.join(map(repr, TEMPLATES))}")
    stray = (set(table) & _ALL_LOAD_KEYS) - _LOAD_KEYS[template]
    if stray:
        raise ValueError(f"{where}: {', '.join(sorted(stray))} do(es) not apply to template {template!r} "
                         f"(its load keys: {', '.join(sorted(_LOAD_KEYS[template])) or 'none: the netlist has the load'})")

    def sub(name, cls):
        value = table.get(name)
        if value is None or value is False:
            return None
        if value is True:
            return cls()
        try:
            return cls(**_table(f"{where} {name}", value))
        except TypeError as err:
            raise ValueError(f"{where} {name}: {err}") from None

    arc = sub("arc", ck.ArcModel)
    option_keys = {k: table[k] for k in ("max_step", "reltol", "method", "wall_timeout") if k in table}
    options = ck.SimulationOptions(**option_keys)
    if template == "netlist":
        if "netlist" not in table:
            raise ValueError(f"{where}: template \"netlist\" needs netlist = \"file.cir\" (with one 'XCONTACT a b' line)")
        for key in ("voltage", "source_resistance", "wiring_resistance", "wiring_inductance",
                    "contact_capacitance", "snubber", "flyback"):
            if key in table:
                raise ValueError(f"{where}: {key} does not apply to template \"netlist\" (put it in the netlist)")
        path = base_dir / str(table["netlist"])
        if not path.is_file():
            raise FileNotFoundError(f"{where} netlist = {str(table['netlist'])!r}: file {str(path)!r} not found")
        kwargs = dict(arc=arc, contact_current_factor=current_factor)
        if "load_probe" in table:
            kwargs["load_probe"] = table["load_probe"]
        if "leakage_conductance" in table:
            kwargs["leakage_conductance"] = table["leakage_conductance"]
        circ = ck.NetlistCircuit.from_file(path, **kwargs)
    else:
        if "netlist" in table or "load_probe" in table:
            raise ValueError(f"{where}: netlist/load_probe apply to template \"netlist\" only")
        source = ck.DCSource(**{k: v for k, v in (("voltage", table.get("voltage")),
                                                 ("internal_resistance", table.get("source_resistance")))
                                if v is not None})
        wiring = ck.Wiring(**{k: v for k, v in (("resistance", table.get("wiring_resistance")),
                                               ("inductance", table.get("wiring_inductance"))) if v is not None})
        if template == "resistive":
            load = ck.ResistiveLoad(**({"resistance": table["load_resistance"]} if "load_resistance" in table else {}))
        elif template == "inductive":
            load = ck.InductiveLoad(**{k: table[f"load_{k}"] for k in ("resistance", "inductance") if f"load_{k}" in table})
        else:
            kw = {k: table[f"load_{k}"] for k in ("resistance", "capacitance") if f"load_{k}" in table}
            if "bleed_resistance" in table:
                kw["bleed_resistance"] = table["bleed_resistance"]
            load = ck.CapacitiveLoad(**kw)
        kwargs = dict(source=source, load=load, wiring=wiring, snubber=sub("snubber", ck.Snubber),
                      flyback=sub("flyback", ck.FlybackDiode), arc=arc, contact_current_factor=current_factor)
        for key in ("contact_capacitance", "leakage_conductance"):
            if key in table:
                kwargs[key] = table[key]
        circ = ck.SwitchCircuit(**kwargs)
    schedule = None
    if "schedule" in table:
        st = _table(f"{where}.schedule", table["schedule"])
        allowed = {"make", "break", "closed_resistance", "edge_time", "opening_speed"}
        for key in st:
            if key not in allowed:
                raise _unknown(f"{where}.schedule", key, allowed)
        if "make" not in st or "break" not in st:
            raise ValueError(f"{where}.schedule: needs make = [...] and break = [...] (s)")
        kw = {k: st[k] for k in ("closed_resistance", "edge_time", "opening_speed") if k in st}
        schedule = ck.ContactSchedule.from_events(st["make"], st["break"], **kw)
    return CircuitSpec(circ, options, schedule, template)


def scene_from_dict(doc: dict, *, base_dir: Path | str = ".", name: str = "scene") -> Scene:
    """Validate a parsed scene document completely and build the Scene."""
    where = name
    doc = _table(where, doc)
    base_dir = Path(base_dir)
    known = set(MECH_SECTIONS) | {"environment"} | set(COUPLING_SECTIONS)
    for section in doc:
        if section not in known:
            close = difflib.get_close_matches(section, list(known), n=1)
            hint = f" (did you mean [{close[0]}]?)" if close else ""
            raise ValueError(f"{where}: unknown section [{section}]{hint}; allowed: {', '.join(sorted(known))}")
    circuit_table = doc.get("circuit")
    schedule_given = isinstance(circuit_table, dict) and "schedule" in circuit_table
    mech_given = [s for s in ("bar", "block", "initial", "contact", "friction", "environment") if s in doc]
    solver_only_t_end = set(_table("[solver]", doc.get("solver", {}))) <= {"t_end"}

    if schedule_given and (mech_given or not solver_only_t_end):
        raise ValueError(f"{where}: [circuit.schedule] prescribes the contact, so the scene runs no mechanics; "
                         f"remove [{'], ['.join(mech_given or ['solver'])}] (only [solver] t_end may stay) "
                         "or remove [circuit.schedule]")
    if "coupling" in doc and (circuit_table is None or schedule_given):
        raise ValueError(f"{where}: [coupling] settings need mechanics and a [circuit] to couple")
    if circuit_table is not None and not schedule_given and "tribology" not in doc:
        raise ValueError(f"{where}: a coupled scene needs [tribology] for R_c(F_n, I) and mu(I): "
                         "source = \"illustrative\" (the shipped, not measured, fit), fit = \"fit.json\" "
                         "or data = \"data.csv\"")
    if schedule_given and "tribology" in doc:
        raise ValueError(f"{where}: [tribology] is unused with [circuit.schedule] (the schedule gives the "
                         "closed resistance); remove one of them")

    tribology = _tribology(doc["tribology"], base_dir, f"{where} [tribology]") if "tribology" in doc else None

    mech = None
    if not schedule_given:
        mech_doc = {k: v for k, v in doc.items() if k in MECH_SECTIONS or k == "environment"}
        if tribology is not None:
            fr = _table("[friction]", mech_doc.get("friction", {}))
            for key in ("mu", "gamma"):
                if key in fr:
                    raise ValueError(f"{where}: friction.{key} and [tribology] both set the friction law; "
                                     f"remove friction.{key} (the laws give gamma and mu(I))")
            mech_doc["friction"] = dict(fr)
        mech = mech_scene_from_dict(mech_doc, where=where, extra_sections=COUPLING_SECTIONS)
        if tribology is not None:
            laws = tribology.laws
            fr = mech.friction
            mu_fn = laws.mu if tribology.feedback else (lambda _i, _mu0=float(laws.mu(0.0)): _mu0)
            friction = Friction(mu=lambda current, f=mu_fn: float(f(current)), gamma=float(laws.gamma),
                                model=fr.model, max_ratio=fr.max_ratio,
                                regularization_speed=fr.regularization_speed)
            mech = MechScene(bar=mech.bar, block=mech.block, contact=mech.contact, friction=friction,
                             initial=mech.initial, solver=mech.solver, gravity=mech.gravity)

    circuit = None
    if circuit_table is not None:
        # R_c(F, I) = g(|I|)/G_F(F): the current factor goes into ngspice (solved without lag)
        factor = tribology.laws.resistance_law.current_factor_expression("I") if tribology is not None else None
        circuit = _circuit(circuit_table, base_dir, f"{where} [circuit]", factor)

    coupling = CouplingOptions(**_known(doc.get("coupling", {}), CouplingOptions, f"{where} [coupling]"))
    output = OutputOptions(**_known(doc.get("output", {}), OutputOptions, f"{where} [output]"))
    t_end = _table("[solver]", doc.get("solver", {})).get("t_end")
    if t_end is not None:
        check_positive("solver.t_end", t_end)
    return Scene(raw=copy.deepcopy(doc), base_dir=base_dir, mech=mech, tribology=tribology, circuit=circuit,
                 coupling=coupling, output=output, name=name)


def _known(table, cls, where: str) -> dict:
    import dataclasses

    table = _table(where, table)
    allowed = [f.name for f in dataclasses.fields(cls)]
    for key in table:
        if key not in allowed:
            raise _unknown(where, key, allowed)
    return dict(table)


def _walk(raw: dict, key: str) -> tuple[dict, str]:
    """The table holding "section.key" (created if missing) and the last part of the key."""
    parts = key.split(".")
    if len(parts) < 2 or not all(parts):
        raise ValueError(f"key {key!r}: expected 'section.key', e.g. 'initial.angle_deg'")
    node = raw
    for part in parts[:-1]:
        node = node.setdefault(part, {})
        if not isinstance(node, dict):
            raise ValueError(f"key {key!r}: {part!r} is not a table")
    return node, parts[-1]


def _rebuild_scene(raw: dict, base_dir: str, name: str) -> Scene:
    return scene_from_dict(raw, base_dir=Path(base_dir), name=name)


def load_scene(path) -> Scene:
    """Read and validate a scene TOML file (SI units; paths inside are relative to it)."""
    path = Path(path)
    return scene_from_dict(read_toml(path), base_dir=path.parent, name=str(path))


def default_scene_text() -> str:
    """The built-in default coupled scene, as TOML text."""
    return resources.files("coupling").joinpath("scenes/default.toml").read_text()


def default_scene() -> Scene:
    """The built-in default coupled scene (coupling/scenes/default.toml)."""
    doc = tomllib.loads(default_scene_text())
    return scene_from_dict(doc, base_dir=Path("."), name="default scene")

