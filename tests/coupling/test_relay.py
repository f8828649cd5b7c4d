"""The relay as a whole (the default scene): its coil, magnet and armature drive the contact.

Physics checked against routes independent of the co-simulation: the static pull-in voltage
from the magnet's force at the rest gap and the return spring's preload; operate time
against coil voltage; the ordering every relay designer
knows (a freewheeling diode slows the release and lengthens the break arc: checked on
examples/relay_suppression.py's runs in test_examples.py); the coil's energy audit closing
at the step rules' second order.
"""

from __future__ import annotations

import copy
import dataclasses
import json

import numpy as np
import pytest
from scipy.optimize import brentq

from coupling import default_scene, run, scene_from_dict
from coupling.core.device import device

CONTACT_SECTIONS = ("bar", "mount", "rivet", "block", "initial", "contact", "tribology", "circuit", "coupling")


def armature_alone(voltage: float, t_end: float = 0.012):
    """The default relay's coil, magnet and armature without the contact spring: an actuator
    (the card's keys go with the blade it pushes)."""
    doc = copy.deepcopy(default_scene().raw)
    for key in CONTACT_SECTIONS:
        doc.pop(key, None)
    doc["armature"] = {k: v for k, v in doc["armature"].items() if not k.startswith("card_")}
    doc["coil"].update(voltage=voltage, off_time=t_end)
    doc["solver"] = {"t_end": t_end}
    return scene_from_dict(doc, name="armature alone")


def drive_defaults() -> dict:
    """The coil drive's default parts (circuit.CoilDrive's fields), which the scene keeps."""
    from circuit.coil_drive import CoilDrive

    return {f.name: f.default for f in dataclasses.fields(CoilDrive)}


def loop_resistance() -> float:
    """ohm: the coil's winding and its driver switch (on) in series, the steady current's."""
    return device(default_scene().raw).resistance + drive_defaults()["switch_resistance"]


def static_pull_in_voltage() -> float:
    """V at which the magnet's steady force at the rest gap (coil current V / R) holds the
    return spring's preload: lever F(V / R, g_rest) = preload torque."""
    raw = default_scene().raw
    spec = device(raw)
    arm, mag = raw["armature"], raw["magnet"]

    def excess(v):
        return mag["lever"] * float(spec.magnet.force_at_current(v / loop_resistance(), mag["rest_gap"])) \
            - arm["spring_preload"]

    return brentq(excess, 0.1, raw["coil"]["voltage"], xtol=1e-9)


def test_below_the_static_pull_in_voltage_the_armature_stays_on_its_rest_stop():
    v_pull = static_pull_in_voltage()
    assert 0.5 < v_pull < 12.0  # the default coil (12 V) pulls in with margin
    # 30 ms: ten of the open magnet's L / R (about 3 ms), the current steady at the end
    below, above = run(armature_alone(0.97 * v_pull, 0.03)), run(armature_alone(1.03 * v_pull, 0.03))
    for res in (below, above):
        assert res.status.value == "ok", res.message
    # 3 % under: the force never reaches the preload, nothing moves though the current
    # reached its steady value (exp(-10) short of it)
    assert below.relay["pull_in_current"] is None
    assert float(np.max(below.waveforms.armature_position)) == 0.0
    assert below.waveforms.coil_current.iloc[-1] == pytest.approx(0.97 * v_pull / loop_resistance(), rel=2e-4)
    # 3 % over: it leaves the stop where the static balance says, and arrives at the pole
    assert above.relay["armature_arrival"] is not None
    assert above.mechanics.armature["first_arrival"] == above.relay["armature_arrival"]
    # it lifts off (the mechanics' located event) at the static pull-in current: the force
    # there is psi^2 extrapolated over a macro step and the current is interpolated between
    # the circuit's points (measured 1.2e-5 apart)
    assert above.relay["pull_in_current"] == pytest.approx(v_pull / loop_resistance(), rel=1e-4)


def test_operate_time_falls_as_the_coil_voltage_rises():
    times = []
    for volts in (10.0, 12.0, 24.0):
        res = run(default_scene().update({"coil.voltage": volts, "solver.t_end": 0.008}))
        assert res.status.value == "ok", res.message
        times.append(res.relay["operate_time"])
    assert all(t is not None for t in times)
    assert times[0] > times[1] > times[2] > 0.0


def test_the_coil_energy_balance_closes_at_second_order_in_the_macro_step():
    """into_coil = copper + magnetic_change + armature_work + residual; the residual is the
    circuit's integration error on its points, second order in their spacing, which the
    macro step sets here (coupling.coil_step_points points per step; the bound from the coil's
    time constant, 37.5 us at its default fraction, left out: it would set the spacing at the
    coarsest step)."""
    residuals = []
    steps = (1e-4, 3e-5, 1e-5)
    for h in steps:
        res = run(armature_alone(12.0).update({"coupling.macro_step": h, "coupling.max_macro_step": h,
                                               "coupling.coil_point_fraction": 1.0}))
        e = res.relay["energy"]
        assert e["into_coil"] > 0 and e["copper"] > 0 and e["armature_work"] > 0
        residuals.append(abs(e["residual"]) / e["into_coil"])
    orders = np.log(np.array(residuals[:-1]) / residuals[1:]) / np.log(np.array(steps[:-1]) / steps[1:])
    assert np.all(orders > 1.7), (residuals, orders)
    assert residuals[-1] < 1e-4


