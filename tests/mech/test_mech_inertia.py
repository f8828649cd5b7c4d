"""The Gram-product inertia terms (mech/inertia.py) against the sparse-tensor route.

Two independent routes to the same bilinear forms: walking every non-zero entry of the
J2 and S tensors (O(n^2), the kernel's former route) and contracting the modal
coordinates with the modes' norms and the axial-bending Gram matrix (O(n_axial
n_bending / 2) + O(n)). They must agree to round-off on random states, in 3D and
planar, for equal and unequal mode counts and with a family absent; J(q) and B(q) also
against the basis' dense invariants. A bar whose frame does not turn (clamped, w = 0) has
modal forces -K q - C eta only: the kernel's short route for it against both full routes
(to round-off: every term it leaves out carries a factor of w) and the dense K and C.
"""

from __future__ import annotations

import numpy as np
import pytest

from mech.inertia import held_modal_terms, inertia_matrix, inertia_terms, inertia_terms_sparse
from mech.modal_basis import build_modal_basis, sparse_invariants
from mech.parameters import Bar

CASES = [(False, 3, 3), (False, 7, 12), (False, 0, 4), (False, 5, 0), (False, 20, 20),
         (True, 3, 3), (True, 6, 9), (True, 0, 3)]


def _basis(planar, n_axial, n_bending):
    """The modal basis of a 6 mm bar with these mode counts (1 % modal damping) and its sparse list."""
    bar = Bar(diameter=0.006, tip_radius=0.003, axial_modes=n_axial, bending_modes=n_bending,
              modal_damping=0.01)
    basis = build_modal_basis(bar, planar)
    return basis, sparse_invariants(basis)


def _outputs(fn, basis, sparse, q, eta, w):
    n = basis.n
    out = [np.zeros((3, 3)), np.zeros((3, n)), np.zeros(n), np.zeros(3), np.zeros(3),
           np.zeros((3, 3)), np.zeros((3, 3))]
    d_modal = fn(n, basis.mass, q, eta, w, basis.J0, *sparse, *out)
    return [np.array([d_modal])] + out


@pytest.mark.parametrize("planar,n_axial,n_bending", CASES)
def test_gram_route_matches_the_sparse_tensor_route(planar, n_axial, n_bending):
    basis, sparse = _basis(planar, n_axial, n_bending)
    rng = np.random.default_rng(n_axial * 100 + n_bending + planar)
    names = ("eta'C eta", "J", "B", "f_e", "dJ/dt w", "f_r", "Schur", "Schur^-1")
    for _trial in range(3):
        # modal amplitudes up to 1 % of L, so the quadratic terms are far above round-off
        q = rng.normal(scale=3e-3, size=basis.n)
        eta = rng.normal(scale=0.5, size=basis.n)
        w = rng.normal(scale=50.0, size=3)
        if planar:
            w[[0, 2]] = 0.0
        ref = _outputs(inertia_terms_sparse, basis, sparse, q, eta, w)
        for fn in (inertia_terms.py_func, inertia_terms):
            got = _outputs(fn, basis, sparse, q, eta, w)
            for name, a, b in zip(names, got, ref):
                scale = max(np.max(np.abs(b)), 1e-300)
                np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * scale, err_msg=name)


@pytest.mark.parametrize("planar,n_axial,n_bending", CASES[:4] + CASES[5:7])
def test_mass_matrix_blocks_match_the_dense_invariants(planar, n_axial, n_bending):
    bar = Bar(diameter=0.006, tip_radius=0.003, axial_modes=n_axial, bending_modes=n_bending)
    b = build_modal_basis(bar, planar)
    rng = np.random.default_rng(7)
    q = rng.normal(scale=3e-3, size=b.n)
    J_ref = b.J0 + np.einsum("jab,j->ab", b.J1, q) + np.einsum("jkab,j,k->ab", b.J2, q, q)
    B_ref = np.einsum("kja,k->aj", b.S, q)
    J = np.zeros((3, 3))
    B = np.zeros((3, b.n))
    inertia_matrix.py_func(b.n, q, b.J0, *sparse_invariants(b), J, B)
    np.testing.assert_allclose(J, J_ref, rtol=0, atol=1e-13 * np.max(np.abs(J_ref)))
    np.testing.assert_allclose(B, B_ref, rtol=0, atol=1e-12 * max(np.max(np.abs(B_ref)), 1e-300))


@pytest.mark.parametrize("planar,n_axial,n_bending", CASES)
def test_a_frame_that_does_not_turn_leaves_only_the_elastic_and_damping_modal_forces(planar, n_axial, n_bending):
    basis, sparse = _basis(planar, n_axial, n_bending)
    n = basis.n
    rng = np.random.default_rng(n_axial * 10 + n_bending + 1000 * planar)
    w = np.zeros(3)
    for _trial in range(3):
        q = rng.normal(scale=3e-3, size=n)
        eta = rng.normal(scale=0.5, size=n)
        f_e, f_r, sv = np.full(n, np.nan), np.full(3, np.nan), np.full(3, np.nan)
        d_modal = held_modal_terms.py_func(n, q, eta, *sparse, f_e, f_r, sv)
        # the closed form from the basis' dense matrices
        ce = basis.damping @ eta
        np.testing.assert_allclose(f_e, -basis.stiffness @ q - ce, rtol=1e-12,
                                   atol=1e-13 * np.max(np.abs(basis.stiffness @ q)))
        np.testing.assert_allclose(d_modal, eta @ ce, rtol=1e-12)
        assert not f_r.any() and not sv.any()
        # both full routes at w = 0, to round-off (the kernel takes the short route for a
        # clamped bar on the strength of this; on this machine the 19 scenes' fingerprints
        # are the same bits, benchmarks/scene_fingerprints.py); their w-terms exact zeros
        for fn in (inertia_terms_sparse, inertia_terms.py_func, inertia_terms):
            d_ref, _, _, f_ref, sv_ref, r_ref, _, _ = _outputs(fn, basis, sparse, q, eta, w)
            np.testing.assert_allclose(d_modal, d_ref[0], rtol=1e-12)
            np.testing.assert_allclose(f_e, f_ref, rtol=0, atol=1e-12 * np.max(np.abs(f_ref)))
            assert not sv_ref.any() and not r_ref.any()
        # a turning frame adds centrifugal and gyroscopic modal forces the short route lacks
        if n_axial and n_bending:
            spin = np.array([0.0, 300.0, 0.0])
            _, _, _, f_spin, _, _, _, _ = _outputs(inertia_terms_sparse, basis, sparse, q, eta, spin)
            assert np.max(np.abs(f_spin - f_e)) > 1e-6 * np.max(np.abs(f_e))
