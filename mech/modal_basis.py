"""The bar's modal basis and the inertia invariants of the floating-frame model.

Body frame: origin at the undeformed centroid, b1 along the bar, x in [-L/2, L/2].
A point's body position is s(x) = x b1 + sum_j Psi_j(x) q_j, with Psi_j = d_j phi_j(x)
(d_j = b1 for axial, b2 or b3 for bending). All integrals are Gauss-Legendre
quadratures computed once per bar:

    J(q)   = J0 + sum_j J1_j q_j + sum_jk J2_jk q_j q_k  inertia tensor about the centroid
    S_jk   = int rho A Psi_j x Psi_k dx                  gyroscopic coupling
    B(q)_j = sum_k q_k S_kj                              angular momentum h = J w + B eta
    M_ee   = m I                                          (mean-square-1 shapes)

J2_jk = int rho A (Psi_j.Psi_k I - Psi_j Psi_k^T) vanishes for two modes of the same
family (orthogonality) but not across families (an axial and a bending shape are not
orthogonal), so the kernel receives every invariant as a sparse list of its non-zero
entries (``sparse_invariants``).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from .modes import axial_shape, bending_shape, free_free_roots
from .parameters import Bar
from .frozen import frozen

FAMILY_DIRECTION = {"axial": 0, "bend2": 1, "bend3": 2}
_QUAD_POINTS = 400


@frozen
class ModalBasis:
    """Modes and invariants of one bar (SI: kg, m, N/m).

    families: family of each modal coordinate ("axial", "bend2", "bend3").
    orders: mode number within its family (1-based).
    frequencies: Hz, undamped natural frequencies sqrt(K_jj/m)/(2 pi) of the basis.
    mass: kg. J0: kg m^2 (3, 3). J1: kg m (n, 3, 3). J2: kg (n, 3, 3). S: kg (n, n, 3).
    stiffness: N/m (n, n). damping: N s/m (n, n).
    psi_tip, theta_tip: (2, n, 3) mode displacement (-) and section rotation (1/m) at the
    two tip-sphere centres x = -L/2 + R and x = L/2 - R.
    x_centre: (2,) body x of the tip-sphere centres, m.
    """

    families: tuple[str, ...]
    orders: tuple[int, ...]
    frequencies: np.ndarray
    mass: float
    J0: np.ndarray
    J1: np.ndarray
    J2: np.ndarray
    S: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    psi_tip: np.ndarray
    theta_tip: np.ndarray
    x_centre: np.ndarray
    # Gram products for the compiled inertia terms (mech/inertia.py), kg:
    # norms (n,) <phi_j, phi_j>; gram (n_axial, n_bending) <phi_i^axial, phi_k^bending>,
    # with <f, g> = int rho A f g dx.
    norms: np.ndarray = None
    gram: np.ndarray = None

    @property
    def n(self) -> int:
        return len(self.families)


@lru_cache(maxsize=4)
def _quadrature(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on xi in [0, 1].

    Newton's method on P_n from Tricomi's asymptotic nodes, all nodes at once, P_n and
    P_n' by the three-term recurrence; weights 2 / ((1 - t^2) P_n'(t)^2). (numpy's
    leggauss solves a dense companion eigenproblem, 1.7 s for 400 nodes here; scipy's
    roots_legendre costs scipy.special's import, ~0.2 s.) Converged to round-off in a
    few iterations; tests/mech/test_mech_modes.py checks it against leggauss and exact
    integrals.
    """
    k = np.arange(1, n + 1)
    theta = np.pi * (4.0 * k - 1.0) / (4.0 * n + 2.0)
    t = (1.0 - (n - 1.0) / (8.0 * n**3)) * np.cos(theta)  # Tricomi's first-order nodes
    for _ in range(100):
        p_prev = np.ones_like(t)
        p = t.copy()
        for m in range(2, n + 1):
            p_prev, p = p, ((2.0 * m - 1.0) * t * p - (m - 1.0) * p_prev) / m
        dp = n * (t * p - p_prev) / (t * t - 1.0)
        step = p / dp
        t = t - step
        if np.max(np.abs(step)) < 1e-16:
            break
    p_prev = np.ones_like(t)
    p = t.copy()
    for m in range(2, n + 1):
        p_prev, p = p, ((2.0 * m - 1.0) * t * p - (m - 1.0) * p_prev) / m
    dp = n * (t * p - p_prev) / (t * t - 1.0)
    w = 2.0 / ((1.0 - t * t) * dp * dp)
    t = t[::-1]
    w = w[::-1]
    return 0.5 * (t + 1.0), 0.5 * w


