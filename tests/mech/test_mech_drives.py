"""Named drive channels: each contact point's friction coefficient (mu.<i>) and Holm's
electrodynamic repulsion (repulsion.<i>), linear in time within a step.

Physics: a held, preloaded contact under a repulsion R carries exactly R less (statics of
a pivoted arm under a constant torque, a statically determinate support), and lifts off
when R reaches the preload; the energy audit closes with a ramping repulsion (its work is
work put in, and the residual shrinks with the tolerance as integration error does); a
friction coefficient given to one contact point sets the friction law there and nowhere
else. Also the interface: names, the value a channel holds between steps, bad input.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from mech.scene import scene_from_dict
from mech.solver import ImpactSolver

STEEL = dict(youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)
L, D, RT = 0.05, 0.005, 0.0025  # arm length, diameter, tip radius (m)
T0 = 0.01  # N m: the pivot's constant preload torque, pressing tip 0 onto the block


def pivot_arm() -> dict:
    """A rigid steel arm hinged at its tip-1 end under a constant preload torque (no torsion
    spring), dropped 10 um onto the block: it bounces and comes to rest on tip 0."""
    return {"bar": dict(length=L, diameter=D, tip_radius=RT, modes=0, **STEEL),
            "mount": dict(kind="pivot", position=L, preload_torque=T0),
            "contact": dict(restitution=0.5),
            "initial": dict(height=1e-5), "solver": dict(t_end=1.0)}


def preload(solver: ImpactSolver) -> float:
    """N: the contact force that balances the arm's moments about the hinge, the preload
    torque and the weight at half the length, on the arm L - R_tip (the arm lies level to
    within its 1e-4 rad of travel: cos differs from 1 by 1e-8)."""
    scene = solver.scene
    return (T0 + solver.model.basis.mass * scene.gravity * L / 2) / (L - RT)


@pytest.fixture(scope="module")
def settled():
    solver = ImpactSolver(scene_from_dict(pivot_arm()))
    solver.advance(0.05)
    assert solver.at_rest and solver.holds[-1][1] == math.inf  # held: nothing changes
    return solver


def test_the_arm_settles_at_the_preload(settled):
    """The statics the repulsion tests start from: F_n = preload, to the arm's 1e-8 tilt."""
    assert settled.contact_now()[0, 2] == pytest.approx(preload(settled), rel=1e-7)


@pytest.mark.parametrize("fraction", [0.3, 0.7])
def test_a_held_contact_under_a_repulsion_carries_exactly_that_much_less(settled, fraction):
    """The arm is a statically determinate support: the contact force plus the repulsion
    balance the same moments, so F_n(R) = F_n(0) - R whatever the Hertz stiffness. A step of
    R releases the hold (its equilibrium moved), the arm rings down and is held again.
    Tolerance: the hold's static equilibrium is converged to rtol x the Hertz penetration
    scale (1e-6 here), which moves the force by ~1e-6 of itself."""
    solver = copy.deepcopy(settled)
    f0 = solver.contact_now()[0, 2]
    holds = len(solver.holds)
    R = fraction * f0
    solver.advance(0.1, {"repulsion.0": R})
    assert len(solver.holds) == holds + 1 and solver.holds[-1][0] > 0.05  # released, then held anew
    assert solver.contact_now()[0, 2] == pytest.approx(f0 - R, abs=1e-6 * f0)
    # a channel not given keeps its value: the next step holds at the same force
    solver.advance(0.2)
    assert solver.drives_now()["repulsion.0"] == R and len(solver.holds) == holds + 1
    assert solver.contact_now()[0, 2] == pytest.approx(f0 - R, abs=1e-6 * f0)


