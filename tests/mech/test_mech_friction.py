"""Friction: the law and its low-load cap, Coulomb sliding to rest, and the oblique impact of
a vertical bar, whose tangential motion decouples, against impulse closed forms built on an
independent 1-DOF Hertz solve; regularized friction's convergence; azimuth invariance."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mech import ImpactSolver, simulate
from mech.friction import friction_limit, regularized_scale, transition_force

from mech_cases import hertz_history, make_scene, start_from, transverse_inertia

G = 9.80665


# --- the law --------------------------------------------------------------------------------

@pytest.mark.parametrize("mu, gamma, max_ratio", [(0.3, 0.0, 1.0), (0.3, 0.7, 1.0), (0.31, 0.7, math.inf),
                                                  (1.5, 0.0, 1.0), (0.3, 0.5, 0.2)])
def test_friction_limit_is_the_power_law_capped_at_max_ratio_times_the_load(mu, gamma, max_ratio):
    loads = np.array([0.0, 1e-9, 1e-4, 0.01, 0.19, 1.0, 8.0, 4e3])
    for fn in loads:
        expected = min(mu * fn ** (1.0 - gamma), max_ratio * fn) if fn > 0 else 0.0
        assert friction_limit(fn, mu, gamma, max_ratio) == pytest.approx(expected, rel=1e-14, abs=0.0)
    assert friction_limit(-1.0, mu, gamma, max_ratio) == 0.0
    # Below F_0 the cap holds, above it the power law: they meet at F_0.
    f0 = transition_force(mu, gamma, max_ratio)
    if 0.0 < f0 < math.inf:
        assert mu * f0 ** (1.0 - gamma) == pytest.approx(max_ratio * f0, rel=1e-12)
        assert friction_limit(0.5 * f0, mu, gamma, max_ratio) == pytest.approx(max_ratio * 0.5 * f0)
        assert friction_limit(2.0 * f0, mu, gamma, max_ratio) == pytest.approx(mu * (2.0 * f0) ** (1 - gamma))


def test_transition_force_of_the_nbse2_film_is_the_documented_value():
    # friction.py: F_0 = (mu / r_max)^(1/gamma) = 0.19 N for mu = 0.31 N^0.7, gamma = 0.7.
    assert transition_force(0.31, 0.7, 1.0) == pytest.approx(0.19, abs=5e-3)
    assert transition_force(0.3, 0.0, 1.0) == 0.0  # Coulomb below the cap: never capped
    assert transition_force(1.5, 0.0, 1.0) == math.inf  # Coulomb above the cap: always capped
    assert transition_force(0.3, 0.7, math.inf) == 0.0


def test_regularized_scale_is_v_over_sqrt_v2_plus_vs2():
    for v, vs in ((0.0, 1e-4), (1e-4, 1e-4), (1.0, 1e-4), (3e-3, 1e-2)):
        assert regularized_scale(v, vs) == pytest.approx(v / math.sqrt(v * v + vs * vs), rel=1e-15)


# --- Coulomb sliding of a bar lying on both tips -----------------------------------------------

MU_SLIDE = 0.3
V_SLIDE = 0.05  # m/s
T_STOP = V_SLIDE / (MU_SLIDE * G)  # closed form: constant deceleration mu g


def lying_bar(t_end: float, axial_modes: int = 0) -> ImpactSolver:
    """Horizontal bar on both tips at the static penetration y_eq = (m g / (2 k))^(2/3), sliding
    along its axis at V_SLIDE. Axial modes do not sag under gravity, so the start is static."""
    scene = make_scene(bar=dict(axial_modes=axial_modes, bending_modes=0), friction=dict(mu=MU_SLIDE),
                       initial=dict(height=0.0, angle_deg=0.0, velocity=(V_SLIDE, 0.0, 0.0)),
                       solver=dict(rtol=1e-8, t_end=t_end), gravity=G)
    solver = ImpactSolver(scene)
    k, m = solver.model.contact.stiffness, scene.bar.mass
    y_eq = (m * G / (2.0 * k)) ** (2.0 / 3.0)
    pos = solver.y[solver.model.slices()["pos"]].copy()
    pos[-1] = scene.bar.tip_radius - y_eq  # centre height: the sphere centres are on the axis
    start_from(solver, pos=pos)
    # R - y_eq keeps y_eq to ~1e-16 R / y_eq ~ 3e-12 relative
    np.testing.assert_allclose(solver.contact_now()[:, 2], 0.5 * m * G, rtol=1e-10)
    return solver


def test_coulomb_sliding_bar_decelerates_at_mu_g_with_friction_mu_times_each_tips_load():
    res = lying_bar(0.9 * T_STOP).run()
    h = res.history
    assert res.contacts.complete.sum() == 0 and len(res.events) == 0  # never lifts, never stops
    assert (h.regime_0 == "slip").all() and (h.regime_1 == "slip").all()
    np.testing.assert_allclose(h.vx, V_SLIDE - MU_SLIDE * G * h.time, rtol=0, atol=1e-6 * V_SLIDE)
    # Friction opposes the slip with mu times the load of that tip, tip by tip.
    for i in range(2):
        np.testing.assert_allclose(h[f"friction_x_{i}"], -MU_SLIDE * h[f"normal_force_{i}"], rtol=1e-12)
    # The friction moment (contact points R below the axis) loads the front and back tips
    # differently but leaves the total at m g on average.
    m = res.model.scene.bar.mass
    total = (h.normal_force_0 + h.normal_force_1).to_numpy()
    assert np.trapezoid(total, h.time) / h.time.iloc[-1] == pytest.approx(m * G, rel=1e-4)
    # friction work = loss of kinetic energy (no other sink is active)
    assert res.energy["friction_dissipation"] == pytest.approx(
        0.5 * m * (V_SLIDE**2 - h.vx.iloc[-1] ** 2), rel=1e-4)


def test_coulomb_sliding_bar_stops_at_v0_over_mu_g_and_then_both_tips_stick():
    # Two axial modes: the axial stiffness makes the two stick constraints along the bar
    # independent (see the rigid-bar case below for why that matters).
    res = lying_bar(1.3 * T_STOP, axial_modes=2).run()
    ev = res.event_table
    assert list(ev.kind) == ["stick_start"]
    assert ev.time[0] == pytest.approx(T_STOP, rel=1e-4)
    ph = res.phases
    for i in range(2):
        tip = ph[ph.tip == i]
        assert list(tip.regime) == ["slip", "stick"]
        assert tip.t_end.iloc[0] == pytest.approx(T_STOP, rel=1e-4)
    h = res.history
    after = h[h.time > T_STOP * 1.01]
    # Stuck: the contact points stay still, held by friction within the limit.
    assert np.max(np.abs(after[["slip_vx_0", "slip_vx_1"]].to_numpy())) < 1e-6
    for i in range(2):
        assert np.all(np.abs(after[f"friction_x_{i}"]) <= MU_SLIDE * after[f"normal_force_{i}"])


# --- oblique impact of a vertical bar --------------------------------------------------------------

V_N = 0.5  # m/s, normal approach speed


def vertical_oblique(vt0: float, friction: dict, model: str = "auto", direction=(1.0, 0.0), rtol=1e-9):
    d = np.array(direction) / np.linalg.norm(direction)
    scene = make_scene(friction=friction,
                       initial=dict(height=1e-5, angle_deg=90.0,
                                    velocity=(vt0 * d[0], vt0 * d[1], -V_N)),
                       solver=dict(rtol=rtol, t_end=4e-4, model=model))
    res = simulate(scene)
    bar = scene.bar
    # The contact point P is L/2 below the centroid on the axis: a tangential impulse dP
    # changes its tangential speed by dP (1/m + (L/2)^2 / I_t); the normal impulse goes
    # through the centroid and does not turn the bar (to first order in the small rotation).
    inv_mass = 1.0 / bar.mass + (bar.length / 2) ** 2 / transverse_inertia(bar)
    normal = hertz_history(bar.mass, res.model.contact.stiffness, V_N)
    return scene, res, inv_mass, normal


def test_vertical_bar_with_coulomb_friction_sticks_when_the_friction_impulse_stops_the_contact_point():
    mu, vt0 = 0.2, 0.3
    scene, res, inv_mass, normal = vertical_oblique(vt0, dict(mu=mu))
    # Slip phase: v_t(t) = vt0 - mu P_n(t) inv_mass, zero at the stick instant.
    reduction = mu * normal["impulse"] * inv_mass
    assert reduction[-1] > vt0  # the friction available over the contact could stop it
    t_stick = np.interp(vt0, reduction, normal["t"])
    c = res.contacts
    ev = res.event_table
    kinds = list(ev.kind)
    assert kinds == ["contact_start", "stick_start", "contact_end"]
    t_rel = ev.time[1] - c.t_start[0]
    # The 1-DOF normal solve ignores the bar's small rotation during the contact (~1e-3 rad).
    assert t_rel == pytest.approx(t_stick, abs=2e-3 * normal["contact_time"])
    # After sticking, the bar pivots on P: v_Px = 0, and the state at the stick instant,
    # Vx = vt0 - mu P_s/m, omega = mu P_s (L/2)/I_t with mu P_s = vt0 / inv_mass, is kept.
    bar = scene.bar
    mu_ps = vt0 / inv_mass
    h = res.history
    assert h.vx.iloc[-1] == pytest.approx(vt0 - mu_ps / bar.mass, rel=1e-3)
    assert h.wy.iloc[-1] == pytest.approx(mu_ps * (bar.length / 2) / transverse_inertia(bar), rel=1e-3)
    assert abs(h.slip_vx_0.iloc[-1]) < 1e-6 * vt0


@pytest.mark.parametrize("gamma, mu, vt0", [(0.0, 0.2, 1.0), (0.7, 0.3, 0.1)])
def test_vertical_bar_sliding_through_the_contact_loses_the_friction_impulse(gamma, mu, vt0):
    scene, res, inv_mass, normal = vertical_oblique(vt0, dict(mu=mu, gamma=gamma))
    # friction impulse of the capped power law min(mu F^(1-gamma), F) over the 1-DOF force history
    f = normal["force"]
    limit = np.minimum(mu * f ** (1.0 - gamma), 1.0 * f)
    friction_impulse = np.trapezoid(limit, normal["t"])
    assert inv_mass * friction_impulse < 0.9 * vt0  # never stops: slides through
    ev = res.event_table
    assert list(ev.kind) == ["contact_start", "contact_end"]
    end = ev[ev.kind == "contact_end"].iloc[0]
    expected = vt0 - inv_mass * friction_impulse
    # 1e-3 of the speed change: the 1-DOF reduction neglects the ~1e-3 rad turn of the bar.
    assert end.slip_speed == pytest.approx(expected, abs=1e-3 * (vt0 - expected))
    bar = scene.bar
    h = res.history
    assert h.vx.iloc[-1] == pytest.approx(vt0 - friction_impulse / bar.mass, abs=1e-3 * (vt0 - expected))


def test_vertical_bar_with_gamma_0_7_sticks_where_the_power_law_impulse_stops_it():
    mu, gamma, vt0 = 0.3, 0.7, 0.004
    scene, res, inv_mass, normal = vertical_oblique(vt0, dict(mu=mu, gamma=gamma))
    f = normal["force"]
    limit = np.minimum(mu * f ** (1.0 - gamma), f)
    # cumulative friction impulse by the trapezoid rule on the fine 1-DOF grid
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (limit[1:] + limit[:-1]) * np.diff(normal["t"]))])
    t_stick = np.interp(vt0, inv_mass * cum, normal["t"])
    ev = res.event_table
    assert list(ev.kind)[:2] == ["contact_start", "stick_start"]
    assert ev.time[1] - ev.time[0] == pytest.approx(t_stick, abs=2e-3 * normal["contact_time"])


def test_regularized_friction_converges_to_the_exact_stick_slip_solution():
    mu, vt0 = 0.2, 0.3
    _, exact, _, _ = vertical_oblique(vt0, dict(mu=mu))
    ref = exact.history.iloc[-1]
    errors = []
    for vs in (1e-2, 1e-3, 1e-4):
        _, reg, _, _ = vertical_oblique(vt0, dict(mu=mu, model="regularized", regularization_speed=vs), rtol=1e-8)
        last = reg.history.iloc[-1]
        errors.append(abs(last.wy - ref.wy) / abs(ref.wy))
    # Measured: smoothed friction converges ~ v_s^0.8; at least a factor 3 per decade here.
    assert errors[0] > 3.0 * errors[1] > 9.0 * errors[2]
    assert errors[2] < 1e-3


def test_oblique_impact_is_invariant_under_the_azimuth_of_the_tangential_velocity():
    mu, vt0 = 0.2, 0.3
    _, along_x, _, _ = vertical_oblique(vt0, dict(mu=mu, gamma=0.0))
    _, along_y, _, _ = vertical_oblique(vt0, dict(mu=mu, gamma=0.0), direction=(0.0, 1.0))
    _, diagonal, _, _ = vertical_oblique(vt0, dict(mu=mu, gamma=0.0), direction=(1.0, -2.0))
    assert along_x.solver["model"] == "planar"
    assert along_y.solver["model"] == "3d" and diagonal.solver["model"] == "3d"
    for other, d in ((along_y, (0.0, 1.0)), (diagonal, (1.0, -2.0))):
        d = np.array(d) / np.linalg.norm(d)
        assert list(other.event_table.kind) == list(along_x.event_table.kind)
        np.testing.assert_allclose(other.event_table.time, along_x.event_table.time, rtol=1e-6)
        a, b = along_x.history.iloc[-1], other.history.iloc[-1]
        # rotate the planar result by the azimuth of d about the vertical
        rot = np.array([[d[0], -d[1], 0.0], [d[1], d[0], 0.0], [0.0, 0.0, 1.0]])
        np.testing.assert_allclose([b.vx, b.vy, b.vz], rot @ [a.vx, a.vy, a.vz], atol=1e-6 * vt0)
        np.testing.assert_allclose([b.wx, b.wy, b.wz], rot @ [a.wx, a.wy, a.wz], atol=1e-6 * abs(a.wy))
