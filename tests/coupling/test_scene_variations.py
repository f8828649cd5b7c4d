"""Property tests: sweep-like variations of a scene (Scene.update, a sweep's check) with
generated values. A variation is a valid scene or one ValueError line that starts with the
scene, names a scene key as the user writes it (never an internal class), and, for a value
outside a key's allowed range, names that key; never another exception."""

from __future__ import annotations

import math
import re

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from coupling.core.scene import builtin_scene
from coupling.app.sweep import Sweep

BASE = builtin_scene("relay_force")  # a relay: clamped blade, rivets, force, materials' laws, circuit, arc

# the dataclasses behind the scene, whose names an error must not show
INTERNAL = re.compile(r"\b(DCSource|CurrentSource|Wiring|ResistiveLoad|InductiveLoad|CapacitiveLoad|Snubber|"
                      r"FlybackDiode|ArcModel|SwitchCircuit|NetlistCircuit|SimulationOptions|ContactSchedule|"
                      r"CouplingOptions|OutputOptions|MetricSettings|MechScene|Bar|Block|Contact|Friction|Initial|"
                      r"SolverOptions|Mount|PointForce|Spring|Rivet|HolmResistance|ConstantResistance)\b")
SCENE_KEY = re.compile(r"\b[a-z_]+(\[\d+\])?\.[a-z_]+|\[[a-z_.]+\]")

# values outside each key's allowed range (SI), on the relay_force scene
OUT_OF_RANGE = {
    "bar.length": [0.0, -0.015], "bar.youngs_modulus": [0.0, -1e9], "bar.poisson_ratio": [0.5, -1.0],
    "bar.density": [0.0], "bar.modal_damping": [1.0, -0.1], "bar.modes": [-1, 41, 2.5, "some"],
    "block.radius": [0.0, -1e-3], "block.poisson_ratio": [0.6],
    "initial.height": [-1e-4], "contact.restitution": [0.0, 1.2], "contact.reference_speed": [0.0, -1.0],
    "solver.rtol": [0.0, 1e-3], "solver.t_end": [0.0, -1.0], "solver.max_steps": [0, 2.5],
    "mount.position": [-0.001, 1.0], "environment.gravity": [-9.81],
    "circuit.voltage": [0.0, -24.0, 2e5], "circuit.source_resistance": [-1.0], "circuit.load_resistance": [0.0],
    "circuit.wiring_inductance": [-1e-6, 2.0], "circuit.contact_capacitance": [-1e-12, 1e-3],
    "circuit.reltol": [0.0, 0.5], "circuit.temperature": [-300.0], "circuit.wall_timeout": [0.0],
    "circuit.method": ["euler"], "circuit.arc.min_voltage": [0.0, 2e3], "circuit.arc.formation_time": [1.0],
    "coupling.macro_step": [0.0, -1e-6], "coupling.scheme": ["gauss"], "coupling.onset_penetration": [-1e-9],
    "output.history_max_rows": [-1, 1.5], "output.csv": [1, "yes"], "metrics.settle_window": [-1e-3],
    "metrics.arc_toggle_limit": [-1, 0.5], "tribology.mu": [0.0, -0.3], "tribology.feedback": [0, "no"],
}
ANY_KEYS = sorted(OUT_OF_RANGE) + ["initial.angle_deg", "block.offset", "contact.law", "circuit.template",
                                   "circuit.arc", "circuit.snubber", "friction.max_ratio", "tribology.source",
                                   "circuit.arc.column_gradient", "coupling.max_macro_step", "output.plots",
                                   "bar.width", "bar.diameter", "force.magnitude"]
anything = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**6, 10**6), st.booleans(),
    st.text(max_size=6), st.lists(st.floats(-1, 1), max_size=4), st.none(),
    st.dictionaries(st.sampled_from(["a", "resistance", "capacitance", "min_voltage"]), st.floats(0, 1), max_size=2),
)


def toml_like(value):
    """What a TOML document can hold (no None)."""
    return "none" if value is None else value


def check_message(err: ValueError, values=()) -> str:
    text = str(err)
    assert "\n" not in text and text.strip(), text
    echoed = text
    for value in values:  # the user's own values, echoed back, may spell anything
        echoed = echoed.replace(repr(value), "")
    assert not INTERNAL.search(echoed), text
    assert SCENE_KEY.search(text), text
    return text


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(changes=st.dictionaries(st.sampled_from(ANY_KEYS), anything.map(toml_like), min_size=1, max_size=3))
def test_any_variation_is_a_scene_or_one_named_line(changes):
    try:
        BASE.update(changes)
    except ValueError as err:
        assert check_message(err, changes.values()).startswith("relay_force scene: ")


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_a_value_out_of_range_names_its_key_in_set_and_in_a_sweep(data):
    key = data.draw(st.sampled_from(sorted(OUT_OF_RANGE)))
    value = data.draw(st.sampled_from(OUT_OF_RANGE[key]))
    good = data.draw(st.sampled_from([None] + [v for v in _valid(key)]))
    try:
        BASE.set(key, value)
    except ValueError as err:
        text = check_message(err)
    else:
        raise AssertionError(f"{key} = {value!r} was accepted")
    assert text.startswith("relay_force scene: ") and f"{key} = " in text, text
    values = [value] if good is None else [good, value]
    try:
        Sweep.grid(BASE, {key: values}).check()
    except ValueError as err:
        sweep_text = check_message(err)
    else:
        raise AssertionError(f"a sweep over {key} = {values!r} was accepted")
    assert sweep_text.startswith("sweep run ") and f"{key} = " in sweep_text, sweep_text


def _valid(key: str) -> list:
    """A value of the key the relay_force scene accepts (its own), to mix into a sweep."""
    node = BASE.raw
    for part in key.split(".")[:-1]:
        node = node.get(part, {}) if isinstance(node, dict) else {}
    value = node.get(key.split(".")[-1]) if isinstance(node, dict) else None
    return [] if value is None or (isinstance(value, float) and not math.isfinite(value)) else [value]
