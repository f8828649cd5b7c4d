"""Conservation laws of the floating-frame bar: energy and angular momentum in free
flight, linear momentum under gravity, and the closing of the energy audit with
damping, friction and modal damping; errors that shrink with the tolerance."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import mech
from mech import ImpactSolver
from mech.kernel import quat_to_matrix

from mech_cases import make_scene, start_from

G = 9.80665


def spinning_vibrating_bar(rtol: float, gravity: float = 0.0, t_end: float = 5e-3) -> mech.ImpactResult:
    """A 3D bar far above the block, tumbling about all three axes with every mode family
    displaced and moving, so the gyroscopic, centrifugal and inertia-variation terms
    (J1, J2, S) all carry energy and angular momentum between rotation and vibration."""
    scene = make_scene(bar=dict(axial_modes=2, bending_modes=2),
                       initial=dict(height=0.5, angle_deg=20.0, velocity=(0.3, -0.2, 0.1),
                                    angular_velocity=(30.0, 50.0, -20.0)),
                       solver=dict(rtol=rtol, t_end=t_end, model="3d"), gravity=gravity)
    solver = ImpactSolver(scene)
    # modes: axial 1-2, bend2 1-2, bend3 1-2; amplitudes up to 0.1 mm and speeds of cm/s
    start_from(solver, q=np.array([2e-6, -1e-6, 1e-4, -3e-5, 6e-5, 2e-5]),
               eta=np.array([0.01, -0.02, 0.05, 0.02, -0.03, 0.04]))
    return solver.run()


def angular_momentum(res: mech.ImpactResult, about_centre_of_mass: bool = False) -> np.ndarray:
    """World angular momentum about the origin (or the centre of mass): R (J w + B eta) + m r x V."""
    b = res.model.basis
    sl = res.model.slices()
    out = np.empty((len(res.t), 3))
    R = np.empty((3, 3))
    for k, y in enumerate(res.states):
        quat_to_matrix(*y[sl["quat"]], R)
        q, eta, w = y[sl["q"]], y[sl["eta"]], y[sl["omega"]]
        J = b.J0 + np.einsum("jab,j->ab", b.J1, q) + np.einsum("jkab,j,k->ab", b.J2, q, q)
        B = np.einsum("kja,k->aj", b.S, q)
        out[k] = R @ (J @ w + B @ eta)
        if not about_centre_of_mass:
            out[k] += b.mass * np.cross(y[sl["pos"]], y[sl["vel"]])
    return out


def free_flight_energy_error(res: mech.ImpactResult) -> float:
    en = res.energy_table
    total = (en.kinetic + en.elastic).to_numpy()
    return float(np.max(np.abs(total / total[0] - 1.0)))


def test_free_flight_of_a_spinning_vibrating_bar_conserves_energy_and_angular_momentum():
    rtol = 1e-9
    res = spinning_vibrating_bar(rtol)
    assert res.contacts.empty
    en = res.energy_table
    # The vibration really exchanges energy with the rotation (else this checks little).
    assert np.ptp(en.elastic) > 1e-3 * en.elastic.max()
    # The error control holds speeds to rtol times the motion's own speed scale
    # (here |V| + |w| L/2 ~ 10 m/s); over the run's ~2600 steps the energy error is
    # 40-58 x rtol for rtol 1e-7..1e-11 (measured), proportional to rtol, which the
    # convergence test below checks by its slope.
    assert free_flight_energy_error(res) < 100 * rtol
    h = angular_momentum(res)
    drift = np.max(np.linalg.norm(h - h[0], axis=1)) / np.linalg.norm(h[0])
    assert drift < 1e-12
    # The audit reports the same: nothing dissipated, residual at the integration error.
    assert res.energy["relative_residual"] < 100 * rtol  # the same measure, as above


def test_free_flight_energy_error_falls_in_proportion_to_rtol():
    rtols = np.array([1e-7, 1e-8, 1e-9, 1e-10])
    errors = np.array([free_flight_energy_error(spinning_vibrating_bar(r)) for r in rtols])
    slope = np.polyfit(np.log10(rtols), np.log10(errors), 1)[0]
    # DOPRI5 with error-per-step control and local extrapolation: global error ~ tol^1.
    assert 0.8 < slope < 1.2, (errors, slope)
    assert np.all(np.diff(errors) < 0)


def test_gravity_changes_linear_momentum_by_exactly_m_g_t_in_free_flight():
    res = spinning_vibrating_bar(1e-8, gravity=G)
    sl = res.model.slices()
    t = res.t
    V = res.states[:, sl["vel"]]
    r = res.states[:, sl["pos"]]
    V0, r0 = V[0], r[0]
    # Gravity is the only external force: m dV/dt = -m g e_z. A Runge-Kutta step integrates a
    # constant derivative exactly, so V and r follow the parabola to round-off.
    expected_V = V0 - G * np.outer(t, [0.0, 0.0, 1.0])
    expected_r = r0 + np.outer(t, V0) - 0.5 * G * np.outer(t**2, [0.0, 0.0, 1.0])
    np.testing.assert_allclose(V, expected_V, rtol=0, atol=1e-13)
    np.testing.assert_allclose(r, expected_r, rtol=0, atol=1e-13)
    # Gravity acts at the centre of mass: the angular momentum about it is still conserved.
    h = angular_momentum(res, about_centre_of_mass=True)
    assert np.max(np.linalg.norm(h - h[0], axis=1)) < 1e-12 * np.linalg.norm(h[0])
    # The audit's potential energy is m g (z - z0): with the translational kinetic energy it
    # is constant to round-off (the rest of the energy is the free rotation and vibration,
    # checked without gravity above).
    en = res.energy_table
    m = res.model.basis.mass
    translational = 0.5 * m * np.sum(V**2, axis=1) + en.potential.to_numpy()
    assert np.max(np.abs(translational - translational[0])) < 1e-13 * en.kinetic.iloc[0]


def audited_impacts(rtol: float) -> mech.ImpactResult:
    """The default scene (3D, 3 modes per family, damped contact, gamma = 0.7 friction) with
    modal damping added, over its first four impacts (5 ms)."""
    base = mech.default_scene()
    scene = dataclasses.replace(
        base, bar=dataclasses.replace(base.bar, modal_damping=0.01),
        solver=dataclasses.replace(base.solver, rtol=rtol, t_end=5e-3))
    return mech.simulate(scene)


def test_energy_audit_closes_with_contact_damping_friction_and_modal_damping():
    residuals, results = [], []
    for rtol in (1e-7, 1e-9):
        res = audited_impacts(rtol)
        e = res.energy
        # every sink is really used, so each quadrature is checked by the balance
        assert len(res.contacts) >= 3
        assert e["normal_dissipation"] > 1e-2 * e["initial"]
        assert e["friction_dissipation"] > 1e-4 * e["initial"]
        assert e["modal_dissipation"] > 1e-5 * e["initial"]
        residuals.append(e["relative_residual"])
        results.append(res)
    # The dissipations are integrated as separate quadratures, the energies evaluated from the
    # state: a wrong sink would leave a residual that does not shrink with the tolerance.
    assert residuals[1] < 1e-7
    assert residuals[1] < residuals[0] / 30.0
    # Both tolerances agree on the dissipated energies to the coarser one's accuracy. The
    # quadratures are error-controlled against the run's energy scale (rtol x E), not their
    # own size: friction takes 0.15 % of the energy here, so its agreement is stated in
    # units of the initial energy (measured: <= 2.4e-6 at rtol 1e-7). A wrong sink would
    # differ at the size of the sink itself.
    e0 = results[1].energy["initial"]
    for key in ("normal_dissipation", "friction_dissipation", "modal_dissipation"):
        assert abs(results[0].energy[key] - results[1].energy[key]) < 1e-5 * e0