def _without(doc: dict, section: str, key: str) -> dict:
    doc = copy.deepcopy(doc)
    doc[section].pop(key)
    return doc


def _with(doc: dict, section: str, key: str, value) -> dict:
    doc = copy.deepcopy(doc)
    doc[section][key] = value
    return doc


@pytest.mark.parametrize("change, message", [
    (lambda d: _without(d, "coil", "resistance"), "[coil] needs resistance (ohm, the winding) with magnet.model = "
                                                  "'flux_tubes'"),
    (lambda d: _without(d, "coil", "turns"), "[coil] needs turns"),
    (lambda d: _without(d, "magnet", "rest_gap"), "[magnet] needs rest_gap (m)"),
    (lambda d: _with(d, "coil", "turns", -4500), "coil.turns = -4500"),
    (lambda d: _with(d, "coil", "suppression", "varistor"), "coil.suppression = 'varistor': allowed values are"),
    (lambda d: _with(d, "coil", "off_time", 5e-4), "coil.off_time = 0.0005 s: must come after on_time"),
    (lambda d: _with(d, "coil", "voltage", 200.0), "coil.switch_breakdown = 100 V: must exceed the supply"),
    # (edge_time is checked before off_time's comparison uses it)
    (lambda d: _with(d, "coil", "edge_time", "fast"), "coil.edge_time = 'fast': must be a real number in s"),
    (lambda d: _with(d, "magnet", "model", "horseshoe"), "magnet.model"),
    # a needed key of a sub-table or of a table magnet left out: named (it was the constructor's TypeError)
    (lambda d: _with(d, "magnet", "working_gap", {}), "[magnet.working_gap] needs area"),
    (lambda d: _with(d, "magnet", "iron", [{"shape": "prism", "area": 1e-5, "material": "9SMnPb28"}]),
     "[magnet.iron[0]] needs length"),
    (lambda d: {**_without(d, "coil", "turns"), "magnet": {"model": "table", "rest_gap": 1e-3, "gaps": [1e-3, 2e-3]}},
     "[magnet] needs currents (A)"),
    (lambda d: {k: v for k, v in d.items() if k != "magnet"}, "[coil] needs [magnet]"),
])
def test_bad_coil_and_magnet_keys_are_one_line_naming_the_key(change, message):
    doc = change(default_scene().raw)
    with pytest.raises(ValueError) as err:
        scene_from_dict(doc, name="relay.toml")
    text = str(err.value)
    assert message in text and "\n" not in text, text


def test_the_suppression_is_a_scene_key():
    scene = default_scene().set("coil.suppression", "diode")
    assert scene.circuit.circuit.coil.suppression == "diode"


def test_an_actuator_alone_writes_its_folder_and_plots(tmp_path, capsys):
    """The plunger solenoid (no contact): the command line writes its tables, the coil panels
    as waveforms.png and a relay line; no contact plot is attempted."""
    from pathlib import Path

    from coupling.app.cli import main

    scene = Path(__file__).resolve().parents[2] / "examples" / "plunger_solenoid.toml"
    out = tmp_path / "out"
    assert main(["run", str(scene), "--out", str(out), "--plots", "--quiet"]) == 0
    (line,) = [x for x in capsys.readouterr().out.splitlines() if x.startswith("switchsim: relay:")]
    assert line.startswith("switchsim: relay: armature at the pole")
    # the plunger rebounds on its pole for the whole run (its stops' restitution is 0.99): the
    # line says how often and when it last arrived, as summary.json's armature block has them
    summary = json.loads((out / "summary.json").read_text())
    arm = summary["armature"]
    assert arm["pole_bounces"] > 10 and arm["last_arrival"] > arm["first_arrival"]
    assert f"({arm['pole_bounces']} rebound(s), last arrival {arm['last_arrival'] * 1e3:.4f} ms)" in line
    # the coil's two audits, as summary.json's relay.energy gives them
    energy = summary["relay"]["energy"]
    assert f"coil energy residual {energy['relative_residual']:.2g}" in line
    assert f"coil-armature interface {energy['interface_relative_residual']:.2g}" in line
    assert (out / "waveforms.png").stat().st_size > 10_000
    assert not (out / "openings.png").exists() and not (out / "normal_force.png").exists()
    html = (out / "waveforms.html").read_text()
    assert all(name in html for name in ("coil current", "magnetic force", "armature travel"))


