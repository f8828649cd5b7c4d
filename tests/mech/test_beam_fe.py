"""Finite-element modes of a free, clamped or pivoted bar (mech.beam_fe) against closed forms.

Every reference here is independent of the finite elements: Euler-Bernoulli frequency
equations solved with brentq, the static cantilever, the rod's wave solutions, and the
analytic free-free basis of mech.modal_basis (closed-form shapes, Gauss quadrature).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from mech import Bar
from mech.beam_fe import (
    FEBeam, PointMass, assemble, beam_basis, beam_frequencies, beam_invariants, beam_modes, default_elements,
    mesh, point_shapes,
)
from mech.modal_basis import build_modal_basis
from mech.modes import free_free_roots

# A steel strip 200 x 12 x 2 mm: I22 (bend3, across the thickness) != I33 (bend2).
L, E, RHO, WIDTH, THICK = 0.2, 2.0e11, 7800.0, 0.012, 0.002
AREA = WIDTH * THICK
I22 = WIDTH * THICK**3 / 12.0
I33 = THICK * WIDTH**3 / 12.0
RHO_A = RHO * AREA
C_ROD = math.sqrt(E / RHO)

# Published roots (Blevins, Formulas for Natural Frequency and Mode Shape, table 8-1).
CLAMPED_FREE = np.array([1.875104, 4.694091, 7.854757, 10.995541])
PINNED_FREE = np.array([3.926602, 7.068583, 10.210176])
FREE_FREE = np.array([4.730041, 7.853205, 10.995608, 14.137165])


def strip(**kw) -> FEBeam:
    return FEBeam(L, E, RHO, AREA, I22, I33, **kw)


def bending_hz(beta_l, second_moment, length=L):
    """Hz: (beta L)^2 / L^2 sqrt(E I / (rho A)) / (2 pi)."""
    return np.asarray(beta_l) ** 2 / length**2 * math.sqrt(E * second_moment / RHO_A) / (2.0 * math.pi)


def roots(f, count, start=0.5, step=0.05):
    """The first ``count`` sign changes of f on a grid from ``start``, refined by brentq."""
    out, a = [], start
    fa = f(a)
    while len(out) < count:
        b = a + step
        fb = f(b)
        if fa * fb < 0.0:
            out.append(brentq(f, a, b, xtol=1e-14, rtol=1e-15))
        a, fa = b, fb
    return np.array(out)


def clamped_free_roots(count):  # 1 + cos b cosh b = 0, divided by cosh b
    return roots(lambda b: math.cos(b) + 1.0 / math.cosh(b), count)


def pinned_free_roots(count):  # tan b = tanh b, as sin b - cos b tanh b = 0 (b > 0)
    return roots(lambda b: math.sin(b) - math.cos(b) * math.tanh(b), count, start=1.0)


# ----------------------------------------------------------------------------- frequencies

def test_the_written_out_gauss_rules_are_the_closed_form_ones():
    """mech.gauss's rules (numpy's leggauss floats written out: no numpy.polynomial import at a
    run's start): the closed-form nodes and weights and numpy's to round-off, exact for
    polynomials of degree 2n - 1 and not of degree 2n."""
    from mech.gauss import LEGGAUSS

    inner, outer = math.sqrt(3 / 7 - 2 / 7 * math.sqrt(6 / 5)), math.sqrt(3 / 7 + 2 / 7 * math.sqrt(6 / 5))
    w_inner, w_outer = (18 + math.sqrt(30)) / 36, (18 - math.sqrt(30)) / 36
    closed = {3: ((-math.sqrt(0.6), 0.0, math.sqrt(0.6)), (5 / 9, 8 / 9, 5 / 9)),
              4: ((-outer, -inner, inner, outer), (w_outer, w_inner, w_inner, w_outer))}
    assert LEGGAUSS.keys() == closed.keys()
    for n, (nodes, weights) in LEGGAUSS.items():
        np.testing.assert_allclose(nodes, closed[n][0], rtol=0, atol=1e-15)
        np.testing.assert_allclose(weights, closed[n][1], rtol=0, atol=1e-15)
        x, w = np.polynomial.legendre.leggauss(n)
        np.testing.assert_allclose(nodes, x, rtol=0, atol=1e-15)
        np.testing.assert_allclose(weights, w, rtol=0, atol=1e-15)
        for k in range(2 * n):  # the integral of x^k over [-1, 1]: 2 / (k + 1), k even
            exact = 2.0 / (k + 1) if k % 2 == 0 else 0.0
            assert sum(wj * xj**k for xj, wj in zip(nodes, weights)) == pytest.approx(exact, rel=0, abs=1e-15)
        assert abs(sum(wj * xj ** (2 * n) for xj, wj in zip(nodes, weights)) - 2.0 / (2 * n + 1)) > 1e-3


def test_clamped_free_bending_matches_the_published_roots_in_both_planes():
    beam = strip(support="clamp", support_position=L)  # held at the tip-1 end
    bend2, bend3 = beam_basis(beam, 0, 4, elements=80)
    # Published roots to 6 decimals (5e-7 relative in f); FE error (beta h)^4/1440 < 3e-7.
    np.testing.assert_allclose(bend3.frequencies, bending_hz(CLAMPED_FREE, I22), rtol=1e-6)
    np.testing.assert_allclose(bend2.frequencies, bending_hz(CLAMPED_FREE, I33), rtol=1e-6)
    # Held at L, tip 0 is free: shapes are 0 with 0 slope at the clamp, positive at tip 0.
    assert np.all(bend3.value([0.0])[:, 0] > 0.0)
    assert np.max(np.abs(bend3.value([L]))) < 1e-12
    assert np.max(np.abs(bend3.slope([L]))) < 1e-10
    # Held at tip 0 instead: the same spectrum, and the free end x = L is the positive one.
    mirrored = beam_modes(strip(support="clamp", support_position=0.0), "bend3", 4, elements=80)
    np.testing.assert_allclose(mirrored.frequencies, bend3.frequencies, rtol=1e-12)
    assert np.all(mirrored.value([L])[:, 0] > 0.0)
    np.testing.assert_allclose(mirrored.value([L - 0.03])[:, 0], bend3.value([0.03])[:, 0], rtol=1e-9)


def test_bending_and_axial_frequencies_converge_at_the_elements_order():
    """Hermite cubic bending: frequency error ~ (beta h)^4 / 1440; cubic axial: ~ h^6."""
    beam = strip(support="clamp", support_position=L)
    exact_b = bending_hz(clamped_free_roots(3), I22)
    k = np.arange(1, 4)
    exact_a = (2 * k - 1) * C_ROD / (4.0 * L)
    err_b, err_a = [], []
    for n in (8, 16, 32):
        err_b.append(beam_modes(beam, "bend3", 3, elements=n).frequencies / exact_b - 1.0)
        err_a.append(beam_modes(beam, "axial", 3, elements=n).frequencies / exact_a - 1.0)
    err_b, err_a = np.array(err_b), np.array(err_a)
    assert np.all(err_b > 0.0) and np.all(err_a > 0.0)  # consistent mass: upper bounds
    order_b = np.log2(err_b[:-1] / err_b[1:])
    order_a = np.log2(err_a[1] / err_a[2])  # modes 1-3 at 16 and 32 elements: 1e-9 .. 3e-6
    assert np.all(np.abs(order_b - 4.0) < 0.15), order_b
    assert np.all(np.abs(order_a - 6.0) < 0.3), order_a
    # The error constant behind the default mesh rule: (beta h)^4 / 1440 within 10 %.
    beta_h = clamped_free_roots(3) / 32.0
    np.testing.assert_allclose(err_b[-1] * 1440.0 / beta_h**4, 1.0, rtol=0.1)


@pytest.mark.parametrize("support, position, closed", [
    ("clamp", L, "clamped"), ("clamp", 0.0, "clamped"), ("pivot", L, "pinned"), ("free", 0.0, "free"),
])
def test_the_default_mesh_resolves_the_highest_requested_mode(support, position, closed):
    count = 12
    ref = {"clamped": clamped_free_roots, "pinned": pinned_free_roots, "free": free_free_roots}[closed](count)
    modes = beam_modes(strip(support=support, support_position=position), "bend3", count)
    assert len(modes.nodes) - 1 == default_elements(count)
    err = modes.frequencies / bending_hz(ref, I22) - 1.0
    # The rule keeps beta h <= 0.5 for the highest mode: (0.5)^4 / 1440 = 4.3e-5.
    assert 0.0 < err[-1] < 4.5e-5
    assert np.all(np.diff(err) > 0.0)


@pytest.mark.parametrize("support, position", [("clamp", L), ("pivot", L), ("free", 0.0)])
@pytest.mark.parametrize("family", ["axial", "bend3", "bend2"])
def test_the_eigenvalues_alone_give_the_shapes_frequencies(support, position, family):
    # beam_frequencies (eigvalsh, no shapes) against beam_modes (the shapes' Rayleigh
    # quotients): two routes to one discrete spectrum, with a rivet's mass on the strip.
    # Measured: at most 3e-9 apart (the first clamped bending mode on the 15-mode mesh),
    # 1e-12 or less near the top of a solve, where frequencies_below compares with its
    # cutoff; the mesh itself is 4e-5 off there (default_elements), so 1e-8 changes no count.
    beam = strip(support=support, support_position=position, point_masses=(PointMass(0.6 * L, 2e-3, 1e-8),))
    for count in (1, 8, 15):
        eig = beam_frequencies(beam, family, count)
        ref = beam_modes(beam, family, count).frequencies
        assert len(eig) == count
        np.testing.assert_allclose(eig, ref, rtol=1e-8, atol=0.0)
        np.testing.assert_allclose(eig[-1], ref[-1], rtol=1e-11, atol=0.0)


def test_pinned_free_drops_the_rotation_about_the_pin_and_matches_the_roots():
    beam = strip(support="pivot", support_position=L)
    bend3 = beam_modes(beam, "bend3", 3, elements=80)
    assert bend3.condition == "pin"
    np.testing.assert_allclose(bend3.frequencies, bending_hz(PINNED_FREE, I22), rtol=1e-6)
    assert np.max(np.abs(bend3.value([L]))) < 1e-12  # w = 0 at the pin
    assert np.min(np.abs(bend3.slope([L]))) > 1.0  # but the section turns there
    # A hinge that clamps the other plane is one keyword away.
    clamped = beam_modes(beam, "bend2", 3, elements=80, condition="clamp")
    np.testing.assert_allclose(clamped.frequencies, bending_hz(CLAMPED_FREE[:3], I33), rtol=1e-6)


def test_free_free_bending_matches_the_roots_and_the_analytic_shapes():
    modes = beam_modes(strip(), "bend3", 4, elements=80)
    np.testing.assert_allclose(modes.frequencies, bending_hz(FREE_FREE, I22), rtol=1e-6)
    # modes.py's closed-form shapes (mean square 1 = generalized mass m, phi(0) = +2).
    from mech.modes import bending_shape
    x = np.linspace(0.0, L, 301)
    exact = np.array([bending_shape(b, x / L) for b in free_free_roots(4)])
    # Shape error O(h^4), about 3e-3 (beta h)^4: 2.7e-6 on mode 4 at 80 elements.
    np.testing.assert_allclose(modes.value(x), exact, atol=4e-6)
    exact_slope = np.array([bending_shape(b, x / L, 1) / L for b in free_free_roots(4)])
    np.testing.assert_allclose(modes.slope(x), exact_slope, atol=2e-4 * np.max(np.abs(exact_slope)))
    # Curvature is piecewise linear: error O(h^2), about 0.1 (beta h)^2 (3e-3 on mode 4).
    exact_curv = np.array([bending_shape(b, x / L, 2) / L**2 for b in free_free_roots(4)])
    np.testing.assert_allclose(modes.curvature(x), exact_curv, atol=5e-3 * np.max(np.abs(exact_curv)))


def test_axial_fixed_free_and_free_free_rod():
    k = np.arange(1, 5)
    for support in ("clamp", "pivot"):  # both hold the axial motion at the support
        fixed = beam_modes(strip(support=support, support_position=L), "axial", 4, elements=40)
        # Cubic elements: error about 5e-6 (k h)^6, 2e-9 on mode 4 at 40 elements.
        np.testing.assert_allclose(fixed.frequencies, (2 * k - 1) * C_ROD / (4.0 * L), rtol=5e-9)
        assert np.all(fixed.value([0.0])[:, 0] > 0.0)
    free = beam_modes(strip(), "axial", 4, elements=40)
    np.testing.assert_allclose(free.frequencies, k * C_ROD / (2.0 * L), rtol=5e-9)
    # sqrt(2) cos(k pi x / L): mean square 1, the generalized mass is m. Shape error O(h^4),
    # about 6e-4 (k h)^4: 5e-6 on mode 4 at 40 elements.
    x = np.linspace(0.0, L, 201)
    np.testing.assert_allclose(free.value(x), math.sqrt(2.0) * np.cos(np.outer(k, x) * math.pi / L),
                               atol=1e-5)


@pytest.mark.parametrize("ratio", [0.3, 2.0])
def test_cantilever_with_a_tip_mass_matches_its_frequency_equation(ratio):
    """1 + cos b cosh b + r b (cos b sinh b - sin b cosh b) = 0, r = M / (rho A L)."""
    tip = ratio * RHO_A * L
    beam = strip(support="clamp", support_position=L, point_masses=[(0.0, tip)])

    def equation(b):  # divided by cosh b so it stays well scaled
        return (1.0 / math.cosh(b) + math.cos(b)
                + ratio * b * (math.cos(b) * math.tanh(b) - math.sin(b)))

    ref = roots(equation, 4)
    modes = beam_modes(beam, "bend3", 4, elements=80)
    assert modes.modal_mass == pytest.approx(RHO_A * L + tip)
    np.testing.assert_allclose(modes.frequencies, bending_hz(ref, I22), rtol=1e-6)
    # The tip mass lowers every frequency below the bare cantilever's.
    assert np.all(modes.frequencies < bending_hz(clamped_free_roots(4), I22))


def test_cantilever_with_a_tip_mass_and_rotary_inertia_matches_the_boundary_value_problem():
    """Clamp at s = 0, tip body (M, J) at s = L. With w = a (cosh - cos) + c (sinh - sin) in
    b s / L, the tip conditions EI w'' = J w^2 w' and EI w''' = -M w^2 w' (from the
    Lagrangian's boundary terms) give a 2 x 2 determinant in b whose roots are the modes."""
    r, j = 0.5, 0.02  # M / (rho A L), J / (rho A L^3)
    beam = strip(support="clamp", support_position=L,
                 point_masses=[PointMass(0.0, r * RHO_A * L, j * RHO_A * L**3)])

    def det(b):
        ch, sh, c, s = math.cosh(b), math.sinh(b), math.cos(b), math.sin(b)
        C0, C1, C2, C3 = ch - c, b * (sh + s), b**2 * (ch + c), b**3 * (sh - s)
        S0, S1, S2, S3 = sh - s, b * (ch - c), b**2 * (sh + s), b**3 * (ch + c)
        b4 = b**4
        return ((C2 - j * b4 * C1) * (S3 + r * b4 * S0) - (S2 - j * b4 * S1) * (C3 + r * b4 * C0)) / ch**2

    ref = roots(det, 3)
    modes = beam_modes(beam, "bend3", 3, elements=80)
    np.testing.assert_allclose(modes.frequencies, bending_hz(ref, I22), rtol=1e-6)


