"""The relay's own sections: [coil] (its drive, a contract) and [magnet], mapped 1:1 onto
circuit.coil_drive.CoilDrive and the magnets of coupling.laws.magnet (SI units).

Each key is a field's (docs/scene_keys.md, written from them): [coil]'s are CoilDrive's,
the winding's resistance and turns included; [magnet]'s are DeviceSpec's (model, rest_gap,
lever), then the model's magnet's (FluxTubeMagnet's sub-tables, docs/magnet.md "Scene
section"; TableMagnet's tables).

The coil's turns are the magnet's: a flux-tube magnet takes [coil] turns (the table's
flux linkages include them already). A netlist circuit places the coil with an XCOIL
line and takes only resistance and turns from [coil] (its drive is the netlist's).
"""

from __future__ import annotations

import dataclasses
from typing import Any

from coupling.core.scene import _field_default, key_fields, section_keys
from coupling.laws.magnet import FluxTubeMagnet, TableMagnet
from mech.validation import check_choice, check_keys, check_positive, internal, scene_key
from mech.frozen import frozen

MAGNET_MODELS = ("flux_tubes", "table", "plunger_solenoid")


def drive_keys() -> tuple[str, ...]:
    """[coil]'s keys of the drive: CoilDrive's scene-key fields. (A function: circuit brings
    PySpice, which a scene without a coil does not import.)"""
    from circuit.coil_drive import CoilDrive

    return tuple(key_fields(CoilDrive))


def coil_keys() -> tuple[str, ...]:
    """[coil]'s keys: the drive's, then the winding's (resistance, turns), which CoilDrive's
    ``coil`` field (a CoilBlock, with the magnet) is made of."""
    from circuit.coil_drive import CoilDrive

    return tuple(section_keys(CoilDrive))


@frozen(kw_only=True)
class DeviceSpec:
    """The relay's coil and magnet as a scene gives them; its scene-key fields are [magnet]'s
    own keys, whatever the model (the model's keys are its magnet's fields).

    coil: the [coil] table, checked (keys; the values are CoilDrive's and CoilBlock's to check).
    magnet: a coupling.laws.magnet magnet (its ngspice current law and force).
    model: the magnet's model, one of MAGNET_MODELS.
    rest_gap: m, the working gap with the armature on its rest stop.
    lever: m of pole-face travel per unit of the armature's travel q (m or rad).
    """

    coil: dict = internal()
    magnet: Any = internal()
    model: str = scene_key("flux_tubes", unit="-", doc='"flux_tubes", "table" or "plunger_solenoid" (built in)')
    rest_gap: float = scene_key(
        unit="m", shown="-", doc="the working gap with the armature on its rest stop (plunger_solenoid: 5e-3)")
    lever: float = scene_key(
        1.0, unit="m/m or m/rad",
        doc="pole-face travel per unit of the armature's q: 1 for a plunger, the pole's distance from the hinge for "
            "a clapper")

    @property
    def resistance(self) -> float:
        return float(self.coil["resistance"])

    def current_law(self) -> str:
        """The coil current as an ngspice expression of PSI (Wb) and GAP (m) (circuit.blocks.CoilBlock)."""
        return self.magnet.current_expression("PSI", "GAP")

    def drive(self):
        """The coil with its drive and suppression (circuit.coil_drive.CoilDrive; its errors
        name the keys as [coil] writes them, coil.voltage)."""
        from circuit.blocks import CoilBlock
        from circuit.coil_drive import DRIVER_NODE, SUPPLY_NODE, CoilDrive

        coil = CoilBlock("", SUPPLY_NODE, DRIVER_NODE, self.resistance, self.current_law())
        return CoilDrive(coil, **{k: v for k, v in self.coil.items() if k in drive_keys()})


# [magnet]'s keys as the fields declare them: its own (DeviceSpec's), then each model's
PLACEMENT_KEYS = tuple(key_fields(DeviceSpec))
FLUX_TUBE_KEYS = tuple(key_fields(FluxTubeMagnet))
TABLE_KEYS = tuple(key_fields(TableMagnet))


def _table(where: str, value) -> dict:
    if not isinstance(value, dict):
        raise ValueError(f"{where}: expected a table of keys, got {value!r}")
    return value


