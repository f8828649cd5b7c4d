"""Undamped Hertz impacts: the rigid vertical bar against the closed forms, the tilted
rigid bar against its effective normal mass, and the elastic flexible bar's energy."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from mech import ImpactSolver, simulate
from mech.contact_laws import hertz_impact, hertz_stiffness

from mech_cases import HERTZ_TIME_FACTOR_EXACT, hertz_closed_form, make_scene, steel_stiffness, transverse_inertia

V0 = 1.0  # m/s, normal impact speed


def test_hertz_stiffness_is_the_papers_formula_and_four_thirds_e_star_sqrt_r():
    R = 0.005
    k = hertz_stiffness(R, 210e9, 0.3, 210e9, 0.3)
    assert k == pytest.approx(steel_stiffness(R), rel=1e-14)
    # The paper's k = 0.424 sqrt(R) / (h1 + h2), h = (1 - nu^2)/(pi E): 0.424 rounds 4/(3 pi).
    h = (1 - 0.3**2) / (math.pi * 210e9)
    assert k == pytest.approx(0.424 * math.sqrt(R) / (2 * h), rel=1.5e-3)
    # Closed form: R = 5 mm on steel with E = 200 GPa: k = 1.036e10 N/m^1.5.
    assert hertz_stiffness(R, 200e9, 0.3, 200e9, 0.3) == pytest.approx(1.036e10, rel=1e-3)
    # The time factor of the closed form: 2 (2/5) B(2/5, 1/2) = 2.943275; mech and the closed-form figures
    # quote 2.9432 (truncated, 2.6e-5 relative low).
    assert HERTZ_TIME_FACTOR_EXACT == pytest.approx(2.9432, abs=1e-4)
    ref = hertz_impact(0.185, 1.036e10, math.sqrt(2 * 9.81 * 0.05))
    # Closed-form figures of the 5 cm drop of the 10 mm bar: 54 um, 162 us, 4.16 kN.
    assert ref.max_penetration == pytest.approx(54e-6, rel=1e-2)
    assert ref.contact_time == pytest.approx(162e-6, rel=1e-2)
    assert ref.peak_force == pytest.approx(4.16e3, rel=1e-2)


def vertical_rigid_scene(rtol=1e-9):
    return make_scene(initial=dict(height=1e-5, angle_deg=90.0, velocity=(0.0, 0.0, -V0)),
                      solver=dict(rtol=rtol, t_end=1e-3))


def test_rigid_vertical_bar_matches_hertz_contact_time_peak_force_and_penetration():
    scene = vertical_rigid_scene()
    solver = ImpactSolver(scene, keep_dense=True)
    segment = solver.advance(scene.solver.t_end)
    res = solver.result()
    k = steel_stiffness(scene.bar.tip_radius)
    assert res.model.contact.stiffness == pytest.approx(k, rel=1e-14)
    ref = hertz_closed_form(scene.bar.mass, k, V0)  # vertical: the normal mass is m
    c = res.contacts
    assert len(c) == 1 and c.tip[0] == 0
    # The closed forms are exact for this problem; 1e-4 leaves room for the integration
    # tolerance only (the issue asks for < 0.5 %).
    assert c.t_end[0] - c.t_start[0] == pytest.approx(ref["contact_time"], rel=1e-4)
    assert c.peak_force[0] == pytest.approx(ref["peak_force"], rel=1e-4)
    # Largest penetration from the dense output, maximized between the records around it.
    h = res.history
    k_max = int(np.argmax(h.penetration_0))
    lo, hi = h.time[k_max - 1], h.time[k_max + 1]
    best = minimize_scalar(lambda t: -segment.contact(t)[0, 0], bounds=(lo, hi), method="bounded",
                           options=dict(xatol=1e-12))
    assert -best.fun == pytest.approx(ref["max_penetration"], rel=1e-4)
    # Elastic: the tip leaves as fast as it came, and Stronge's energetic ratio is 1.
    assert c.kinematic_restitution[0] == pytest.approx(1.0, abs=1e-5)
    assert c.energetic_restitution[0] == pytest.approx(1.0, abs=1e-5)
    assert c.impulse[0] == pytest.approx(2.0 * scene.bar.mass * V0, rel=1e-5)


def tilted_rebound(angle_deg: float, diameter: float = 0.01, tip_radius: float = 0.005):
    scene = make_scene(bar=dict(diameter=diameter, tip_radius=tip_radius),
                       initial=dict(height=1e-5, angle_deg=angle_deg, velocity=(0.0, 0.0, -V0)),
                       solver=dict(rtol=1e-9, t_end=1e-3))
    res = simulate(scene)
    bar = scene.bar
    theta = math.radians(angle_deg)
    a = 0.5 * bar.length - bar.tip_radius  # centroid to the tip-sphere centre
    i_t = transverse_inertia(bar)
    # The normal force acts through the sphere centre, a cos(theta) horizontally from the
    # centroid: 1/m_eff = 1/m + (a cos theta)^2 / I_t.
    m_eff = bar.mass / (1.0 + bar.mass * (a * math.cos(theta)) ** 2 / i_t)
    return scene, res, m_eff, a, i_t


@pytest.mark.parametrize("angle_deg", [30.0, 60.0])
def test_tilted_rigid_bar_rebounds_with_the_effective_normal_mass(angle_deg):
    scene, res, m_eff, a, i_t = tilted_rebound(angle_deg)
    m = scene.bar.mass
    c = res.contacts
    assert len(c) == 1
    ref = hertz_closed_form(m_eff, res.model.contact.stiffness, V0)
    # The bar turns by ~omega t_c ~ 2e-3 rad during the contact, which changes the lever arm
    # a cos(theta) by that order: the 1-DOF reduction holds to ~1e-3.
    tol = 2e-3
    assert c.t_end[0] - c.t_start[0] == pytest.approx(ref["contact_time"], rel=tol)
    assert c.peak_force[0] == pytest.approx(ref["peak_force"], rel=tol)
    h = res.history
    impulse = 2.0 * m_eff * V0  # elastic: the normal speed of the contact point reverses
    assert h.vz.iloc[-1] - h.vz.iloc[0] == pytest.approx(impulse / m, rel=tol)
    # Angular impulse of the normal force about the centroid; it spins the lower (tip 0)
    # end up, i.e. about +y for a bar rising towards +x.
    assert h.wy.iloc[-1] == pytest.approx(-impulse * a * math.cos(math.radians(angle_deg)) / i_t
                                          * np.sign(res.model.basis.x_centre[0]), rel=tol)
    assert c.energetic_restitution[0] == pytest.approx(1.0, abs=1e-5)


@pytest.mark.parametrize("angle_deg", [30.0, 60.0])
def test_slender_tilted_bar_tends_to_the_notes_effective_mass(angle_deg):
    # d = 0.2 mm, R = 0.1 mm: a = L/2 - R and I_t = m L^2/12 + rho L I differ from the
    # slender values by < 1e-3, so m_eff -> m / (1 + 3 cos^2 theta).
    scene, res, m_eff, _, _ = tilted_rebound(angle_deg, diameter=2e-4, tip_radius=1e-4)
    m = scene.bar.mass
    slender = m / (1.0 + 3.0 * math.cos(math.radians(angle_deg)) ** 2)
    h = res.history
    assert m * (h.vz.iloc[-1] - h.vz.iloc[0]) == pytest.approx(2.0 * slender * V0, rel=2e-3)
    assert m_eff == pytest.approx(slender, rel=1e-3)


def test_elastic_flexible_impacts_conserve_energy_and_have_unit_energetic_restitution():
    # 30 deg, 3 modes per family, no damping, no friction: the tip chatters (several
    # contacts) while energy flows into vibration.
    scene = make_scene(bar=dict(axial_modes=3, bending_modes=3),
                       initial=dict(height=1e-5, angle_deg=30.0, velocity=(0.0, 0.0, -V0)),
                       # rtol 1e-8: the residual goes as ~30 rtol here (measured 3e-6 at 1e-7,
                       # 3e-7 at 1e-8), so 1e-8 is the loosest tolerance meeting 1e-6.
                       solver=dict(rtol=1e-8, t_end=2e-3))
    res = simulate(scene)
    en = res.energy_table
    e0 = res.energy["initial"]
    assert np.max(np.abs(en.residual)) < 1e-6 * e0
    assert en.normal_dissipation.abs().max() == 0.0
    c = res.contacts
    assert len(c) >= 2
    # Hertz contact is a conservative spring: the work it takes in compression it returns in
    # restitution, whatever the bar's vibration does (Stronge's ratio is 1) ...
    np.testing.assert_allclose(c.energetic_restitution, 1.0, atol=1e-6)
    # ... while the kinematic ratio is not 1: the tip's speed includes the vibration.
    assert np.max(np.abs(c.kinematic_restitution - 1.0)) > 1e-2
    # Energy left in vibration after the last contact is real (elastic + modal kinetic).
    assert en.elastic.iloc[-1] > 1e-4 * e0
