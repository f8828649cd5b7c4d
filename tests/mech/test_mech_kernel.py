"""The compiled right-hand side against its Python source, and the inertia it implies
against a brute-force quadrature of the kinetic energy over the bar's volume."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mech.kernel import (
    A_FN, A_Y, FREE, NAUX, SLIP, STICK, dynamics, energies, make_work, quat_to_matrix,
)
from mech.model import build_model, matrix_to_quaternion

from mech_cases import make_scene

RNG_SEED = 20240611


def random_rotation(rng) -> np.ndarray:
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    R = np.empty((3, 3))
    quat_to_matrix(*q, R)
    return R


def model_for(planar: bool, friction: str, modes: int = 2):
    fr = {"none": dict(mu=0.0), "exact": dict(mu=0.3, gamma=0.7),
          "regularized": dict(mu=0.3, gamma=0.0, model="regularized", regularization_speed=1e-3)}[friction]
    velocity = (0.2, 0.0, -1.0) if planar else (0.2, 0.1, -1.0)
    scene = make_scene(bar=dict(axial_modes=modes, bending_modes=modes),
                       contact=dict(restitution=0.7), friction=fr,
                       initial=dict(height=1e-3, angle_deg=35.0, velocity=velocity),
                       gravity=9.81, solver=dict(model="planar" if planar else "3d"))
    return build_model(scene)


def evaluate(fn, model, t, y, regime, eref):
    dy = np.empty_like(y)
    aux = np.empty((2, NAUX))
    fn(t, y, model.arrays, regime, eref, dy, aux, make_work(model.n))
    return dy, aux


def rotation_y(a: float) -> np.ndarray:
    return np.array([[math.cos(a), 0.0, math.sin(a)], [0.0, 1.0, 0.0], [-math.sin(a), 0.0, math.cos(a)]])


def random_state_in_contact(model, rng, penetrations=(1.0, 0.5), q_scale=None):
    """A random state with tips 0 and 1 pressed in by the given multiples of the Hertz
    penetration scale, random speeds, modal coordinates and (3D) a random small tilt."""
    y = model.initial_state()
    sl = model.slices()
    dstar = model.contact.penetration_scale
    n = model.n
    y[sl["q"]] = rng.normal(scale=q_scale or 5.0 * dstar, size=n)
    y[sl["eta"]] = rng.normal(scale=0.05, size=n)
    y[sl["vel"]] = rng.normal(scale=0.5, size=sl["vel"].stop - sl["vel"].start)
    y[sl["omega"]] = rng.normal(scale=2.0, size=sl["omega"].stop - sl["omega"].start)
    base = np.eye(3)
    if not model.planar:
        tilt = rng.normal(scale=0.3, size=3)
        base = random_rotation_about_vertical(tilt[0]) @ rotation_x(tilt[2] * 0.1)
    z_index = sl["pos"].start + (1 if model.planar else 2)
    regime = np.zeros(2, np.int64)
    eref = np.array([[1.0, 0.0], [0.0, 1.0]])
    target = np.array(penetrations) * dstar

    def pens(x):
        z, pitch = x
        y[z_index] = z
        if model.planar:
            y[sl["angle"]] = pitch
        else:
            y[sl["quat"]] = matrix_to_quaternion(rotation_y(pitch) @ base)
        _, aux = evaluate(dynamics, model, 0.0, y, regime, eref)
        return aux[:, A_Y].copy()

    # Newton on (height, pitch) so both tips reach their penetrations.
    x = np.array([y[z_index], 0.0])
    for _ in range(8):
        f = pens(x) - target
        Jac = np.empty((2, 2))
        for c, hstep in enumerate((1e-7, 1e-7)):
            xp = x.copy()
            xp[c] += hstep
            Jac[:, c] = (pens(xp) - target - f) / hstep
        x = x - np.linalg.solve(Jac, f)
    got = pens(x)
    np.testing.assert_allclose(got, target, atol=1e-6 * dstar)
    return y


def rotation_x(a: float) -> np.ndarray:
    return np.array([[1.0, 0.0, 0.0], [0.0, math.cos(a), -math.sin(a)], [0.0, math.sin(a), math.cos(a)]])


def random_rotation_about_vertical(a: float) -> np.ndarray:
    return np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0], [0.0, 0.0, 1.0]])


CASES = [
    # (planar, friction, regimes of tips 0 and 1)
    (True, "none", (FREE, FREE)),
    (True, "exact", (SLIP, SLIP)),
    (True, "exact", (STICK, SLIP)),
    (True, "exact", (STICK, STICK)),
    (True, "regularized", (SLIP, SLIP)),
    (False, "none", (FREE, FREE)),
    (False, "exact", (SLIP, SLIP)),
    (False, "exact", (STICK, SLIP)),
    (False, "exact", (STICK, STICK)),
    (False, "regularized", (SLIP, SLIP)),
]


@pytest.mark.parametrize("planar, friction, regimes", CASES)
def test_compiled_dynamics_equals_its_python_source(planar, friction, regimes):
    model = model_for(planar, friction)
    rng = np.random.default_rng(RNG_SEED + 7 * planar + len(friction) + 3 * regimes[0] + regimes[1])
    checked = 0
    for trial in range(20):
        y = random_state_in_contact(model, rng)
        regime = np.array(regimes, np.int64)
        eref = np.array([[0.6, 0.8], [-1.0, 0.0]])
        dy_c, aux_c = evaluate(dynamics, model, 1e-3, y, regime, eref)
        dy_p, aux_p = evaluate(dynamics.py_func, model, 1e-3, y, regime, eref)
        scale = np.maximum(np.abs(dy_c), np.abs(dy_p))
        # Same arithmetic in a different compiler: differences are round-off of the
        # largest terms (contact forces of kN against accelerations of mm/s^2 elsewhere).
        np.testing.assert_allclose(dy_c, dy_p, rtol=1e-12, atol=1e-12 * np.max(scale))
        np.testing.assert_allclose(aux_c, aux_p, rtol=1e-12, atol=1e-12 * np.max(np.abs(aux_c)))
        checked += aux_c[0, A_FN] > 0.0 and aux_c[1, A_FN] > 0.0
    assert checked >= 10  # most draws really exercise both contacts


# --- brute-force inertia ---------------------------------------------------------------

def independent_shapes(bar, families_orders, xi):
    """Free-free shapes written out from their textbook form, normalized numerically to
    mean square 1 (not taken from mech.modes): values and d/dxi at xi."""
    from scipy.optimize import brentq

    xq, wq = np.polynomial.legendre.leggauss(300)
    xq, wq = 0.5 * (xq + 1), 0.5 * wq
    out, slope = [], []
    for fam, k in families_orders:
        if fam == "axial":
            f = lambda s, k=k: np.cos(k * math.pi * s)
            df = lambda s, k=k: -k * math.pi * np.sin(k * math.pi * s)
        else:
            b = brentq(lambda x: math.cos(x) * math.cosh(x) - 1.0, (k + 0.5) * math.pi - 0.4,
                       (k + 0.5) * math.pi + 0.4, xtol=1e-15)
            sig = (math.cosh(b) - math.cos(b)) / (math.sinh(b) - math.sin(b))
            f = lambda s, b=b, sig=sig: np.cosh(b * s) + np.cos(b * s) - sig * (np.sinh(b * s) + np.sin(b * s))
            df = lambda s, b=b, sig=sig: b * (np.sinh(b * s) - np.sin(b * s) - sig * (np.cosh(b * s) + np.cos(b * s)))
        norm = math.sqrt(np.sum(wq * f(xq) ** 2))
        out.append(f(xi) / norm)
        slope.append(df(xi) / norm)
    return np.array(out), np.array(slope)


def material_velocity_jacobians(model, q, R):
    """For material points of the cylinder (Gauss in x, polar Gauss over the section):
    weights rho dV and the Jacobians d v_point / d u, u = (V world, w body, eta)."""
    bar = model.scene.bar
    fam = list(zip(model.basis.families, model.basis.orders))
    n = model.n
    L = bar.length
    xg, wg = np.polynomial.legendre.leggauss(80)
    xi = 0.5 * (xg + 1.0)
    phi, _ = independent_shapes(bar, fam, xi)
    direction = {"axial": 0, "bend2": 1, "bend3": 2}
    psi = np.zeros((len(xi), n, 3))
    for j, (f, _) in enumerate(fam):
        psi[:, j, direction[f]] = phi[j]
    rg, rw = np.polynomial.legendre.leggauss(6)
    radius = 0.5 * bar.diameter
    rr = 0.5 * radius * (rg + 1.0)
    ang = 2.0 * math.pi * np.arange(8) / 8
    weights, jacs = [], []
    for p in range(len(xi)):
        s_axis = np.array([L * (xi[p] - 0.5), 0.0, 0.0]) + psi[p].T @ q
        for a in range(len(rr)):
            for c in ang:
                # sections translate with the centreline (Euler-Bernoulli without rotary
                # inertia of the bending slope), so a point keeps its offset in the section
                sp = s_axis + np.array([0.0, rr[a] * math.cos(c), rr[a] * math.sin(c)])
                dV = 0.5 * L * wg[p] * 0.5 * radius * rw[a] * rr[a] * (2.0 * math.pi / len(ang))
                G = np.zeros((3, 6 + n))
                G[:, 0:3] = np.eye(3)
                skew = np.array([[0, -sp[2], sp[1]], [sp[2], 0, -sp[0]], [-sp[1], sp[0], 0]])
                G[:, 3:6] = -R @ skew  # R (w x s) = -R [s]x w
                G[:, 6:] = R @ psi[p].T
                weights.append(bar.density * dV)
                jacs.append(G)
    return np.array(weights), np.array(jacs)


def invariant_mass_matrix(model, q):
    """M(q) from the basis' invariants: m I, J(q) = J0 + J1 q + J2 q q, B(q) = q.S, m I."""
    b = model.basis
    n = b.n
    m = b.mass
    J = b.J0 + np.einsum("jab,j->ab", b.J1, q) + np.einsum("jkab,j,k->ab", b.J2, q, q)
    B = np.einsum("kja,k->aj", b.S, q)
    M = np.zeros((6 + n, 6 + n))
    M[0:3, 0:3] = m * np.eye(3)
    M[3:6, 3:6] = J
    M[3:6, 6:] = B
    M[6:, 3:6] = B.T
    M[6:, 6:] = m * np.eye(n)
    return M


