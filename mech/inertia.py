"""Inertia terms of the floating-frame bar from the modes' Gram products (compiled).

The quadratic inertia terms are bilinear forms in the modal coordinates. With the
deformation u(x) = sum_j Psi_j(x) q_j = (u_1, u_2, u_3) (axial, b2 and b3 bending) and
the weighted products int rho A f g dx written <f, g>:

    J(q)       = J0 + sum_j J1_j q_j + tr(P) I - P,      P_ab = <u_a, u_b>
    B[:, k]    = <u x Psi_k>                              (angular momentum h = J w + B eta)
    centrifugal  1/2 w' dJ/dq_k w = 1/2 w' J1_k w + Y_c |w|^2 - w_c (Y . w)
    gyroscopic   2 w . sum_l S_kl eta_l = 2 w . <phi_k e_c x du/dt>
    dJ/dt w    = J1(eta) w + (tr Q I - Q) w,             Q_ab = <du_a/dt, u_b> + <u_a, du_b/dt>

for mode k of family c (direction e_c, shape phi_k), Y_b = <u_b, phi_k>. Every product
<phi_j, phi_k> is one of: the norm d_j = <phi_j, phi_j> within a family (the shapes of
a family are orthogonal); the same norm between a b2 and a b3 mode of equal order (the
two bending families share their shapes); the axial-bending Gram matrix
G_ik = <phi_i^axial, phi_k^bending>. So all the terms follow from G q and G' q and the
same with eta: O(nnz(G)) = O(n_axial n_bending / 2) work (G is zero between shapes of
opposite symmetry about the centre) and O(n) for the rest, against the O(n^2) entries
of the J2 and S tensors the sparse-list route (``inertia_terms_sparse``) walks.

Both routes read one sparse list (``modal_basis.sparse_invariants``): J1, J2, S, K, C
entries in sections 0-4, then the layout row (n_axial, n_bending, first b2 index,
first b3 index; -1 where a family is absent; value 1 when G's entries with i + k even
are zero), the norms d_j, and G's non-zero entries
(i axial, k bending). The pure-Python sources (``.py_func``) are the readable reference.
"""

from __future__ import annotations

import math

import numpy as np

from .jit import njit, njit_borrowing

# sections of the sparse invariant list
SEC_J1, SEC_J2, SEC_S, SEC_K, SEC_C, SEC_LAYOUT, SEC_NORM, SEC_GRAM = range(8)


@njit_borrowing
def inverse3(A, out):
    """Inverse of a 3x3 matrix by cofactors (the Schur complement is symmetric positive definite)."""
    c00 = A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1]
    c01 = A[1, 2] * A[2, 0] - A[1, 0] * A[2, 2]
    c02 = A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0]
    det = A[0, 0] * c00 + A[0, 1] * c01 + A[0, 2] * c02
    # singular only at a trial state far off the motion (a step through a contact): NaN
    # then, which the step control rejects, where the compiled division would raise
    inv = 1.0 / det if det != 0.0 else math.nan
    out[0, 0] = c00 * inv
    out[1, 0] = c01 * inv
    out[2, 0] = c02 * inv
    out[0, 1] = (A[0, 2] * A[2, 1] - A[0, 1] * A[2, 2]) * inv
    out[1, 1] = (A[0, 0] * A[2, 2] - A[0, 2] * A[2, 0]) * inv
    out[2, 1] = (A[0, 1] * A[2, 0] - A[0, 0] * A[2, 1]) * inv
    out[0, 2] = (A[0, 1] * A[1, 2] - A[0, 2] * A[1, 1]) * inv
    out[1, 2] = (A[0, 2] * A[1, 0] - A[0, 0] * A[1, 2]) * inv
    out[2, 2] = (A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]) * inv


