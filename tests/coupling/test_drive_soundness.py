"""Every drive kind is judged against an energy scale that counts it: each sound scene is
"ok" with its energy residual stated, and the same scene integrated wrongly on purpose (a
kick of 1 % to every speed, twenty times over the run) is still unsound."""

from __future__ import annotations

import numpy as np
import pytest

from coupling import run, scene_from_dict
from coupling.core.results import CoupledResult
from coupling.core.soundness import assess
from mech.solver import ImpactSolver

STEEL = dict(youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)


def blade(**over) -> dict:
    """A 20 x 3 x 0.3 mm steel blade clamped at its tip-1 end, a rivet 0.1 mm above the block."""
    doc = {
        "bar": dict(length=0.02, width=0.003, thickness=0.0003, tip_radius=0.0016, **STEEL,
                    modes={"axial": 1, "bending": 6}, modal_damping=0.02),
        "mount": dict(kind="clamp", position=0.02),
        "rivet": [dict(position=0.0015, offset=0.0, radius=0.0015)],
        "initial": dict(height=1e-4),
        "contact": dict(law="hunt_crossley", restitution=0.5),
        "solver": dict(t_end=0.01),
        "environment": dict(gravity=0.0),
    }
    doc.update(over)
    return doc


def arm(**over) -> dict:
    """A rigid steel arm 0.1 m long hinged at its tip-1 end, its tip-0 cap 1 mm above the block."""
    doc = {"bar": dict(length=0.1, diameter=0.01, tip_radius=0.005, **STEEL, modes=0),
           "mount": dict(kind="pivot", position=0.1),
           "initial": dict(height=1e-3),
           "contact": dict(law="hunt_crossley", restitution=0.3, reference_speed=0.1),
           "solver": dict(t_end=0.02), "environment": dict(gravity=0.0)}
    doc.update(over)
    return doc


DRIVES = {
    "constant force": blade(force=[dict(position=0.01, magnitude=1.0)]),
    "tabulated force": blade(force=[dict(position=0.01, time=[0.0, 0.003], value=[0.0, 2.0])]),
    "pivot preload torque": arm(mount=dict(kind="pivot", position=0.1, preload_torque=0.05)),
    "spring preload": arm(spring=[dict(anchor=[-0.045, 0.0, 0.05], position=0.05, stiffness=100.0, preload=-2.0)]),
    "base motion": blade(mount=dict(kind="clamp", position=0.02, base_motion=dict(
        time=[0.0, 0.002], displacement=[[0.0, 0.0, 0.0], [0.0, 0.0, -3e-4]]))),
    "gravity on a clamped blade": blade(environment=dict(gravity=9.81), initial=dict(height=1e-3)),
    "gravity on a pendulum": arm(environment=dict(gravity=9.81), initial=dict(height=0.05),
                                 solver=dict(t_end=0.15)),
}


@pytest.mark.parametrize("kind", list(DRIVES))
def test_a_sound_scene_of_each_drive_kind_is_ok_with_its_residual_stated(kind):
    result = run(scene_from_dict(DRIVES[kind]))
    verdict = assess(result)
    assert verdict["problems"] == [] and result.status == "ok"
    mres = result.mechanics
    energy = result.summary["energy"]
    assert 0.0 <= energy["relative_residual"] <= mres.model.scene.solver.energy_tolerance
    assert verdict["relative_residual"] == pytest.approx(energy["relative_residual"], rel=1e-12)
    # the scale holds every energy the run reached, and the audit closes within it
    assert verdict["max_kinetic"] <= verdict["energy_scale"]


def kicked(scene, pieces: int = 20, kick: float = 1.01):
    """The scene integrated with every speed multiplied by ``kick`` at each of ``pieces``
    instants: a wrong integration that puts energy in, as too coarse a one can."""
    solver = ImpactSolver(scene.mech)
    sl = solver.model.slices()
    for t in np.linspace(0.0, scene.t_end, pieces + 1)[1:]:
        solver.advance(t)
        for part in ("vel", "omega", "eta"):
            solver.y[sl[part]] *= kick
    return CoupledResult(scene=scene, mechanics=solver.result(), waveform_columns=None, stats={})


@pytest.mark.parametrize("kind", list(DRIVES))
def test_the_same_scene_integrated_wrongly_is_still_unsound(kind):
    scene = scene_from_dict(DRIVES[kind])
    verdict = assess(kicked(scene))
    assert any(p.startswith("energy audit") for p in verdict["problems"]), verdict
    # a kick of 1 (no kick) in the same pieces is sound: the pieces themselves are not the fault
    assert assess(kicked(scene, kick=1.0))["problems"] == []