def test_inertia_invariants_reproduce_the_kinetic_energy_of_the_bar_volume():
    model = model_for(planar=False, friction="none", modes=2)
    rng = np.random.default_rng(RNG_SEED)
    n = model.n
    L = model.scene.bar.length
    sl = model.slices()
    for trial in range(4):
        # Large modal amplitudes (up to 1 % of L) so J1, J2 and S matter well above round-off.
        q = rng.normal(scale=0.01 * L, size=n)
        R = random_rotation(rng)
        u = np.concatenate([rng.normal(size=3), rng.normal(scale=10.0, size=3), rng.normal(size=n)])
        w, G = material_velocity_jacobians(model, q, R)
        M_brute = np.einsum("p,pia,pib->ab", w, G, G)
        M_inv = invariant_mass_matrix(model, q)
        # T = 1/2 u' M u by both routes, and M entry by entry.
        T_brute = 0.5 * np.sum(w * np.sum((G @ u) ** 2, axis=1))
        assert 0.5 * u @ M_inv @ u == pytest.approx(T_brute, rel=1e-10)
        np.testing.assert_allclose(M_inv, M_brute, atol=1e-10 * np.max(np.abs(M_brute)))
        # The compiled energy routine (sparse invariants) gives the same kinetic energy.
        y = model.initial_state()
        y[sl["quat"]] = matrix_to_quaternion(R)
        y[sl["pos"]] = [0.0, 0.0, 1.0]
        y[sl["q"]] = q
        y[sl["vel"]] = u[0:3]
        y[sl["omega"]] = u[3:6]
        y[sl["eta"]] = u[6:]
        out = np.empty(5)
        energies(y, model.arrays, make_work(n), out)
        assert out[0] == pytest.approx(T_brute, rel=1e-10)


