"""A run is "ok" only when it is physically sound: the bounds as pure laws, the energy
scale of a resting bar, the rtol range, an unsound run's status and exit code."""

from __future__ import annotations

import json
import math
import textwrap

import pytest

from coupling.core import soundness
from coupling.app.cli import main
from coupling.core.scene import scene_from_dict


def test_speed_bound_is_the_speed_that_carries_the_whole_energy():
    m, e = 0.185, 0.23
    v = soundness.speed_bound(e, m)
    assert 0.5 * m * v**2 == pytest.approx(e, rel=1e-14)


def test_penetration_bound_is_where_the_hertz_spring_stores_the_whole_energy():
    k, e = 1.088e10, 0.23
    y = soundness.penetration_bound(e, k)
    # U(y) = int_0^y k s^1.5 ds = (2/5) k y^2.5
    assert 0.4 * k * y**2.5 == pytest.approx(e, rel=1e-12)


def test_penetration_bound_with_the_weight_pressing_the_tip_in():
    k, e, w = 1.088e10, 1e-9, 1.8
    y = soundness.penetration_bound(e, k, w)
    assert 0.4 * k * y**2.5 == pytest.approx(e + w * y, rel=1e-12)
    # a bar resting on a tip (E ~ 0) can still be pressed to its static depth (W/k)^(2/3) and beyond
    assert y > (w / k) ** (2 / 3)


def test_loop_current_bound_is_twice_the_loop_current():
    assert soundness.loop_current_bound(24.0, 12.05) == pytest.approx(2 * 24.0 / 12.05)


@pytest.mark.parametrize("check, inside, outside", [
    (lambda x: soundness.energy_problem(x, 0.2, 1e-3), 1.9e-4, 2.1e-4),
    (lambda x: soundness.kinetic_problem(x, 0.2), 0.2, 0.21),
    (lambda x: soundness.speed_problem(x, 1.5), 1.5, 1.6),
    (lambda x: soundness.penetration_problem(x, 7e-5, 5e-3), 7e-5, 7.2e-5),
    (lambda x: soundness.current_problem(x, 3.98), 3.98, 4.1),
])
def test_each_bound_passes_inside_and_names_the_cause_and_the_fix_outside(check, inside, outside):
    assert check(inside) is None
    message = check(outside)
    assert message is not None and "rtol" in message and "\n" not in message


def test_a_penetration_deeper_than_the_tip_is_unsound_whatever_the_energy():
    assert soundness.penetration_problem(6e-3, 1.0, 5e-3) is not None


def test_a_standing_bar_at_rest_is_judged_against_the_energy_it_could_release():
    """The audit's case: relative residual 0.14 = 1.4e-9 J over a 1e-8 J kinetic energy.
    The scale is m g (L/2 - R): the potential energy of the centre above the lying bar."""
    from coupling import run

    scene = scene_from_dict({"initial": {"angle_deg": 90.0, "resting": True, "velocity": [0.0, 0.0, 0.0]},
                             "bar": {"modes": 3}, "solver": {"t_end": 2e-3}})
    res = run(scene).mechanics
    bar = scene.mech.bar
    assert res.energy_scale == pytest.approx(bar.mass * scene.mech.gravity * (bar.length / 2 - bar.tip_radius),
                                             rel=1e-5)
    e = res.energy
    assert e["relative_residual"] < 1e-6
    assert soundness.assess(run(scene))["problems"] == []


