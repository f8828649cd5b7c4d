"""docs/scene_keys.md lists every section and key the scene validators accept (and no other),
and the default it lists for a key is the value a scene that leaves the key out gets."""

from __future__ import annotations

import dataclasses
import re
import tomllib
from pathlib import Path

import pytest

import circuit as ck
from coupling.core import scene as cs
from coupling.core.device import FLUX_TUBE_KEYS, PLACEMENT_KEYS, TABLE_KEYS, coil_keys
from coupling.core.duty import DUTY_KEYS, LIFE_KEYS
from coupling.core.metrics import MetricSettings
from mech.scene import ENVIRONMENT_KEYS, LIST_SECTIONS, SECTIONS, entry_keys

DOC = Path(__file__).resolve().parents[2] / "docs" / "scene_keys.md"


def _rows() -> dict[str, dict[str, str]]:
    """section -> key -> the text of its default column."""
    out: dict[str, dict[str, str]] = {}
    section = None
    for line in DOC.read_text().splitlines():
        m = re.match(r"^## \[\[?([a-z_.]+)\]\]?", line)  # [section] or [[array of tables]]
        if m:
            section = m.group(1)
            out[section] = {}
            continue
        m = re.match(r"^\| `([a-z_]+)` \|", line)
        if m and section:
            cells = [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]
            out[section][m.group(1)] = cells[2]
    return out


def _documented() -> dict[str, set[str]]:
    return {section: set(keys) for section, keys in _rows().items()}


def _fields(cls) -> set[str]:
    return {f.name for f in dataclasses.fields(cls)}


def test_every_accepted_key_is_documented_and_nothing_else():
    doc = _documented()
    expected = {name: _fields(cls) for name, cls in SECTIONS.items()}
    # [bar] modes stands for axial_modes/bending_modes
    expected["bar"] = (expected["bar"] - {"axial_modes", "bending_modes"}) | {"modes"}
    expected["initial"] = expected["initial"]
    expected["environment"] = set(ENVIRONMENT_KEYS)
    for name in LIST_SECTIONS:  # [[force]], [[spring]], [[rivet]], [[fixed]]
        expected[name] = set(entry_keys(name))  # (not the field holding the entry's place, force[0], ...)
    expected["tribology"] = set(cs.TRIBOLOGY_KEYS)
    expected["circuit"] = set(cs.CIRCUIT_KEYS)
    expected["circuit.schedule"] = set(cs.section_keys(ck.ContactSchedule))  # the keys [circuit.schedule] takes
    for part, cls in (("snubber", ck.Snubber), ("flyback", ck.FlybackDiode), ("arc", ck.ArcModel)):
        expected[f"circuit.{part}"] = _fields(cls)
    expected["coupling"] = _fields(cs.CouplingOptions)
    expected["output"] = _fields(cs.OutputOptions)
    expected["metrics"] = _fields(MetricSettings)
    expected["duty"] = set(DUTY_KEYS)
    expected["duty.life"] = set(LIFE_KEYS)
    expected["coil"] = set(coil_keys())
    expected["magnet"] = set(PLACEMENT_KEYS + FLUX_TUBE_KEYS + TABLE_KEYS)
    assert set(doc) == set(expected), "sections of docs/scene_keys.md differ from the scene's"
    for section, keys in expected.items():
        assert doc[section] == keys, f"[{section}]: missing {keys - doc[section]}, extra {doc[section] - keys}"


def test_the_key_tables_are_written_from_the_dataclass_fields():
    """Each generated table of the page is what coupling.app.keys_doc writes from the fields
    now: a key added, renamed or redescribed in its dataclass without regenerating fails here."""
    from coupling.app import keys_doc

    text = DOC.read_text()
    assert keys_doc.render(text) == text, f"docs/scene_keys.md is stale: run `{keys_doc.COMMAND}`"