def mode_list(bar: Bar, planar: bool) -> list[tuple[str, int]]:
    """(family, order) of every modal coordinate; planar models keep b3-plane bending only."""
    modes = [("axial", k) for k in range(1, bar.axial_modes + 1)]
    bend_families = ("bend3",) if planar else ("bend2", "bend3")
    for fam in bend_families:
        modes += [(fam, k) for k in range(1, bar.bending_modes + 1)]
    return modes


def shape_values(bar: Bar, modes, xi: np.ndarray, derivative: int = 0) -> np.ndarray:
    """(n, len(xi)) scalar shapes phi_j (derivative w.r.t. x in SI, 1/m^derivative)."""
    roots = free_free_roots(bar.bending_modes) if bar.bending_modes else np.array([])
    out = np.empty((len(modes), len(xi)))
    for j, (fam, k) in enumerate(modes):
        if fam == "axial":
            out[j] = axial_shape(k, xi, derivative)
        else:
            out[j] = bending_shape(roots[k - 1], xi, derivative)
    return out / bar.length**derivative


def build_modal_basis(bar: Bar, planar: bool) -> ModalBasis:
    """Modes, stiffness and the inertia invariants of ``bar`` (planar: axial + b3 bending)."""
    modes = mode_list(bar, planar)
    n = len(modes)
    L = bar.length
    m = bar.mass
    rho_a = bar.density * bar.area
    xi, w = _quadrature(_QUAD_POINTS)
    x = L * (xi - 0.5)
    dx = L * w

    phi = shape_values(bar, modes, xi)
    d1 = shape_values(bar, modes, xi, 1)
    dirs = np.zeros((n, 3))
    for j, (fam, _) in enumerate(modes):
        dirs[j, FAMILY_DIRECTION[fam]] = 1.0
    psi = phi[:, :, None] * dirs[:, None, :]  # (n, points, 3)

    i22, i33 = bar.second_moments
    J0 = np.diag([
        bar.density * L * (i22 + i33),  # polar: rotation about the axis
        m * L**2 / 12.0 + bar.density * L * i22,
        m * L**2 / 12.0 + bar.density * L * i33,
    ])
    e1 = np.array([1.0, 0.0, 0.0])
    eye = np.eye(3)
    J1 = np.zeros((n, 3, 3))
    J2 = np.zeros((n, n, 3, 3))
    S = np.zeros((n, n, 3))
    # d/dq_j of int rho A (s.s I - s s^T) at q = 0, with s = x e1: first moments m1[j, a]
    m1 = psi.transpose(0, 2, 1) @ (rho_a * dx * x)  # (n, 3)
    for j in range(n):
        outer = np.outer(e1, m1[j])
        J1[j] = 2.0 * m1[j, 0] * eye - (outer + outer.T)
    # all pairs at once (a Python loop over pairs took 0.23 s at 23 modes)
    wq = rho_a * dx
    flat = psi.transpose(0, 2, 1).reshape(3 * n, len(wq))  # (j a, p)
    # einsum, not @: a BLAS call spun its threads for 40-70 ms on the shared 2-core machine
    outer2 = np.einsum("ap,bp->ab", flat * wq, flat).reshape(n, 3, n, 3).transpose(0, 2, 1, 3)
    dot = np.einsum("jkaa->jk", outer2)
    J2[:] = dot[:, :, None, None] * eye - outer2
    S[:, :, 0] = outer2[:, :, 1, 2] - outer2[:, :, 2, 1]
    S[:, :, 1] = outer2[:, :, 2, 0] - outer2[:, :, 0, 2]
    S[:, :, 2] = outer2[:, :, 0, 1] - outer2[:, :, 1, 0]

    # stiffness: per family, the Gram matrix of the strain shapes (one product per family)
    K = np.zeros((n, n))
    bend_ix = [j for j, (f, _) in enumerate(modes) if f != "axial"]
    d2 = np.zeros_like(d1)
    if bar.bending == "euler_bernoulli" and bend_ix:
        d2[bend_ix] = shape_values(bar, [modes[j] for j in bend_ix], xi, 2)
    for fam in ("axial", "bend2", "bend3"):
        ix = [j for j, (f, _) in enumerate(modes) if f == fam]
        if not ix:
            continue
        if fam == "axial":
            strain, coef = d1[ix], bar.youngs_modulus * bar.area
        elif bar.bending == "euler_bernoulli":
            strain, coef = d2[ix], bar.youngs_modulus * (i33 if fam == "bend2" else i22)
        else:  # the paper's shear-type energy (G/nu) A (d delta/dx)^2
            strain, coef = d1[ix], bar.shear_modulus / bar.poisson_ratio * bar.area
        K[np.ix_(ix, ix)] = coef * (strain * dx) @ strain.T
    # Exact eigenmodes give a diagonal K; quadrature leaves round-off off the diagonal.
    if bar.bending == "euler_bernoulli":
        K = np.diag(np.diag(K))
    omega = np.sqrt(np.diag(K) / m) if n else np.zeros(0)
    C = np.diag(2.0 * bar.modal_damping * m * omega) if n else np.zeros((0, 0))

    x_centre = np.array([-0.5 * L + bar.tip_radius, 0.5 * L - bar.tip_radius])
    xi_c = x_centre / L + 0.5
    phi_c = shape_values(bar, modes, xi_c)
    slope_c = shape_values(bar, modes, xi_c, 1)
    psi_tip = np.zeros((2, n, 3))
    theta_tip = np.zeros((2, n, 3))
    for j, (fam, _) in enumerate(modes):
        psi_tip[:, j, FAMILY_DIRECTION[fam]] = phi_c[j]
        # Small section rotation: delta2' turns the section about b3, delta3' about -b2.
        if fam == "bend2":
            theta_tip[:, j, 2] = slope_c[j]
        elif fam == "bend3":
            theta_tip[:, j, 1] = -slope_c[j]

    norms, gram = _gram(bar, modes, phi, rho_a * dx)

    return ModalBasis(
        families=tuple(f for f, _ in modes),
        orders=tuple(k for _, k in modes),
        frequencies=omega / (2.0 * np.pi),
        mass=m,
        J0=J0,
        J1=J1,
        J2=J2,
        S=S,
        stiffness=K,
        damping=C,
        psi_tip=psi_tip,
        theta_tip=theta_tip,
        x_centre=x_centre,
        norms=norms,
        gram=gram,
    )


