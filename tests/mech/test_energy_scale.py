"""The energy scale counts the work of every steady load, bounded from the scene before the
run: checked against closed forms (a pendulum's and a preloaded arm's fall to the block, a
cantilever's sag) and the bound of a load on elastic modes against a numerical optimiser."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import minimize

from mech.model import load_release_bound, load_work_bound
from mech.scene import scene_from_dict
from mech.solver import ImpactSolver

STEEL = dict(youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)


@pytest.mark.parametrize("seed", range(6))
def test_the_release_bound_is_the_optimum_a_numerical_optimiser_finds(seed):
    """max f.q over {1/2 q K q - f.q <= e} (and c.q <= room): the closed form against SLSQP
    from 8 starts, which meets its constraints to ~1e-10 here (tolerance 1e-7)."""
    rng = np.random.default_rng(seed)
    n = 4
    A = rng.normal(size=(n, n))
    K = A @ A.T + n * np.eye(n)
    f, c = rng.normal(size=n), rng.normal(size=n)
    e, room = abs(rng.normal()) * 0.3, abs(rng.normal()) * 0.2
    for cut in (None, c):
        cons = [{"type": "ineq", "fun": lambda q: e - (0.5 * q @ K @ q - f @ q)}]
        if cut is not None:
            cons.append({"type": "ineq", "fun": lambda q: room - c @ q})
        best = max(-minimize(lambda q: -(f @ q), rng.normal(size=n) * 0.1, constraints=cons, method="SLSQP",
                             options=dict(ftol=1e-14, maxiter=500)).fun for _ in range(8))
        assert load_release_bound(K, f, e, cut, room) == pytest.approx(best, rel=1e-7)
    # from rest, unconstrained: twice the static work f K^-1 f
    assert load_release_bound(K, f, 0.0) == pytest.approx(2.0 * f @ np.linalg.solve(K, f), rel=1e-14)


def arm(**over) -> dict:
    """A rigid steel arm 0.1 m long hinged at its tip-1 end, level, its tip-0 cap 5 cm above the block."""
    doc = {"bar": dict(length=0.1, diameter=0.01, tip_radius=0.005, **STEEL, modes=0),
           "mount": dict(kind="pivot", position=0.1),
           "initial": dict(height=0.05),
           "contact": dict(law="hunt_crossley", restitution=0.3, reference_speed=0.1),
           "solver": dict(t_end=0.15), "environment": dict(gravity=0.0)}
    doc.update(over)
    return doc


def energy_at_first_contact(res) -> float:
    """J: the kinetic energy at the first contact start (nothing dissipates before it)."""
    t0 = res.contact_columns["t_start"][0]
    k = int(np.searchsorted(res.t, t0))
    return float(res.energy_columns["kinetic"][k])


def test_a_pendulum_is_judged_against_the_fall_of_its_centre_to_the_block():
    """Released level, the arm turns by asin(h / (L - R)) until its cap meets the block; its
    centre, L/2 from the hinge, falls L/2 h / (L - R): that m g times, and nothing else,
    is the energy scale (the caps may sink in by the Hertz penetration, ~3e-5 m against
    the 5 cm gap: 1e-3 relative). The kinetic energy at the first contact is that fall."""
    L, R, h = 0.1, 0.005, 0.05
    res = ImpactSolver(scene_from_dict(arm(environment=dict(gravity=9.81)))).run()
    m = res.model.basis.mass
    fall = m * 9.81 * (L / 2) * h / (L - R)
    assert load_work_bound(res.model, 0.0) == pytest.approx(fall, rel=1e-3)  # from the scene, before the run
    assert res.energy_scale == pytest.approx(fall, rel=1e-3)
    assert energy_at_first_contact(res) == pytest.approx(fall, rel=1e-3)
    assert res.max_kinetic <= res.energy_scale and res.flags == []


def test_a_preloaded_arm_is_judged_against_the_work_of_its_torque():
    """A preload torque T with no spring rate and no gravity turns the arm by
    asin(h / (L - R)) onto the block: T times that angle (the audit's case judged it
    against 1e-300 J)."""
    L, R, h, T = 0.1, 0.005, 1e-3, 0.05
    res = ImpactSolver(scene_from_dict(arm(mount=dict(kind="pivot", position=L, preload_torque=T),
                                           initial=dict(height=h), solver=dict(t_end=0.03)))).run()
    work = T * math.asin(h / (L - R))
    assert load_work_bound(res.model, 0.0) == pytest.approx(work, rel=1e-2)  # from the scene, before the run
    assert res.energy_scale == pytest.approx(work, rel=1e-2)
    assert energy_at_first_contact(res) == pytest.approx(work, rel=1e-3)
    assert res.max_kinetic <= res.energy_scale and res.flags == []


def sagging_blade(rtol: float):
    L, b, t = 0.02, 0.003, 0.0003
    doc = {"bar": dict(length=L, width=b, thickness=t, tip_radius=0.0016, **STEEL,
                       modes={"axial": 1, "bending": 6}),
           "mount": dict(kind="clamp", position=L), "initial": dict(height=1e-3),
           "contact": dict(law="hunt_crossley", restitution=0.5), "solver": dict(t_end=2e-3, rtol=rtol),
           "environment": dict(gravity=9.81)}
    w = 7850.0 * b * t * 9.81
    return ImpactSolver(scene_from_dict(doc)).run(), w * w * L**5 / (20.0 * 210e9 * b * t**3 / 12.0)


def test_a_sagging_cantilever_is_judged_against_twice_its_static_work():
    """A blade clamped at one end, released straight under gravity, nothing else (the audit
    judged it against 1e-300 J): its modes can take at most twice the static work of its
    weight, 2 w^2 L^5 / (20 E I) for the uniform load w = rho A g (Euler-Bernoulli). Six
    bending modes capture all but the modes above them, whose share of the static work
    falls as 1/j^6: within 1e-3. A load applied at once swings each mode through twice its
    static deflection, its kinetic energy peaking at half its static work: the run's peak is
    half the static work, within the 3 % the higher modes hold (they peak at other times)."""
    res, static = sagging_blade(1e-8)
    assert res.energy_scale == pytest.approx(2.0 * static, rel=1e-3)
    assert res.max_kinetic == pytest.approx(0.5 * static, rel=3e-2)
    assert len(res.contact_columns["tip"]) == 0 and res.flags == []


def test_a_sag_integrated_too_coarsely_is_caught_against_that_scale():
    """At rtol 1e-6 the same undamped swing is integrated 0.5 % off in its peak kinetic
    energy (the error control's scales assume the weight's work over the 1 mm gap, 1000
    times the sag's): the audit against twice the static work sees it."""
    loose, static = sagging_blade(1e-6)
    fine, _ = sagging_blade(1e-8)
    assert abs(loose.max_kinetic / fine.max_kinetic - 1.0) > 1e-3
    assert loose.energy_scale == fine.energy_scale
    assert loose.energy["relative_residual"] > 1e-3 and "energy residual" in loose.flags[0]