def test_a_field_without_its_key_description_is_named():
    """A field added without scene_key(...) or internal(...) stops the generator, naming the
    field and what to add (so that a new key gets its row)."""
    from coupling.app.keys_doc import field_rows
    from mech.validation import internal, scene_key

    @dataclasses.dataclass(frozen=True)
    class Widget:
        width: float = scene_key(1e-3, unit="m", doc="how wide")
        place: str = internal("widget[0]")
        depth: float = 2e-3

    with pytest.raises(ValueError, match=r"Widget\.depth: no scene-key description; declare it as "
                                         r"`depth: \.\.\. = scene_key\(<default>, unit="):
        field_rows(Widget)


def test_readme_relay_quick_start_scene_is_valid():
    """The README's "model my relay" scene validates as written (and uses the material law)."""
    import tomllib

    from coupling.core.scene import scene_from_dict

    text = (DOC.parents[1] / "README.md").read_text()
    block = re.search(r"```toml\n(# relay\.toml.*?)```", text, re.S).group(1)
    scene = scene_from_dict(tomllib.loads(block), name="relay")
    assert scene.kind == "coupled" and scene.tribology.laws.resistance_law.materials == ("AgNi10", "Ag")
    assert scene.mech.initial.height == 0.4e-3 and scene.circuit.circuit.load.load_resistance == 5.0


# --- the default column ------------------------------------------------------------------

NO_VALUE = object()  # "-": no value, or the key is needed
NETLIST = "net\nV1 a 0 24\nXCONTACT a b\nVLOAD b c 0\nR1 c 0 12\n"
COUPLED = {"tribology": {"source": "illustrative"}, "circuit": {}}
# entries of the arrays of tables with the keys they need (a key checked is left out)
ENTRIES = {"force": {"magnitude": 1.0}, "spring": {"stiffness": 1e3}, "rivet": {},
           "fixed": {"point": "tip0", "gap": 1e-3}}
# and the rest of the scene such an entry needs: [[fixed]] on a blade clamped at tip 1 (its
# one contact point tip 0: every contact point must strike a fixed contact)
ENTRY_SCENES = {"fixed": {"mount": {"kind": "clamp", "position": 0.3}}}
# keys that set one field together, so none has a default of its own: the alternatives choosing
# the contact laws (TribologySpec.laws) or the contact (the schedule), file names
NO_FIELD = {("tribology", k) for k in ("source", "fit", "data", "mu", "resistance")} | {
    ("circuit", "netlist"), ("circuit", "schedule"), ("circuit.schedule", "make"), ("circuit.schedule", "break")}
# keys whose default follows from the scene's other sections or from a life study's first sample,
# documented in words and checked where they are made (tests/coupling/test_duty_erosion.py,
# test_duty_needs_materials_a_circuit_and_a_gap; tests/coupling/test_life.py, the limits)
DERIVED = {("duty", k) for k in ("materials", "conductor_radius", "cap_height")} | {
    ("duty.life", k) for k in ("gap_range", "min_force", "max_resistance")} | {
    # the winding: needed or not by the magnet's model (documented in words, checked in
    # tests/coupling/test_relay.py, bad input); a magnet's lists of tubes: "-", none
    ("coil", "resistance"), ("coil", "turns"), ("magnet", "iron"), ("magnet", "fixed_gap")}
# [coil] and [magnet] of each magnet model that needs its keys (a key checked is left out): a
# flux-tube magnet of one working gap, and the table of an ideal gap, psi = k i / g and
# F = k i^2 / (2 g^2) with k = N^2 mu0 A = 1e-6 H m (consistent: F = -dW'/dg exactly)
MAGNETS = {"flux_tubes": {"coil": {"resistance": 10.0, "turns": 100},
                          "magnet": {"rest_gap": 1e-3, "working_gap": {"area": 1e-4}}},
           "table": {"coil": {"resistance": 10.0},
                     "magnet": {"model": "table", "rest_gap": 1e-3, "currents": [0.0, 1.0], "gaps": [1e-3, 2e-3],
                                "flux_linkages": [[0.0, 0.0], [1e-3, 5e-4]], "forces": [[0.0, 0.0], [0.5, 0.125]]}}}