def device(doc: dict) -> DeviceSpec | None:
    """The scene's [coil] and [magnet] (both or neither), checked; None without them."""
    if "coil" not in doc and "magnet" not in doc:
        return None
    if "coil" not in doc or "magnet" not in doc:
        missing = "coil" if "coil" not in doc else "magnet"
        raise ValueError(f"[{'magnet' if missing == 'coil' else 'coil'}] needs [{missing}]: the coil drives the "
                         "armature through the magnet (docs/magnet.md)")
    coil = dict(check_keys("[coil]", _table("[coil]", doc["coil"]), coil_keys()))
    table = _table("[magnet]", doc["magnet"])
    model = check_choice("magnet.model", table.get("model", _field_default(DeviceSpec, "model")), MAGNET_MODELS)
    if model == "plunger_solenoid":
        from coupling.laws.magnet import plunger_solenoid

        check_keys("[magnet]", table, PLACEMENT_KEYS)
        solenoid = plunger_solenoid()
        coil.setdefault("resistance", solenoid.coil_resistance)
        turns = coil.setdefault("turns", solenoid.magnet.turns)
        magnet = solenoid.magnet if turns == solenoid.magnet.turns else dataclasses.replace(
            solenoid.magnet, turns=check_positive("coil.turns", turns))
        rest = table.get("rest_gap", solenoid.rest_gap)
    else:
        for key in ("resistance",) + (("turns",) if model == "flux_tubes" else ()):
            if key not in coil:
                raise ValueError(f"[coil] needs {key} ({'ohm, the winding' if key == 'resistance' else 'the winding'})"
                                 f" with magnet.model = {model!r}")
        if "rest_gap" not in table:
            raise ValueError("[magnet] needs rest_gap (m): the working gap with the armature on its rest stop")
        rest = table["rest_gap"]
        if model == "flux_tubes":
            check_keys("[magnet]", table, PLACEMENT_KEYS + FLUX_TUBE_KEYS)
            magnet = flux_tube_magnet(table, check_positive("coil.turns", coil["turns"]))
        else:
            check_keys("[magnet]", table, PLACEMENT_KEYS + TABLE_KEYS)
            if "turns" in coil:
                raise ValueError("coil.turns: a table magnet's flux linkages include the turns; remove coil.turns")
            magnet = table_magnet(table)
    check_positive("coil.resistance", coil["resistance"])
    rest = check_positive("magnet.rest_gap", rest)
    lever = check_positive("magnet.lever", table.get("lever", _field_default(DeviceSpec, "lever")))
    return DeviceSpec(coil=coil, magnet=magnet, model=model, rest_gap=float(rest), lever=float(lever))


def flux_tube_magnet(table: dict, turns: float):
    """[magnet] with model = "flux_tubes" as a FluxTubeMagnet; each tube named by its key path."""
    from coupling.laws.magnet import (
        AIR_SHAPES, IRON_SHAPES, FixedGap, FluxTubeMagnet, LinearMaterial, PoleLeakage, TabulatedMaterial,
        WorkingGap, magnetic_material,
    )

    if "working_gap" not in table:
        raise ValueError("[magnet] with model = \"flux_tubes\" needs [magnet.working_gap] with its area (m^2)")
    working = WorkingGap(**_fields("magnet.working_gap", table["working_gap"], WorkingGap),
                         name="magnet.working_gap")
    leakage = None
    if "pole_leakage" in table:
        leakage = PoleLeakage(**_fields("magnet.pole_leakage", table["pole_leakage"], PoleLeakage),
                              name="magnet.pole_leakage")

    def material(where: str, value):
        own = "your own curve, {relative_permeability = ...} or {flux_density = [...], field_strength = [...]} (T, A/m)"
        if value is None:
            raise ValueError(f"{where.rsplit('.', 1)[0]} needs material: a built-in name or {own}")
        if isinstance(value, str):
            try:
                return magnetic_material(value, where)
            except ValueError as err:  # the built-in names are few: say how to give the yoke's own steel
                raise ValueError(f"{err}; or {own}") from None
        value = _table(where, value)
        if "relative_permeability" in value:
            return LinearMaterial(**_fields(where, value, LinearMaterial), name=where)
        return TabulatedMaterial(**_fields(where, value, TabulatedMaterial), name=where)

    iron = []
    for k, entry in enumerate(_list("magnet.iron", table.get("iron", []))):
        where = f"magnet.iron[{k}]"
        entry = dict(_table(where, entry))
        shape = check_choice(f"{where}.shape", entry.pop("shape", None), tuple(IRON_SHAPES))
        cls = IRON_SHAPES[shape]
        entry["material"] = material(f"{where}.material", entry.get("material"))
        iron.append(cls(**_fields(where, entry, cls), name=where))
    fixed = []
    for k, entry in enumerate(_list("magnet.fixed_gap", table.get("fixed_gap", []))):
        where = f"magnet.fixed_gap[{k}]"
        entry = check_keys(where, _table(where, entry), ("tube",))
        tubes = []
        for j, tube in enumerate(_list(f"{where}.tube", entry.get("tube", []))):
            there = f"{where}.tube[{j}]"
            tube = dict(_table(there, tube))
            shape = check_choice(f"{there}.shape", tube.pop("shape", None), tuple(AIR_SHAPES))
            cls = AIR_SHAPES[shape]
            tubes.append(cls(**_fields(there, tube, cls), name=there))
        fixed.append(FixedGap(tuple(tubes), name=where))
    return FluxTubeMagnet(turns=float(turns), working_gap=working, iron=tuple(iron), fixed_gap=tuple(fixed),
                          pole_leakage=leakage)


def table_magnet(table: dict):
    """[magnet] with model = "table" as a TableMagnet (checked for consistency on load)."""
    from coupling.laws.magnet import TableMagnet

    return TableMagnet(**_fields("[magnet]", {k: table[k] for k in TABLE_KEYS if k in table}, TableMagnet))


def _fields(where: str, table, cls) -> dict:
    """The keyword arguments of ``cls`` a table gives (its name field set by the caller)."""
    table = _table(where, table)
    allowed = [f.name for f in dataclasses.fields(cls) if f.name != "name"]
    section = where if where.startswith("[") else f"[{where}]"
    check_keys(section, table, allowed)
    for f in dataclasses.fields(cls):  # a needed key left out: named, not the constructor's TypeError
        needed = f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
        if needed and f.name not in table and f.name != "material":  # (the caller sets the material)
            unit = f.metadata.get("unit", "-")
            raise ValueError(f"{section} needs {f.name}" + (f" ({unit})" if unit != "-" else ""))
    return dict(table)


def _list(where: str, value) -> list:
    if not isinstance(value, list):
        raise ValueError(f"{where} = {value!r}: expected a list of tables ([[{where}]])")
    return value