# ----------------------------------------------------------------------------- statics

def test_static_cantilever_through_the_truncated_modal_expansion():
    """Tip load P on a cantilever: w_tip = P L^3 / (3 E I), slope -P L^2 / (2 E I) (clamp at
    x = L, tip at x = 0); the modal sums converge at order 3 and 2 in the mode count."""
    P = 1.5
    beam = strip(support="clamp", support_position=L)
    modes = beam_modes(beam, "bend3", 16, elements=80)
    k_modal = beam.total_mass * modes.omega**2
    phi0, slope0 = modes.value([0.0])[:, 0], modes.slope([0.0])[:, 0]
    w_n = np.cumsum(phi0 * phi0 * P / k_modal)
    s_n = np.cumsum(slope0 * phi0 * P / k_modal)
    w_ref, s_ref = P * L**3 / (3 * E * I22), -P * L**2 / (2 * E * I22)
    assert np.all(np.diff(w_n) > 0.0)  # every mode adds flexibility
    err_w = 1.0 - w_n[[3, 7, 15]] / w_ref
    err_s = 1.0 - s_n[[3, 7, 15]] / s_ref
    assert 0.0 < err_w[-1] < 2e-5 and 0.0 < err_s[-1] < 1e-3
    np.testing.assert_allclose(np.log2(err_w[:-1] / err_w[1:]), 3.0, atol=0.2)
    np.testing.assert_allclose(np.log2(err_s[:-1] / err_s[1:]), 2.0, atol=0.2)
    # Maxwell: tip deflection under a load at x = a equals P s^2 (3 L - s) / (6 E I), s = L - a.
    a = 0.3 * L
    s = L - a
    w_a = np.sum(phi0 * modes.value([a])[:, 0] * P / k_modal)
    assert w_a == pytest.approx(P * s**2 * (3 * L - s) / (6 * E * I22), rel=1e-4)


