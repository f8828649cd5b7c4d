"""Switch mechanisms: held bars, actuator forces, springs, rivets, a spherical block.

Each check is a closed form of statics or vibration, an energy balance, or agreement
between the finite-element route and the analytic free-free route of the same bar.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from mech.contact_laws import hertz_stiffness
from mech.scene import scene_from_dict
from mech.solver import ImpactSolver

STEEL = dict(youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)


def blade(**over) -> dict:
    """A 20 x 3 x 0.3 mm steel blade clamped at its tip-1 end, a rivet at tip 0."""
    doc = {
        "bar": dict(length=0.02, width=0.003, thickness=0.0003, tip_radius=0.0016, **STEEL,
                    modes={"axial": 1, "bending": 6}, modal_damping=0.2),
        "mount": dict(kind="clamp", position=0.02),
        "rivet": [dict(position=0.0015, offset=0.0, radius=0.0015)],
        "initial": dict(height=1e-4),
        "contact": dict(law="hunt_crossley", restitution=0.5),
        "solver": dict(t_end=0.03),
        "environment": dict(gravity=0.0),
    }
    for key, value in over.items():
        doc[key] = value
    return doc


def settled(result, column: str, span: float = 2e-3) -> float:
    h = result.history
    tail = h[h.time >= h.time.iloc[-1] - span]
    return float(tail[column].mean())


def test_free_bar_pressed_by_a_force_settles_at_the_static_hertz_penetration():
    """A rigid bar standing on tip 0, pushed down along its axis by F: F_n -> F and the
    penetration -> (F/k)^(2/3)."""
    F = 20.0
    doc = {
        "bar": dict(length=0.1, diameter=0.01, tip_radius=0.005, **STEEL, modes=0),
        "block": dict(youngs_modulus=210e9, poisson_ratio=0.3),
        "initial": dict(height=0.0, angle_deg=90.0, velocity=[0.0, 0.0, 0.0]),
        "force": [dict(position=0.05, magnitude=F, direction=[0.0, 0.0, -1.0])],
        # damping calibrated at 0.1 m/s: an underdamped settling (at the 1 mm/s scale of
        # this start from rest the contact would be overdamped and creep for long)
        "contact": dict(law="hunt_crossley", restitution=0.3, reference_speed=0.1),
        "solver": dict(t_end=0.01),
        "environment": dict(gravity=0.0),
    }
    res = ImpactSolver(scene_from_dict(doc)).run()
    k = hertz_stiffness(0.005, 210e9, 0.3, 210e9, 0.3)
    assert settled(res, "normal_force_0") == pytest.approx(F, rel=1e-3)
    assert settled(res, "penetration_0") == pytest.approx((F / k) ** (2 / 3), rel=1e-3)
    assert settled(res, "normal_force_1") == 0.0


def test_pivoted_rigid_bar_under_a_torque_presses_with_torque_over_arm():
    """A rigid arm hinged at its tip-1 end, preload torque T: contact force T / arm."""
    T = 0.05
    L, R = 0.1, 0.005
    doc = {
        "bar": dict(length=L, diameter=0.01, tip_radius=R, **STEEL, modes=0),
        "mount": dict(kind="pivot", position=L, preload_torque=T),
        "initial": dict(height=0.0),
        "contact": dict(law="hunt_crossley", restitution=0.3, reference_speed=0.1),
        "solver": dict(t_end=0.02),
        "environment": dict(gravity=0.0),
    }
    res = ImpactSolver(scene_from_dict(doc)).run()
    arm = L - R  # hinge to the tip-0 cap centre, the bar level
    assert settled(res, "normal_force_0") == pytest.approx(T / arm, rel=2e-3)


def test_rigid_pivoted_bar_on_a_torsion_spring_oscillates_at_sqrt_k_over_i():
    L, d = 0.1, 0.01
    kt = 2.0
    doc = {
        "bar": dict(length=L, diameter=d, tip_radius=0.005, **STEEL, modes=0),
        "mount": dict(kind="pivot", position=L, stiffness=kt),
        "initial": dict(height=0.05, angular_velocity=[0.0, 1.0, 0.0]),
        "solver": dict(t_end=0.2, rtol=1e-8),
        "environment": dict(gravity=0.0),
    }
    res = ImpactSolver(scene_from_dict(doc)).run()
    rho = 7850.0
    area = math.pi * d**2 / 4
    i22 = math.pi * d**4 / 64
    inertia = rho * area * L**3 / 3 + rho * L * i22  # about the hinge, with the section's own
    omega = math.sqrt(kt / inertia)
    h = res.history
    wy = h.wy.to_numpy()
    t = h.time.to_numpy()
    # downward zero crossings of the angular velocity, one per period
    idx = np.where((wy[:-1] > 0) & (wy[1:] <= 0))[0]
    tc = t[idx] - wy[idx] * (t[idx + 1] - t[idx]) / (wy[idx + 1] - wy[idx])
    period = np.mean(np.diff(tc))
    assert period == pytest.approx(2 * math.pi / omega, rel=1e-5)
    assert res.contacts.empty
    assert abs(res.energy_table.residual.iloc[-1]) < 1e-6 * 0.5 * inertia * 1.0**2


def test_clamped_blade_vibrates_at_the_cantilever_frequency():
    doc = blade(initial=dict(height=0.01), bar=dict(length=0.02, width=0.003, thickness=0.0003,
                                                     tip_radius=0.0016, **STEEL, modes={"axial": 0, "bending": 3}))
    solver = ImpactSolver(scene_from_dict(doc))
    n = solver.model.n
    q0 = np.zeros(n)
    q0[0] = 1e-5
    solver.set_modal_state(q=q0)
    res = solver.run()
    E = 210e9
    I = 0.003 * 0.0003**3 / 12
    rhoA = 7850.0 * 0.003 * 0.0003
    f1 = 1.875104**2 / 0.02**2 * math.sqrt(E * I / rhoA) / (2 * math.pi)
    q = res.history["q_bend31"].to_numpy()
    t = res.history.time.to_numpy()
    idx = np.where((q[:-1] > 0) & (q[1:] <= 0))[0]
    tc = t[idx] - q[idx] * (t[idx + 1] - t[idx]) / (q[idx + 1] - q[idx])
    assert 1 / np.mean(np.diff(tc)) == pytest.approx(f1, rel=1e-4)


def test_cantilever_sags_under_gravity_by_the_closed_form():
    """Uniform load w = rho A g: tip deflection w L^4 / (8 E I), through the modes' L_j."""
    doc = blade(initial=dict(height=0.01), environment=dict(gravity=9.81),
                bar=dict(length=0.02, width=0.003, thickness=0.0003, tip_radius=0.0016, **STEEL,
                         modes={"axial": 0, "bending": 8}, modal_damping=0.5),
                rivet=[dict(position=0.0, offset=0.0, radius=0.0015)])
    res = ImpactSolver(scene_from_dict(doc)).run()
    E, I = 210e9, 0.003 * 0.0003**3 / 12
    w = 7850.0 * 0.003 * 0.0003 * 9.81
    sag = w * 0.02**4 / (8 * E * I)
    # the rivet at tip 0 (no mass) sits on the tip: its height drops by the sag
    drop = res.history.tip_height_0.iloc[0] - settled(res, "tip_height_0")
    assert drop == pytest.approx(sag, rel=2e-3)