@pytest.mark.parametrize("top", [0.97, 1.03])
def test_a_repulsion_ramped_past_the_preload_blows_the_contact_open(settled, top):
    """Ramped slowly (100 ms, ~6000 periods of the arm on its contact) from 0 to ``top``
    times the preload: below it the contact stays closed at the rest F_n = preload - R;
    above it, it opens once R has reached the preload. The Hertz contact softens as its
    force goes to zero (its stiffness ~ F_n^(1/3)), so the opening lags that instant a
    little: it must come within 1 % of the preload's ramp time, not before it."""
    solver = copy.deepcopy(settled)
    f0 = solver.contact_now()[0, 2]
    t0, ramp = solver.t, 0.1
    seg = solver.advance(t0 + ramp, {"repulsion.0": (0.0, top * f0)}, stop_at_switch=True)
    opened = [e for e in seg.events if e["kind"] == "contact_end" and e["tip"] == 0]
    if top < 1.0:
        assert not opened and not solver.at_rest  # followed the ramp: no hold during it
        solver.advance(t0 + ramp + 0.05)  # held at the ramp's end value now
        assert solver.at_rest
        assert solver.contact_now()[0, 2] == pytest.approx(f0 * (1.0 - top), abs=1e-6 * f0)
    else:
        assert opened
        r_open = top * f0 * (opened[0]["time"] - t0) / ramp
        assert f0 <= r_open <= 1.01 * f0
        assert solver.contact_now()[0, 2] == 0.0


def ramped_repulsion(doc: dict, peak: float, rtol: float, input_work: bool = False, steps: int = 20):
    """Run ``doc`` with every contact point's repulsion ramped up and down over ``steps``
    steps (a new slope each step: 0 -> peak -> 0 as sin^2)."""
    doc = copy.deepcopy(doc)
    doc["solver"]["rtol"] = rtol
    solver = ImpactSolver(scene_from_dict(doc), input_work=input_work)
    names = [n for n in solver.drive_names if n.startswith("repulsion.")]
    t_end = doc["solver"]["t_end"]
    before = 0.0
    for k in range(1, steps + 1):
        value = peak * math.sin(math.pi * k / steps) ** 2
        solver.advance(t_end * k / steps, {n: (before, value) for n in names})
        before = value
    return solver.result()


FREE = {"bar": dict(length=0.1, diameter=0.006, tip_radius=0.003, modes=3, **STEEL),
        "initial": dict(height=1e-4, angle_deg=10.0, velocity=[0.1, 0.0, -0.5]),
        "friction": dict(mu=0.3), "contact": dict(restitution=0.7), "solver": dict(t_end=0.005)}
BLADE = {"bar": dict(length=0.02, width=0.003, thickness=0.0003, tip_radius=0.0016, **STEEL,
                     modes={"axial": 1, "bending": 6}, modal_damping=0.2),
         "mount": dict(kind="clamp", position=0.02),
         "rivet": [dict(position=0.0015, offset=0.0, radius=0.0015)],
         "force": [dict(position=0.01, time=[0.0, 0.0005], value=[0.0, 2.0])],
         "initial": dict(height=2e-5), "contact": dict(law="hunt_crossley", restitution=0.5),
         "friction": dict(mu=0.3), "solver": dict(t_end=0.005), "environment": dict(gravity=0.0)}


@pytest.mark.parametrize("doc, peak, input_work", [(FREE, 300.0, True), (BLADE, 0.4, False)],
                         ids=["free bar, repulsion on both tips", "clamped blade, below blow-off"])
