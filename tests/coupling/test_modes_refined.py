"""modes = "auto" checked on the run's own impacts (coupling.run; mech.model.refined_mode_count).

The count is chosen before the run from an estimated impact speed; a driven mechanism's
impacts may be much faster. The Hertz contact time falls as v^(-1/5), so the cutoff rises:
where the run's fastest impact asks for more modes, the run is made again with them.
"""

from __future__ import annotations

import copy

import pytest

from coupling import builtin_scene, run, scene_from_dict

FORCE_FACTOR = 30.0  # the relay's armature force x 30: the rivet strikes at ~7.8 m/s, not 1 m/s


def hard_pressed_relay(**changes):
    """relay_force's mechanics alone, its force 30 times larger, to the end of the first impact."""
    raw = copy.deepcopy(builtin_scene("relay_force").raw)
    for key in ("circuit", "tribology", "coupling", "output", "duty"):
        raw.pop(key, None)
    raw["force"][0]["value"] = [v * FORCE_FACTOR for v in raw["force"][0]["value"]]
    raw["solver"]["t_end"] = 2.5e-4
    raw["friction"] = {"mu": 0.3}
    scene = scene_from_dict(raw, name="hard-pressed relay")
    for key, value in changes.items():
        scene = scene.set(key, value)
    return scene


def first_peak(result) -> float:
    return float(result.mechanics.contacts.peak_force.iloc[0])


def test_a_faster_impact_than_estimated_reruns_with_the_count_it_asks_for():
    auto = run(hard_pressed_relay())
    refined = auto.stats["modes_refined"]
    chosen = refined["modes"]
    # estimated at 1 m/s: 11 bending modes; the impact came at ~7.8 m/s: t_c shorter by
    # 7.8^(1/5) = 1.5, and with it the cutoff higher
    assert chosen["bending"] > 11
    assert auto.summary["solver"]["modes"] == chosen["axial"] + chosen["bending"]
    assert "refined after a first run" in auto.summary["solver"]["modes_rule"]
    first = run(hard_pressed_relay(**{"bar.modes": {"axial": 3, "bending": 11}}))
    converged = run(hard_pressed_relay(**{"bar.modes": {"axial": 3, "bending": 30}}))
    # the first impact's peak force moves towards the converged one (measured 147.6 N with
    # 11 bending modes, 145.9 N with the refined 13, 144.4 N with 30)
    assert abs(first_peak(auto) - first_peak(converged)) < 0.6 * abs(first_peak(first) - first_peak(converged))


@pytest.mark.parametrize("name", ["relay_force", "free_drop"])
def test_an_estimate_the_impacts_confirm_runs_once(name):
    """The shipped scenes' impacts ask for no more modes than chosen: one run, no refinement."""
    scene = builtin_scene(name)
    raw = copy.deepcopy(scene.raw)
    for key in ("circuit", "tribology", "coupling", "output", "duty"):
        raw.pop(key, None)
    res = run(scene_from_dict(raw, name=name))
    assert "modes_refined" not in res.stats
    assert res.summary["solver"]["modes_rule"].startswith("auto:")