@njit_borrowing
def _gram_products(n, q, eta, w, sp_ptr, sp_idx, sp_val, Jm, B, f_e, sv, forces):
    """J(q) into Jm, B(q) into B; with ``forces``, also the centrifugal and gyroscopic
    modal forces added to f_e and dJ/dt w into sv (f_e and sv must hold their other
    contributions or zeros). Jm must hold J0 + J1 q on entry."""
    lay = sp_ptr[SEC_LAYOUT]
    na = sp_idx[lay, 0]
    nb = sp_idx[lay, 1]
    o2 = sp_idx[lay, 2]
    o3 = sp_idx[lay, 3]
    d0 = sp_ptr[SEC_NORM]
    for j in range(n):
        B[0, j] = 0.0
        B[1, j] = 0.0
        B[2, j] = 0.0
    w0 = w[0]
    w1 = w[1]
    w2 = w[2]
    # axial-bending Gram products, G stored dense row-major (i axial, k bending): B's
    # axial columns get (0, G q3, -G q2), the bending columns G' q1 (b2: row 2, b3: -row 1);
    # the gyroscopic forces need G eta2, G eta3 and G' eta1.
    g0 = sp_ptr[SEC_GRAM]
    # layout value 1: G vanishes where i + k is even (axial and bending shapes of opposite
    # symmetry about the centre), so each row is walked with stride 2
    step = 2 if sp_val[lay] == 1.0 else 1
    if na > 0 and nb > 0:
        G = sp_val[g0:g0 + na * nb]
        if o2 >= 0:
            for i in range(na):
                row = i * nb
                qa = q[i]
                ca = -2.0 * w2 * eta[i]
                s2 = 0.0
                t2 = 0.0
                for k in range((i + 1) % step, nb, step):
                    g = G[row + k]
                    s2 += g * q[o2 + k]
                    t2 += g * eta[o2 + k]
                    B[2, o2 + k] += g * qa
                    f_e[o2 + k] += ca * g
                B[2, i] = -s2
                f_e[i] += 2.0 * w2 * t2
        if o3 >= 0:
            for i in range(na):
                row = i * nb
                qa = q[i]
                ca = 2.0 * w1 * eta[i]
                s3 = 0.0
                t3 = 0.0
                for k in range((i + 1) % step, nb, step):
                    g = G[row + k]
                    s3 += g * q[o3 + k]
                    t3 += g * eta[o3 + k]
                    B[1, o3 + k] -= g * qa
                    f_e[o3 + k] += ca * g
                B[1, i] = s3
                f_e[i] -= 2.0 * w1 * t3
    # b2-b3 products: equal shapes, so <phi_k, phi_k> = d_k between modes of equal order
    if o2 >= 0 and o3 >= 0:
        for k in range(nb):
            d = sp_val[d0 + o2 + k]
            B[0, o2 + k] = -d * q[o3 + k]
            B[0, o3 + k] = d * q[o2 + k]
            if forces:
                f_e[o2 + k] += 2.0 * w0 * d * eta[o3 + k]
                f_e[o3 + k] -= 2.0 * w0 * d * eta[o2 + k]
    # P_ab = <u_a, u_b> and Q_ab = <du_a/dt, u_b> + <u_a, du_b/dt>
    p00 = 0.0
    p11 = 0.0
    p22 = 0.0
    p01 = 0.0
    p02 = 0.0
    p12 = 0.0
    q00 = 0.0
    q11 = 0.0
    q22 = 0.0
    q01 = 0.0
    q02 = 0.0
    q12 = 0.0
    for i in range(na):
        d = sp_val[d0 + i]
        p00 += d * q[i] * q[i]
        q00 += 2.0 * d * q[i] * eta[i]
        p01 -= q[i] * B[2, i]  # q1 . G q2
        p02 += q[i] * B[1, i]  # q1 . G q3
        q01 -= eta[i] * B[2, i]  # eta1 . G q2
        q02 += eta[i] * B[1, i]  # eta1 . G q3
    if o2 >= 0:
        for k in range(nb):
            j = o2 + k
            d = sp_val[d0 + j]
            p11 += d * q[j] * q[j]
            q11 += 2.0 * d * q[j] * eta[j]
            q01 += B[2, j] * eta[j]  # q1 . G eta2
    if o3 >= 0:
        for k in range(nb):
            j = o3 + k
            d = sp_val[d0 + j]
            p22 += d * q[j] * q[j]
            q22 += 2.0 * d * q[j] * eta[j]
            q02 -= B[1, j] * eta[j]  # q1 . G eta3
    if o2 >= 0 and o3 >= 0:
        for k in range(nb):
            d = sp_val[d0 + o2 + k]
            p12 += d * q[o2 + k] * q[o3 + k]
            q12 += d * (eta[o2 + k] * q[o3 + k] + q[o2 + k] * eta[o3 + k])
    tr = p00 + p11 + p22
    Jm[0, 0] += tr - p00
    Jm[1, 1] += tr - p11
    Jm[2, 2] += tr - p22
    Jm[0, 1] -= p01
    Jm[1, 0] -= p01
    Jm[0, 2] -= p02
    Jm[2, 0] -= p02
    Jm[1, 2] -= p12
    Jm[2, 1] -= p12
    if not forces:
        return
    tq = q00 + q11 + q22
    sv[0] += (tq - q00) * w0 - q01 * w1 - q02 * w2
    sv[1] += -q01 * w0 + (tq - q11) * w1 - q12 * w2
    sv[2] += -q02 * w0 - q12 * w1 + (tq - q22) * w2
    # centrifugal Y_c |w|^2 - w_c (Y . w), Y_b = <u_b, phi_k>: own family d_k q_k, the
    # others from B's columns
    ww = w0 * w0 + w1 * w1 + w2 * w2
    for i in range(na):
        y0 = sp_val[d0 + i] * q[i]
        y1 = -B[2, i]
        y2 = B[1, i]
        f_e[i] += y0 * ww - w0 * (y0 * w0 + y1 * w1 + y2 * w2)
    if o2 >= 0:
        for k in range(nb):
            j = o2 + k
            y1 = sp_val[d0 + j] * q[j]
            y0 = B[2, j]
            y2 = -B[0, j]
            f_e[j] += y1 * ww - w1 * (y0 * w0 + y1 * w1 + y2 * w2)
    if o3 >= 0:
        for k in range(nb):
            j = o3 + k
            y2 = sp_val[d0 + j] * q[j]
            y0 = -B[1, j]
            y1 = B[0, j]
            f_e[j] += y2 * ww - w2 * (y0 * w0 + y1 * w1 + y2 * w2)