# an actuator alone: the built-in solenoid's magnet, its armature, the coil's drive as the circuit
ACTUATOR = {"armature": {"kind": "plunger", "mass": 0.026, "travel": 4.75e-3, "stop_stiffness": 1e11},
            "magnet": {"model": "plunger_solenoid"}, "coil": {}}
DUTY = {"tribology": {"resistance": {"law": "holm", "materials": ["Ag", "Ag"]}, "mu": 0.3}, "circuit": {}}
# the bridge template names its contacts after two electrical [[fixed]] contacts: a free bar's
# two end caps over two of them
BRIDGE = {"fixed": [{"point": "tip0", "name": "a", "gap": 1e-3}, {"point": "tip1", "name": "b", "gap": 1e-3}],
          "tribology": {"source": "illustrative"}}
# the changeover template's contacts are the electrical [[fixed]] contacts named NO and NC
CHANGEOVER = {"fixed": [{"point": "tip0", "name": "NO", "gap": 1e-3}, {"point": "tip1", "name": "NC", "gap": 1e-3}],
              "tribology": {"source": "illustrative"}}
OPTION_KEYS = {f.name for f in dataclasses.fields(ck.SimulationOptions)}
CONTEXTS = {"initial": {"held bar": {"mount": {"kind": "clamp", "position": 0.3}}}}


def _split(cell: str) -> tuple[str, dict[str, str]]:
    """'12 (inductive: 24; capacitive: 0.5)' -> ('12', {'inductive': '24', 'capacitive': '0.5'})."""
    m = re.fullmatch(r"(.+?) \((.+)\)", cell)
    if m and all(re.fullmatch(r"[a-z_ ]+: .+", part) for part in m.group(2).split("; ")):
        return m.group(1), dict(part.split(": ", 1) for part in m.group(2).split("; "))
    return cell, {}


def _literal(text: str):
    """A default as the TOML value it stands for ('-': NO_VALUE); anything else fails the test."""
    if text == "-":
        return NO_VALUE
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        raise AssertionError(f"default {text!r} is neither a TOML value nor '-'") from None


def _plain(value):
    return [_plain(v) for v in value] if isinstance(value, (list, tuple)) else value


def _circuit_value(spec, name: str):
    """The field a circuit scene key ('circuit.voltage', 'circuit.arc.min_voltage') sets: the
    field of that name of the built circuit's parts (the fields are named as the keys)."""
    *section, key = name.split(".")
    if section == ["circuit"]:
        c = spec.circuit
        parts = [spec, spec.options, c] + [getattr(c, a, None) for a in ("source", "load", "wiring")]
    else:
        parts = [{"circuit.schedule": spec.schedule}.get(".".join(section), getattr(spec.circuit, section[1], None))]
    for part in parts:
        if part is not None and key in {f.name for f in dataclasses.fields(part)}:
            return getattr(part, key)
    raise AssertionError(f"{name}: no field of the built circuit is set by it")


def _omitted(section: str, key: str, patch: dict, folder: Path):
    """What a scene leaving ``key`` out gets (NO_VALUE: None, or an error because it is needed)."""
    try:
        value = _field_without(section, key, patch, folder)
    except ValueError:
        return NO_VALUE
    return NO_VALUE if value is None else value


