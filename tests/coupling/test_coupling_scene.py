"""Coupled scenes: kinds, only the named parts built, and a clear error for each bad scene before anything runs."""

from __future__ import annotations

import textwrap

import pytest

from coupling import builtin_scene, load_scene
from coupling.core.scene import scene_from_dict

MECH = {"bar": {"modes": 0}, "initial": {"height": 1e-3, "angle_deg": 90.0, "velocity": [0, 0, -0.5]}}
TRIB = {"tribology": {"source": "illustrative"}}
CIRCUIT = {"circuit": {"template": "resistive", "load_resistance": 12.0}}


def test_free_drop_scene_is_coupled_and_3d():
    sc = builtin_scene("free_drop")
    assert sc.kind == "coupled"
    assert sc.mech.friction.gamma == pytest.approx(sc.tribology.laws.gamma)
    assert sc.circuit.circuit.contact_current_factor is not None
    assert sc.circuit.circuit.arc.column_gradient > 0


def test_kinds_follow_the_sections():
    assert scene_from_dict(dict(MECH)).kind == "mechanics"
    assert scene_from_dict({**MECH, **TRIB}).kind == "mechanics"
    assert scene_from_dict({**MECH, **TRIB, **CIRCUIT}).kind == "coupled"
    sched = {"circuit": {"template": "resistive", "schedule": {"make": [1e-4], "break": [2e-4]}},
             "solver": {"t_end": 1e-3}}
    sc = scene_from_dict(sched)
    assert sc.kind == "circuit" and sc.mech is None and sc.t_end == pytest.approx(1e-3)


def test_set_revalidates_and_keeps_the_original():
    sc = builtin_scene("free_drop")
    changed = sc.set("initial.angle_deg", 45).set("circuit.load_resistance", 6.0)
    assert changed.mech.initial.angle_deg == 45 and changed.circuit.circuit.load.load_resistance == 6.0
    assert sc.mech.initial.angle_deg == 30.0
    with pytest.raises(ValueError, match="initial.height"):
        sc.set("initial.height", -1e-3)


@pytest.mark.parametrize("doc, message", [
    ({**MECH, **TRIB, "circuit": {"template": "capacitor"}}, "template = 'capacitor': allowed values"),
    ({**MECH, "tribology": {"fit": "missing.json"}, **CIRCUIT}, "missing.json"),
    ({**MECH, **CIRCUIT}, "needs \\[tribology\\]"),
    ({**MECH, **TRIB, **CIRCUIT, "friction": {"mu": 0.3}}, "friction.mu and \\[tribology\\]"),
    ({**MECH, **TRIB, **CIRCUIT, "friction": {"gamma": 0.3}}, "friction.gamma and \\[tribology\\]"),
    ({**MECH, "coupling": {"macro_step": 1e-6}}, "\\[coupling\\] settings need"),
    ({**MECH, "circuit": {"schedule": {"make": [1e-4], "break": [2e-4]}}}, "runs no mechanics"),
    ({"circuit": {"schedule": {"make": [1e-4], "break": [2e-4]}}, **TRIB}, "\\[tribology\\] is unused"),
    ({**MECH, **TRIB, "circuit": {"template": "resistive", "load_inductance": 1e-3}}, "load_inductance"),
    ({**MECH, **TRIB, "circuit": {"template": "netlist"}}, "needs netlist"),
    ({**MECH, **TRIB, "circuit": {"load_resistnce": 3.0}}, "did you mean 'load_resistance'"),
    ({**MECH, "circuitry": {}}, "unknown section \\[circuitry\\]"),
    ({**MECH, **TRIB, **CIRCUIT, "coupling": {"scheme": "gauss_seidel"}}, "coupling.scheme"),
    ({**MECH, **TRIB, **CIRCUIT, "coupling": {"macro_step": 1e-5, "max_macro_step": 1e-6}}, "max_macro_step"),
    # the step rules: fractions of a time scale (a step past the scale extrapolates beyond what the
    # last points say), the gap rule at most a few gaps
    ({**MECH, **TRIB, **CIRCUIT, "coupling": {"time_scale_fraction": 0.0}},
     "coupling.time_scale_fraction = 0.0: allowed range is \\(0.0, 1.0\\]"),
    ({**MECH, **TRIB, **CIRCUIT, "coupling": {"coil_time_scale_fraction": 2}}, "coupling.coil_time_scale_fraction = 2"),
    ({**MECH, **TRIB, **CIRCUIT, "coupling": {"gap_change_fraction": "1"}}, "coupling.gap_change_fraction = '1'"),
    ({**MECH, **TRIB, **CIRCUIT, "coupling": {"gap_change_fraction": 50.0}}, "allowed range is \\(0.0, 10.0\\]"),
    # the coil's circuit step rules: a whole count of points, a fraction of the time constant
    ({**MECH, **TRIB, **CIRCUIT, "coupling": {"coil_step_points": 0}},
     "coupling.coil_step_points = 0: expected a whole number in \\[1, 64\\]"),
    ({**MECH, **TRIB, **CIRCUIT, "coupling": {"coil_step_points": 2.5}}, "coupling.coil_step_points = 2.5"),
    ({**MECH, **TRIB, **CIRCUIT, "coupling": {"coil_point_fraction": 0.0}},
     "coupling.coil_point_fraction = 0.0: allowed range is \\(0.0, 1.0\\]"),
    ({**MECH, "tribology": {"source": "illustrative", "fit": "x.json"}}, "exactly one of"),
    ({**MECH, "tribology": {"source": "paper"}}, "only built-in source"),
    ({**MECH, **TRIB, "circuit": {"voltage": -5.0}}, "voltage"),
    ({**MECH, "output": {"plots": "yes"}}, "expected true or false"),
])
def test_bad_scene_gives_a_clear_error_before_running(doc, message):
    with pytest.raises((ValueError, FileNotFoundError), match=message):
        scene_from_dict(doc)


