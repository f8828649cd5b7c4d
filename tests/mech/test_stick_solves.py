"""The small dense solves behind stick: the Jacobi eigen-decomposition against LAPACK (numpy),
the minimum-norm holding-force solve against a least-squares solve with the same cut-off,
on regular, near-singular and singular symmetric matrices like G M^-1 G^T."""

from __future__ import annotations

import numpy as np
import pytest

from mech.kernel import min_norm_solve, symmetric_eigen


def psd_matrices(rng, n, count=200):
    for _ in range(count):
        B = rng.normal(size=(n, n)) * 10.0 ** rng.uniform(-3, 3)
        yield B @ B.T
        # rank-deficient: two identical constraint rows (two stick points on one line)
        g = rng.normal(size=(n - 1, n + 2)) if n > 1 else rng.normal(size=(1, 3))
        G = np.vstack([g, g[:1]])[:n]
        yield G @ G.T


@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_jacobi_eigen_decomposition_matches_lapack(n):
    rng = np.random.default_rng(n)
    for A in psd_matrices(rng, n):
        w, V = symmetric_eigen(A)
        scale = np.max(np.abs(A))
        np.testing.assert_allclose(V @ np.diag(w) @ V.T, A, atol=1e-13 * scale)
        np.testing.assert_allclose(V.T @ V, np.eye(n), atol=1e-13)
        np.testing.assert_allclose(np.sort(w), np.linalg.eigvalsh(A), atol=1e-13 * scale)


@pytest.mark.parametrize("n", [2, 3, 4])
def test_min_norm_solve_is_least_squares_with_a_relative_cut_off_of_1e_7(n):
    rng = np.random.default_rng(10 + n)
    for A in psd_matrices(rng, n):
        rhs = rng.normal(size=n)
        x = min_norm_solve(A, rhs)
        ref = np.linalg.lstsq(A, rhs, rcond=1e-7)[0]
        np.testing.assert_allclose(x, ref, rtol=1e-8, atol=1e-10 * np.max(np.abs(ref)))
