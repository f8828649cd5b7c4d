"""Held bars: a finite-element modal basis of a straight beam that is free, clamped or pivoted.

The bar lies on x in [0, L], x measured from the tip-0 end (the scene's ``position`` keys).
Three independent families, each discretised on the same mesh:

- ``"axial"``: u(x) along b1, 4-node cubic (Lagrange, C0) elements, consistent mass;
- ``"bend2"``, ``"bend3"``: Euler-Bernoulli bending w(x) along b2 or b3, 2-node Hermite cubic
  elements (w, w' per node), consistent mass. ``bend3`` (displacement along b3) bends about b2
  and uses I22 = int x3^2 dA, ``bend2`` uses I33 (as ``Bar.second_moments``).

Cubic axial elements (rather than linear or quadratic) give the axial shapes the same
accuracy orders as the Hermite bending shapes: value O(h^4), slope O(h^3), eigenvalue
O(h^6). Quadratic elements were tried first: their value error O(h^3) left 1e-3 (slope 2 %)
on the highest mode of the default mesh, and the axial displacement at a contact point is
what the kernel uses. C0 Lagrange elements (not C1 Hermite) because the axial strain jumps
at a point mass or an interior support.

Boundary conditions at the support node (the mesh always has a node exactly there):
axial u = 0 for ``clamp`` and ``pivot``; bending w = w' = 0 for ``clamp``, w = 0 for
``pivot`` (pinned). Rigid motions are not elastic modes and are dropped: 1 axial and 2
bending modes for a free bar, the rotation about the pin for a pivoted one; the kept
modes are checked to be M-orthogonal to the exact rigid shapes.

Point masses (rivets) sit on the axis at ``position`` with a mass and an isotropic rotary
inertia about their own centre; they enter the mass matrix as m N^T N + J N'^T N' through
the element shape functions N at their position.

Every mode is normalised to the TOTAL mass of bar and point masses,

    int rho A phi_j phi_k dx + sum_p m_p phi_j(x_p) phi_k(x_p) + sum_p J_p phi'_j(x_p) phi'_k(x_p)
        = m_total delta_jk,

so that the kernel's modal mass matrix is m_total I, and K_jj = m_total omega_j^2.
Sign: each shape is non-negative at the reference free end (tip 0, x = 0, for a free bar
and for a bar held at x >= L/2; x = L for a bar held nearer tip 0).
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from .eigen_cache import cached
from .gauss import LEGGAUSS
from .validation import check_choice, check_finite, check_nonnegative, check_positive, check_whole
from .frozen import frozen

FAMILIES = ("axial", "bend2", "bend3")
SUPPORTS = ("free", "clamp", "pivot")
CONDITIONS = ("free", "clamp", "pin")
FAMILY_DIRECTION = {"axial": 0, "bend2": 1, "bend3": 2}

# Default element count: the highest requested mode's wavenumber times the element length,
# beta h, is kept below _BETA_H. The relative frequency error of the Hermite cubic
# (consistent mass) is (beta h)^4 / 1440 (benchmarks/bench_beam_fe.py prints the constant),
# so beta h = 0.5 gives 4e-5 for the highest requested mode, 16 times less at half its
# order; the cubic axial elements are more accurate still (O(h^6)).
_BETA_H = 0.5
_MIN_ELEMENTS = 8
_COINCIDENT = 1e-9  # relative to L: a support this close to an end is at the end
_QUAD_XI, _QUAD_W = (np.array(v) for v in LEGGAUSS[4])  # exact for degree 7 per element
_QUAD_XI = 0.5 * (_QUAD_XI + 1.0)
_QUAD_W = 0.5 * _QUAD_W
_G3_XI, _G3_W = (np.array(v) for v in LEGGAUSS[3])
_GAUSS3 = (0.5 * (_G3_XI + 1.0), 0.5 * _G3_W)  # on [0, 1], exact for degree 5


@frozen
class PointMass:
    """A rivet on the bar's axis: position m from tip 0, mass kg, rotary_inertia kg m^2.

    The rotary inertia is about the mass's own centre and the same about every axis (a
    sphere-like rivet): it loads both bending families through the section rotation.
    """

    position: float
    mass: float
    rotary_inertia: float = 0.0

    def __post_init__(self):
        check_finite("point_mass.position", self.position)
        check_nonnegative("point_mass.mass", self.mass)
        check_nonnegative("point_mass.rotary_inertia", self.rotary_inertia)


@frozen
class FEBeam:
    """A uniform straight beam for the finite-element modes (SI).

    length: m. youngs_modulus: Pa. density: kg/m^3. area: m^2. i22, i33: m^4 (I22 =
    int x3^2 dA, used by bend3; I33 = int x2^2 dA, used by bend2).
    support: "free" | "clamp" | "pivot"; support_position: m from tip 0 (ignored when free).
    point_masses: PointMass entries or (position, mass[, rotary_inertia]) tuples.
    """

    length: float
    youngs_modulus: float
    density: float
    area: float
    i22: float
    i33: float
    support: str = "free"
    support_position: float = 0.0
    point_masses: tuple = ()

    def __post_init__(self):
        for name in ("length", "youngs_modulus", "density", "area", "i22", "i33"):
            check_positive(name, getattr(self, name))
        check_choice("support", self.support, SUPPORTS)
        pos = check_finite("support_position", self.support_position)
        if self.support != "free" and not 0.0 <= pos <= self.length:
            raise ValueError(
                f"support_position = {self.support_position!r}: must lie on the bar, in [0, {self.length!r}] m"
            )
        masses = []
        for i, p in enumerate(self.point_masses):
            if not isinstance(p, PointMass):
                try:
                    p = PointMass(*p)
                except TypeError:
                    raise ValueError(
                        f"point_masses[{i}] = {p!r}: expected (position, mass[, rotary_inertia])"
                    ) from None
            if not 0.0 <= p.position <= self.length:
                raise ValueError(
                    f"point_masses[{i}].position = {p.position!r}: must lie on the bar, in [0, {self.length!r}] m"
                )
            masses.append(p)
        object.__setattr__(self, "point_masses", tuple(masses))

    @classmethod
    def from_bar(cls, bar, support: str = "free", support_position: float = 0.0,
                 point_masses=()) -> "FEBeam":
        """The beam of a ``mech.Bar`` (length, E, rho, section) held as given."""
        i22, i33 = bar.second_moments
        return cls(bar.length, bar.youngs_modulus, bar.density, bar.area, i22, i33,
                   support=support, support_position=support_position, point_masses=tuple(point_masses))

    @property
    def bar_mass(self) -> float:
        """kg: rho A L."""
        return self.density * self.area * self.length

    @property
    def total_mass(self) -> float:
        """kg: bar plus point masses (the generalized mass of every mode)."""
        return self.bar_mass + sum(p.mass for p in self.point_masses)

    @property
    def centroid(self) -> float:
        """m from tip 0: the composite centre of mass of bar and point masses."""
        first = self.bar_mass * 0.5 * self.length + sum(p.mass * p.position for p in self.point_masses)
        return first / self.total_mass

    @property
    def frame_origin(self) -> float:
        """m from tip 0: body-frame origin, the support for a held bar, the centroid for a free one."""
        return self.centroid if self.support == "free" else float(self.support_position)

    def modulus(self, family: str) -> float:
        """N (axial, E A) or N m^2 (bending, E I of that family)."""
        check_choice("family", family, FAMILIES)
        if family == "axial":
            return self.youngs_modulus * self.area
        return self.youngs_modulus * (self.i33 if family == "bend2" else self.i22)

    def condition(self, family: str) -> str:
        """Boundary condition of ``family`` at the support: "free", "clamp" or "pin"."""
        check_choice("family", family, FAMILIES)
        if self.support == "free":
            return "free"
        if family == "axial" or self.support == "clamp":
            return "clamp"  # axial: u = 0 for both held kinds
        return "pin"


@frozen
class BeamModes:
    """Elastic modes of one family, evaluable anywhere on the bar.

    family: "axial" | "bend2" | "bend3". condition: "free" | "clamp" | "pin" applied.
    frequencies: Hz, (n,). modal_mass: kg, generalized mass of every mode (m_total).
    nodes: m from tip 0, the element end nodes (E + 1,).
    coefficients: axial (n, 3E + 1) nodal u (element end node i at 3 i, two equally spaced
    inner nodes between); bending (n, E + 1, 2) nodal (w, w'), dimensionless and 1/m.
    """

    family: str
    condition: str
    frequencies: np.ndarray
    modal_mass: float
    nodes: np.ndarray
    coefficients: np.ndarray

    @property
    def n(self) -> int:
        return len(self.frequencies)

    @property
    def omega(self) -> np.ndarray:
        """rad/s."""
        return 2.0 * math.pi * self.frequencies

    def shape(self, x, derivative: int = 0) -> np.ndarray:
        """(n, len(x)): d^derivative phi / dx^derivative at x (m from tip 0), derivative 0, 1, 2.

        Piecewise polynomial: at a node the element to its right is used (the last
        element at x = L); the second derivative may jump at nodes.
        """
        if derivative not in (0, 1, 2):
            raise ValueError(f"derivative = {derivative!r}: allowed values are 0, 1, 2")
        x = np.atleast_1d(np.asarray(x, dtype=float))
        idx, xi, h = _locate(self.nodes, x)
        if self.family == "axial":
            basis = _lagrange(xi, h, derivative)  # (P, p + 1)
            local = self.coefficients[:, _AXIAL_P * idx[:, None] + np.arange(_AXIAL_P + 1)]
        else:
            basis = _hermite(xi, h, derivative)  # (P, 4)
            c = self.coefficients
            local = np.stack([c[:, idx, 0], c[:, idx, 1], c[:, idx + 1, 0], c[:, idx + 1, 1]], axis=-1)
        return np.einsum("npk,pk->np", local, basis)

    def value(self, x) -> np.ndarray:
        """(n, len(x)) phi(x), dimensionless."""
        return self.shape(x, 0)

    def slope(self, x) -> np.ndarray:
        """(n, len(x)) phi'(x), 1/m."""
        return self.shape(x, 1)

    def curvature(self, x) -> np.ndarray:
        """(n, len(x)) phi''(x), 1/m^2."""
        return self.shape(x, 2)


@frozen
class FESystem:
    """Assembled (unconstrained) matrices of one family, with point masses included.

    nodes: m (E + 1,). stiffness: N/m-type (dof, dof), with the family's E A or E I.
    mass: kg-type (dof, dof). constrained: dof indices fixed by the support (sorted).
    Bending dofs are (w_i, w'_i) per node; axial dofs are u at the element end nodes (node
    i at dof 3 i) and at two equally spaced inner nodes per element.
    """

    family: str
    nodes: np.ndarray
    stiffness: np.ndarray
    mass: np.ndarray
    constrained: np.ndarray


@frozen
class BeamInvariants:
    """Inertia invariants of the floating-frame model about the body origin x0 (SI).

    Body position of an axis point: s(x) = (x - x0) b1 + sum_j Psi_j(x) q_j, Psi_j = d_j phi_j.
    families, orders: family and 1-based order of each modal coordinate. frequencies: Hz (n,).
    x0: m from tip 0. mass: kg (bar + point masses). first_moment: c = int rho A s0 dx +
    sum m_p s0_p, kg m (3,). translational_coupling: L_j = int rho A Psi_j + sum m_p Psi_j(x_p),
    kg (3, n). rotational_coupling: H_j = int rho A s0 x Psi_j + sum m_p s0_p x Psi_j(x_p) +
    sum J_p theta_j(x_p), kg m (3, n) (zero-order part of the angular momentum's modal term).
    J0: kg m^2 (3, 3) about x0, with the section's rotary inertia and the point masses'
    J_p. J1: kg m (n, 3, 3). J2: kg (n, n, 3, 3). S: kg (n, n, 3) - as in mech.modal_basis,
    with the point masses as extra mass points. stiffness: N/m (n, n) = diag(m omega^2).
    damping: N s/m (n, n) = diag(2 zeta m omega). modal_mass = mass (every mode).
    """

    families: tuple[str, ...]
    orders: tuple[int, ...]
    frequencies: np.ndarray
    x0: float
    mass: float
    first_moment: np.ndarray
    translational_coupling: np.ndarray
    rotational_coupling: np.ndarray
    J0: np.ndarray
    J1: np.ndarray
    J2: np.ndarray
    S: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray

    @property
    def n(self) -> int:
        return len(self.families)


# ----------------------------------------------------------------------------- elements

def _hermite(xi: np.ndarray, h: np.ndarray, derivative: int) -> np.ndarray:
    """(P, 4) Hermite cubic shapes for dofs (w0, w0', w1, w1'), d/dx^derivative."""
    if derivative == 0:
        return np.stack([1 - 3 * xi**2 + 2 * xi**3, h * (xi - 2 * xi**2 + xi**3),
                         3 * xi**2 - 2 * xi**3, h * (-xi**2 + xi**3)], axis=-1)
    if derivative == 1:
        return np.stack([(-6 * xi + 6 * xi**2) / h, 1 - 4 * xi + 3 * xi**2,
                         (6 * xi - 6 * xi**2) / h, -2 * xi + 3 * xi**2], axis=-1)
    return np.stack([(-6 + 12 * xi) / h**2, (-4 + 6 * xi) / h,
                     (6 - 12 * xi) / h**2, (-2 + 6 * xi) / h], axis=-1)


# Axial elements: Lagrange polynomials of degree _AXIAL_P on equally spaced element nodes.
_AXIAL_P = 3
_LAGRANGE_COEF = np.linalg.inv(np.vander(np.linspace(0.0, 1.0, _AXIAL_P + 1), increasing=True))


def _lagrange(xi: np.ndarray, h: np.ndarray, derivative: int) -> np.ndarray:
    """(P, p + 1) Lagrange shapes of the axial element, d/dx^derivative (x = x_e + xi h)."""
    powers = np.arange(_AXIAL_P + 1)
    factor = np.ones(_AXIAL_P + 1)
    for d in range(derivative):
        factor = factor * np.maximum(powers - d, 0)
    exps = np.maximum(powers - derivative, 0)
    mono = factor * np.asarray(xi, dtype=float)[:, None] ** exps  # d^k/dxi^k of xi^i
    return (mono @ _LAGRANGE_COEF) / np.asarray(h, dtype=float)[:, None] ** derivative


def _reference_axial_matrices():
    """int N'_i N'_j dxi and int N_i N_j dxi on [0, 1] (Gauss, exact): scaled by 1/h and h."""
    xi, w = (np.array(v) for v in LEGGAUSS[_AXIAL_P + 1])
    xi, w = 0.5 * (xi + 1.0), 0.5 * w
    one = np.ones_like(xi)
    n0, n1 = _lagrange(xi, one, 0), _lagrange(xi, one, 1)
    return np.einsum("q,qi,qj->ij", w, n1, n1), np.einsum("q,qi,qj->ij", w, n0, n0)


def _locate(nodes: np.ndarray, x: np.ndarray):
    """Element index, local coordinate xi in [0, 1] and element length at every x."""
    L = nodes[-1]
    tol = _COINCIDENT * L
    if np.any((x < -tol) | (x > L + tol)) or not np.all(np.isfinite(x)):
        bad = x[(x < -tol) | (x > L + tol) | ~np.isfinite(x)][0]
        raise ValueError(f"x = {bad!r}: must lie on the bar, in [0, {L!r}] m")
    idx = np.clip(np.searchsorted(nodes, x, side="right") - 1, 0, len(nodes) - 2)
    h = nodes[idx + 1] - nodes[idx]
    return idx, (x - nodes[idx]) / h, h


def default_elements(count: int) -> int:
    """Elements for ``count`` modes per family: ceil((count + 1/2) pi / 0.5), at least 8.

    (count + 1/2) pi bounds beta_n L of the n-th elastic bending mode for every support:
    a support adds at most two constraints, which by eigenvalue interlacing raise the n-th
    elastic eigenvalue at most to the free bar's, beta_n L = (n + 1/2) pi (approximately);
    it also bounds the axial k_n L <= n pi. Point masses only lower the eigenvalues and so
    the wavenumbers in the bar. The highest requested mode is then within about 4e-5 in
    frequency, lower modes much closer (error ~ (beta h)^4 / 1440).
    """
    return max(_MIN_ELEMENTS, math.ceil((count + 0.5) * math.pi / _BETA_H))


def mesh(beam: FEBeam, elements: int) -> np.ndarray:
    """Node positions (m from tip 0): about ``elements`` elements, a node exactly at the support.

    The bar is cut at the support and at every point mass (a point mass closer than a
    quarter element to another cut is not a cut; it is still placed exactly through the
    shape functions) and each piece gets ceil(piece / (L / elements)) equal elements.
    """
    L = beam.length
    h = L / elements
    cuts = [0.0, L]
    if beam.support != "free":
        s = float(beam.support_position)
        if _COINCIDENT * L < s < L * (1 - _COINCIDENT):
            cuts.append(s)
    for p in beam.point_masses:
        if min(abs(p.position - c) for c in cuts) > 0.25 * h:
            cuts.append(float(p.position))
    cuts = np.sort(np.array(cuts))
    pieces = [np.linspace(a, b, max(1, math.ceil((b - a) / h - 1e-9)) + 1)[:-1]
              for a, b in zip(cuts[:-1], cuts[1:])]
    return np.concatenate(pieces + [np.array([L])])


def _support_node(beam: FEBeam, nodes: np.ndarray) -> int:
    """Index of the node at the support (``mesh`` always puts one there)."""
    i = int(np.argmin(np.abs(nodes - beam.support_position)))
    if abs(nodes[i] - beam.support_position) > 1.01 * _COINCIDENT * beam.length:
        raise RuntimeError(f"no mesh node at support_position = {beam.support_position!r}")
    return i


_KB = np.array([[12, 6, -12, 6], [6, 4, -6, 2], [-12, -6, 12, -6], [6, 2, -6, 4]], float)
_MB = np.array([[156, 22, 54, -13], [22, 4, 13, -3], [54, 13, 156, -22], [-13, -3, -22, 4]], float)
_KA, _MA = _reference_axial_matrices()


def assemble(beam: FEBeam, family: str, elements: int | None = None, count: int = 1,
             condition: str | None = None) -> FESystem:
    """Stiffness and consistent mass of ``family`` (unconstrained), point masses included.

    elements: None takes ``default_elements(count)``. condition overrides the
    family's boundary condition ("free", "clamp", "pin").
    """
    check_choice("family", family, FAMILIES)
    cond = beam.condition(family) if condition is None else check_choice("condition", condition, CONDITIONS)
    if elements is None:
        elements = default_elements(count)
    check_whole("elements", elements, 1)
    nodes = mesh(beam, int(elements))
    h = np.diff(nodes)
    ne = len(h)
    rho_a = beam.density * beam.area
    modulus = beam.modulus(family)
    if family == "axial":
        ndof = _AXIAL_P * ne + 1
        ke = (modulus / h)[:, None, None] * _KA
        me = (rho_a * h)[:, None, None] * _MA
        dofs = _AXIAL_P * np.arange(ne)[:, None] + np.arange(_AXIAL_P + 1)
    else:
        ndof = 2 * (ne + 1)
        hp = np.stack([np.ones_like(h), h, np.ones_like(h), h], axis=-1)  # (E, 4) dof length factors
        scale = hp[:, :, None] * hp[:, None, :]
        ke = (modulus / h**3)[:, None, None] * _KB * scale
        me = (rho_a * h / 420.0)[:, None, None] * _MB * scale
        dofs = 2 * np.arange(ne)[:, None] + np.arange(4)
    K = np.zeros((ndof, ndof))
    M = np.zeros((ndof, ndof))
    rows, cols = dofs[:, :, None], dofs[:, None, :]
    np.add.at(K, (rows, cols), ke)
    np.add.at(M, (rows, cols), me)
    for p in beam.point_masses:
        idx, xi, hh = _locate(nodes, np.array([float(p.position)]))
        if family == "axial":
            d = _AXIAL_P * idx[0] + np.arange(_AXIAL_P + 1)
            n0 = _lagrange(xi, hh, 0)[0]
            M[np.ix_(d, d)] += p.mass * np.outer(n0, n0)
        else:
            d = 2 * idx[0] + np.arange(4)
            n0 = _hermite(xi, hh, 0)[0]
            n1 = _hermite(xi, hh, 1)[0]
            M[np.ix_(d, d)] += p.mass * np.outer(n0, n0) + p.rotary_inertia * np.outer(n1, n1)
    if cond == "free":
        fixed = np.zeros(0, dtype=np.int64)
    else:
        s = _support_node(beam, nodes)
        if family == "axial":
            fixed = np.array([_AXIAL_P * s])
        else:
            fixed = np.array([2 * s, 2 * s + 1]) if cond == "clamp" else np.array([2 * s])
    return FESystem(family=family, nodes=nodes, stiffness=K, mass=M, constrained=fixed)


def _rigid_shapes(system: FESystem, cond: str, x_ref: float) -> np.ndarray:
    """(r, dof) exact rigid motions allowed by the support (translation, rotation about x_ref)."""
    nodes = system.nodes
    if system.family == "axial":
        if cond != "free":
            return np.zeros((0, system.mass.shape[0]))
        return np.ones((1, system.mass.shape[0]))
    ndof = system.mass.shape[0]
    rot = np.zeros(ndof)
    rot[0::2] = nodes - x_ref
    rot[1::2] = 1.0
    if cond == "clamp":
        return np.zeros((0, ndof))
    if cond == "pin":
        return rot[None, :]
    trans = np.zeros(ndof)
    trans[0::2] = 1.0
    return np.stack([trans, rot])


def _element_values(family: str, nodes: np.ndarray, full: np.ndarray, xi: float, derivative: int) -> np.ndarray:
    """(n, E): d^derivative phi/dx^derivative at local coordinate xi of every element."""
    h = np.diff(nodes)
    xis = np.full(len(h), xi)
    if family == "axial":
        basis = _lagrange(xis, h, derivative)
        local = full[:, _AXIAL_P * np.arange(len(h))[:, None] + np.arange(_AXIAL_P + 1)]
    else:
        basis = _hermite(xis, h, derivative)
        c = full.reshape(len(full), -1, 2)
        local = np.stack([c[:, :-1, 0], c[:, :-1, 1], c[:, 1:, 0], c[:, 1:, 1]], axis=-1)
    return np.einsum("nek,ek->ne", local, basis)


def _strain_integral(family: str, nodes: np.ndarray, full: np.ndarray) -> np.ndarray:
    """(n,): int (phi'')^2 dx (bending) or int (phi')^2 dx (axial), 3-point Gauss (exact).

    Computed from the curvature, not as v' K v: the matrix product loses eps * lambda_max
    in absolute terms, the curvature only about eps / (beta h)^2 relative (first
    clamped-free mode at 256 elements, error against the FE theory (beta h)^4 / 720:
    6e-8 from v' K v, 4e-12 from the curvature; measured in this module's development).
    """
    h = np.diff(nodes)
    derivative = 1 if family == "axial" else 2
    total = np.zeros(len(full))
    for xi, w in zip(*_GAUSS3):
        total += _element_values(family, nodes, full, xi, derivative) ** 2 @ (w * h)
    return total


_BLAS = []  # the process's threadpoolctl controller, made once: its scan of the loaded libraries is the cost


def _one_blas_thread():
    """A context in which BLAS and LAPACK run on one thread: their threaded kernels sum in
    another order than the serial ones, so the FE modes, and through them a whole run, came
    out different in the last digits with the thread count (the same scene gave 236 macro
    steps from Python and 233 from the command line, which sets one thread). The FE
    problems are a few hundred dof: one thread costs nothing measurable. The libraries are
    scanned once per process (0.4 ms a scan; a held bar's build solves ~7 eigenproblems)."""
    if not _BLAS:
        from threadpoolctl import ThreadpoolController

        _BLAS.append(ThreadpoolController())
    return _BLAS[0].limit(limits=1, user_api="blas")


def _generalized_eigh(a: np.ndarray, b: np.ndarray, vectors: bool = True):
    """Eigenpairs of a v = mu b v (a symmetric, b symmetric positive definite), mu ascending,
    v^T b v = 1: with b = L L^T, the standard problem of L^-1 a L^-T (numpy alone: scipy's
    eigh would cost scipy.linalg's import, ~0.13 s, on every held bar's first build).
    vectors=False: (mu, None), the eigenvalues alone (eigvalsh, a third of the cost).
    Solved once per machine and problem (mech.eigen_cache: the same arrays, bit for bit)."""
    return cached(a, b, vectors, _solve_generalized_eigh)


def _solve_generalized_eigh(a: np.ndarray, b: np.ndarray, vectors: bool):
    """``_generalized_eigh``'s solution, computed."""
    with _one_blas_thread():
        low = np.linalg.cholesky(b)
        inv = np.linalg.solve(low, np.eye(len(b)))
        c = inv @ a @ inv.T
        if not vectors:
            return np.linalg.eigvalsh(0.5 * (c + c.T)), None
        mu, w = np.linalg.eigh(0.5 * (c + c.T))
        return mu, inv.T @ w


def _shift_inverted(beam: FEBeam, system: FESystem, cond: str, count: int):
    """The reduced matrices of ``_solve``'s shift-inverted problem: (Kr, Mr, sigma, free dof
    indices, rigid shapes), after checking that the mesh has ``count`` elastic modes."""
    K, M = system.stiffness, system.mass
    ndof = K.shape[0]
    free = np.ones(ndof, dtype=bool)  # (np.setdiff1d would import numpy.ma, ~10 ms of a run's start)
    free[system.constrained] = False
    keep = np.flatnonzero(free)
    x_ref = beam.centroid if cond == "free" else float(beam.support_position)
    rigid = _rigid_shapes(system, cond, x_ref)
    if count + len(rigid) > len(keep):
        raise ValueError(
            f"count = {count!r}: the mesh of {len(system.nodes) - 1} elements has only "
            f"{len(keep) - len(rigid)} elastic modes in family {system.family!r}; use more elements"
        )
    modulus = beam.modulus(system.family)
    rho_a = beam.density * beam.area
    power = 2 if system.family == "axial" else 4
    sigma = modulus / (rho_a * beam.length**power)
    return K[np.ix_(keep, keep)], M[np.ix_(keep, keep)], sigma, keep, rigid


def _lowest(mu: np.ndarray, sigma: float, count: int, r: int, family: str) -> np.ndarray:
    """The count + r lowest eigenvalues lambda (ascending) of the shift-inverted problem's mu
    (ascending), its r rigid (zero) ones checked."""
    nk = len(mu)
    lam = 1.0 / mu[:nk - count - r - 1:-1] - sigma  # the count + r largest mu: ascending lambda
    if r:
        first = lam[r]
        if np.any(np.abs(lam[:r]) > 1e-3 * abs(first)):
            raise RuntimeError(
                f"family {family!r}: expected {r} rigid (zero) eigenvalues, got {lam[:r]!r} "
                f"against the first elastic {first!r}"
            )
    return lam


def _solve(beam: FEBeam, system: FESystem, cond: str, count: int):
    """Lowest ``count`` elastic eigenpairs: (omega^2 (count,), full dof vectors (count, dof)).

    Solved in shift-inverted form M v = mu (K + sigma M) v for the largest mu, with sigma
    of the order of the first eigenvalue: the direct form K v = lambda M v only resolves
    lambda to eps * lambda_max in absolute terms, which is 5e-5 relative on the first
    clamped-free mode at 256 elements (measured); the inverted form resolves the lowest
    modes to a relative eps-level. omega^2 is then the Rayleigh quotient of each vector
    with the strain energy from its curvature (error second order in the vector's).
    """
    M = system.mass
    ndof = M.shape[0]
    Kr, Mr, sigma, keep, rigid = _shift_inverted(beam, system, cond, count)
    r = len(rigid)
    nk = len(keep)
    mu, vec = _generalized_eigh(Mr, Kr + sigma * Mr)
    _lowest(mu, sigma, count, r, system.family)  # (its check of the rigid eigenvalues: omega^2 comes below)
    vec = vec[:, :nk - count - r - 1:-1]
    if r:
        vec = vec[:, r:]
    full = np.zeros((count, ndof))
    full[:, keep] = vec.T
    if r:
        # Remove the round-off rigid component exactly (K R' = 0, so the strain energy is
        # unchanged), then check the M-orthogonality to the exact rigid shapes.
        rm = rigid @ M
        full -= np.linalg.solve(rm @ rigid.T, rm @ full.T).T @ rigid
    full /= np.sqrt(np.sum((full @ M) * full, axis=1))[:, None]
    if r:
        cross = rm @ full.T
        norm = np.sqrt(np.einsum("ij,ij->i", rm, rigid))[:, None]
        if np.any(np.abs(cross) > 1e-10 * norm):
            raise RuntimeError(f"family {system.family!r}: elastic modes not orthogonal to the rigid motions")
    omega2 = beam.modulus(system.family) * _strain_integral(system.family, system.nodes, full)  # v' M v = 1
    full *= math.sqrt(beam.total_mass)  # generalized mass m_total
    return omega2, full


def _fix_signs(beam: FEBeam, family: str, full: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """Make phi(x_ref) >= 0 at the reference free end; if it vanishes there, phi'(x_ref)."""
    at_end = beam.support == "free" or beam.support_position >= 0.5 * beam.length
    if family == "axial":
        i = 0 if at_end else full.shape[1] - 1
        candidates = [full[:, i]]
        scale = np.max(np.abs(full), axis=1)
    else:
        i = 0 if at_end else len(nodes) - 1
        candidates = [full[:, 2 * i], full[:, 2 * i + 1] * beam.length]
        scale = np.max(np.abs(full[:, 0::2]), axis=1)
    sign = np.zeros(len(full))
    for c in candidates:
        undecided = sign == 0
        significant = np.abs(c) > 1e-8 * scale
        sign[undecided & significant] = np.sign(c[undecided & significant])
    undecided = sign == 0
    if np.any(undecided):  # odd about the reference in value and slope: largest entry positive
        big = np.argmax(np.abs(full), axis=1)
        sign[undecided] = np.sign(full[np.arange(len(full)), big][undecided])
    return full * sign[:, None]


def _package(beam, family, cond, system, lam, full) -> BeamModes:
    full = _fix_signs(beam, family, full, system.nodes)
    coeff = full if family == "axial" else full.reshape(len(full), len(system.nodes), 2)
    freq = np.sqrt(lam) / (2.0 * math.pi)
    coeff.setflags(write=False)
    freq.setflags(write=False)
    nodes = system.nodes.copy()
    nodes.setflags(write=False)
    return BeamModes(family=family, condition=cond, frequencies=freq, modal_mass=beam.total_mass,
                     nodes=nodes, coefficients=coeff)


def beam_modes(beam: FEBeam, family: str, count: int, elements: int | None = None,
               condition: str | None = None) -> BeamModes:
    """The lowest ``count`` elastic modes of ``family`` ("axial", "bend2", "bend3").

    elements: None takes ``default_elements(count)``. condition: override of the
    family's boundary condition at the support ("free", "clamp", "pin"; e.g. a hinge that
    pins bend3 but clamps bend2).
    """
    count = check_whole("count", count)
    system = assemble(beam, family, elements, max(count, 1), condition)
    cond = beam.condition(family) if condition is None else condition
    if count == 0:
        lam, full = np.zeros(0), np.zeros((0, system.mass.shape[0]))
    else:
        lam, full = _solve(beam, system, cond, count)
    return _package(beam, family, cond, system, lam, full)


def beam_frequencies(beam: FEBeam, family: str, count: int) -> np.ndarray:
    """Hz: the lowest ``count`` elastic frequencies of ``family`` on ``beam_modes``'s mesh,
    from the shift-inverted problem's eigenvalues alone (no shapes: about a third of the
    cost; mech.model.frequencies_below, which only counts modes below a cutoff). They
    agree with ``beam_modes``'s, whose squares are the shapes' Rayleigh quotients, within
    1e-8 relative (measured at most 3e-9, on a clamped strip's first bending mode) and
    1e-11 at a solve's highest mode, where a count compares with its cutoff
    (tests/mech/test_beam_fe.py)."""
    count = check_whole("count", count)
    system = assemble(beam, family, None, max(count, 1))
    if count == 0:
        return np.zeros(0)
    cond = beam.condition(family)
    Kr, Mr, sigma, _, rigid = _shift_inverted(beam, system, cond, count)
    mu, _ = _generalized_eigh(Mr, Kr + sigma * Mr, vectors=False)
    lam = _lowest(mu, sigma, count, len(rigid), family)[len(rigid):]
    return np.sqrt(lam) / (2.0 * math.pi)


def beam_basis(beam: FEBeam, axial: int, bending: int, planar: bool = False,
               elements: int | None = None) -> tuple[BeamModes, ...]:
    """Modes of every family in kernel order: axial, bend2, bend3 (planar: axial, bend3).

    Families with a zero count are left out. bend2 and bend3 share the mesh, the boundary
    conditions and the mass, so their shapes are the same and the eigenproblem is solved
    once; the frequencies scale with sqrt(E I).
    """
    axial = check_whole("axial", axial)
    bending = check_whole("bending", bending)
    if elements is None:
        elements = default_elements(max(axial, bending, 1))
    out = []
    if axial:
        out.append(beam_modes(beam, "axial", axial, elements))
    if bending:
        families = ("bend3",) if planar else ("bend2", "bend3")
        cond = beam.condition("bend3")
        system = assemble(beam, "bend3", elements, bending, cond)
        lam, full = _solve(beam, system, cond, bending)
        for fam in families:
            ratio = beam.modulus(fam) / beam.modulus("bend3")
            out.append(_package(beam, fam, cond, system, lam * ratio, full))
    return tuple(out)


# ----------------------------------------------------------------------------- invariants

def point_shapes(modes: Sequence[BeamModes], x, offset=0.0, offset2=0.0):
    """Mode displacement Psi and small section rotation theta at body points.

    x: m from tip 0 (P,); offset: m along b3 (and offset2 along b2) from the axis, scalar
    or (P,). Returns (psi, theta), each (P, n, 3): psi dimensionless, theta 1/m, with
    Psi = d phi(x) + theta x (offset2 b2 + offset b3); theta = phi' b3 for bend2 and
    -phi' b2 for bend3 (as mech.modal_basis), 0 for axial. So a point on the face of a
    blade (offset h along b3) moves axially by -h w3'(x) in a bend3 mode.
    """
    x = np.atleast_1d(np.asarray(x, dtype=float))
    off = np.zeros((len(x), 3))
    off[:, 1] = offset2
    off[:, 2] = offset
    n = sum(m.n for m in modes)
    psi = np.zeros((len(x), n, 3))
    theta = np.zeros((len(x), n, 3))
    j = 0
    for m in modes:
        sl = slice(j, j + m.n)
        psi[:, sl, FAMILY_DIRECTION[m.family]] = m.value(x).T
        if m.family == "bend2":
            theta[:, sl, 2] = m.slope(x).T
        elif m.family == "bend3":
            theta[:, sl, 1] = -m.slope(x).T
        j += m.n
    psi += np.cross(theta, off[:, None, :])
    return psi, theta


def _quadrature_points(modes: Sequence[BeamModes], L: float):
    """Gauss points (4 per interval of the union of all meshes): exact for the FE shapes."""
    # sorted; repeated nodes go with the coincident ones below (np.unique would import numpy.ma)
    nodes = np.sort(np.concatenate([m.nodes for m in modes] + [np.array([0.0, L])]))
    keep = np.concatenate([[True], np.diff(nodes) > _COINCIDENT * L])
    nodes = nodes[keep]
    nodes[-1] = L
    h = np.diff(nodes)
    x = (nodes[:-1, None] + h[:, None] * _QUAD_XI).ravel()
    w = (h[:, None] * _QUAD_W).ravel()
    return x, w


def beam_invariants(beam: FEBeam, modes: Sequence[BeamModes], x0: float | None = None,
                    modal_damping: float = 0.0) -> BeamInvariants:
    """Every inertia invariant of the floating-frame kernel, about x0 (default beam.frame_origin).

    Gauss quadrature over the bar (exact for the piecewise-polynomial shapes) plus the
    point masses as extra mass points; see BeamInvariants for the definitions.
    modal_damping: damping ratio zeta of every mode, C = 2 zeta m omega.
    """
    x0 = beam.frame_origin if x0 is None else check_finite("x0", x0)
    zeta = check_nonnegative("modal_damping", modal_damping)
    L = beam.length
    rho = beam.density
    rho_a = rho * beam.area
    m_tot = beam.total_mass
    for md in modes:
        if abs(md.nodes[-1] - L) > _COINCIDENT * L or not math.isclose(md.modal_mass, m_tot, rel_tol=1e-12):
            raise ValueError(f"modes of family {md.family!r} were not built for this beam")
    xg, wg = _quadrature_points(modes, L) if modes else (np.zeros(0), np.zeros(0))
    xp = np.array([p.position for p in beam.point_masses], dtype=float)
    mp = np.array([p.mass for p in beam.point_masses], dtype=float)
    jp = np.array([p.rotary_inertia for p in beam.point_masses], dtype=float)
    x = np.concatenate([xg, xp])
    w = np.concatenate([rho_a * wg, mp])  # mass weights, kg
    s = x - x0
    psi, _ = point_shapes(modes, x)  # (P, n, 3)
    _, theta_p = point_shapes(modes, xp)
    n = psi.shape[1]

    # Rigid part, exact: bar about x0 plus point masses.
    bar_first = rho_a * L * (0.5 * L - x0)
    bar_second = rho_a * (((L - x0) ** 3 - (-x0) ** 3) / 3.0)
    first = bar_first + float(np.sum(mp * (xp - x0)))
    second = bar_second + float(np.sum(mp * (xp - x0) ** 2))
    jsum = float(np.sum(jp))
    J0 = np.diag([
        rho * L * (beam.i22 + beam.i33) + jsum,
        second + rho * L * beam.i22 + jsum,
        second + rho * L * beam.i33 + jsum,
    ])
    c = np.array([first, 0.0, 0.0])

    Lc = np.einsum("p,pja->aj", w, psi)  # (3, n)
    e1_cross = np.zeros_like(psi)  # s0 x Psi with s0 = s e1: (0, -s Psi_3, s Psi_2)
    e1_cross[:, :, 1] = -s[:, None] * psi[:, :, 2]
    e1_cross[:, :, 2] = s[:, None] * psi[:, :, 1]
    H = np.einsum("p,pja->aj", w, e1_cross) + np.einsum("p,pja->aj", jp, theta_p)

    eye = np.eye(3)
    axial = np.einsum("p,p,pj->j", w, s, psi[:, :, 0])  # int s0 . Psi_j
    outer = np.zeros((n, 3, 3))
    outer[:, 0, :] = np.einsum("p,p,pja->ja", w, s, psi)  # int s0 Psi_j^T, s0 = s e1
    J1 = 2.0 * axial[:, None, None] * eye - (outer + outer.transpose(0, 2, 1))
    flat = psi.reshape(len(x), 3 * n)
    G = ((flat * w[:, None]).T @ flat).reshape(n, 3, n, 3).transpose(0, 2, 1, 3)  # int w Psi_j Psi_k^T
    dot = np.einsum("jkaa->jk", G)
    J2 = dot[:, :, None, None] * eye - G
    S = np.stack([G[..., 1, 2] - G[..., 2, 1], G[..., 2, 0] - G[..., 0, 2], G[..., 0, 1] - G[..., 1, 0]], axis=-1)

    freq = np.concatenate([md.frequencies for md in modes]) if modes else np.zeros(0)
    omega = 2.0 * math.pi * freq
    K = np.diag(m_tot * omega**2)
    C = np.diag(2.0 * zeta * m_tot * omega)
    return BeamInvariants(
        families=tuple(md.family for md in modes for _ in range(md.n)),
        orders=tuple(k + 1 for md in modes for k in range(md.n)),
        frequencies=freq, x0=float(x0), mass=m_tot, first_moment=c,
        translational_coupling=Lc, rotational_coupling=H,
        J0=J0, J1=J1, J2=J2, S=S, stiffness=K, damping=C,
    )