def test_static_cantilever_from_the_fe_stiffness_is_nodally_exact():
    P = 1.5
    system = assemble(strip(support="clamp", support_position=L), "bend3", elements=7)
    free = np.setdiff1d(np.arange(len(system.stiffness)), system.constrained)
    f = np.zeros(len(system.stiffness))
    f[0] = P  # w dof of node 0 (tip 0)
    u = np.zeros_like(f)
    u[free] = np.linalg.solve(system.stiffness[np.ix_(free, free)], f[free])
    assert u[0] == pytest.approx(P * L**3 / (3 * E * I22), rel=1e-12)
    assert u[1] == pytest.approx(-P * L**2 / (2 * E * I22), rel=1e-12)


# ----------------------------------------------------------------------------- normalisation

def gauss_rule(pieces=400, points=6):
    """Our own composite Gauss-Legendre on [0, L] (not the module's): nodes, weights."""
    t, w = np.polynomial.legendre.leggauss(points)
    edges = np.linspace(0.0, L, pieces + 1)
    h = np.diff(edges)
    return (edges[:-1, None] + 0.5 * h[:, None] * (t + 1.0)).ravel(), (0.5 * h[:, None] * w).ravel()


@pytest.mark.parametrize("support, position", [("free", 0.0), ("clamp", L), ("pivot", 0.15), ("clamp", 0.07)])
def test_modes_have_the_total_mass_as_generalized_mass_with_rivets(support, position):
    # With the support at 0.07 the third rivet is within a quarter element (h = 4 mm) of its
    # node: it gets no node of its own and enters through the shape functions.
    rivets = [PointMass(0.0, 0.004, 2e-8), PointMass(0.11, 0.01, 5e-7), PointMass(0.0705, 0.003, 1e-8)]
    beam = strip(support=support, support_position=position, point_masses=rivets)
    nodes = mesh(beam, 50)
    assert 0.11 in nodes and (0.0705 in nodes) == (position != 0.07)
    for modes in beam_basis(beam, 3, 4, elements=50):
        n = modes.n
        x, w = gauss_rule()
        phi = modes.value(x)
        gen = (phi * (RHO_A * w)) @ phi.T
        for p in rivets:
            v, d = modes.value([p.position])[:, 0], modes.slope([p.position])[:, 0]
            gen += p.mass * np.outer(v, v)
            if modes.family != "axial":
                gen += p.rotary_inertia * np.outer(d, d)
        np.testing.assert_allclose(gen, beam.total_mass * np.eye(n), atol=1e-9 * beam.total_mass)