def contact_point_jacobian(model, q, R, tip):
    """d v_P / d u for tip's contact point P = sphere centre - R_tip e_z, by our own
    kinematics: the cap is rigidly attached to the end section, which turns with the
    bending slope (delta2' about b3, delta3' about -b2)."""
    bar = model.scene.bar
    fam = list(zip(model.basis.families, model.basis.orders))
    n = model.n
    L, Rt = bar.length, bar.tip_radius
    xc = (-1.0 if tip == 0 else 1.0) * (L / 2 - Rt)
    phi, dphi = independent_shapes(bar, fam, np.array([xc / L + 0.5]))
    direction = {"axial": 0, "bend2": 1, "bend3": 2}
    psi = np.zeros((n, 3))
    theta = np.zeros((n, 3))
    for j, (f, _) in enumerate(fam):
        psi[j, direction[f]] = phi[j, 0]
        if f == "bend2":
            theta[j, 2] = dphi[j, 0] / L
        elif f == "bend3":
            theta[j, 1] = -dphi[j, 0] / L
    sc = np.array([xc, 0.0, 0.0]) + psi.T @ q
    arm = np.array([0.0, 0.0, -Rt])  # world: centre to contact point
    skew = lambda v: np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    G = np.zeros((3, 6 + n))
    G[:, 0:3] = np.eye(3)
    # centre: R (w x s_c + Psi eta); cap rotation Omega = R (w + Theta eta): Omega x arm
    G[:, 3:6] = -R @ skew(sc) - skew(arm) @ R
    G[:, 6:] = R @ psi.T - skew(arm) @ R @ theta.T
    return G