@njit_borrowing
def _linear_and_modal(n, q, eta, w, J0, sp_ptr, sp_idx, sp_val, Jm, f_e, sv):
    """Jm = J0 + J1 q; f_e = 1/2 w' J1 w - K q - C eta; sv = J1(eta) w. Returns the modal
    damping power eta' C eta (W)."""
    for a in range(3):
        for b in range(3):
            Jm[a, b] = J0[a, b]
        sv[a] = 0.0
    for j in range(n):
        f_e[j] = 0.0
    for e in range(sp_ptr[SEC_J1], sp_ptr[SEC_J1 + 1]):
        j = sp_idx[e, 0]
        a = sp_idx[e, 1]
        b = sp_idx[e, 2]
        v = sp_val[e]
        Jm[a, b] += v * q[j]
        f_e[j] += 0.5 * v * w[a] * w[b]
        sv[a] += v * eta[j] * w[b]
    return elastic_and_damping(q, eta, sp_ptr, sp_idx, sp_val, f_e)


@njit_borrowing
def elastic_and_damping(q, eta, sp_ptr, sp_idx, sp_val, f_e):
    """Subtract the modal stiffness and damping forces K q + C eta (N) from f_e, the K and C
    entries of the sparse list in its order (every inertia route's last terms). Returns the
    modal damping power eta' C eta (W)."""
    for e in range(np.uint64(sp_ptr[SEC_K]), np.uint64(sp_ptr[SEC_K + 1])):
        f_e[np.uint64(sp_idx[e, 0])] -= sp_val[e] * q[np.uint64(sp_idx[e, 1])]
    d_modal = 0.0
    for e in range(np.uint64(sp_ptr[SEC_C]), np.uint64(sp_ptr[SEC_C + 1])):
        j = np.uint64(sp_idx[e, 0])
        ce = sp_val[e] * eta[np.uint64(sp_idx[e, 1])]
        f_e[j] -= ce
        d_modal += eta[j] * ce
    return d_modal


