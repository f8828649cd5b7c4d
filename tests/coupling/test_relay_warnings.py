"""Relay runs that said "ok" where a designer is misled: the warnings that now say so
(coupling/core/diagnostics.py, docs/coupling.md "Warnings") and the arc energy that
counted the open gap's leakage (coupling/core/metrics.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from circuit.arc import ArcModel
from coupling import default_scene
from coupling.core.diagnostics import arc_floor, held_arc_current
from coupling.core.master import run
from coupling.core.metrics import arc_duration, arc_energy, bounce_metrics
from coupling.core.scene import load_scene, scene_from_dict

OFF = 9e-3  # s: the default relay's coil.off_time
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _relay_lines(result, start: str) -> list[str]:
    return [w for w in result.summary["warnings"] if w.startswith(start)]


def _pole_events(result, kind: str, before: float) -> list[float]:
    return [float(e["time"]) for e in result.mechanics.events
            if e.get("stop") == "pole" and e["kind"] == kind and float(e["time"]) <= before]


@pytest.fixture(scope="module")
def default_run():
    return run(default_scene())


def test_the_default_relay_seated_at_the_pole_gets_none_of_the_new_lines(default_run):
    """The default relay's armature seats on the pole (an armature_seat event) before its coil
    is switched off, its contact makes and its break clears: no line about either."""
    assert default_run.summary["warnings"] == []
    assert _pole_events(default_run, "armature_seat", OFF)


def test_an_armature_that_leaves_the_pole_while_the_coil_is_on_is_warned():
    """armature.spring_preload = 4e-3 (the audit's pre4.toml): the armature bounces off the pole
    at 7.66 ms and hovers a few um short of it with the contact closed until the coil is switched
    off; drop_out_current is then missing. The line names the departure the mechanics located."""
    res = run(default_scene().set("armature.spring_preload", 4e-3))
    left = _pole_events(res, "armature_stop_end", OFF)
    arrived = _pole_events(res, "armature_stop_start", OFF) + _pole_events(res, "armature_seat", OFF)
    assert left and max(left) > max(arrived)  # off the pole at the switch-off
    assert res.relay["armature_arrival"] is not None and res.relay["drop_out_current"] is None
    w = res.waveform_columns
    assert np.interp(OFF, w["time"], w["normal_force"]) > 0.0  # the contact spring holds it off
    lines = _relay_lines(res, "relay: the armature left the pole")
    assert len(lines) == 1, res.summary["warnings"]
    assert f"at {max(left) * 1e3:.4g} ms" in lines[0] and "balance against the contact spring" in lines[0]


def test_an_actuator_rebounding_off_its_pole_stop_is_not_held_off():
    """examples/plunger_solenoid.toml: the plunger (no spring, no contact) bounces on its pole
    stop and is in flight at the run's end with the coil on; nothing holds it off, so no line."""
    res = run(load_scene(EXAMPLES / "plunger_solenoid.toml"))
    end = res.scene.t_end
    left, back = _pole_events(res, "armature_stop_end", end), _pole_events(res, "armature_stop_start", end)
    assert left and back and max(left) > max(back)  # off the pole at the end, after many arrivals
    assert not any(w.startswith("relay: the armature") for w in res.summary["warnings"])


@pytest.fixture(scope="module")
def held_off_run():
    """The default relay with a 0.4 mm contact gap breaking 30 V into 6 ohm (the audit's dc5a):
    the overtravel the card asks is more than the magnet can pull, and the arc at the full gap
    stays below the source."""
    return run(default_scene().set("initial.height", 4e-4).set("circuit.voltage", 30.0)
               .set("circuit.load_resistance", 6.0))


def test_an_armature_that_never_reaches_the_pole_while_the_coil_is_on_is_warned(held_off_run):
    res = held_off_run
    assert not _pole_events(res, "armature_stop_start", OFF) and res.relay["armature_arrival"] is None
    assert res.bounce["first_make"] is not None  # the contact made: its force is the magnet's balance
    lines = _relay_lines(res, "relay: the armature never reached the pole")
    assert len(lines) == 1, res.summary["warnings"]
    assert "(1 ms to 9 ms, coil.off_time)" in lines[0] and "[initial] height" in lines[0]


def test_a_dc_break_that_cannot_clear_in_its_gap_says_so_not_run_longer(held_off_run):
    """At the run's end the simulated arc current is the source's steady operating point on the
    arc model's characteristic at the gap of that moment (ngspice's solution against KVL:
    (E - U_min - E_col d) / (R_loop + R_arc), within 1 %: the 1 uH wiring's time constant is
    0.2 us, the gap still moves); that point is above min_current, so no t_end clears it."""
    res = held_off_run
    w = res.waveform_columns
    arc = res.scene.circuit.circuit.arc
    loop = 0.05 + 0.0 + 6.0  # ohm: the default's source and wiring resistance and this load
    expected = held_arc_current(arc, float(w["gap"][-1]), 30.0, loop)
    assert expected is not None and expected > arc.min_current
    assert abs(w["arc_current"][-1]) == pytest.approx(expected, rel=1e-2)
    brk = [op["break"] for op in res.operations if "break" in op]
    assert brk and brk[-1]["complete"] is False
    lines = [x for x in res.summary["warnings"] if "its arc still burned" in x]
    assert len(lines) == 1
    assert "cannot clear in this gap" in lines[0] and "run longer" not in lines[0]


def test_the_default_breaks_arc_goes_out_where_the_source_cannot_hold_min_current(default_run):
    """24 V behind 10.05 ohm against 12 V + 2e4 V/m x 0.5 mm: (24 - 22) / 10.1 = 0.2 A < 0.4 A,
    so the arc cannot be held at the rest gap, and the simulated break did clear."""
    arc = default_run.scene.circuit.circuit.arc
    held = held_arc_current(arc, 5e-4, 24.0, 10.05)
    assert held == pytest.approx((24.0 - 12.0 - 2e4 * 5e-4) / (10.05 + arc.resistance), rel=1e-12)
    assert held < arc.min_current
    assert all(op["break"]["complete"] for op in default_run.operations if "break" in op)


@pytest.mark.parametrize("arc", [ArcModel(column_gradient=2e4),
                                 ArcModel(characteristic="ayrton", ayrton_c=11.66, ayrton_d=1.054e4,
                                          column_gradient=2e3)])
def test_the_held_arc_current_is_where_the_source_line_meets_the_arc_characteristic(arc):
    """KVL at the operating point: E - R I = U_arc(d, I) for either characteristic (the Ayrton
    one the stable, larger root); a source below U_min + E_col d holds none."""
    e, r, d = 30.0, 2.0, 4e-4
    i = held_arc_current(arc, d, e, r)
    assert i is not None and i > 0.0
    assert e - r * i == pytest.approx(arc_floor(arc, d, i), rel=1e-12)
    assert held_arc_current(arc, d, arc.min_voltage + arc.column_gradient * d - 0.1, r) is None


def test_an_armature_at_the_pole_whose_contact_never_makes_is_warned():
    """initial.height = 0.5 (a gap in mm written as m): the armature reaches the pole, the card's
    0.0118 m/rad x 0.045 rad - 0.1 mm = 0.431 mm of travel cannot close a 500 mm gap."""
    res = run(default_scene().set("initial.height", 0.5).set("solver.t_end", 7e-3))
    assert res.relay["armature_arrival"] is not None and res.bounce["first_make"] is None
    lines = _relay_lines(res, "relay: the armature reached the pole")
    assert len(lines) == 1, res.summary["warnings"]
    card = 0.0118 * 0.045 - 1e-4
    assert f"{card * 1e3:.4g} mm" in lines[0] and "contact gap of 500 mm" in lines[0]


@pytest.mark.parametrize("keys, words", [
    ({"coil.on_time": 3e-3, "coil.off_time": 4e-3}, "coil.on_time = 3 ms is at or after the run's end"),
    ({"coil.off_time": 5e-3}, "coil.off_time = 5 ms is at or after the run's end"),
])
def test_coil_times_beyond_the_runs_end_are_warned_with_key_value_and_t_end(keys, words):
    scene = default_scene().set("solver.t_end", 2e-3)
    for key, value in keys.items():
        scene = scene.set(key, value)
    res = run(scene)
    lines = [w for w in res.summary["warnings"] if words in w]
    assert len(lines) == 1, res.summary["warnings"]
    assert "[solver] t_end = 2 ms" in lines[0]
    assert res.relay["release_time"] is None


def test_arc_energy_counts_only_where_the_arc_burns():
    """A 12 V arc carrying 1 A at the samples in [1, 3) ms (10 us apart), and the extinguished
    gap's 1 nS leakage at 100 V elsewhere: duration and energy take the steps whose left sample
    burns, 2 ms, the last one (into the extinguished sample) a trapezoid from 12 W to 1e-5 W;
    the leakage's 1e-5 W x 8 ms (8e-8 J) is not in it."""
    t = np.linspace(0.0, 10e-3, 1001)
    burning = (t >= 1e-3 - 1e-12) & (t < 3e-3 - 1e-12)
    v = np.where(burning, 12.0, 100.0)
    i = np.where(burning, 1.0, 1e-9 * v)
    assert arc_duration(t, i, 0.0, 10e-3) == pytest.approx(2e-3, rel=1e-9)
    h = 1e-5
    assert arc_energy(t, v, i) == pytest.approx(12.0 * (2e-3 - h) + 0.5 * (12.0 + 1e-5) * h, rel=1e-9)
    assert arc_energy(t, v, np.where(burning, 0.0, i)) == 0.0


def test_a_contact_that_never_closed_has_no_arc_energy():
    """A bar falling 50 um short of the block with the arc model on: the arc branch carries
    only the open gap's leakage, 1 nS x 24 V, which the old trapezoid counted as arc energy."""
    res = run(scene_from_dict({
        "bar": {"modes": 0}, "initial": {"height": 1e-3, "angle_deg": 90.0, "velocity": [0.0, 0.0, -0.5]},
        "solver": {"t_end": 1e-4}, "tribology": {"source": "illustrative"},
        "circuit": {"template": "resistive", "voltage": 24.0, "arc": True}, "output": {"plots": False}},
        name="never"))
    w = res.waveform_columns
    assert res.bounce["first_make"] is None and np.abs(w["arc_current"]).max() > 0.0  # the leakage
    assert res.bounce["arc_energy"] == 0.0
    direct = bounce_metrics([], res.scene.t_end, False, w["time"], w["contact_voltage"], None, w["arc_current"])
    assert direct["arc_energy"] == 0.0


def test_a_makes_arc_energy_is_its_bounce_openings_arc_energies(default_run):
    """The make's arc energy and the openings' rows now add the same burning steps: the make's
    is the sum of its bounce openings' (the old masked trapezoid also took half a step past
    each opening's ends, 5e-7 J of the default relay's 0.0119 J). Two sums of one set of
    terms in another order: equal to round-off (1e-9 relative)."""
    make = default_run.operations[0]["make"]
    rows = [r for r in default_run.bounce["openings"] if r["reclosed"]][:make["bounces"]]
    assert make["bounces"] >= 1 and len(rows) == make["bounces"]
    assert make["arc_energy"] == pytest.approx(sum(r["arc_energy"] for r in rows), rel=1e-9)
    assert make["arc_energy"] > 0.0