def test_the_default_relay_reports_its_make_and_its_break_as_one_operation():
    """The coil-driven default: one operation, its make (the top-level bounce keys describe
    it) and its complete break; operate and release time are those operations' times less
    the coil's switching times."""
    res = run(default_scene())
    assert res.status.value == "ok", res.message
    (op,) = res.operations
    coil = default_scene().raw["coil"]
    assert op["make"]["bounces"] == res.bounce["bounces"] and op["make"]["settled"]
    assert op["make"]["time"] == pytest.approx(res.bounce["first_make"], abs=1e-12)
    assert op["break"]["complete"] and op["break"]["arc_duration"] > 0.0
    assert res.relay["operate_time"] == pytest.approx(op["make"]["time"] - coil["on_time"], abs=1e-12)
    assert res.relay["release_time"] == pytest.approx(op["break"]["time"] - coil["off_time"], abs=1e-12)
    # the contact makes after the armature has left its rest stop and before it reaches the
    # pole (the card's overtravel), and breaks after it has left the pole
    events = res.mechanics.events
    left_rest = min(e["time"] for e in events if e.get("stop") == "rest" and e["kind"] == "armature_stop_end")
    left_pole = [e["time"] for e in events if e.get("stop") == "pole" and e["kind"] == "armature_stop_end"
                 and e["time"] >= coil["off_time"]]
    assert left_rest < op["make"]["time"] < res.relay["armature_arrival"]
    assert left_pole and left_pole[0] < op["break"]["time"]


def test_a_release_the_run_does_not_reach_is_said_missing_and_how_to_reach_it():
    """Through a diode the default relay's flux decays slowly: the contact is still closed
    3 ms after the coil's switch-off, when the 12 ms run ends (its release takes 6.5 ms,
    examples/relay_suppression.py). release_time is then None, and a warning says it is
    missing and what to lengthen; run past the release, the warning goes and the release
    time is there. Without suppression (a 0.32 ms release) there is no such line."""
    def missing(result):
        return [w for w in result.warnings if w.startswith("relay: the contact was still closed")]

    diode = default_scene().set("coil.suppression", "diode")
    short = run(diode)
    assert short.relay["operate_time"] is not None and short.relay["release_time"] is None
    (line,) = missing(short)
    assert "3 ms after the coil was switched off" in line and "[solver] t_end" in line and "\n" not in line
    longer = run(diode.set("solver.t_end", 0.02))
    assert longer.relay["release_time"] > 3e-3 and not missing(longer)
    assert not missing(run(default_scene()))


def test_run_check_compares_operate_and_release_time():
    """switchsim run --check judges a relay's operate and release time as it judges the make
    times: the refined rerun's change against max(1 us, 1 % of the switching window)."""
    from coupling.app.accuracy import compare, metrics_of, time_tolerance, tip_intervals

    res = run(default_scene())
    base = metrics_of(res)
    assert base["operate_time"] == res.relay["operate_time"] and base["release_time"] == res.relay["release_time"]
    tips = tip_intervals(res)
    late = dict(base, release_time=base["release_time"] + 2 * time_tolerance(base))
    assert compare(base, late, tips, tips)["moved"] == ["release_time"]
    assert compare(base, dict(base), tips, tips)["moved"] == []


def test_an_actuators_circuit_table_sets_ngspices_options_and_nothing_else():
    """An armature alone has no contact: its circuit is the coil's drive, and [circuit] may set
    ngspice's options for it (before, any [circuit] table built a switch template whose
    contact nothing drove, and the run failed at t = 0). The coil's energy residual is the
    circuit's integration error on its points: a tenth of ngspice's step makes it far smaller
    (second order in the points' spacing: a hundredth, less where the macro steps already set
    the spacing). Both runs leave ngspice its own steps otherwise (one point per macro step
    at least, no bound from the coil's time constant): the coupling's default bounds would
    set the spacing themselves."""
    own_steps = {"coupling": {"coil_step_points": 1, "coil_point_fraction": 1.0}}
    doc = copy.deepcopy(armature_alone(12.0).raw) | own_steps
    coarse = scene_from_dict(doc, name="actuator.toml")
    doc["circuit"] = {"max_step": 5e-6}
    fine = scene_from_dict(doc, name="actuator.toml")
    assert fine.circuit.options.max_step == 5e-6
    residual = [abs(run(scene).relay["energy"]["relative_residual"]) for scene in (coarse, fine)]
    assert residual[1] < 0.02 * residual[0], residual  # (measured 3.4e-3 of it)
    doc["circuit"] = {"template": "resistive", "voltage": 24.0}
    with pytest.raises(ValueError) as err:
        scene_from_dict(doc, name="actuator.toml")
    text = str(err.value)
    assert "circuit.template, circuit.voltage: an armature alone (no [bar]) has no contact" in text, text
    assert "\n" not in text