def test_force_on_a_clamped_blade_settles_at_the_beam_statics_contact_force():
    """Force P at distance a from the clamp; rivet at distance b >= a, gap g: the contact
    force R solves P a^2 (3b - a)/(6EI) - R b^3/(3EI) = g + (R/k)^(2/3)."""
    P, g = 2.0, 1e-4
    doc = blade(force=[dict(position=0.01, magnitude=P)],
                bar=dict(length=0.02, width=0.003, thickness=0.0003, tip_radius=0.0016, **STEEL,
                         modes={"axial": 0, "bending": 10}, modal_damping=0.3))
    res = ImpactSolver(scene_from_dict(doc)).run()
    E, I = 210e9, 0.003 * 0.0003**3 / 12
    a, b = 0.01, 0.02 - 0.0015
    k = hertz_stiffness(0.0015, 210e9, 0.3, 210e9, 0.3)
    R = brentq(lambda R: P * a**2 * (3 * b - a) / (6 * E * I) - R * b**3 / (3 * E * I) - g - (R / k) ** (2 / 3),
               0.0, P)
    assert settled(res, "normal_force_0") == pytest.approx(R, rel=5e-3)


@pytest.mark.parametrize("extra", [
    dict(force=[dict(position=0.01, time=[0.0, 0.002, 0.004], value=[0.0, 3.0, -1.0])]),
    dict(spring=[dict(anchor=[0.004, 0.0, -0.005], position=0.004, stiffness=200.0, preload=0.5, damping=0.01)]),
    dict(mount=dict(kind="clamp", position=0.02,
                    base_motion=dict(time=[0.0, 0.003, 0.006], displacement=[[0, 0, 0], [0, 0, -3e-4], [0, 0, 2e-4]]))),
])
def test_energy_audit_closes_with_actuator_work_springs_and_a_moving_clamp(extra):
    doc = blade(**extra, solver=dict(t_end=0.008, rtol=1e-8))
    doc["bar"] = dict(doc["bar"], modal_damping=0.0)
    res = ImpactSolver(scene_from_dict(doc)).run()
    en = res.energy_table
    scale = float(np.max(np.abs(en.kinetic)) + np.max(np.abs(en.elastic)) + np.max(np.abs(en.work_in))
                  + np.max(np.abs(en.spring_stored)))
    assert scale > 0
    assert float(np.max(np.abs(en.residual))) < 1e-5 * scale
    assert not res.contacts.empty  # the check includes impacts