# ----------------------------------------------------------------------------- invariants

def test_free_free_invariants_agree_with_the_analytic_modal_basis():
    """Two routes: closed-form shapes and 400-point Gauss (modal_basis) vs FE shapes and exact
    element quadrature. The FE shape error is O(h^4) (about 1e-7 of the shapes at 80
    elements), the frequency error (beta h)^4 / 720 in K."""
    bar = Bar(length=0.3, diameter=None, width=0.012, thickness=0.004, tip_radius=0.007,
              axial_modes=3, bending_modes=3)
    ref = build_modal_basis(bar, planar=False)
    beam = FEBeam.from_bar(bar)
    assert (beam.i22, beam.i33) == bar.second_moments and beam.bar_mass == pytest.approx(bar.mass)
    modes = beam_basis(beam, 3, 3, elements=80)
    inv = beam_invariants(beam, modes)
    assert inv.families == ref.families and inv.orders == ref.orders
    assert inv.x0 == pytest.approx(0.15) and inv.mass == pytest.approx(ref.mass)
    np.testing.assert_allclose(inv.J0, ref.J0, rtol=1e-12)
    for name, tol in (("J1", 1e-9), ("J2", 1e-9), ("S", 1e-9)):
        a, b = getattr(inv, name), getattr(ref, name)
        np.testing.assert_allclose(a, b, atol=tol * np.max(np.abs(b)), err_msg=name)
    np.testing.assert_allclose(np.diag(inv.stiffness), np.diag(ref.stiffness), rtol=1e-6)
    np.testing.assert_allclose(inv.frequencies, ref.frequencies, rtol=1e-6)
    # Tip-sphere centres: body x = -L/2 + R and L/2 - R are x = R and L - R from tip 0.
    psi, theta = point_shapes(modes, [bar.tip_radius, bar.length - bar.tip_radius])
    np.testing.assert_allclose(psi, ref.psi_tip, atol=1e-6)
    np.testing.assert_allclose(theta, ref.theta_tip, atol=2e-5 * np.max(np.abs(ref.theta_tip)))
    zeta = 0.02
    damped = beam_invariants(beam, modes, modal_damping=zeta)
    np.testing.assert_allclose(np.diag(damped.damping), 2 * zeta * inv.mass * 2 * np.pi * inv.frequencies)