@pytest.mark.parametrize("regimes", [(FREE, FREE), (SLIP, FREE), (SLIP, SLIP)])
def test_accelerations_at_rest_solve_brute_force_mass_matrix_with_virtual_work_forces(regimes):
    """At zero speeds every velocity-product term vanishes, so M udot = Q exactly: gravity,
    -K q and the tip forces mapped by virtual work through our own contact-point Jacobian."""
    friction = "none" if regimes == (FREE, FREE) else "exact"
    model = model_for(planar=False, friction=friction, modes=2)
    rng = np.random.default_rng(RNG_SEED + 1)
    n = model.n
    sl = model.slices()
    m = model.basis.mass
    for trial in range(3):
        y = random_state_in_contact(model, rng, q_scale=1e-3 * model.scene.bar.length)
        y[sl["vel"]] = 0.0
        y[sl["omega"]] = 0.0
        y[sl["eta"]] = 0.0
        regime = np.array(regimes, np.int64)
        eref = np.array([[0.6, 0.8], [-1.0, 0.0]])
        dy, aux = evaluate(dynamics, model, 0.0, y, regime, eref)
        assert aux[0, A_FN] > 0.0 and aux[1, A_FN] > 0.0
        R = np.empty((3, 3))
        quat_to_matrix(*y[sl["quat"]], R)
        q = y[sl["q"]]
        udot = np.concatenate([dy[sl["vel"]], dy[sl["omega"]], dy[sl["eta"]]])
        w, Gp = material_velocity_jacobians(model, q, R)
        M = np.einsum("p,pia,pib->ab", w, Gp, Gp)
        Q = np.zeros(6 + n)
        Q[2] = -m * model.scene.gravity
        # modal stiffness K_jj = m (2 pi f_j)^2, with f_j checked against the closed forms
        Q[6:] = -m * (2.0 * math.pi * np.asarray(model.basis.frequencies)) ** 2 * q
        mu = model.scene.friction.mu
        for tip in range(2):
            fn = aux[tip, A_FN]
            if fn <= 0.0:
                continue
            F = np.array([0.0, 0.0, fn])
            if regime[tip] == SLIP:
                # speeds are zero: slip starts along the reference direction
                limit = min(mu * fn ** (1.0 - model.scene.friction.gamma), model.scene.friction.max_ratio * fn)
                F[0:2] = -limit * eref[tip]
            Q += contact_point_jacobian(model, q, R, tip).T @ F
        np.testing.assert_allclose(M @ udot, Q, rtol=1e-9, atol=1e-9 * np.max(np.abs(Q)))


def test_the_compiled_cache_folder_follows_the_mechanics_sources(tmp_path):
    """A changed source file (any of the package's) must compile afresh: the cache folder's
    key is a hash of every .py file, so editing one changes it and restoring it restores it."""
    from mech.compiled_cache import source_key

    for name, text in (("kernel.py", "x = 1\n"), ("integrator.py", "y = 2\n")):
        (tmp_path / name).write_text(text)
    before = source_key(tmp_path)
    (tmp_path / "kernel.py").write_text("x = 3\n")
    changed = source_key(tmp_path)
    (tmp_path / "kernel.py").write_text("x = 1\n")
    assert changed != before and source_key(tmp_path) == before