def test_the_energy_audit_closes_with_a_ramping_repulsion(doc, peak, input_work):
    """The repulsion's work enters the audit as work put in: the residual is integration
    error, so it shrinks with the tolerance (a missing or wrong source would leave a
    residual of the size of that work at every tolerance). For the free bar the repulsion is
    the only work put in, and an independent route gives it: the trapezoid rule on the
    recorded steps of -R(t) dy/dt over the contact intervals (the steps resolve the motion
    to a few 1e-4 of that integral)."""
    results = [ramped_repulsion(doc, peak, rtol, input_work) for rtol in (1e-7, 1e-9)]
    residuals = [r.energy["relative_residual"] for r in results]
    assert residuals[1] < 1e-7 and residuals[1] < residuals[0] / 30.0
    fine = results[1]
    h = fine.history_columns
    assert len(fine.contacts) >= 2
    if input_work:
        t = h["time"]
        steps, t_end = 20, doc["solver"]["t_end"]
        k = np.minimum((t / t_end * steps).astype(int), steps - 1)
        frac = t / t_end * steps - k
        r_t = peak * ((1.0 - frac) * np.sin(math.pi * k / steps) ** 2 + frac * np.sin(math.pi * (k + 1) / steps) ** 2)
        work = np.zeros(len(t))
        for i in range(2):
            power = np.where(h[f"penetration_{i}"] > 0.0, -r_t * h[f"penetration_rate_{i}"], 0.0)
            inside = (h[f"penetration_{i}"][1:] > 0.0) & (h[f"penetration_{i}"][:-1] > 0.0)
            work[1:] += np.cumsum(np.where(inside, 0.5 * (power[1:] + power[:-1]) * np.diff(t), 0.0))
        w_in = h["work_in"]
        size = np.max(np.abs(w_in))
        assert size > 1e4 * residuals[1] * fine.energy_scale  # the audit sees this work
        np.testing.assert_allclose(w_in, work, rtol=0.0, atol=1e-3 * size)


def test_mu_given_to_one_contact_point_sets_only_its_friction():
    """A 3D bar sliding onto the block on tip 0, then on tip 1 (Coulomb, gamma = 0). With
    mu.1 = 0.4 given and the scene's mu = 0.1 elsewhere, every slipping step carries
    |F_t| = mu_i F_n at its own point: 0.1 at tip 0, 0.4 at tip 1 (to round-off: the
    friction is the limit times a unit direction). Tip 0's contact is over before tip 1
    touches, so mu.1 has nothing to act on there: its history is the same as with mu = 0.1."""
    doc = {"bar": dict(length=0.1, diameter=0.006, tip_radius=0.003, modes=2, **STEEL),
           "initial": dict(height=1e-4, angle_deg=2.0, velocity=[0.5, 0.0, -0.5]),
           "friction": dict(mu=0.1), "contact": dict(restitution=0.3), "solver": dict(t_end=0.004)}
    plain, given = ImpactSolver(scene_from_dict(doc)), ImpactSolver(scene_from_dict(doc))
    plain.advance(0.004)
    given.advance(0.004, {"mu.1": 0.4})
    for solver, mus in ((plain, (0.1, 0.1)), (given, (0.1, 0.4))):
        h = solver.result().history_columns
        for i, mu in enumerate(mus):
            slip = (h[f"regime_{i}"] == 1) & (h[f"normal_force_{i}"] > 0.0)
            assert slip.sum() > 20
            ratio = np.hypot(h[f"friction_x_{i}"], h[f"friction_y_{i}"])[slip] / h[f"normal_force_{i}"][slip]
            np.testing.assert_allclose(ratio, mu, rtol=1e-12)
    a, b = plain.result(), given.result()
    first_tip1 = next(e["time"] for e in b.events if e["tip"] == 1 and e["kind"] == "contact_start")
    before = a.t <= first_tip1
    np.testing.assert_array_equal(a.states[before], b.states[: before.sum()])


def test_the_channels_are_named_by_contact_point_and_checked():
    free = ImpactSolver(scene_from_dict(copy.deepcopy(FREE)))
    assert free.drive_names == ("mu.0", "mu.1", "repulsion.0", "repulsion.1")
    blade = ImpactSolver(scene_from_dict(copy.deepcopy(BLADE)))
    assert blade.drive_names == ("mu.0", "repulsion.0")  # one rivet: one contact point
    with pytest.raises(ValueError, match=r"'repulsion\.1'.*mu\.0, repulsion\.0"):
        blade.advance(1e-4, {"repulsion.1": 1.0})
    with pytest.raises(ValueError, match=r"drives\['repulsion\.0'\] = -1\.0: must be a finite number >= 0"):
        blade.advance(1e-4, {"repulsion.0": -1.0})
    with pytest.raises(ValueError, match=r"drives\['mu\.0'\] = \(0\.1, nan\)"):
        blade.advance(1e-4, {"mu.0": (0.1, float("nan"))})
    with pytest.raises(ValueError, match="both given"):
        blade.advance(1e-4, {"mu.0": 0.2}, mu=0.3)
    # a free bar keeps no input-work quadrature unless asked: a repulsion would escape the audit
    with pytest.raises(ValueError, match=r"input_work=True"):
        free.advance(1e-4, {"repulsion.0": 1.0})
    free.advance(1e-4, {"repulsion.0": 0.0})  # zero does no work: allowed
    assert blade.t == 0.0 and free.t == 1e-4