def test_free_bar_with_rivets_is_a_mean_axis_frame_about_the_composite_centroid():
    rivets = [PointMass(0.0, 0.005, 3e-8), PointMass(0.13, 0.012, 4e-7)]
    beam = strip(point_masses=rivets)
    modes = beam_basis(beam, 3, 4)
    inv = beam_invariants(beam, modes)
    m = beam.total_mass
    x_c = (RHO_A * L * L / 2 + 0.005 * 0.0 + 0.012 * 0.13) / m
    assert inv.x0 == pytest.approx(x_c, rel=1e-14)
    assert np.max(np.abs(inv.first_moment)) < 1e-15 * m * L
    # Translation and rotation do not excite the modes: L = 0 and H = 0 (Tisserand).
    assert np.max(np.abs(inv.translational_coupling)) < 1e-12 * m
    assert np.max(np.abs(inv.rotational_coupling)) < 1e-12 * m * L
    # J0 about the composite centroid, from the bar's and the rivets' own inertia.
    about_b2 = (RHO_A * (L**3 / 12 + L * (L / 2 - x_c) ** 2) + RHO * L * I22
                + sum(p.mass * (p.position - x_c) ** 2 + p.rotary_inertia for p in rivets))
    assert inv.J0[1, 1] == pytest.approx(about_b2, rel=1e-13)
    # A clamped blade is no mean-axis frame: its first bending mode has a large mean.
    held = beam_invariants(strip(support="clamp", support_position=L),
                           beam_basis(strip(support="clamp", support_position=L), 0, 1, planar=True))
    assert abs(held.translational_coupling[2, 0]) > 0.5 * RHO_A * L