@pytest.mark.parametrize("name", ["free_drop", "relay_force", "pushbutton"])
def test_normal_forces_from_the_kinematics_equal_the_right_hand_sides(name):
    """The peak-force samples inside a step and the circuit's force callback evaluate only
    the contact kinematics (integrator.tip_forces); at every recorded state of a run (a free
    3D bar with friction, the relay blade on a spherical rivet, the pivoted lever) they give
    the normal forces and penetrations of the full right-hand side."""
    from pathlib import Path

    import tomllib

    from mech import ImpactSolver
    from mech.compiled import dense_force_arguments, dense_tip_forces, dynamics, make_work
    from mech.kernel_layout import A_FN, A_Y, C_ON, NAUX
    from mech.scene import SCENE_SECTIONS, scene_from_dict

    root = Path(__file__).resolve().parents[2]
    path = root / "examples" / "pushbutton.toml" if name == "pushbutton" else root / "coupling" / "scenes" / f"{name}.toml"
    doc = {k: v for k, v in tomllib.loads(path.read_text()).items() if k in SCENE_SECTIONS}
    # the mechanics of the shipped scene (read from its file: these tests build scenes from
    # mech alone); coupled, its mu comes from [tribology], here a Coulomb 0.3 keeps friction on
    doc.setdefault("friction", {"mu": 0.3})
    mech_scene = scene_from_dict(doc, where=str(path))
    solver = ImpactSolver(mech_scene)
    res = solver.run()
    arrays, work = solver.arrays, make_work(solver.model.n)
    aux, dy = np.empty((2, NAUX)), np.empty(res.states.shape[1])
    touched = 0
    for k in np.linspace(0, len(res.t) - 1, 300).astype(int):
        y = np.ascontiguousarray(res.states[k])
        dynamics(res.t[k], y, arrays, res.regimes[k], solver.eref, dy, aux, work)
        coef = np.zeros((1, 5, len(y)))
        coef[0, 0] = y  # a one-point dense output: the state itself
        args = dense_force_arguments(np.array([res.t[k]]), np.array([res.t[k]]), np.ones(1), coef, arrays)
        out = np.array(dense_tip_forces(res.t[k], args))
        np.testing.assert_allclose(out[:2], aux[:, A_FN], rtol=1e-12, atol=1e-12 * max(1.0, aux[:, A_FN].max()))
        on = solver.model.cpar[:, C_ON] > 0.0
        np.testing.assert_allclose(out[3:][on], aux[on, A_Y], rtol=1e-12, atol=1e-15)
        touched += int(aux[:, A_FN].max() > 0.0)
    assert touched > 10  # the check saw contacts carrying force


def test_the_dense_forces_scratch_is_sized_alike_and_checked():
    """mech.compiled.dense_force_arguments sizes the scratch vector of dense_tip_forces by
    the formula of mech.integrator.dense_force_scratch_size (the compiled side's check), and
    a scratch vector too short is refused, not written past."""
    from mech import ImpactSolver
    from mech.compiled import dense_force_arguments, dense_pair_forces, dense_tip_forces
    from mech.integrator import dense_force_scratch_size
    from mech.scene import scene_from_dict

    solver = ImpactSolver(scene_from_dict({"bar": dict(length=0.1, diameter=0.006, tip_radius=0.003, modes=2,
                                                       youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0),
                                           "initial": dict(height=1e-4, velocity=[0.0, 0.0, -1.0]),
                                           "solver": dict(t_end=3e-4)}), keep_dense=True)
    seg = solver.advance(3e-4)
    coef = np.ascontiguousarray(seg._coef)
    args = dense_force_arguments(seg._t_valid, seg._t0, seg._h, coef, solver.arrays)
    m = solver.model
    assert len(args[-1]) == dense_force_scratch_size(coef.shape[2], m.n, m.rows)
    t = 0.5 * (seg.t_start + seg.t_end)
    assert dense_tip_forces(t, args) == seg.tip_forces(t)
    short = args[:-1] + (np.zeros(len(args[-1]) - 1),)
    with pytest.raises(ValueError, match="scratch"):
        dense_tip_forces(t, short)
    with pytest.raises(ValueError, match="scratch"):
        dense_pair_forces(t, short, np.empty((m.rows, 2)))