@njit_borrowing
def held_modal_terms(n, q, eta, sp_ptr, sp_idx, sp_val, f_e, f_r, sv):
    """The inertia terms of a bar whose frame does not turn (w = 0: a clamped bar): f_e =
    -K q - C eta, f_r and dJ/dt w (sv[0:3]) zero; J, B and the Schur complement are not
    formed (a clamped bar's accelerations do not use them: kernel._solve_mounted). Every
    other term of the full routes carries a factor of w and adds an exact zero there, and
    the K and C terms are theirs (``elastic_and_damping``): the same bits at a fraction of
    the cost. Returns the modal damping power eta' C eta (W)."""
    for a in range(3):
        f_r[a] = 0.0
        sv[a] = 0.0
    for j in range(n):
        f_e[j] = 0.0
    return elastic_and_damping(q, eta, sp_ptr, sp_idx, sp_val, f_e)


@njit_borrowing
def _rotational_rhs(n, m, w, eta, Jm, B, sv, f_r, Amat, Ainv):
    """f_r = -w x (J w + B eta) - dJ/dt w; Schur complement J - B B'/m and its inverse."""
    h0 = Jm[0, 0] * w[0] + Jm[0, 1] * w[1] + Jm[0, 2] * w[2]
    h1 = Jm[1, 0] * w[0] + Jm[1, 1] * w[1] + Jm[1, 2] * w[2]
    h2 = Jm[2, 0] * w[0] + Jm[2, 1] * w[1] + Jm[2, 2] * w[2]
    for j in range(n):
        h0 += B[0, j] * eta[j]
        h1 += B[1, j] * eta[j]
        h2 += B[2, j] * eta[j]
    f_r[0] = -(w[1] * h2 - w[2] * h1) - sv[0]
    f_r[1] = -(w[2] * h0 - w[0] * h2) - sv[1]
    f_r[2] = -(w[0] * h1 - w[1] * h0) - sv[2]
    schur_complement(n, m, Jm, B, Amat, Ainv)


@njit_borrowing
def schur_complement(n, m, Jm, B, Amat, Ainv):
    """Amat = J - B B'/m (kg m^2, symmetric) and its inverse into Ainv."""
    inv_m = 1.0 / m
    for a in range(3):
        for b in range(a, 3):
            acc = 0.0
            for j in range(n):
                acc += B[a, j] * B[b, j]
            Amat[a, b] = Jm[a, b] - acc * inv_m
            Amat[b, a] = Amat[a, b]
    inverse3(Amat, Ainv)


@njit_borrowing
def inertia_terms(n, m, q, eta, w, J0, sp_ptr, sp_idx, sp_val, Jm, B, f_e, sv, f_r, Amat, Ainv):
    """Inertia and modal terms of the equations of motion at (q, eta, w).

    Fills Jm = J(q) (kg m^2), B = B(q) (kg m, 3 x n), f_e = modal forces without the
    applied loads (centrifugal + gyroscopic - K q - C eta, N), sv = dJ/dt w (N m),
    f_r = -w x h - dJ/dt w (N m), Amat = J - B B'/m and Ainv its inverse. m: bar mass
    (kg). Returns the modal damping power eta' C eta (W). O(n + nnz(G)) work.
    """
    d_modal = _linear_and_modal(n, q, eta, w, J0, sp_ptr, sp_idx, sp_val, Jm, f_e, sv)
    _gram_products(n, q, eta, w, sp_ptr, sp_idx, sp_val, Jm, B, f_e, sv, True)
    _rotational_rhs(n, m, w, eta, Jm, B, sv, f_r, Amat, Ainv)
    return d_modal