def test_cantilever_couplings_give_the_closed_form_effective_masses():
    """Clamped-free modes phi = cosh - cos - sigma (sinh - sin) (mean square 1): from
    EI phi'''' = rho A w^2 phi, int phi ds = 2 sigma / beta and int s phi ds = 2 / beta^2 (s from
    the clamp), so the effective masses are L_j^2 / m = m 4 sigma^2 / (beta L)^2 (61.3 %,
    18.8 %, ...) and H_j^2 / m = m L^2 4 / (beta L)^4 (their sum over all modes is m L^2 / 3)."""
    beam = strip(support="clamp", support_position=L)
    inv = beam_invariants(beam, beam_basis(beam, 0, 4, planar=True, elements=80))
    b = clamped_free_roots(4)
    sigma = (np.sinh(b) - np.sin(b)) / (np.cosh(b) + np.cos(b))
    m = RHO_A * L
    assert inv.mass == pytest.approx(m)
    np.testing.assert_allclose(inv.translational_coupling[2] ** 2 / m, m * 4 * sigma**2 / b**2, rtol=1e-6)
    np.testing.assert_allclose(inv.rotational_coupling[1] ** 2 / m, m * L**2 * 4 / b**4, rtol=1e-6)
    np.testing.assert_allclose((inv.translational_coupling[2] ** 2 / m**2)[:2], [0.6131, 0.1883], atol=1e-4)
    assert np.all(inv.translational_coupling[[0, 1]] == 0.0) and np.all(inv.rotational_coupling[[0, 2]] == 0.0)


