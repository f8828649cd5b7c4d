"""Springs between the armature and the bar ([[spring]] between = "armature"): statics of two
springs in series against the closed form, the energy audit with a snapping force-travel
spring, bad input.

The rig: a rigid steel arm (modes = 0, no gravity) on a hinge of torsion stiffness K_T at
its end, so its point at tip 0 (a lever LEVER from the hinge) is a spring of K_T / LEVER^2
to a small angle; above that point a plunger armature carries the spring's anchor end,
straight above it, and moves it down by q. The point's drop is computed here from the
arm's angle by the rigid geometry, the armature's q read from its state.
"""

from __future__ import annotations

import numpy as np
import pytest

from mech.scene import scene_from_dict
from mech.solver import ImpactSolver

STEEL = dict(youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)
LEVER = 0.05  # m: the arm, hinge to its point
TIP_R = 0.0025  # m
K_T = 50.0  # N m/rad: the hinge's torsion spring: K_T / LEVER^2 = 20 000 N/m at the point
K_R = 500.0  # N/m: the armature's return spring (no preload)
Q0 = 1e-3  # m: the armature's start, between its stops
ANCHOR_Z = 0.03  # m: the spring's armature end at the start, above the point


def rig(spring: dict, gap=5e-3, t_end=0.2, rtol=1e-6, armature=None, k_t=K_T) -> dict:
    doc = {"bar": dict(length=LEVER, diameter=2 * TIP_R, tip_radius=TIP_R, modes=0, **STEEL),
           "mount": dict(kind="pivot", position=LEVER, stiffness=k_t, damping=5e-3),
           "spring": [dict(dict(anchor=[-LEVER, 0.0, ANCHOR_Z], position=0.0, between="armature"), **spring)],
           "armature": armature or dict(kind="plunger", mass=1e-3, travel=5e-3, spring_rate=K_R,
                                        spring_preload=0.0, stop_stiffness=1e7, stop_damping=10.0,
                                        damping=1.0, initial_position=Q0),
           "initial": dict(height=gap), "environment": dict(gravity=0.0),
           "solver": dict(t_end=t_end, rtol=rtol)}
    return doc


def drop(states: np.ndarray) -> np.ndarray:
    """m: the arm's point's drop below its start (x, z, angle, ... per row)."""
    z = states[:, 1] + LEVER * np.sin(states[:, 2])
    return z[0] - z


def test_two_springs_in_series_hold_the_armature_and_the_bar_at_the_closed_form():
    """A drive of 2 N on the armature, its spring (1000 N/m, unstressed at the start) on the
    arm's point (20 000 N/m through the hinge): at rest the spring's compression (q - q0) - w
    carries k_s ((q - q0) - w) = k_b w, so the armature feels the series rate
    k = k_s k_b / (k_s + k_b) and F = K_R q + k (q - q0): q = (F + k q0) / (K_R + k),
    w = k (q - q0) / k_b. The dashpots ring the two down within 0.2 s to far below 1e-6;
    the small angle (1e-3 rad) is off by its square, 5e-7; within 1e-5."""
    k_s, f = 1000.0, 2.0
    solver = ImpactSolver(scene_from_dict(rig(dict(stiffness=k_s, damping=0.1))))
    solver.advance(0.2, {"armature.force": f})
    res = solver.result()
    q = res.states[:, solver.model.slices()["armature"]][:, 0]
    w = drop(res.states)
    k_b = K_T / LEVER ** 2
    k = k_s * k_b / (k_s + k_b)
    q_rest = (f + k * Q0) / (K_R + k)
    assert q[-1] == pytest.approx(q_rest, rel=1e-5)
    assert w[-1] == pytest.approx(k * (q_rest - Q0) / k_b, rel=1e-5)
    assert not any(e["kind"] == "contact_start" for e in solver.events)


# a dome between the plunger and the arm: stiff, then snapping through (negative slope),
# then stiff again; its release branch below
DOME = dict(travel=[0.0, 2e-4, 4e-4, 6e-4], force=[0.0, 2.0, 1.0, 6.0], release_force=[-0.2, 1.2, 0.5, 5.0])


def test_the_audit_closes_with_a_snapping_spring_between_the_armature_and_the_bar():
    """A drive ramped to 3 N over 5 ms presses the plunger onto the dome, which snaps
    through and presses the arm onto the block 0.2 mm below; released at 10 ms. The
    spring's stored energy counts once (its length between the two moving ends), the work
    it passes between armature and bar cancels: the audit's residual is integration error,
    below 100 times rtol of the energy scale and shrinking more than 10-fold from rtol 1e-6
    to 1e-8 (measured 1.4e-6 and 1.2e-8)."""
    residuals = []
    for rtol in (1e-6, 1e-8):
        solver = ImpactSolver(scene_from_dict(rig(dict(DOME, damping=0.05), gap=2e-4, t_end=0.02, rtol=rtol, k_t=0.5)))
        solver.advance(0.005, {"armature.force": (0.0, 3.0)})
        solver.advance(0.010, {"armature.force": 3.0})
        solver.advance(0.020, {"armature.force": (3.0, 0.0)})
        res = solver.result()
        assert any(e["kind"] == "contact_start" for e in solver.events)
        compression = (res.states[:, solver.model.slices()["armature"]][:, 0] - Q0) - drop(res.states)
        assert compression.max() > DOME["travel"][2]  # (through the snap, into the dome's stiff end)
        residuals.append(res.energy["relative_residual"])
    assert residuals[0] < 100 * 1e-6
    assert residuals[1] < residuals[0] / 10


@pytest.mark.parametrize("change, words", [
    (dict(between="bar"), "spring[0].between = 'bar': allowed values are 'frame', 'armature'"),
    (dict(between="frame", lever=2.0), "spring[0].lever = 2.0: the lever moves a spring's end with the armature"),
    (dict(lever=-1.0), "spring[0].lever = -1.0"),
])
def test_a_bad_armature_spring_is_refused_in_one_line_naming_the_key(change, words):
    with pytest.raises(ValueError) as err:
        scene_from_dict(rig(dict(stiffness=1000.0, **change)))
    message = str(err.value)
    assert words in message and "\n" not in message


def test_an_armature_spring_needs_an_armature_and_a_clapper_needs_its_lever():
    doc = rig(dict(stiffness=1000.0))
    del doc["armature"]
    with pytest.raises(ValueError, match=r"spring\[0\].between = 'armature': needs an \[armature\]"):
        scene_from_dict(doc)
    clapper = dict(kind="clapper", inertia=1e-7, travel=0.05, stop_stiffness=10.0)
    with pytest.raises(ValueError, match=r"spring\[0\].lever: needed for a spring on a clapper"):
        scene_from_dict(rig(dict(stiffness=1000.0), armature=clapper))