def test_mu_shorthand_sets_every_point_and_a_ramp_ends_where_its_step_ends():
    solver = ImpactSolver(scene_from_dict(copy.deepcopy(FREE)))
    solver.advance(1e-4, mu=(0.2, 0.6))
    assert solver.drives_now() == pytest.approx({"mu.0": 0.6, "mu.1": 0.6, "repulsion.0": 0.0, "repulsion.1": 0.0})
    solver.advance(3e-4)  # held at 0.6, not continued at the ramp's slope
    assert solver.drives_now()["mu.0"] == pytest.approx(0.6) and solver.drives_now()["mu.1"] == pytest.approx(0.6)


@pytest.fixture(scope="module")
def stuck_blade():
    """The clamped blade pressed by 2 N, settled and held with its rivet stuck: the blade's
    bending pulls the contact point along the block, friction holds it."""
    solver = ImpactSolver(scene_from_dict(copy.deepcopy(BLADE)))
    solver.advance(0.02)
    assert solver.at_rest and solver.regime[0] == 2  # STICK
    return solver


@pytest.mark.parametrize("factor", [1.1, 0.9])
def test_a_held_stick_ends_when_its_mu_drops_below_the_friction_it_needs(stuck_blade, factor):
    """The held contact needs the friction ratio |F_t| / F_n (Coulomb); a mu.0 above it keeps
    the hold, one below ends the stick at once: the rivet slides until the friction it
    needs is within the new limit, and is held again there."""
    solver = copy.deepcopy(stuck_blade)
    aux = solver.contact_now()
    f_n = aux[0, 2]
    needed = abs(solver.result().history_columns["friction_x_0"][-1]) / f_n
    holds = len(solver.holds)
    solver.advance(0.03, {"mu.0": factor * needed})
    h = solver.result().history_columns
    if factor > 1.0:
        assert len(solver.holds) == holds and solver.at_rest  # nothing moved
    else:
        assert len(solver.holds) == holds + 1  # released, slid, held anew
        after = h["time"] > 0.02
        assert h["regime_0"][after][0] == 1  # SLIP from the step's start
        assert abs(h["friction_x_0"][-1]) <= factor * needed * h["normal_force_0"][-1] * (1 + 1e-9)


@pytest.mark.parametrize("doc", ["default", "blade"])
def test_a_zero_repulsion_given_every_step_changes_nothing(doc):
    """Stepped as the coupling steps (mu ramped per step), the default scene (a free bar: no
    input-work quadrature needed for a zero force) and the blade (which comes to rest and is
    held) move exactly as without the repulsion channels: a zero repulsion neither acts nor
    releases a hold nor restarts the watch for rest (same machine, same run: bit for bit)."""
    import mech

    scene = mech.default_scene() if doc == "default" else scene_from_dict(copy.deepcopy(BLADE))
    t_end = 5e-3 if doc == "default" else 0.012
    runs = []
    for zero in (False, True):
        solver = ImpactSolver(scene)
        names = [n for n in solver.drive_names if n.startswith("repulsion.")]
        for k in range(1, 41):
            mu = (0.3 + 0.001 * k, 0.3 + 0.001 * (k + 1))
            solver.advance(t_end * k / 40, {n: 0.0 for n in names} if zero else None, mu=mu)
        runs.append((solver.result(), list(solver.holds)))
    (a, holds_a), (b, holds_b) = runs
    np.testing.assert_array_equal(a.states, b.states)
    assert holds_a == holds_b and (doc == "default" or holds_a)