def _field_without(section: str, key: str, patch: dict, folder: Path):
    if section in SECTIONS or section == "environment":
        scene = cs.scene_from_dict(patch)
        if section == "environment":
            return scene.mech.gravity
        part = getattr(scene.mech, section)
        if key == "modes":
            assert part.axial_modes == part.bending_modes
            return part.axial_modes
        return getattr(part, key)
    if section in LIST_SECTIONS:
        entry = {k: v for k, v in ENTRIES[section].items() if k != key}
        scene = cs.scene_from_dict({section: [entry], **ENTRY_SCENES.get(section, {})})
        return getattr(getattr(scene.mech, LIST_SECTIONS[section][0])[0], key)
    if section == "tribology":
        return getattr(cs.scene_from_dict(COUPLED).tribology, key)
    if section in ("coupling", "output", "metrics"):
        return getattr(getattr(cs.scene_from_dict(COUPLED), section), key)
    if section == "duty":
        return getattr(cs.scene_from_dict({**DUTY, "duty": {}}).duty, key)
    if section == "duty.life":
        return getattr(cs.scene_from_dict({**DUTY, "duty": {"life": {}}}).duty.life, key)
    if section == "coil":
        return getattr(cs.scene_from_dict(ACTUATOR).circuit.circuit, key)
    if section == "magnet":
        from coupling.core.device import PLACEMENT_KEYS, device

        doc = MAGNETS["table" if key in TABLE_KEYS else "flux_tubes"]
        spec = device({"coil": doc["coil"], "magnet": {k: v for k, v in doc["magnet"].items() if k != key}})
        return getattr(spec if key in PLACEMENT_KEYS else spec.magnet, key)
    table = {"schedule": {"make": [1e-4], "break": []}, **patch}
    if table.get("template") == "netlist":
        (folder / "net.cir").write_text(NETLIST)
        table["netlist"] = "net.cir"
    if section != "circuit":  # a sub-table: [circuit.arc], [circuit.schedule], ...
        part = section.split(".")[1]
        table[part] = {k: v for k, v in table.get(part, {}).items() if k != key}
    if table.get("template") in ("bridge", "changeover"):  # a coupled scene: its mechanics name the contacts
        table.pop("schedule")
        mech = BRIDGE if table["template"] == "bridge" else CHANGEOVER
        spec = cs.scene_from_dict({"circuit": table, **mech}, base_dir=folder).circuit
        return _circuit_value(spec, f"{section}.{key}")
    spec = cs.scene_from_dict({"circuit": table}, base_dir=folder).circuit
    return _circuit_value(spec, f"{section}.{key}")


def _same(got, expected) -> bool:
    if isinstance(got, bool) or isinstance(expected, bool):
        return got is expected
    return _plain(got) == _plain(expected)


def _cases():
    for section, rows in _rows().items():
        for key, cell in rows.items():
            yield pytest.param(section, key, cell, id=f"{section}.{key}")


@pytest.mark.parametrize("section, key, cell", list(_cases()))
def test_the_documented_default_is_what_an_omitted_key_gets(section, key, cell, tmp_path):
    if (section, key) in NO_FIELD:
        assert cell == "-", f"{section}.{key}: no field holds it, so it has no default"
        return
    if (section, key) in DERIVED:
        return
    base, named = _split(cell)
    contexts = dict(CONTEXTS.get(section, {}))
    patch: dict = {}
    if section == "circuit" and key not in {"template", "probes"} | OPTION_KEYS:
        # checked in every template that takes the key; the first one is the plain default
        templates = [t for t in cs.TEMPLATES if key in cs.template_keys(t)]
        patch = {"template": templates[0]}
        contexts = {t: {"template": t} for t in templates[1:]}
    elif section == "circuit.flyback":
        patch = {"template": "inductive", "flyback": {}}
    elif section in ("circuit.arc", "circuit.snubber"):
        patch = {section.split(".")[1]: {"resistance": 100.0, "capacitance": 1e-7} if "snubber" in section else {}}
    assert set(named) <= set(contexts), f"{section}.{key}: unknown context(s) {set(named) - set(contexts)}"
    for name, extra in [(None, patch)] + [(n, {**patch, **p}) for n, p in contexts.items()]:
        expected = _literal(named.get(name, base) if name else base)
        got = _omitted(section, key, extra, tmp_path)
        where = f"{section}.{key}" + (f" ({name})" if name else "")
        same = got is expected if NO_VALUE in (got, expected) else _same(got, expected)
        assert same, f"{where}: documented {cell!r}, a scene without it gets {got!r}"