def test_pinned_modes_carry_no_angular_momentum_about_the_pin():
    """The rotation about the pin is M-orthogonal to the pinned modes, rivets' rotary
    inertia included; the hinge reaction (translation) is not."""
    beam = strip(support="pivot", support_position=0.16, point_masses=[PointMass(0.01, 0.008, 3e-7)])
    inv = beam_invariants(beam, beam_basis(beam, 2, 3, planar=True))
    assert inv.x0 == 0.16
    bend = [j for j, f in enumerate(inv.families) if f == "bend3"]
    assert np.max(np.abs(inv.rotational_coupling[:, bend])) < 1e-12 * inv.mass * L
    assert np.min(np.abs(inv.translational_coupling[2, bend])) > 1e-3 * inv.mass


def test_point_on_the_face_of_a_blade_moves_with_the_section_rotation():
    """Offset h along b3: a bend3 mode moves the point by -h w3' along b1; at a clamp the
    section neither moves nor turns, at a pin it turns, so only the pinned point moves."""
    h = THICK / 2
    for support, moves in (("clamp", False), ("pivot", True)):
        beam = strip(support=support, support_position=0.12)
        modes = beam_basis(beam, 0, 3, planar=True)
        psi, theta = point_shapes(modes, [0.12, 0.05], offset=h)
        slope = modes[0].slope([0.12, 0.05])
        np.testing.assert_allclose(psi[:, :, 0], -h * slope.T, rtol=1e-14)
        np.testing.assert_allclose(psi[:, :, 2], modes[0].value([0.12, 0.05]).T)
        np.testing.assert_allclose(theta[:, :, 1], -slope.T)
        assert (np.min(np.abs(psi[0, :, 0])) > 1e-3 * h) == moves
        assert np.max(np.abs(psi[0, :, 2])) < 1e-12


# ----------------------------------------------------------------------------- mesh, input

def test_a_support_between_mesh_nodes_gets_its_own_node_and_splits_the_bar():
    """A clamp inside the bar makes two independent cantilevers of lengths a and L - a."""
    a = 0.3137 * L
    beam = strip(support="clamp", support_position=a)
    nodes = mesh(beam, 10)
    assert a in nodes and np.all(np.diff(nodes) <= L / 10 + 1e-15)
    bend = beam_modes(beam, "bend3", 4, elements=60)
    pieces = np.concatenate([bending_hz(CLAMPED_FREE, I22, a), bending_hz(CLAMPED_FREE, I22, L - a)])
    np.testing.assert_allclose(bend.frequencies, np.sort(pieces)[:4], rtol=2e-6)
    axial = beam_modes(beam, "axial", 3, elements=60)
    k = np.arange(1, 4)
    rods = np.concatenate([(2 * k - 1) * C_ROD / (4 * a), (2 * k - 1) * C_ROD / (4 * (L - a))])
    np.testing.assert_allclose(axial.frequencies, np.sort(rods)[:3], rtol=1e-9)


@pytest.mark.parametrize("kwargs, message", [
    (dict(support="hinge"), "support = 'hinge'"),
    (dict(support="clamp", support_position=0.25), "support_position = 0.25"),
    (dict(point_masses=[(0.3, 0.01)]), "point_masses[0].position = 0.3"),
    (dict(point_masses=[(0.1, -0.01)]), "point_mass.mass = -0.01"),
    (dict(point_masses=[(0.1, 0.01, float("nan"))]), "point_mass.rotary_inertia = nan"),
])
def test_bad_input_names_the_field(kwargs, message):
    with pytest.raises(ValueError) as err:
        strip(**kwargs)
    assert message in str(err.value)


def test_asking_for_more_modes_than_the_mesh_holds_is_an_error():
    with pytest.raises(ValueError, match="count = 40"):
        beam_modes(strip(), "bend3", 40, elements=10)
    with pytest.raises(ValueError, match="outside|on the bar"):
        beam_modes(strip(), "bend3", 2).value([L * 1.1])


def test_no_modes_leaves_the_rigid_bar_about_the_support():
    beam = strip(support="pivot", support_position=L)
    assert beam_modes(beam, "bend3", 0).n == 0 and beam_basis(beam, 0, 0) == ()
    inv = beam_invariants(beam, ())
    assert inv.n == 0 and inv.stiffness.shape == (0, 0)
    # A bar hinged at its end: I = m L^2 / 3 (plus the section's rotary inertia), c = -m L / 2.
    assert inv.J0[1, 1] == pytest.approx(RHO_A * L**3 / 3 + RHO * L * I22, rel=1e-14)
    assert inv.first_moment[0] == pytest.approx(-RHO_A * L * L / 2, rel=1e-14)