def test_free_bar_through_the_finite_element_route_matches_the_analytic_route():
    """Two massless rivets where the end caps are: the FE free-free basis about the
    centroid must reproduce the analytic free-free bar's impacts."""
    base = {
        "bar": dict(length=0.3, diameter=0.01, tip_radius=0.005, **STEEL, modes=3),
        "initial": dict(height=0.0005, angle_deg=30.0, velocity=[0.2, 0.0, -1.0]),
        "contact": dict(law="paper", restitution=0.8),
        "solver": dict(t_end=0.004),
    }
    analytic = ImpactSolver(scene_from_dict(base)).run()
    fe = dict(base, rivet=[dict(position=0.005, radius=0.005), dict(position=0.295, radius=0.005)])
    routed = ImpactSolver(scene_from_dict(fe)).run()
    a, b = analytic.contacts, routed.contacts
    assert len(a) == len(b) and len(a) >= 2
    np.testing.assert_allclose(b.t_start, a.t_start, rtol=0, atol=2e-7)
    np.testing.assert_allclose(b.peak_force, a.peak_force, rtol=2e-3)


@pytest.mark.parametrize("over, message", [
    (dict(rivet=[dict(position=0.03, radius=0.001)]), "rivet[0].position = 0.03"),
    (dict(rivet=[dict(position=0.0195, radius=0.001)]), "sits in the clamp"),
    (dict(spring=[dict(anchor=[0, 0, 0.01], position=0.01, stiffness=-5.0)]), "spring[0].stiffness"),
    (dict(mount=dict(kind="clamp", position=0.02, base_motion=dict(time=[0.0, 0.002, 0.001],
                                                                    displacement=[[0, 0, 0]] * 3))),
     "mount.base_motion.time[2]"),
    (dict(force=[dict(position=0.01, time=[0.0, 0.001], value=[1.0, float("nan")])]), "force[0][1]"),
    (dict(mount=dict(kind="pivot", position=0.02, base_motion=dict(time=[0.0], displacement=[[0, 0, 0]]))),
     "mount.base_motion"),
    (dict(block=dict(shape="sphere")), "block.radius"),
    (dict(mount=dict(kind="clamp")), "mount.position"),
])
def test_bad_mechanism_input_is_a_named_error(over, message):
    with pytest.raises(ValueError, match=message.replace("[", r"\[").replace("]", r"\]").replace(".", r"\.")):
        scene_from_dict(blade(**over))