def test_scene_files_resolve_paths_next_to_them(tmp_path):
    from coupling.laws.tribology import default_fit

    default_fit().to_json(tmp_path / "fit.json")
    (tmp_path / "scene.toml").write_text(textwrap.dedent("""
        [bar]
        modes = 0
        [tribology]
        fit = "fit.json"
        [circuit]
        template = "inductive"
        load_resistance = 24.0
        load_inductance = 0.01
        arc = true
        """))
    sc = load_scene(tmp_path / "scene.toml")
    assert sc.kind == "coupled" and "fit.json" in sc.tribology.source
    with pytest.raises(FileNotFoundError, match="not found"):
        load_scene(tmp_path / "absent.toml")
    (tmp_path / "bad.toml").write_text("[bar\nlength = 1")
    with pytest.raises(ValueError, match="not valid TOML"):
        load_scene(tmp_path / "bad.toml")


def test_scene_pickles_as_its_document_for_other_processes():
    """ngspice is one instance per process, so parallel sweeps ship scenes to other
    processes: a scene travels as its document and is rebuilt (and validated) there."""
    import pickle
    from concurrent.futures import ProcessPoolExecutor

    sc = builtin_scene("free_drop").set("initial.angle_deg", 40.0)
    back = pickle.loads(pickle.dumps(sc))
    assert back.raw == sc.raw and back.name == sc.name and back.mech.initial.angle_deg == 40.0
    assert back.mech.friction.mu_at(2.0) == sc.mech.friction.mu_at(2.0)
    with ProcessPoolExecutor(max_workers=1) as pool:
        angle = pool.submit(_angle_of, sc).result(timeout=120)
    assert angle == 40.0


def _angle_of(scene):
    return scene.mech.initial.angle_deg


def test_update_validates_once_and_unset_restores_defaults():
    sc = builtin_scene("free_drop")
    # resting needs angle 0: one at a time the first change alone is invalid
    with pytest.raises(ValueError, match="initial.resting"):
        sc.set("initial.resting", True)
    rest = sc.update({"initial.resting": True, "initial.angle_deg": 0.0})
    assert rest.mech.initial.resting and rest.mech.initial.angle_deg == 0.0
    damped = sc.unset("contact.restitution").set("contact.damping", 1e7)
    assert damped.mech.contact.damping == 1e7 and damped.mech.contact.restitution is None
    with pytest.raises(ValueError, match="expected 'section.key'"):
        sc.unset("contact")