def test_rtol_above_the_range_shown_sound_is_refused_before_the_run(tmp_path, capsys):
    scene = tmp_path / "loose.toml"
    scene.write_text("[solver]\nrtol = 1e-3\n")
    assert main(["run", str(scene), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "solver.rtol = 0.001" in err[0] and "1e-05]" in err[0]
    assert not (tmp_path / "out").exists()


STRICT = """
        [bar]
        modes = 2
        [initial]
        height = 0.0002
        angle_deg = 30.0
        velocity = [0.0, 0.0, -0.5]
        [solver]
        t_end = 0.001
        energy_tolerance = 1e-13
        [output]
        plots = false
        """


def test_an_unsound_run_ends_unsound_with_exit_3_and_names_cause_and_fix(tmp_path, capsys):
    """A run whose energy audit misses its tolerance: written, status 'unsound', exit 3."""
    scene = tmp_path / "strict.toml"
    scene.write_text(textwrap.dedent(STRICT))
    out = tmp_path / "out"
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 3
    err = capsys.readouterr().err
    assert "unsound: energy audit" in err and "rtol" in err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "unsound"
    s = summary["soundness"]
    assert s["relative_residual"] > 1e-13 and len(s["problems"]) == 1
    # the other bounds hold, with room: a sound impact is far inside them
    assert s["max_speed"] < s["speed_bound"] and s["max_penetration"] < s["penetration_bound"]
    assert math.isfinite(s["energy_scale"]) and s["energy_scale"] > 0


def test_a_loose_integration_is_caught_and_the_fix_the_message_names_works():
    """The mechanics default over its first impacts (5 ms): at rtol 1e-4 (outside the allowed
    range, set here on purpose past the validation) the audit misses by ~4x its tolerance;
    10 times tighter, the loosest allowed rtol, the same run is sound."""
    import dataclasses

    import mech
    from coupling.core.results import CoupledResult

    base = mech.default_scene()
    wrapper = scene_from_dict({"bar": {"modes": 0}})  # a mechanics-only scene to hold the result

    def judged(rtol):
        solver = dataclasses.replace(base.solver, t_end=5e-3)
        object.__setattr__(solver, "rtol", rtol)  # past the validated range on purpose
        res = mech.simulate(dataclasses.replace(base, solver=solver))
        return soundness.assess(CoupledResult(scene=wrapper, mechanics=res, waveform_columns=None, stats={}))

    loose = judged(1e-4)
    assert len(loose["problems"]) >= 1 and "rtol" in loose["problems"][0]
    assert loose["relative_residual"] > 1e-3
    tight = judged(1e-5)
    assert tight["problems"] == [] and tight["relative_residual"] < 1e-4


def test_the_api_and_a_sweep_row_judge_the_same_run_the_same_way(tmp_path):
    """One judge where the result is made: coupling.run and a sweep row say "unsound" with the
    same problem the command line names (before, only the command line judged)."""
    from coupling import load_scene, run
    from coupling.app.sweep import execute
    from coupling.core.results import RunStatus

    path = tmp_path / "strict.toml"
    path.write_text(textwrap.dedent(STRICT))
    result = run(load_scene(path))
    assert result.status is RunStatus.UNSOUND and result.status == "unsound"
    assert len(result.problems) == 1 and result.problems[0].startswith("energy audit")
    assert result.summary["status"] == "unsound" and result.summary["message"] == result.problems[0]
    sound = run(load_scene(path).set("solver.energy_tolerance", 1e-3))
    assert sound.status is RunStatus.OK and not sound.problems and "message" not in sound.summary
    doc = {"base": load_scene(path).raw, "common": {}, "base_dir": str(tmp_path), "base_name": "strict",
           "waveforms": False}
    row = execute(doc, {"run_id": "r0", "name": "strict", "params": {}}, None)
    assert row["status"] == "unsound" and row["error"] == result.problems[0]


def test_a_changeover_on_a_small_nc_load_is_bounded_by_both_throws_not_no_alone():
    """The changeover's load_current is the common's lead: resting on NC it carries
    V / (R_source + R_wiring + R_nc) (+ the closed contact's milliohms). With NO's 1 kohm
    alone the bound was 2 x 24 V / 1 kohm = 48 mA and the 44 A run was judged unsound."""
    from pathlib import Path

    import numpy as np

    from coupling import load_scene, run

    example = Path(__file__).resolve().parents[2] / "examples" / "changeover_relay.toml"
    scene = load_scene(example).update({
        "solver.t_end": 2e-3,  # the blade rests on NC under its preload; the coil is off until 6 ms
        "circuit.load_resistance": 1e3, "circuit.nc_load_resistance": 0.5,
        "output.csv": False, "output.plots": False})
    res = run(scene)
    assert res.status.value == "ok", res.message
    circ = scene.circuit.circuit
    expected = circ.source.voltage / (circ.source.source_resistance + circ.wiring.wiring_resistance + 0.5)
    # the closed silver contact adds milliohms (Holm) to the 0.55 ohm loop: < 1 %
    assert float(np.asarray(res.waveform_columns["load_current"])[-1]) == pytest.approx(expected, rel=1e-2)
    verdict = soundness.assess(res)
    assert verdict["problems"] == []
    assert verdict["load_current_bound"] >= expected