def test_a_settled_blade_is_held_for_a_second_at_its_static_force_without_chatter():
    """A contact at rest is the end of a closure: over 1 s the solver holds it (no event
    chatter, a bounded number of steps) at the force the beam statics give."""
    P, g = 2.0, 1e-4
    doc = blade(force=[dict(position=0.01, magnitude=P)], solver=dict(t_end=1.0),
                bar=dict(length=0.02, width=0.003, thickness=0.0003, tip_radius=0.0016, **STEEL,
                         modes={"axial": 0, "bending": 10}, modal_damping=0.3))
    solver = ImpactSolver(scene_from_dict(doc))
    res = solver.run()
    assert solver.holds and solver.holds[0][1] == math.inf  # held to the end: nothing changes
    assert solver.holds[0][0] < 0.05
    E, I = 210e9, 0.003 * 0.0003**3 / 12
    a, b = 0.01, 0.02 - 0.0015
    k = hertz_stiffness(0.0015, 210e9, 0.3, 210e9, 0.3)
    R = brentq(lambda R: P * a**2 * (3 * b - a) / (6 * E * I) - R * b**3 / (3 * E * I) - g - (R / k) ** (2 / 3),
               0.0, P)
    assert res.history.normal_force_0.iloc[-1] == pytest.approx(R, rel=5e-3)
    # the work it took: the settling, not the second it is held (a whole second at the
    # settling's step would be > 1e5 steps)
    assert res.stats["steps"] < 20_000 and len(res.events) < 200
    assert abs(res.energy_table.residual.iloc[-1]) < 1e-3 * res.energy_scale


def test_a_blade_following_a_slow_force_ramp_is_not_held_at_a_stale_force():
    """Quasi-static is not at rest: under a force ramped slowly (1 to 3 N over 50 s) the
    blade is as quiet as a settled one, yet its contact force must follow the ramp."""
    g = 1e-4
    doc = blade(force=[dict(position=0.01, time=[0.0, 50.0], value=[1.0, 3.0])], solver=dict(t_end=0.5),
                bar=dict(length=0.02, width=0.003, thickness=0.0003, tip_radius=0.0016, **STEEL,
                         modes={"axial": 0, "bending": 6}, modal_damping=0.3))
    solver = ImpactSolver(scene_from_dict(doc))
    res = solver.run()
    E, I = 210e9, 0.003 * 0.0003**3 / 12
    a, b = 0.01, 0.02 - 0.0015
    k = hertz_stiffness(0.0015, 210e9, 0.3, 210e9, 0.3)

    def statics(P):
        return brentq(lambda R: P * a**2 * (3 * b - a) / (6 * E * I) - R * b**3 / (3 * E * I) - g
                      - (R / k) ** (2 / 3), 0.0, P)

    P_end = 1.0 + 2.0 * 0.5 / 50.0
    # the ramp moves the force by 2 % over the run: held at a stale force, it would be off
    # by ~ (statics(P_end) - statics(1.0)); followed, it is within 0.2 % of that
    assert res.history.normal_force_0.iloc[-1] == pytest.approx(statics(P_end), abs=0.1 * (statics(P_end) - statics(1.0)))
    assert not solver.holds


@pytest.mark.parametrize("offset, flagged", [(0.0, False), (2e-4, True)])
def test_a_contact_away_from_the_top_of_a_spherical_block_is_flagged(offset, flagged):
    """The fixed rivet is treated by its tangent plane: 0.2 mm off its top the 1.5 mm
    sphere lies d^2/(2R) = 13 um below that plane, far more than the micrometre the
    contact penetrates; aligned, the wipe stays within the plane's validity."""
    doc = blade(block=dict(shape="sphere", radius=0.0015, offset=offset),
                force=[dict(position=0.01, magnitude=2.0)], solver=dict(t_end=0.002))
    res = ImpactSolver(scene_from_dict(doc)).run()
    notes = [f for f in res.flags if "spherical block" in f]
    assert bool(notes) == flagged