def _gram(bar: Bar, modes, phi: np.ndarray, weight: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Norms <phi_j, phi_j> (n,) and the axial-bending Gram matrix (n_axial, n_bending), kg,
    from the same quadrature as the J2 and S invariants. The bending shapes of the first
    bending family present stand for both (b2 and b3 share them)."""
    norms = np.einsum("jp,p->j", phi * phi, weight)
    axial = [j for j, (fam, _) in enumerate(modes) if fam == "axial"]
    bend = [j for j, (fam, _) in enumerate(modes) if fam != "axial"][: bar.bending_modes]
    gram = np.einsum("ip,kp,p->ik", phi[axial], phi[bend], weight) if axial and bend else (
        np.zeros((len(axial), len(bend))))
    return norms, gram


def sparse_invariants(basis: ModalBasis, rel_tol: float = 1e-12):
    """The invariants J1, J2, S, K, C and the Gram products as one list for the kernel.

    Returns (ptr, idx, val): entries ptr[0]:ptr[1] are J1 (j, a, b), ptr[1]:ptr[2] J2
    (j, k, a, b), ptr[2]:ptr[3] S (j, k, a), ptr[3]:ptr[4] K (j, k), ptr[4]:ptr[5] C (j, k);
    then (mech/inertia.py) ptr[5]:ptr[6] one layout row (n_axial, n_bending, first b2
    index, first b3 index; -1 for an absent family; value 1.0 when the Gram entries with
    i + k even are zero), ptr[6]:ptr[7] the norms (j), all n
    of them, and ptr[7]:ptr[8] the Gram matrix (i, k), dense, row-major.
    Entries below rel_tol of their array's largest magnitude are quadrature round-off of
    exact zeros (orthogonality) and are dropped.
    """
    idx_parts, val_parts, ptr = [], [], [0]

    def add(idx, val):
        idx_parts.append(idx)
        val_parts.append(val)
        ptr.append(ptr[-1] + len(val))

    for arr in (basis.J1, basis.J2, basis.S, basis.stiffness, basis.damping):
        big = np.max(np.abs(arr)) if arr.size else 0.0
        nz = np.argwhere(np.abs(arr) > rel_tol * big) if big > 0 else np.zeros((0, arr.ndim), int)
        idx = np.zeros((len(nz), 4), dtype=np.int64)
        idx[:, : arr.ndim] = nz
        add(idx, arr[tuple(nz.T)] if len(nz) else np.zeros(0))
    # Gram products (mech/inertia.py); a finite-element basis has none (its kernel takes
    # the sparse-list route): an empty layout row keeps the sections' places
    if basis.gram is None:
        add(np.array([[basis.families.count("axial"), 0, -1, -1]], dtype=np.int64), np.array([0.0]))
        add(np.zeros((0, 4), dtype=np.int64), np.zeros(0))
        add(np.zeros((0, 4), dtype=np.int64), np.zeros(0))
        return (np.array(ptr, dtype=np.int64), np.concatenate(idx_parts).astype(np.int64),
                np.concatenate(val_parts).astype(float))
    fams = basis.families
    layout = [fams.count("axial"), basis.gram.shape[1],
              fams.index("bend2") if "bend2" in fams else -1, fams.index("bend3") if "bend3" in fams else -1]
    gram = basis.gram
    even = (np.add.outer(np.arange(gram.shape[0]), np.arange(gram.shape[1])) % 2) == 0
    big = np.max(np.abs(gram)) if gram.size else 0.0
    parity = float(not gram.size or np.all(np.abs(gram[even]) <= rel_tol * big))
    add(np.array([layout], dtype=np.int64), np.array([parity]))
    idx = np.zeros((basis.n, 4), dtype=np.int64)
    idx[:, 0] = np.arange(basis.n)
    add(idx, np.asarray(basis.norms, dtype=float))
    # the Gram matrix dense, row-major (i axial, k bending): its zeros (shapes of opposite
    # symmetry) cost less than indexing around them
    na, nb = basis.gram.shape
    idx = np.zeros((na * nb, 4), dtype=np.int64)
    idx[:, 0] = np.repeat(np.arange(na), nb)
    idx[:, 1] = np.tile(np.arange(nb), na)
    add(idx, np.ascontiguousarray(basis.gram, dtype=float).ravel())
    return (np.array(ptr, dtype=np.int64), np.concatenate(idx_parts).astype(np.int64),
            np.concatenate(val_parts).astype(float))
