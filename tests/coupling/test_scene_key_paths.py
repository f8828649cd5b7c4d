"""Every scene key is reachable from Python, from a sweep file and from TOML alike: list
entries by index (rivet[0].mass, force[1].value, magnet.fixed_gap[0].tube[1].length) and a
netlist's .param values (circuit.params.RF). The three routes build the same scene; a
list-entry key changes exactly the entry it names; bad keys are one line naming the key."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest

from coupling.app.sweep import load_sweep
from coupling.core.scene import key_steps, load_scene, scene_from_dict
from value_errors import one_line_value_error as _one_line

# A mechanics scene with two entries in each list of tables (the two rivets are the contact).
LISTS = {
    "bar": {"length": 0.1, "diameter": 0.005, "tip_radius": 0.003},
    "rivet": [{"position": 0.01, "radius": 1e-3, "mass": 1e-4}, {"position": 0.09, "radius": 1.5e-3, "mass": 2e-4}],
    "force": [{"position": 0.05, "magnitude": 1.0}, {"position": 0.02, "time": [0.0, 1e-3], "value": [0.0, 2.0]}],
    "spring": [{"position": 0.03, "stiffness": 1e3}, {"position": 0.07, "stiffness": 2e3, "damping": 0.1}],
    "initial": {"height": 1e-3, "velocity": [0.1, 0.0, -1.0]},
    "solver": {"t_end": 1e-3},
}


def toml_text(doc: dict) -> str:
    """A scene document as TOML text, every table inline (the test's own writer, so that the
    TOML route shares no code with Scene.set)."""
    def value(v) -> str:
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, (int, float)):
            assert math.isfinite(v)
            return repr(v)
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, (list, tuple)):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, dict):
            return "{" + ", ".join(f"{json.dumps(k)} = {value(x)}" for k, x in v.items()) + "}"
        raise TypeError(type(v))

    return "".join(f"{json.dumps(k)} = {value(v)}\n" for k, v in doc.items())


def placed(doc: dict, key: str, new) -> dict:
    """A copy of doc with ``new`` at ``key``, placed by hand (json round trip, then a walk)."""
    out = json.loads(json.dumps(doc))
    steps = key_steps(key)
    node = out
    for step in steps[:-1]:
        node = node[step] if isinstance(step, int) else node.setdefault(step, {})
    node[steps[-1]] = new
    return out


def three_routes(tmp_path: Path, base_doc: dict, key: str, new, files: dict | None = None):
    """(Python set, the TOML file written with the value, a sweep file's case) of one key."""
    for name, text in (files or {}).items():
        (tmp_path / name).write_text(text)
    (tmp_path / "base.toml").write_text(toml_text(base_doc))
    base = load_scene(tmp_path / "base.toml")
    by_python = base.set(key, new)
    (tmp_path / "edited.toml").write_text(toml_text(placed(base_doc, key, new)))
    by_toml = load_scene(tmp_path / "edited.toml")
    (tmp_path / "sweep.toml").write_text(
        f'[sweep]\nscene = "base.toml"\ndesign = "cases"\n[[sweep.cases]]\n{json.dumps(key)} = '
        f'{toml_text({"v": new})[6:]}')
    sweep = load_sweep(tmp_path / "sweep.toml")
    by_sweep = sweep.scene(sweep.runs[0])
    return base, by_python, by_toml, by_sweep


def _plain(v):
    return [_plain(x) for x in v] if isinstance(v, (list, tuple)) else v


LIST_CASES = [
    ("rivet[0].mass", 3e-4, "rivets", 0, "mass"),
    ("rivet[1].radius", 2e-3, "rivets", 1, "radius"),
    ("force[1].value", [0.0, 3.0], "forces", 1, "value"),
    ("force[1].value[1]", 4.0, "forces", 1, "value"),
    ("force[0].magnitude", 1.5, "forces", 0, "magnitude"),
    ("spring[0].stiffness", 1.5e3, "springs", 0, "stiffness"),
    ("spring[1].damping", 0.2, "springs", 1, "damping"),
]


@pytest.mark.parametrize("key, new, field, index, attr", LIST_CASES, ids=[c[0] for c in LIST_CASES])
def test_a_list_entry_key_changes_exactly_that_entry(key, new, field, index, attr, tmp_path):
    base, by_python, by_toml, by_sweep = three_routes(tmp_path, LISTS, key, new)
    assert by_python.raw == by_toml.raw == by_sweep.raw
    assert by_python.mech == by_toml.mech == by_sweep.mech  # the same scene by every route
    expected = _plain(getattr(getattr(base.mech, field)[index], attr))
    if isinstance(new, list) or not isinstance(expected, list):
        expected = new
    else:  # an index into the entry's own list: that element alone
        expected[key_steps(key)[-1]] = new
    for f in dataclasses.fields(base.mech):
        old_value, new_value = getattr(base.mech, f.name), getattr(by_python.mech, f.name)
        if f.name != field:
            assert new_value == old_value, f"{key} changed {f.name}"
            continue
        for k, (was, now) in enumerate(zip(old_value, new_value, strict=True)):
            for g in dataclasses.fields(was):
                changed = k == index and g.name == attr
                got = _plain(getattr(now, g.name))
                assert got == (expected if changed else _plain(getattr(was, g.name))), f"{key}: {f.name}[{k}].{g.name}"


def test_an_index_into_a_list_of_numbers(tmp_path):
    base, by_python, by_toml, by_sweep = three_routes(tmp_path, LISTS, "initial.velocity[2]", -0.5)
    assert by_python.mech == by_toml.mech == by_sweep.mech
    assert by_python.mech.initial.velocity == (0.1, 0.0, -0.5)
    assert dataclasses.replace(by_python.mech.initial, velocity=base.mech.initial.velocity) == base.mech.initial


MAGNET = {
    "armature": {"kind": "plunger", "mass": 5e-3, "travel": 1e-3, "stop_stiffness": 1e6, "spring_rate": 100.0,
                 "spring_preload": 0.1},
    "coil": {"voltage": 12.0, "on_time": 1e-4, "resistance": 40.0, "turns": 957},
    "magnet": {"model": "flux_tubes", "rest_gap": 1.5e-3, "working_gap": {"area": 7.853981633974483e-5},
               "iron": [{"shape": "axial", "outer_radius": 5e-3, "length": 6.5e-3, "material": "9SMnPb28"},
                        {"shape": "prism", "length": 20e-3, "area": 5e-5,
                         "material": {"relative_permeability": 1000.0}}],
               "fixed_gap": [{"tube": [{"shape": "radial", "inner_radius": 5e-3, "thickness": 0.65e-3,
                                        "length": 3.5e-3},
                                       {"shape": "axial", "length": 0.1e-3, "area": 2e-5}]}]},
    "solver": {"t_end": 2e-3},
}


@pytest.mark.parametrize("key, new, path", [
    ("magnet.iron[1].length", 30e-3, ("iron", 1)),
    ("magnet.iron[1].material.relative_permeability", 500.0, ("iron", 1)),
    ("magnet.fixed_gap[0].tube[1].length", 0.2e-3, ("fixed_gap", 0)),
])
def test_magnet_list_entries(key, new, path, tmp_path):
    from coupling.core.device import device

    base, by_python, by_toml, by_sweep = three_routes(tmp_path, MAGNET, key, new)
    assert by_python.raw == by_toml.raw == by_sweep.raw
    magnets = [device(s.raw).magnet for s in (base, by_python, by_toml, by_sweep)]
    assert magnets[1] == magnets[2] == magnets[3] != magnets[0]
    # the coil's current law psi -> i (an ngspice expression of the reluctances) follows the change
    assert by_python.circuit == by_toml.circuit == by_sweep.circuit != base.circuit
    section, index = path
    for k, (was, now) in enumerate(zip(getattr(magnets[0], section), getattr(magnets[1], section), strict=True)):
        assert (was == now) is (k != index), f"{key}: {section}[{k}]"
    for f in dataclasses.fields(magnets[0]):
        if f.name != section:
            assert getattr(magnets[0], f.name) == getattr(magnets[1], f.name), f"{key} changed magnet.{f.name}"


def test_bad_keys_are_one_line_naming_the_key(tmp_path):
    base = scene_from_dict(LISTS, name="lists.toml")
    _one_line(lambda: base.set("rivet[2].mass", 1e-4), "lists.toml", "'rivet[2].mass'", "beyond rivet",
              "2 entries", "rivet[0] to rivet[1]")
    _one_line(lambda: base.set("bar[0].length", 0.2), "'bar[0].length'", "bar is a table, not a list",
              "write bar.length")
    _one_line(lambda: base.set("initial.height[1]", 0.2), "'initial.height[1]'", "initial.height is 0.001",
              "not a list")
    _one_line(lambda: base.set("rivet.mass", 1e-4), "'rivet.mass'", "list of 2 entries", "rivet[0].mass")
    _one_line(lambda: base.set("mount[0].kind", "clamp"), "'mount[0].kind'", "beyond mount", "0 entries")
    _one_line(lambda: base.set("rivet[-1].mass", 1e-4), "'rivet[-1].mass'", "whole number >= 0")
    _one_line(lambda: base.set("force[1].value[2]", 1.0), "'force[1].value[2]'", "beyond force[1].value",
              "2 entries")
    # the sweep file says the same, naming the run
    (tmp_path / "base.toml").write_text(toml_text(LISTS))
    (tmp_path / "sweep.toml").write_text('[sweep]\nscene = "base.toml"\ndesign = "grid"\n[sweep.grid]\n'
                                         '"rivet[3].mass" = [1e-4, 2e-4]\n')
    _one_line(lambda: load_sweep(tmp_path / "sweep.toml"), "run0000", "'rivet[3].mass'", "2 entries")


def test_unset_of_a_list_entry(tmp_path):
    base = scene_from_dict(LISTS)
    fewer = base.unset("force[0]", "spring[1].damping")
    assert fewer.mech.forces == (dataclasses.replace(base.mech.forces[1], name="force[0]"),)
    assert fewer.mech.springs[1].damping == 0.0 and fewer.mech.springs[0] == base.mech.springs[0]


# --- a netlist's .param from the scene -------------------------------------------------------

RC_NETLIST = """rc charged through the contact
.param RF=1k CF={RF*1n*1000/RF}
.subckt LOCAL a b params: RS=1
R1 a b {RS}
.ends
V1 a 0 10
XCONTACT a b
R1 b c {RF}
VLOAD c d 0
C1 d 0 {CF}
.ic v(d)=0
"""
RC_SCENE = {"circuit": {"template": "netlist", "netlist": "rc.cir", "probes": ["v(d)"], "max_step": 2e-5,
                        "schedule": {"make": [1e-4], "break": []}},
            "solver": {"t_end": 1e-2}}


def test_a_param_set_from_the_scene_changes_the_circuit_ngspice_computes(tmp_path):
    """v(d) = 10 V (1 - exp(-(t - t_make) / tau)), tau = (RF + R_closed) CF: the closed form
    with the scene's RF, not the netlist's 1k. ngspice's error is its time step's (second
    order: 3.9e-2, 2.9e-3, 4.8e-4 V at TMAX = 125, 50, 20 us for tau = 1 ms); at 20 us it meets
    the closed form to 2 mV (measured 0.5 mV); with the netlist's RF the error would be volts."""
    from coupling import run

    base, by_python, by_toml, by_sweep = three_routes(tmp_path, RC_SCENE, "circuit.params.RF", 4e3,
                                                      {"rc.cir": RC_NETLIST})
    assert by_python.circuit == by_toml.circuit == by_sweep.circuit != base.circuit
    assert by_python.circuit.circuit.params == (("RF", 4e3),)
    make, closed = 1e-4, by_python.circuit.schedule.closed_resistance
    for scene, rf in ((base, 1e3), (by_python, 4e3)):
        w = run(scene).waveforms
        t, v = w["time"].to_numpy(), w["v(d)"].to_numpy()
        after = t > make + 1e-5
        exact = 10.0 * (1.0 - np.exp(-(t[after] - make) / ((rf + closed) * 1e-6)))
        assert np.max(np.abs(v[after] - exact)) < 2e-3, rf


def test_params_bad_input_is_one_line(tmp_path):
    (tmp_path / "rc.cir").write_text(RC_NETLIST)
    base = scene_from_dict(RC_SCENE, base_dir=tmp_path, name="rc.toml")
    _one_line(lambda: base.set("circuit.params.RG", 1.0), "rc.toml", "circuit.params.RG = 1.0",
              "no '.param RG'", "did you mean 'RF'", "CF, RF")
    _one_line(lambda: base.set("circuit.params.RS", 1.0), "circuit.params.RS", "no '.param RS' at its top level")
    _one_line(lambda: base.set("circuit.params.RF", "1k\n.control"), "circuit.params.RF", "expected a finite number")
    _one_line(lambda: base.set("circuit.params.RF", float("inf")), "circuit.params.RF = inf")
    _one_line(lambda: base.set("circuit.params", 3.0), "circuit.params = 3.0", "a table of name = number")
    resistive = scene_from_dict({"circuit": {"schedule": {"make": [1e-4], "break": []}}})
    _one_line(lambda: resistive.set("circuit.params.RF", 1.0), "circuit.params", "do(es) not apply to template")


# --- every key of docs/scene_keys.md ---------------------------------------------------------

DOC = Path(__file__).resolve().parents[2] / "docs" / "scene_keys.md"


def _doc_rows() -> list[tuple[str, str, str]]:
    """(section, key, default column) of every key row of docs/scene_keys.md."""
    import re

    out, section = [], None
    for line in DOC.read_text().splitlines():
        m = re.match(r"^## \[\[?([a-z_.]+)\]\]?", line)
        if m:
            section = m.group(1)
            continue
        m = re.match(r"^\| `([a-z_]+)` \|", line)
        if m and section:
            cells = [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]
            out.append((section, m.group(1), cells[2]))
    return out


# values for keys without a default to perturb, and choices (a string default has no "next" value)
EXAMPLES = {
    "bar.bending": "paper_shear", "bar.modes": 3, "bar.diameter": 9e-3, "block.radius": 2e-3,
    "mount.position": 0.2, "spring.rest_length": 0.01,
    "mount.kind": "clamp", "contact.law": "hunt_crossley", "contact.reference_speed": 1.0,
    "contact.stiffness": 1e9, "friction.model": "regularized", "solver.max_step": 1e-5, "solver.model": "3d",
    "force.magnitude": 2.0, "force.frame": "body", "spring.preload": 1.0, "spring.stiffness": 2e3,
    "rivet.youngs_modulus": 76e9, "rivet.poisson_ratio": 0.37, "armature.mass": 2e-3, "armature.travel": 2e-3,
    "armature.stop_stiffness": 2e6, "armature.initial_position": 1e-4,
    "circuit.template": "inductive", "circuit.method": "trap", "circuit.max_step": 1e-5, "circuit.pull": "down",
    "circuit.load_probe": "VLOAD2", "circuit.probes": ["v(load)"], "circuit.arc.breakdown_voltage": 300.0,
    "circuit.arc.characteristic": "ayrton", "circuit.snubber.resistance": 47.0,
    "circuit.snubber.capacitance": 47e-9, "circuit.schedule.opening_speed": 1.0,
    "circuit.schedule.make": [2e-4], "circuit.schedule.break": [5e-4], "circuit.params": {"RS": 2.0},
    "coupling.scheme": "jacobi", "metrics.make_guard": 1e-9, "duty.moving_node": "b",
    "duty.materials": ["Ag", "AgNi10"], "duty.erosion_coefficient": 1e-12, "duty.cap_height": 1e-4,
    "duty.conductor_radius": 2e-3, "duty.life.stop_on_weld": "never", "duty.life.min_force": 0.1,
    "duty.life.max_resistance": 0.1, "duty.life.gap_range": [1e-4, 2e-3],
    "force.interpolation": "pchip", "coil.on_time": 2e-4, "coil.off_time": 1e-3, "coil.suppression": "diode", "coil.resistance": 50.0,
    "coil.turns": 1000, "magnet.rest_gap": 2e-3, "magnet.working_gap": {"area": 5e-5},
    "magnet.pole_leakage": {"width": 0.03, "radius": 1e-3},
    "magnet.iron": [{"shape": "prism", "length": 0.02, "area": 5e-5, "material": "9SMnPb28"}],
    "magnet.fixed_gap": [{"tube": [{"shape": "axial", "length": 1e-4, "area": 2e-5}]}],
    "spring.travel": [-1e-3, 2e-3], "spring.force": [0.0, 2.0], "spring.release_force": [0.0, 0.5],
    "force.travel": [0.0, 2e-3], "force.share": [1.0, 0.5],
    "spring.between": "armature", "spring.lever": 2.0,
    "rivet.name": "mid", "fixed.name": "NO", "fixed.radius": 2e-3, "fixed.facing": "down", "fixed.gap": 2e-3,
    "circuit.nc_load_resistance": 20.0, "circuit.nc_load_inductance": 5e-3,
}
RC_PLAIN = "net\n.param RS=1\nV1 a 0 24\nXCONTACT a b\nVLOAD b c 0\nR1 c 0 {RS}\n"
COUPLED = {"tribology": {"source": "illustrative"}, "circuit": {}, "solver": {"t_end": 1e-3}}
DUTY = {"tribology": {"resistance": {"law": "holm", "materials": ["Ag", "Ag"]}, "mu": 0.3}, "circuit": {},
        "solver": {"t_end": 1e-3}}
SCHEDULE = {"make": [1e-4], "break": []}


def _perturbed(default: str, example):
    """A value other than the documented default: the example, else the default moved."""
    import tomllib

    if example is not None:
        return example
    if default == "-":
        return None
    try:
        d = tomllib.loads(f"v = {default.split(' (')[0]}")["v"]
    except tomllib.TOMLDecodeError:
        return None
    if isinstance(d, bool):
        return not d
    if isinstance(d, (int, float)):
        return d + 1 if isinstance(d, int) and d > 1 else 1.1 * d if d else 1e-4
    if isinstance(d, list) and all(isinstance(x, (int, float)) for x in d):
        return [1.1 * x if x else 1e-4 for x in d]
    return None


def _base_and_key(section: str, key: str) -> tuple[dict, str]:
    """A scene document in which ``key`` of ``section`` applies, and the key as a path."""
    from mech.scene import LIST_SECTIONS, SECTIONS

    from coupling.core import scene as cs

    if section in LIST_SECTIONS:
        entry = {"force": {"magnitude": 1.0}, "spring": {"stiffness": 1e3}, "rivet": {},
                 "fixed": {"point": "tip0", "gap": 1e-3}}[section]
        if section == "spring" and key in ("travel", "force", "release_force"):  # a force-travel spring's keys
            entry = {"travel": [0.0, 1e-3], "force": [0.0, 1.0]}
        if section == "force" and key in ("travel", "share"):  # a force that follows its travel
            entry = {"magnitude": 1.0, "travel": [0.0, 1e-3], "share": [1.0, 0.0]}
        if section == "spring" and key in ("between", "lever"):  # a spring the armature carries (lever)
            entry = dict(entry, between="armature") if key == "lever" else entry
            armature = {"armature": {"kind": "plunger", "mass": 1e-3, "travel": 1e-3, "stop_stiffness": 1e6}}
            return {section: [entry], **armature, "bar": {}, "solver": {"t_end": 1e-3}}, f"{section}[0].{key}"
        if section == "fixed" and key in ("radius", "offset"):
            entry = dict(entry, shape="sphere", radius=1e-3)
        # a [[fixed]] entry's point tip0: the bar clamped at tip 1 (every contact point strikes one)
        held = {"mount": {"kind": "clamp", "position": 0.3}} if section == "fixed" else {}
        return {section: [entry], **held, "solver": {"t_end": 1e-3}}, f"{section}[0].{key}"
    if section in SECTIONS or section == "environment":
        context = {"block": {"block": {"shape": "sphere", "radius": 1e-3}} if key in ("radius", "offset") else {},
                   "mount": {"mount": {"kind": "pivot", "position": 0.3}},
                   "armature": {"armature": {"kind": "plunger", "mass": 1e-3, "travel": 1e-3,
                                             "stop_stiffness": 1e6}}}.get(section, {})
        return {**context, "solver": {"t_end": 1e-3}}, f"{section}.{key}"
    if section in ("tribology", "coupling", "output", "metrics"):
        return json.loads(json.dumps(COUPLED)), f"{section}.{key}"
    if section.startswith("duty"):
        life = {"life": {}} if section == "duty.life" else {}
        return {**json.loads(json.dumps(DUTY)), "duty": life}, f"{section}.{key}"
    if section in ("coil", "magnet"):  # an actuator: a flux-tube magnet, its armature, the coil's drive
        return json.loads(json.dumps(MAGNET)), f"{section}.{key}"
    table = {"schedule": dict(SCHEDULE)}
    if section == "circuit":
        templates = [t for t in cs.TEMPLATES if key in cs.template_keys(t)] or ["resistive"]
        table["template"] = templates[0]
        if templates[0] == "netlist":
            table["netlist"] = "net.cir"
        if templates[0] == "changeover":  # coupled: its contacts are the [[fixed]] contacts NO and NC
            del table["schedule"]
            return {"circuit": table, "tribology": {"source": "illustrative"}, "solver": {"t_end": 1e-3},
                    "fixed": [{"point": "tip0", "name": "NO", "gap": 1e-3},
                              {"point": "tip1", "name": "NC", "gap": 1e-3}]}, f"{section}.{key}"
    elif section == "circuit.flyback":
        table.update(template="inductive", flyback={})
    elif section == "circuit.snubber":
        table["snubber"] = {"resistance": 100.0, "capacitance": 1e-7}
    elif section == "circuit.arc":
        table["arc"] = {}
    return {"circuit": table}, f"{section}.{key}"


def _view(scene) -> dict:
    """What a scene is, the raw document aside: its built parts (the friction law by its values:
    its mu is a function)."""
    out = {"circuit": scene.circuit, "coupling": scene.coupling, "output": scene.output,
           "metrics": scene.metrics, "duty": scene.duty,
           "tribology": None if scene.tribology is None else (scene.tribology.source, scene.tribology.feedback)}
    if scene.mech is not None:
        mech = scene.mech
        out.update({f.name: getattr(mech, f.name) for f in dataclasses.fields(mech) if f.name != "friction"})
        fr = mech.friction
        out["friction"] = (fr.mu_at(0.0), fr.mu_at(5.0), fr.gamma, fr.model, fr.max_ratio, fr.regularization_speed)
    return out


def _outcome(call):
    try:
        return call(), None
    except (ValueError, FileNotFoundError) as err:
        return None, str(err).split(": ", 1)[1]  # the file name first differs between routes


#: Keys whose new value is refused in the base scene the test builds (they need other keys
#: set with them); the three routes must still refuse them alike.
NEEDS_COMPANIONS = {"bar.width", "bar.thickness", "mount.base_motion", "force.time", "force.value",
                    "armature.inertia", "armature.card_position", "armature.card_lever", "armature.card_stiffness",
                    "armature.card_free_travel", "armature.card_damping", "armature.force_gain",
                    "initial.resting", "circuit.netlist", "circuit.arc.ayrton_d", "circuit.arc.breakdown_gradient",
                    "tribology.fit", "tribology.data", "tribology.mu", "tribology.resistance",
                    "circuit.schedule", "circuit.snubber", "circuit.flyback", "circuit.arc", "metrics.logic",
                    "duty.life", "contact.damping", "block.shape", "armature.kind", "tribology.source",
                    "circuit.arc.ayrton_c", "contact.calibration", "circuit.phase_deg",
                    # another contact point, a sphere's radius with it, height instead of gap
                    "fixed.point", "fixed.shape", "fixed.height",
                    # a table magnet's keys in a flux-tube scene, and the choice between them
                    "magnet.model", "magnet.currents", "magnet.gaps", "magnet.flux_linkages", "magnet.forces",
                    "magnet.force_tolerance"}


@pytest.mark.parametrize("section, key, default", _doc_rows(), ids=[f"{s}.{k}" for s, k, _ in _doc_rows()])
def test_every_documented_key_round_trips(section, key, default, tmp_path):
    """Set from Python, from a sweep file and from TOML: the same scene (or the same refusal);
    a key set to a value other than its default changes what the scene builds."""
    name = f"{section}.{key}"
    new = _perturbed(default, EXAMPLES.get(name))
    if new is None:
        assert name in NEEDS_COMPANIONS, f"{name}: give the test a value for it (EXAMPLES)"
        return
    base_doc, path = _base_and_key(section, key)
    (tmp_path / "net.cir").write_text(RC_PLAIN)
    routes = [_outcome(lambda: three_routes(tmp_path, base_doc, path, new))]
    if routes[0][1] is not None:  # one of the routes refused: each must, alike
        (tmp_path / "base.toml").write_text(toml_text(base_doc))
        base = load_scene(tmp_path / "base.toml")
        errors = {_outcome(lambda: base.set(path, new))[1],
                  _outcome(lambda: load_scene(_written(tmp_path, placed(base_doc, path, new))))[1]}
        assert len(errors) == 1 and None not in errors, f"{name}: routes differ: {errors}"
        assert name in NEEDS_COMPANIONS, f"{name} = {new!r} refused: {errors.pop()}"
        return
    base, by_python, by_toml, by_sweep = routes[0][0]
    assert by_python.raw == by_toml.raw == by_sweep.raw
    assert _view(by_python) == _view(by_toml) == _view(by_sweep), name
    assert _view(by_python) != _view(base), f"{name} = {new!r} changed nothing the scene builds"


def _written(folder: Path, doc: dict) -> Path:
    path = folder / "edited.toml"
    path.write_text(toml_text(doc))
    return path