@njit(cache=True)
def inertia_matrix(n, q, J0, sp_ptr, sp_idx, sp_val, Jm, B):
    """J(q) into Jm (kg m^2) and B(q) into B (kg m, 3 x n), the mass matrix's coupling blocks."""
    for a in range(3):
        for b in range(3):
            Jm[a, b] = J0[a, b]
    for e in range(sp_ptr[SEC_J1], sp_ptr[SEC_J1 + 1]):
        Jm[sp_idx[e, 1], sp_idx[e, 2]] += sp_val[e] * q[sp_idx[e, 0]]
    _gram_products(n, q, np.zeros(n), np.zeros(3), sp_ptr, sp_idx, sp_val, Jm, B, np.zeros(n), np.zeros(3), False)


@njit_borrowing
def _added(k, x, s0, s1, s2):
    """(s0, s1, s2) with x added to component k (0, 1 or 2): a 3-vector summed in registers."""
    if k == 0:
        return s0 + x, s1, s2
    if k == 1:
        return s0, s1 + x, s2
    return s0, s1, s2 + x


# The sparse route's loops below are written for their cost per entry, every sum taken in
# the list's order (so to the last bit what the plain loops gave): the indices are read as
# unsigned (numba then does not test each for Python's negative indexing), each entry's
# inputs are read once into locals, and dJ/dt w and each mode's force are summed in locals
# (sv0..2; fj, the force of the mode the entries are at: the list is ordered by mode) --
# stored to the arrays, which numba must assume may alias q, eta and w, every sum waited
# for its previous store and every entry reloaded its inputs. Measured on the default
# scene's states (3 axial + 11 bending finite-element modes, 436 entries): 1.8 -> 0.9 us
# per call (docs/mechanics.md, "Cost of the compiled kernel").


@njit_borrowing
def inertia_matrix_sparse(n, q, J0, sp_ptr, sp_idx, sp_val, Jm, B):
    """J(q) into Jm (kg m^2) and B(q) into B (kg m, 3 x n) from the J1, J2 and S entries of
    the sparse list: ``inertia_matrix`` for a finite-element basis (mech.kernel.energies)."""
    for a in range(3):
        for b in range(3):
            Jm[a, b] = J0[a, b]
    for j in range(n):
        for a in range(3):
            B[a, j] = 0.0
    for e in range(np.uint64(sp_ptr[SEC_J1]), np.uint64(sp_ptr[SEC_J1 + 1])):
        Jm[np.uint64(sp_idx[e, 1]), np.uint64(sp_idx[e, 2])] += sp_val[e] * q[np.uint64(sp_idx[e, 0])]
    for e in range(np.uint64(sp_ptr[SEC_J2]), np.uint64(sp_ptr[SEC_J2 + 1])):
        Jm[np.uint64(sp_idx[e, 2]), np.uint64(sp_idx[e, 3])] += (sp_val[e] * q[np.uint64(sp_idx[e, 0])]
                                                                * q[np.uint64(sp_idx[e, 1])])
    for e in range(np.uint64(sp_ptr[SEC_S]), np.uint64(sp_ptr[SEC_S + 1])):
        B[np.uint64(sp_idx[e, 2]), np.uint64(sp_idx[e, 1])] += sp_val[e] * q[np.uint64(sp_idx[e, 0])]


