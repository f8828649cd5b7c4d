"""Free-free modes of the bar: roots, frequencies, shape orthogonality, modal invariants,
and a free vibration of the whole solver at the closed-form frequency."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mech import Bar, ImpactSolver
from mech.modal_basis import build_modal_basis, mode_list, shape_values
from mech.modes import free_free_roots

from mech_cases import make_scene, start_from

# Published roots of cos(b) cosh(b) = 1 (e.g. Blevins, Formulas for Natural Frequency
# and Mode Shape, table 8-1), six decimals.
PUBLISHED_ROOTS = np.array([4.730041, 7.853205, 10.995608, 14.137165, 17.278760])


def gauss(points: int = 200):
    """Gauss-Legendre nodes and weights on xi in [0, 1] (our own quadrature, not the basis's)."""
    t, w = np.polynomial.legendre.leggauss(points)
    return 0.5 * (t + 1.0), 0.5 * w


def test_free_free_roots_match_published_values_and_solve_the_frequency_equation():
    roots = free_free_roots(5)
    np.testing.assert_allclose(roots, PUBLISHED_ROOTS, atol=6e-7)
    # cos b cosh b = 1 for every root, checked in the well-scaled form cos b - 1/cosh b.
    many = free_free_roots(30)
    assert np.all(np.abs(np.cos(many) - 1.0 / np.cosh(many)) < 1e-14)
    # The roots tend to (n + 1/2) pi, with an error decaying like exp(-b).
    assert abs(many[-1] - 30.5 * math.pi) < 1e-12
    assert np.all(np.diff(many) > 0.0)


def test_basis_frequencies_match_euler_bernoulli_and_axial_closed_forms():
    bar = Bar(axial_modes=5, bending_modes=5)
    basis = build_modal_basis(bar, planar=False)
    freqs = np.asarray(basis.frequencies)
    fam = np.array(basis.families)
    L, E, rho, A = bar.length, bar.youngs_modulus, bar.density, bar.area
    i22, _ = bar.second_moments  # round section: equal in both planes
    # Euler-Bernoulli free-free: f_n = (beta_n L)^2 / (2 pi L^2) sqrt(E I / (rho A)).
    expected_bend = PUBLISHED_ROOTS**2 / (2.0 * math.pi * L**2) * math.sqrt(E * i22 / (rho * A))
    # Axial free-free: f_k = k c / (2 L), c = sqrt(E / rho).
    expected_axial = np.arange(1, 6) * math.sqrt(E / rho) / (2.0 * L)
    # The published roots carry 7 digits: 1e-6 relative is their precision, far inside 0.1 %.
    np.testing.assert_allclose(freqs[fam == "bend2"], expected_bend, rtol=1e-6)
    np.testing.assert_allclose(freqs[fam == "bend3"], expected_bend, rtol=1e-6)
    np.testing.assert_allclose(freqs[fam == "axial"], expected_axial, rtol=1e-12)


def test_steel_bar_frequencies_match_the_notes_figures():
    # Closed forms: steel, L = 0.3 m, d = 10 mm: 499, 1376, 2698, 4460, 6662 Hz; c ~ 5050 m/s,
    # i.e. E = 200 GPa, rho = 7850 kg/m^3. Figures rounded to 1 Hz: 0.1 % is their precision.
    bar = Bar(length=0.3, diameter=0.01, youngs_modulus=200e9, density=7850.0,
              axial_modes=1, bending_modes=5)
    basis = build_modal_basis(bar, planar=True)
    fam = np.array(basis.families)
    np.testing.assert_allclose(np.asarray(basis.frequencies)[fam == "bend3"],
                               [499, 1376, 2698, 4460, 6662], rtol=1e-3)
    np.testing.assert_allclose(np.asarray(basis.frequencies)[fam == "axial"], 5050 / 0.6, rtol=1e-3)


def test_rectangular_section_bends_with_the_second_moment_of_its_plane():
    # width along b2, thickness along b3: delta2 bends about b3 (I = t w^3/12), delta3 about b2.
    w, t = 0.012, 0.004
    bar = Bar(diameter=None, width=w, thickness=t, tip_radius=0.007, axial_modes=0, bending_modes=1)
    basis = build_modal_basis(bar, planar=False)
    f = dict(zip(basis.families, basis.frequencies))
    assert f["bend2"] / f["bend3"] == pytest.approx(math.sqrt((t * w**3) / (w * t**3)), rel=1e-10)


@pytest.mark.parametrize("count", [5, 20])
def test_mode_shapes_are_orthonormal_zero_mean_and_bending_has_zero_first_moment(count):
    bar = Bar(axial_modes=count, bending_modes=count)
    modes = mode_list(bar, planar=True)
    xi, w = gauss(400)
    phi = shape_values(bar, modes, xi)
    assert np.all(np.isfinite(phi))
    fam = np.array([f for f, _ in modes])
    for family in ("axial", "bend3"):
        p = phi[fam == family]
        gram = (p * w) @ p.T
        # Mean square 1 (modal mass = bar mass) and orthogonal within a family.
        np.testing.assert_allclose(gram, np.eye(count), atol=1e-10)
        # Zero mean: no net translation, so the frame at the centroid stays at the centroid.
        np.testing.assert_allclose(p @ w, 0.0, atol=1e-10)
    # Zero first moment of the bending shapes: no net rotation (mean-axis frame).
    np.testing.assert_allclose(phi[fam == "bend3"] @ (w * (xi - 0.5)), 0.0, atol=1e-10)
    # Free ends of the bending modes: phi(0) = 2, |phi(1)| = 2 in this normalization, and
    # the second derivative (moment) vanishes there.
    ends = shape_values(bar, modes, np.array([0.0, 1.0]))[fam == "bend3"]
    np.testing.assert_allclose(np.abs(ends), 2.0, rtol=1e-9)
    bending = [mk for mk in modes if mk[0] == "bend3"]
    curv = shape_values(bar, bending, np.array([0.0, 1.0]), 2) * bar.length**2
    roots = free_free_roots(count)
    np.testing.assert_allclose(curv / roots[:, None] ** 2, 0.0, atol=1e-8)


def test_modal_invariants_have_the_symmetries_and_closed_forms_of_the_mean_axis_frame():
    bar = Bar(axial_modes=3, bending_modes=3)
    b = build_modal_basis(bar, planar=False)
    m, L = bar.mass, bar.length
    fam = b.families
    n = b.n
    # Gyroscopic coupling is antisymmetric: S_jk = int rho A Psi_j x Psi_k = -S_kj.
    np.testing.assert_allclose(b.S, -np.transpose(b.S, (1, 0, 2)), atol=1e-14 * m)
    # J2_jk = int rho A (Psi_j . Psi_k I - Psi_j Psi_k^T) gives J2_kj = J2_jk^T.
    np.testing.assert_allclose(b.J2, np.transpose(b.J2, (1, 0, 3, 2)), atol=1e-14 * m)
    direction = {"axial": 0, "bend2": 1, "bend3": 2}
    for j in range(n):
        for k in range(n):
            if fam[j] == fam[k] and j != k:
                # Orthogonal shapes of one family: no coupling.
                assert np.max(np.abs(b.J2[j, k])) < 1e-10 * m
            if j == k:
                d = np.zeros(3)
                d[direction[fam[j]]] = 1.0
                np.testing.assert_allclose(b.J2[j, j], m * (np.eye(3) - np.outer(d, d)), atol=1e-10 * m)
    for j in range(n):
        if fam[j] == "axial":
            # Stretching a mode k changes the transverse inertia by 2 int rho A x phi:
            # int_0^1 (xi - 1/2) sqrt(2) cos(k pi xi) dxi = sqrt(2) ((-1)^k - 1) / (k pi)^2.
            k = b.orders[j]
            a = m * L * math.sqrt(2.0) * ((-1) ** k - 1) / (k * math.pi) ** 2
            np.testing.assert_allclose(b.J1[j], 2.0 * a * np.diag([0.0, 1.0, 1.0]), atol=1e-12 * m * L)
        else:
            # Bending modes have zero first moment: they do not change the inertia to first order.
            assert np.max(np.abs(b.J1[j])) < 1e-12 * m * L
    # Tip-sphere centres at x = -+(L/2 - R), where the tip's contact geometry is attached.
    np.testing.assert_allclose(b.x_centre, [-(L / 2 - bar.tip_radius), L / 2 - bar.tip_radius])


def zero_crossing_frequency(t: np.ndarray, x: np.ndarray) -> float:
    """Hz from the interval between the first and last sign change (linear interpolation,
    accurate to second order because a sine is straight at its zero crossings)."""
    s = np.sign(x)
    idx = np.nonzero(s[:-1] * s[1:] < 0)[0]
    tz = t[idx] - x[idx] * (t[idx + 1] - t[idx]) / (x[idx + 1] - x[idx])
    return (len(tz) - 1) / (2.0 * (tz[-1] - tz[0]))


@pytest.mark.parametrize("family, order, model", [
    ("axial", 1, "planar"), ("bend3", 2, "planar"), ("bend2", 1, "3d"),
])
def test_free_bar_started_in_one_mode_vibrates_at_that_modes_frequency(family, order, model):
    bar = Bar(axial_modes=2, bending_modes=2)
    basis = build_modal_basis(bar, planar=(model == "planar"))
    j = [i for i, (f, k) in enumerate(zip(basis.families, basis.orders)) if (f, k) == (family, order)][0]
    f_expected = float(basis.frequencies[j])  # checked against the closed forms above
    periods = 12
    scene = make_scene(bar=dict(axial_modes=2, bending_modes=2),
                       initial=dict(height=1.0, angle_deg=20.0, velocity=(0.0, 0.0, 0.0)),
                       solver=dict(rtol=1e-8, t_end=periods / f_expected, model=model))
    solver = ImpactSolver(scene)
    q0 = np.zeros(basis.n)
    q0[j] = 1e-5
    start_from(solver, q=q0)
    res = solver.run()
    assert res.contacts.empty
    q = res.states[:, res.model.slices()["q"]]
    f_measured = zero_crossing_frequency(res.t, q[:, j])
    assert f_measured == pytest.approx(f_expected, rel=1e-4)
    # A single free mode of a bar that neither moves nor spins excites nothing else.
    others = np.delete(q, j, axis=1)
    assert np.max(np.abs(others)) < 1e-9 * q0[j]
