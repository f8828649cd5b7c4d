"""[circuit] keys map 1:1 onto the circuit dataclasses; every error names the key the user wrote.

Also the current_source template from a scene: its keys, its bad inputs, and a prescribed-schedule
run whose closed-contact current is I_set less the output resistance's share (closed form).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import circuit as ck
from coupling import run
from coupling.core.scene import CIRCUIT_KEYS, scene_from_dict

MECH = {"bar": {"modes": 0}, "initial": {"height": 1e-3, "angle_deg": 90.0, "velocity": [0, 0, -0.5]}}
TRIB = {"tribology": {"source": "illustrative"}}


def _scene(circuit: dict):
    return scene_from_dict({**MECH, **TRIB, "circuit": circuit}, name="s.toml")


def _error(circuit: dict) -> str:
    with pytest.raises(ValueError) as info:
        _scene(circuit)
    text = str(info.value)
    assert "\n" not in text  # one line
    return text


@pytest.mark.parametrize("circuit, key, internal", [
    ({"voltage": -1.0}, "circuit.voltage = -1 V is out of range", "DCSource"),
    ({"load_resistance": 0.0}, "circuit.load_resistance = 0 ohm is out of range", "ResistiveLoad"),
    ({"source_resistance": -1.0}, "circuit.source_resistance = -1 ohm", "DCSource"),
    ({"wiring_inductance": 2.0}, "circuit.wiring_inductance = 2 H", "Wiring"),
    ({"template": "inductive", "load_inductance": 0.0}, "circuit.load_inductance = 0 H", "InductiveLoad"),
    ({"template": "capacitive", "bleed_resistance": 0.0}, "circuit.bleed_resistance = 0 ohm", "CapacitiveLoad"),
    ({"contact_capacitance": 1.0}, "circuit.contact_capacitance = 1 F", "SwitchCircuit"),
    ({"arc": {"min_voltage": -1.0}}, "circuit.arc.min_voltage = -1 V", "ArcModel"),
    ({"arc": {"breakdown_gradient": 1e3}}, "circuit.arc.breakdown_gradient = 1000 V/m needs breakdown_voltage",
     "ArcModel"),
    ({"snubber": {"resistance": 100.0, "capacitance": 1.0}}, "circuit.snubber.capacitance = 1 F", "Snubber"),
    ({"flyback": True}, "circuit.flyback is set but load is ResistiveLoad", "SwitchCircuit"),
    ({"reltol": 0.5}, "circuit.reltol = 0.5 is out of range", "SimulationOptions"),
    ({"method": "euler"}, "circuit.method = 'euler'", "SimulationOptions"),
    ({"template": "current_source", "current": 0.0}, "circuit.current = 0 A is out of range", "CurrentSource"),
    ({"template": "current_source", "current": -2.0}, "circuit.current = -2 A is out of range", "CurrentSource"),
    ({"template": "current_source", "current": 1.0, "compliance_voltage": 5.0, "load_resistance": 12.0},
     "circuit.compliance_voltage = 5 V is below circuit.current x (circuit.wiring_resistance + "
     "circuit.load_resistance) = 1 A x 12.01 ohm = 12.01 V", "CurrentSource"),
])
def test_value_errors_name_the_scene_key(circuit, key, internal):
    text = _error(circuit)
    assert text.startswith("s.toml: ")
    assert key in text
    assert internal not in text


def test_a_schedule_scene_runs_for_its_solver_t_end():
    """A circuit-only scene's length is its [solver] t_end (its one key there), held by the
    scene itself: the waveforms end there; left out, the key's documented default; a bad
    value is refused naming the key, and any other [solver] key as well."""
    schedule = {"schedule": {"make": [1e-4], "break": [3e-4]}, "max_step": 1e-5}
    scene = scene_from_dict({"circuit": schedule, "solver": {"t_end": 6e-4}})
    assert scene.mech is None and scene.t_end == 6e-4 and scene.set("solver.t_end", 8e-4).t_end == 8e-4
    assert run(scene).waveforms["time"].iloc[-1] == pytest.approx(6e-4, rel=1e-12)
    assert scene_from_dict({"circuit": schedule}).t_end == 0.05  # docs/scene_keys.md, [solver] t_end
    with pytest.raises(ValueError, match=r"^s.toml: solver.t_end = -1.0: must be > 0$"):
        scene_from_dict({"circuit": schedule, "solver": {"t_end": -1.0}}, name="s.toml")
    with pytest.raises(ValueError, match=r"only \[solver\] t_end may stay"):
        scene_from_dict({"circuit": schedule, "solver": {"t_end": 1e-3, "rtol": 1e-6}})


def test_schedule_errors_name_the_scene_key():
    doc = {"circuit": {"schedule": {"make": [2e-4], "break": [1e-4], "closed_resistance": 0.01}},
           "solver": {"t_end": 1e-3}}
    with pytest.raises(ValueError, match=r"circuit\.schedule\.make/break") as info:
        scene_from_dict(doc)
    assert "ContactSchedule" not in str(info.value)
    doc["circuit"]["schedule"] = {"make": [1e-4], "break": [2e-4], "closed_resistance": -1.0}
    with pytest.raises(ValueError, match=r"circuit\.schedule\.closed_resistance = -1 ohm"):
        scene_from_dict(doc)


@pytest.mark.parametrize("circuit, expected", [
    ({"arc": {"min_voltag": 10.0}}, "circuit.arc: unknown key 'min_voltag' (did you mean 'min_voltage'?); "
                                    "allowed keys: ayrton_c, ayrton_d, breakdown_gradient, breakdown_voltage, "
                                    "characteristic, column_gradient, formation_time, min_current, min_voltage, "
                                    "resistance, time_constant"),
    ({"snubber": {"resistanse": 1.0, "capacitance": 1e-9}}, "did you mean 'resistance'?"),
    ({"flyback": {"saturation": 1e-9}}, "did you mean 'saturation_current'?"),
    ({"complience_voltage": 10.0}, "[circuit]: unknown key 'complience_voltage' (did you mean "
                                   "'compliance_voltage'?); allowed keys: abstol, arc, bleed_resistance"),
])
def test_unknown_keys_list_the_allowed_ones_with_a_did_you_mean(circuit, expected):
    assert expected in _error(circuit)


def test_every_circuit_key_is_a_field_of_the_same_name():
    """Each [circuit] key is the field of that name of a dataclass a template builds (or the
    scene's own, or the ngspice options'): no table translates names."""
    from coupling.core.scene import TEMPLATES, CircuitSpec, template_classes

    classes = {CircuitSpec, ck.SimulationOptions}.union(*(template_classes(t) for t in TEMPLATES))
    fields = set().union(*({f.name for f in dataclasses.fields(cls)} for cls in classes))
    assert CIRCUIT_KEYS <= fields, CIRCUIT_KEYS - fields
    option_fields = {f.name for f in dataclasses.fields(ck.SimulationOptions)}
    assert option_fields <= CIRCUIT_KEYS  # every ngspice option a scene can set
    assert {"template", "schedule", "probes", "snubber", "flyback", "arc"} <= CIRCUIT_KEYS


def test_snubber_needs_both_values():
    assert "circuit.snubber needs both resistance (ohm) and capacitance (F); missing: capacitance" in _error(
        {"snubber": {"resistance": 100.0}})
    assert "circuit.snubber = true: give its resistance" in _error({"snubber": True})
    sn = _scene({"snubber": {"resistance": 47.0, "capacitance": 22e-9}}).circuit.circuit.snubber
    assert (sn.resistance, sn.capacitance) == (47.0, 22e-9)
    assert _scene({"snubber": False}).circuit.circuit.snubber is None


def test_omitted_keys_take_the_dataclass_defaults():
    """One source of defaults: the scene layer adds none of its own."""
    c = _scene({}).circuit.circuit
    assert c == ck.SwitchCircuit(contact_current_factor=c.contact_current_factor)
    cs = _scene({"template": "current_source", "load_resistance": 0.1}).circuit.circuit
    assert cs.source == ck.CurrentSource() and cs.load == ck.ResistiveLoad(0.1)
    assert _scene({}).circuit.options == ck.SimulationOptions()


def test_current_source_keys_build_the_source():
    sc = _scene({"template": "current_source", "current": 2.0, "compliance_voltage": 8.0,
                 "output_capacitance": 4.7e-6, "output_resistance": 2e4, "load_resistance": 0.05,
                 "arc": True})
    c = sc.circuit.circuit
    assert c.source == ck.CurrentSource(2.0, 8.0, 4.7e-6, 2e4)
    assert c.load == ck.ResistiveLoad(0.05) and c.arc == ck.ArcModel()


@pytest.mark.parametrize("circuit, expected", [
    ({"template": "current_source", "current": 1.0, "voltage": 24.0}, "circuit.voltage and circuit.current both "
                                                                      "name a source"),
    ({"voltage": 24.0, "current": 1.0}, "both name a source"),
    ({"template": "current_source", "source_resistance": 0.1}, "circuit.source_resistance do(es) not apply to "
                                                               "template 'current_source'"),
    ({"current": 1.0}, "circuit.current do(es) not apply to template 'resistive' (a current source needs "
                       "template = \"current_source\")"),
    ({"template": "current_source", "load_inductance": 1e-3}, "circuit.load_inductance do(es) not apply"),
    ({"template": "current_source", "flyback": True}, "circuit.flyback is set but load is ResistiveLoad"),
])
def test_current_source_contradictions(circuit, expected):
    assert expected in _error(circuit)


def test_current_source_schedule_run_closed_current_is_i_set_less_the_output_share():
    """Through the scene and run(): the prescribed-schedule kind, contact closed 0.1-0.3 ms."""
    circuit = {"template": "current_source", "current": 2.0, "compliance_voltage": 10.0, "output_resistance": 50.0,
               "output_capacitance": 1e-7, "load_resistance": 0.1, "wiring_resistance": 0.01,
               "wiring_inductance": 0.0, "max_step": 1e-6,
               "schedule": {"make": [1e-4], "break": [3e-4], "closed_resistance": 0.02}}
    sc = scene_from_dict({"circuit": circuit, "solver": {"t_end": 5e-4}, "output": {"plots": False}})
    assert sc.kind == "circuit"
    w = run(sc).waveforms
    t, i = w.time.to_numpy(), w.load_current.to_numpy()
    r_loop = 0.1 + 0.01 + 0.02
    closed = (t > 2e-4) & (t < 2.9e-4)
    assert np.allclose(i[closed], 2.0 * 50.0 / (50.0 + r_loop), rtol=1e-6, atol=0)
    src = sc.circuit.circuit.source
    assert w.contact_voltage.iloc[-1] == pytest.approx(src.open_voltage(1e-12), abs=1e-4)
    assert w.contact_voltage.iloc[0] == pytest.approx(src.open_voltage(1e-12), abs=1e-4)