@njit_borrowing
def inertia_terms_sparse(n, m, q, eta, w, J0, sp_ptr, sp_idx, sp_val, Jm, B, f_e, sv, f_r, Amat, Ainv):
    """The same as ``inertia_terms`` by walking the J2 and S tensors' non-zero entries
    (O(n^2): every axial-bending pair): the kernel's route for a finite-element basis
    (mech.kernel.dynamics, I_INERTIA), and the Gram route's independent reference in the
    tests and benchmarks/bench_rhs_cost.py."""
    inv_m = 1.0 / m
    for a in range(3):
        for b in range(3):
            Jm[a, b] = J0[a, b]
    for j in range(n):
        f_e[j] = 0.0
        for a in range(3):
            B[a, j] = 0.0
    sv0 = 0.0
    sv1 = 0.0
    sv2 = 0.0
    for e in range(np.uint64(sp_ptr[SEC_J1]), np.uint64(sp_ptr[SEC_J1 + 1])):
        j = np.uint64(sp_idx[e, 0])
        a = np.uint64(sp_idx[e, 1])
        b = np.uint64(sp_idx[e, 2])
        v = sp_val[e]
        wb = w[b]
        Jm[a, b] += v * q[j]
        f_e[j] += 0.5 * v * w[a] * wb
        sv0, sv1, sv2 = _added(a, v * eta[j] * wb, sv0, sv1, sv2)
    jf = np.uint64(n)  # the mode whose force fj holds (n: none yet)
    fj = 0.0
    for e in range(np.uint64(sp_ptr[SEC_J2]), np.uint64(sp_ptr[SEC_J2 + 1])):
        j = np.uint64(sp_idx[e, 0])
        kk = np.uint64(sp_idx[e, 1])
        a = np.uint64(sp_idx[e, 2])
        b = np.uint64(sp_idx[e, 3])
        v = sp_val[e]
        qk = q[kk]
        wa = w[a]
        wb = w[b]
        Jm[a, b] += v * q[j] * qk
        if j != jf:
            if jf < n:
                f_e[jf] = fj
            jf = j
            fj = f_e[j]
        vq = v * qk
        fj += vq * wa * wb
        ve = vq * eta[j]
        sv0, sv1, sv2 = _added(a, ve * wb, sv0, sv1, sv2)
        sv0, sv1, sv2 = _added(b, ve * wa, sv0, sv1, sv2)
    if jf < n:
        f_e[jf] = fj
    sv[0] = sv0
    sv[1] = sv1
    sv[2] = sv2
    for e in range(np.uint64(sp_ptr[SEC_S]), np.uint64(sp_ptr[SEC_S + 1])):
        j = np.uint64(sp_idx[e, 0])
        kk = np.uint64(sp_idx[e, 1])
        a = np.uint64(sp_idx[e, 2])
        v = sp_val[e]
        B[a, kk] += v * q[j]
        f_e[j] += 2.0 * v * w[a] * eta[kk]
    d_modal = elastic_and_damping(q, eta, sp_ptr, sp_idx, sp_val, f_e)
    h0 = Jm[0, 0] * w[0] + Jm[0, 1] * w[1] + Jm[0, 2] * w[2]
    h1 = Jm[1, 0] * w[0] + Jm[1, 1] * w[1] + Jm[1, 2] * w[2]
    h2 = Jm[2, 0] * w[0] + Jm[2, 1] * w[1] + Jm[2, 2] * w[2]
    for j in range(n):
        h0 += B[0, j] * eta[j]
        h1 += B[1, j] * eta[j]
        h2 += B[2, j] * eta[j]
    f_r[0] = -(w[1] * h2 - w[2] * h1) - sv[0]
    f_r[1] = -(w[2] * h0 - w[0] * h2) - sv[1]
    f_r[2] = -(w[0] * h1 - w[1] * h0) - sv[2]
    for a in range(3):
        for b in range(3):
            acc = 0.0
            for j in range(n):
                acc += B[a, j] * B[b, j]
            Amat[a, b] = Jm[a, b] - acc * inv_m
    inverse3(Amat, Ainv)
    return d_modal
