"""Compiled right-hand side of the floating-frame bar with tip contact and friction.

State layout (3D):     r(3) quat(4) q(n) | V(3) w(3) eta(n) | quadratures(NQ)
State layout (planar): x z phi q(n)      | vx vz wy eta(n)  | quadratures(NQ)
r, V: centre of mass in the world frame (z up, m, m/s); quat: body->world (scalar
first); phi: rotation about world y; w: body angular velocity (rad/s); q, eta: modal
coordinates (m) and speeds (m/s). Quadratures integrate dissipation and contact work
so the energy audit and Stronge's restitution come out of the same integration.

Equations (see docs/mechanics.md for the derivation):
    m dV/dt = F
    [J  B ] [dw/dt  ]   [tau - w x h - dJ/dt w                                    ]
    [B' mI] [deta/dt] = [Q - K q - C eta + 1/2 w' dJ/dq_j w + 2 w . sum_k S_jk eta_k]
with h = J w + B eta. The block is the plane z = 0; tip i is a sphere of radius R whose
centre is the material point x_i = -+(L/2 - R) on the axis. Stick is an exact
constraint (zero slip velocity of the contact point), its force solved each evaluation.

All functions here are numba-compiled; their Python sources (``.py_func``) are the
readable reference and are tested against the compiled versions.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .contact_laws import normal_force
from .friction import friction_limit, regularized_scale
from .inertia import inertia_matrix, inertia_terms

# fpar indices
F_MASS, F_G, F_K, F_C, F_BETA, F_GAMMA, F_MU0, F_MU_SLOPE, F_T_MU, F_MAX_RATIO, F_RTIP, F_VREG, F_BAUM, F_VBOUND = range(14)
N_FPAR = 14
# ipar indices
I_N, I_PLANAR, I_FRICTION = range(3)
FRICTION_NONE, FRICTION_EXACT, FRICTION_REGULARIZED = 0, 1, 2
# regimes of a tip
FREE, SLIP, STICK = 0, 1, 2
# quadratures: dissipations; per tip i, compression work at Q_WCOMP + 2i, restitution
# work at Q_WCOMP + 2i + 1, normal impulse at Q_IMPULSE + i
Q_DNORMAL, Q_DFRICTION, Q_DMODAL, Q_WCOMP, Q_IMPULSE = 0, 1, 2, 3, 7
NQ = 9
# aux columns per tip
A_Y, A_YDOT, A_FN, A_FTX, A_FTY, A_VTX, A_VTY, A_MARGIN = range(8)
NAUX = 8
# events per tip: contact (y), force clip, slip direction, stick margin, compression
# turn (dy/dt = 0: splits the normal work into compression and restitution exactly)
EV_CONTACT, EV_CLIP, EV_SLIP, EV_STICK, EV_COMPRESSION = range(5)
NEV_TIP = 5


@njit(cache=True)
def layout(n, planar):
    """(position size, velocity size) of the state for n modes."""
    if planar:
        return 3 + n, 3 + n
    return 7 + n, 6 + n


@njit(cache=True)
def state_size(n, planar):
    npos, nvel = layout(n, planar)
    return npos + nvel + NQ


@njit(cache=True)
def quat_to_matrix(qw, qx, qy, qz, R):
    """Body->world rotation matrix of a (not necessarily unit) quaternion, into R."""
    s = 1.0 / (qw * qw + qx * qx + qy * qy + qz * qz)
    R[0, 0] = 1.0 - 2.0 * s * (qy * qy + qz * qz)
    R[0, 1] = 2.0 * s * (qx * qy - qz * qw)
    R[0, 2] = 2.0 * s * (qx * qz + qy * qw)
    R[1, 0] = 2.0 * s * (qx * qy + qz * qw)
    R[1, 1] = 1.0 - 2.0 * s * (qx * qx + qz * qz)
    R[1, 2] = 2.0 * s * (qy * qz - qx * qw)
    R[2, 0] = 2.0 * s * (qx * qz - qy * qw)
    R[2, 1] = 2.0 * s * (qy * qz + qx * qw)
    R[2, 2] = 1.0 - 2.0 * s * (qx * qx + qy * qy)


@njit(cache=True)
def unpack(y, n, planar, r, R, q, V, w, eta):
    """Fill 3D position r, rotation R, q, V, body w and eta from the state y."""
    if planar:
        r[0] = y[0]
        r[1] = 0.0
        r[2] = y[1]
        c = math.cos(y[2])
        s = math.sin(y[2])
        R[0, 0] = c
        R[0, 1] = 0.0
        R[0, 2] = s
        R[1, 0] = 0.0
        R[1, 1] = 1.0
        R[1, 2] = 0.0
        R[2, 0] = -s
        R[2, 1] = 0.0
        R[2, 2] = c
        for j in range(n):
            q[j] = y[3 + j]
        V[0] = y[3 + n]
        V[1] = 0.0
        V[2] = y[4 + n]
        w[0] = 0.0
        w[1] = y[5 + n]
        w[2] = 0.0
        for j in range(n):
            eta[j] = y[6 + n + j]
    else:
        for i in range(3):
            r[i] = y[i]
        quat_to_matrix(y[3], y[4], y[5], y[6], R)
        for j in range(n):
            q[j] = y[7 + j]
        for i in range(3):
            V[i] = y[7 + n + i]
            w[i] = y[10 + n + i]
        for j in range(n):
            eta[j] = y[13 + n + j]


@njit(cache=True)
def inverse3(A, out):
    """Inverse of a 3x3 matrix by cofactors (the Schur complement is symmetric positive definite)."""
    c00 = A[1, 1] * A[2, 2] - A[1, 2] * A[2, 1]
    c01 = A[1, 2] * A[2, 0] - A[1, 0] * A[2, 2]
    c02 = A[1, 0] * A[2, 1] - A[1, 1] * A[2, 0]
    det = A[0, 0] * c00 + A[0, 1] * c01 + A[0, 2] * c02
    inv = 1.0 / det
    out[0, 0] = c00 * inv
    out[1, 0] = c01 * inv
    out[2, 0] = c02 * inv
    out[0, 1] = (A[0, 2] * A[2, 1] - A[0, 1] * A[2, 2]) * inv
    out[1, 1] = (A[0, 0] * A[2, 2] - A[0, 2] * A[2, 0]) * inv
    out[2, 1] = (A[0, 1] * A[2, 0] - A[0, 0] * A[2, 1]) * inv
    out[0, 2] = (A[0, 1] * A[1, 2] - A[0, 2] * A[1, 1]) * inv
    out[1, 2] = (A[0, 2] * A[1, 0] - A[0, 0] * A[1, 2]) * inv
    out[2, 2] = (A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]) * inv


@njit(cache=True)
def make_work(n):
    """A tuple of scratch arrays for ``dynamics`` (kept out of the hot loop's allocations)."""
    return (
        np.zeros(3), np.zeros((3, 3)), np.zeros(n), np.zeros(3), np.zeros(3), np.zeros(n),  # r R q V w eta
        np.zeros((3, 3)), np.zeros((3, n)), np.zeros((3, 3)),  # J B Ainv
        np.zeros(3), np.zeros(n), np.zeros(3),  # f_r f_e F
        np.zeros(3), np.zeros(n), np.zeros(3),  # wdot etadot Vdot
        np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3)),  # s_tip sdot_tip theta_dot_tip (body)
        np.zeros((2, 3)),  # vP world
        np.zeros((4, 3)), np.zeros((4, n)), np.zeros((4, 3)),  # unit responses: wdot etadot Vdot
        np.zeros(12), np.zeros((3, 3)),  # small vectors, Schur complement
    )


@njit(cache=True)
def tip_offset(i, xc, psi, modal, n, out):
    """Body-frame offset of tip sphere i from the centroid, x_i b1 + sum_j Psi_ij modal_j
    (with modal = q: the position; with modal = eta, and xc zero: its rate)."""
    out[0] = xc[i]
    out[1] = 0.0
    out[2] = 0.0
    for j in range(n):
        out[0] += psi[i, j, 0] * modal[j]
        out[1] += psi[i, j, 1] * modal[j]
        out[2] += psi[i, j, 2] * modal[j]


@njit(cache=True)
def mu_at(t, fpar):
    """N^gamma: friction coefficient, linear in time within a coupling step."""
    mu = fpar[F_MU0] + fpar[F_MU_SLOPE] * (t - fpar[F_T_MU])
    return mu if mu > 0.0 else 0.0


@njit(cache=True)
def _add_point_force(i, Fw, Mw, R, s_tip, psi, theta, n, F, f_r, f_e):
    """Generalized forces of world force Fw at tip-sphere centre i plus world moment Mw."""
    for a in range(3):
        F[a] += Fw[a]
    # body components: Fb = R^T Fw, Mb = R^T Mw
    fb0 = R[0, 0] * Fw[0] + R[1, 0] * Fw[1] + R[2, 0] * Fw[2]
    fb1 = R[0, 1] * Fw[0] + R[1, 1] * Fw[1] + R[2, 1] * Fw[2]
    fb2 = R[0, 2] * Fw[0] + R[1, 2] * Fw[1] + R[2, 2] * Fw[2]
    mb0 = R[0, 0] * Mw[0] + R[1, 0] * Mw[1] + R[2, 0] * Mw[2]
    mb1 = R[0, 1] * Mw[0] + R[1, 1] * Mw[1] + R[2, 1] * Mw[2]
    mb2 = R[0, 2] * Mw[0] + R[1, 2] * Mw[1] + R[2, 2] * Mw[2]
    s0 = s_tip[i, 0]
    s1 = s_tip[i, 1]
    s2 = s_tip[i, 2]
    f_r[0] += s1 * fb2 - s2 * fb1 + mb0
    f_r[1] += s2 * fb0 - s0 * fb2 + mb1
    f_r[2] += s0 * fb1 - s1 * fb0 + mb2
    for j in range(n):
        f_e[j] += (psi[i, j, 0] * fb0 + psi[i, j, 1] * fb1 + psi[i, j, 2] * fb2
                   + theta[i, j, 0] * mb0 + theta[i, j, 1] * mb1 + theta[i, j, 2] * mb2)


@njit(cache=True)
def _solve_accel(f_r, f_e, Ainv, B, m, n, wdot, etadot):
    """[J B; B' mI] [wdot; etadot] = [f_r; f_e] by the 3x3 Schur complement."""
    r0 = f_r[0]
    r1 = f_r[1]
    r2 = f_r[2]
    for j in range(n):
        fe = f_e[j] / m
        r0 -= B[0, j] * fe
        r1 -= B[1, j] * fe
        r2 -= B[2, j] * fe
    for a in range(3):
        wdot[a] = Ainv[a, 0] * r0 + Ainv[a, 1] * r1 + Ainv[a, 2] * r2
    for j in range(n):
        etadot[j] = (f_e[j] - B[0, j] * wdot[0] - B[1, j] * wdot[1] - B[2, j] * wdot[2]) / m


@njit(cache=True)
def _tip_accel(k, R, s_tip, psi, theta, n, Rtip, Vdot, wdot, etadot, out):
    """World acceleration of tip k's contact point from (Vdot, wdot, etadot), no velocity terms."""
    # a = Vdot + R (wdot x s + Psi etadot) + (R (wdot + Theta etadot)) x (0, 0, -Rtip)
    ab0 = wdot[1] * s_tip[k, 2] - wdot[2] * s_tip[k, 1]
    ab1 = wdot[2] * s_tip[k, 0] - wdot[0] * s_tip[k, 2]
    ab2 = wdot[0] * s_tip[k, 1] - wdot[1] * s_tip[k, 0]
    ob0 = wdot[0]
    ob1 = wdot[1]
    ob2 = wdot[2]
    for j in range(n):
        e = etadot[j]
        ab0 += psi[k, j, 0] * e
        ab1 += psi[k, j, 1] * e
        ab2 += psi[k, j, 2] * e
        ob0 += theta[k, j, 0] * e
        ob1 += theta[k, j, 1] * e
        ob2 += theta[k, j, 2] * e
    for a in range(3):
        out[a] = Vdot[a] + R[a, 0] * ab0 + R[a, 1] * ab1 + R[a, 2] * ab2
    ow0 = R[0, 0] * ob0 + R[0, 1] * ob1 + R[0, 2] * ob2
    ow1 = R[1, 0] * ob0 + R[1, 1] * ob1 + R[1, 2] * ob2
    # (ow x (0,0,-Rtip)) = (-ow1 * Rtip ... ): x: ow1*(-Rtip) - 0, y: 0 - ow0*(-Rtip)
    out[0] += -ow1 * Rtip
    out[1] += ow0 * Rtip


@njit(cache=True)
def dynamics(t, y, fpar, ipar, J0, sp_ptr, sp_idx, sp_val, psi, theta, xc, regime, eref, dy, aux, work):
    """Time derivative of the state into ``dy``; per-tip contact quantities into ``aux`` (2, NAUX).

    regime: (2,) FREE/SLIP/STICK per tip (friction bookkeeping; the normal force always
    follows the penetration). eref: (2, 2) reference slip direction per tip.
    """
    n = ipar[I_N]
    planar = ipar[I_PLANAR]
    fmodel = ipar[I_FRICTION]
    (r, R, q, V, w, eta, Jm, B, Ainv, f_r, f_e, F, wdot, etadot, Vdot,
     s_tip, sd_tip, th_tip, vP, u_wdot, u_etadot, u_Vdot, sv, Amat) = work
    unpack(y, n, planar, r, R, q, V, w, eta)
    m = fpar[F_MASS]
    k_h = fpar[F_K]
    c_h = fpar[F_C]
    beta = fpar[F_BETA]
    Rtip = fpar[F_RTIP]

    # Inertia, centrifugal, gyroscopic, stiffness and damping terms (mech/inertia.py)
    d_modal = inertia_terms(n, m, q, eta, w, J0, sp_ptr, sp_idx, sp_val, Jm, B, f_e, sv, f_r, Amat, Ainv)
    F[0] = 0.0
    F[1] = 0.0
    F[2] = -m * fpar[F_G]

    mu = mu_at(t, fpar) if fmodel != FRICTION_NONE else 0.0
    gam = fpar[F_GAMMA]
    maxr = fpar[F_MAX_RATIO]
    d_normal = 0.0
    d_friction = 0.0
    n_stick = 0
    Fw = sv[0:3]
    Mw = sv[3:6]
    for i in range(2):
        # tip-sphere centre: body position, velocity; section rotation rate
        s_tip[i, 0] = xc[i]
        s_tip[i, 1] = 0.0
        s_tip[i, 2] = 0.0
        for a in range(3):
            sd_tip[i, a] = 0.0
            th_tip[i, a] = 0.0
        for j in range(n):
            for a in range(3):
                s_tip[i, a] += psi[i, j, a] * q[j]
                sd_tip[i, a] += psi[i, j, a] * eta[j]
                th_tip[i, a] += theta[i, j, a] * eta[j]
        vb0 = w[1] * s_tip[i, 2] - w[2] * s_tip[i, 1] + sd_tip[i, 0]
        vb1 = w[2] * s_tip[i, 0] - w[0] * s_tip[i, 2] + sd_tip[i, 1]
        vb2 = w[0] * s_tip[i, 1] - w[1] * s_tip[i, 0] + sd_tip[i, 2]
        zc = r[2] + R[2, 0] * s_tip[i, 0] + R[2, 1] * s_tip[i, 1] + R[2, 2] * s_tip[i, 2]
        vc0 = V[0] + R[0, 0] * vb0 + R[0, 1] * vb1 + R[0, 2] * vb2
        vc1 = V[1] + R[1, 0] * vb0 + R[1, 1] * vb1 + R[1, 2] * vb2
        vc2 = V[2] + R[2, 0] * vb0 + R[2, 1] * vb1 + R[2, 2] * vb2
        ob0 = w[0] + th_tip[i, 0]
        ob1 = w[1] + th_tip[i, 1]
        ob2 = w[2] + th_tip[i, 2]
        ow0 = R[0, 0] * ob0 + R[0, 1] * ob1 + R[0, 2] * ob2
        ow1 = R[1, 0] * ob0 + R[1, 1] * ob1 + R[1, 2] * ob2
        # contact point P = centre + (0, 0, -Rtip): v_P = v_c + Omega x (0, 0, -Rtip)
        vP[i, 0] = vc0 - ow1 * Rtip
        vP[i, 1] = vc1 + ow0 * Rtip
        vP[i, 2] = vc2
        pen = Rtip - zc
        pdot = -vc2
        fn = normal_force(pen, pdot, k_h, c_h, beta)
        aux[i, A_Y] = pen
        aux[i, A_YDOT] = pdot
        aux[i, A_FN] = fn
        aux[i, A_FTX] = 0.0
        aux[i, A_FTY] = 0.0
        aux[i, A_VTX] = vP[i, 0]
        aux[i, A_VTY] = vP[i, 1]
        lim = friction_limit(fn, mu, gam, maxr) if fmodel != FRICTION_NONE else 0.0
        aux[i, A_MARGIN] = lim
        if pen > 0.0:
            d_normal += (fn - k_h * pen * math.sqrt(pen)) * pdot
        if fn > 0.0:
            Fw[0] = 0.0
            Fw[1] = 0.0
            Fw[2] = fn
            Mw[0] = 0.0
            Mw[1] = 0.0
            Mw[2] = 0.0
            _add_point_force(i, Fw, Mw, R, s_tip, psi, theta, n, F, f_r, f_e)
            ftx = 0.0
            fty = 0.0
            if fmodel == FRICTION_EXACT and regime[i] == SLIP:
                # Friction opposes the slip velocity while it points to the side of the
                # reference direction; past that (v_t . e_ref <= 0, only in trial stages
                # of a step that crosses the slip event) it keeps the reference direction,
                # so the slip speed goes through zero and the event sees it. Following the
                # actual direction there would pin v_t at zero inside the step (measured:
                # 1e-10 s steps, 1.3 M steps for 1 ms).
                vt = math.sqrt(vP[i, 0] ** 2 + vP[i, 1] ** 2)
                if vt > 1e-14 and vP[i, 0] * eref[i, 0] + vP[i, 1] * eref[i, 1] > 0.0:
                    ftx = -lim * vP[i, 0] / vt
                    fty = -lim * vP[i, 1] / vt
                else:
                    ftx = -lim * eref[i, 0]
                    fty = -lim * eref[i, 1]
            elif fmodel == FRICTION_REGULARIZED:
                vt = math.sqrt(vP[i, 0] ** 2 + vP[i, 1] ** 2)
                if vt > 0.0:
                    sc = regularized_scale(vt, fpar[F_VREG]) / vt
                    ftx = -lim * sc * vP[i, 0]
                    fty = -lim * sc * vP[i, 1]
            elif fmodel == FRICTION_EXACT and regime[i] == STICK:
                n_stick += 1
            if ftx != 0.0 or fty != 0.0:
                Fw[0] = ftx
                Fw[1] = fty
                Fw[2] = 0.0
                # moment of the friction force about the sphere centre: (0,0,-Rtip) x Ft
                Mw[0] = Rtip * fty
                Mw[1] = -Rtip * ftx
                Mw[2] = 0.0
                _add_point_force(i, Fw, Mw, R, s_tip, psi, theta, n, F, f_r, f_e)
                aux[i, A_FTX] = ftx
                aux[i, A_FTY] = fty
                d_friction -= ftx * vP[i, 0] + fty * vP[i, 1]
                aux[i, A_MARGIN] = lim - math.sqrt(ftx * ftx + fty * fty)

    for a in range(3):
        Vdot[a] = F[a] / m
    _solve_accel(f_r, f_e, Ainv, B, m, n, wdot, etadot)

    if n_stick > 0:
        _apply_stick(fpar, n, planar, R, w, eta, s_tip, sd_tip, th_tip, vP, regime, aux,
                     psi, theta, Ainv, B, m, Rtip, Vdot, wdot, etadot, u_Vdot, u_wdot, u_etadot)

    # assemble dy
    npos, nvel = layout(n, planar)
    if planar:
        dy[0] = V[0]
        dy[1] = V[2]
        dy[2] = w[1]
        for j in range(n):
            dy[3 + j] = eta[j]
        dy[3 + n] = Vdot[0]
        dy[4 + n] = Vdot[2]
        dy[5 + n] = wdot[1]
        for j in range(n):
            dy[6 + n + j] = etadot[j]
    else:
        for a in range(3):
            dy[a] = V[a]
        qw = y[3]
        qx = y[4]
        qy = y[5]
        qz = y[6]
        dy[3] = 0.5 * (-qx * w[0] - qy * w[1] - qz * w[2])
        dy[4] = 0.5 * (qw * w[0] + qy * w[2] - qz * w[1])
        dy[5] = 0.5 * (qw * w[1] + qz * w[0] - qx * w[2])
        dy[6] = 0.5 * (qw * w[2] + qx * w[1] - qy * w[0])
        for j in range(n):
            dy[7 + j] = eta[j]
        for a in range(3):
            dy[7 + n + a] = Vdot[a]
            dy[10 + n + a] = wdot[a]
        for j in range(n):
            dy[13 + n + j] = etadot[j]
    base = npos + nvel
    dy[base + Q_DNORMAL] = d_normal
    dy[base + Q_DFRICTION] = d_friction
    dy[base + Q_DMODAL] = d_modal
    for i in range(2):
        p = aux[i, A_FN] * aux[i, A_YDOT]
        dy[base + Q_WCOMP + 2 * i] = p if p > 0.0 else 0.0
        dy[base + Q_WCOMP + 2 * i + 1] = p if p < 0.0 else 0.0
        dy[base + Q_IMPULSE + i] = aux[i, A_FN]


@njit(cache=True)
def _sticking_tips(regime, aux):
    tips = np.empty(2, np.int64)
    ns = 0
    for i in range(2):
        if regime[i] == STICK and aux[i, A_FN] > 0.0:
            tips[ns] = i
            ns += 1
    return tips, ns


@njit(cache=True)
def _min_norm_solve(W, rhs):
    """Least-squares, minimum-norm solution of W x = rhs.

    Two stick points of a rigid bar along its axis constrain the same motion: W is then
    singular and the holding forces are statically indeterminate; the minimum-norm
    choice shares them equally (a flexible bar's axial modes make W regular).
    """
    x, _res, _rank, _sv = np.linalg.lstsq(W, rhs, 1e-10)
    return x


@njit(cache=True)
def _stick_matrix(n, planar, R, s_tip, psi, theta, Ainv, B, m, Rtip, tips, ns, u_Vdot, u_wdot, u_etadot):
    """W = G M^-1 G^T for the sticking contact points; columns of M^-1 G^T into u_*."""
    ndir = 1 if planar else 2
    nc = ns * ndir
    W = np.zeros((nc, nc))
    f_r = np.zeros(3)
    f_e = np.zeros(n)
    Fz = np.zeros(3)
    Fw = np.zeros(3)
    Mw = np.zeros(3)
    acc = np.zeros(3)
    for a_i in range(ns):
        i = tips[a_i]
        for d in range(ndir):
            col = a_i * ndir + d
            f_r[:] = 0.0
            f_e[:] = 0.0
            Fz[:] = 0.0
            Fw[:] = 0.0
            Fw[d] = 1.0
            Mw[0] = Rtip * Fw[1]
            Mw[1] = -Rtip * Fw[0]
            Mw[2] = 0.0
            _add_point_force(i, Fw, Mw, R, s_tip, psi, theta, n, Fz, f_r, f_e)
            for a in range(3):
                u_Vdot[col, a] = Fz[a] / m
            _solve_accel(f_r, f_e, Ainv, B, m, n, u_wdot[col], u_etadot[col])
            for b_k in range(ns):
                k = tips[b_k]
                _tip_accel(k, R, s_tip, psi, theta, n, Rtip, u_Vdot[col], u_wdot[col], u_etadot[col], acc)
                for d2 in range(ndir):
                    W[b_k * ndir + d2, col] = acc[d2]
    return W


@njit(cache=True)
def _apply_stick(fpar, n, planar, R, w, eta, s_tip, sd_tip, th_tip, vP, regime, aux,
                 psi, theta, Ainv, B, m, Rtip, Vdot, wdot, etadot, u_Vdot, u_wdot, u_etadot):
    """Solve the stick constraint forces: tangential acceleration of each sticking contact
    point = -baumgarte * its slip velocity; add their accelerations and record them in aux."""
    tips, ns = _sticking_tips(regime, aux)
    if ns == 0:
        return
    ndir = 1 if planar else 2
    W = _stick_matrix(n, planar, R, s_tip, psi, theta, Ainv, B, m, Rtip, tips, ns, u_Vdot, u_wdot, u_etadot)
    rhs = np.zeros(ns * ndir)
    acc = np.zeros(3)
    baum = fpar[F_BAUM]
    # free tangential acceleration incl. velocity-product terms:
    # R (2 w x sdot + w x (w x s)) + (R (w x theta_dot)) x (0, 0, -Rtip)
    for b_k in range(ns):
        k = tips[b_k]
        _tip_accel(k, R, s_tip, psi, theta, n, Rtip, Vdot, wdot, etadot, acc)
        s0, s1, s2 = s_tip[k, 0], s_tip[k, 1], s_tip[k, 2]
        ws0 = w[1] * s2 - w[2] * s1
        ws1 = w[2] * s0 - w[0] * s2
        ws2 = w[0] * s1 - w[1] * s0
        g0 = 2.0 * (w[1] * sd_tip[k, 2] - w[2] * sd_tip[k, 1]) + (w[1] * ws2 - w[2] * ws1)
        g1 = 2.0 * (w[2] * sd_tip[k, 0] - w[0] * sd_tip[k, 2]) + (w[2] * ws0 - w[0] * ws2)
        g2 = 2.0 * (w[0] * sd_tip[k, 1] - w[1] * sd_tip[k, 0]) + (w[0] * ws1 - w[1] * ws0)
        t0 = w[1] * th_tip[k, 2] - w[2] * th_tip[k, 1]
        t1 = w[2] * th_tip[k, 0] - w[0] * th_tip[k, 2]
        t2 = w[0] * th_tip[k, 1] - w[1] * th_tip[k, 0]
        tw0 = R[0, 0] * t0 + R[0, 1] * t1 + R[0, 2] * t2
        tw1 = R[1, 0] * t0 + R[1, 1] * t1 + R[1, 2] * t2
        a0 = acc[0] + R[0, 0] * g0 + R[0, 1] * g1 + R[0, 2] * g2 - tw1 * Rtip
        a1 = acc[1] + R[1, 0] * g0 + R[1, 1] * g1 + R[1, 2] * g2 + tw0 * Rtip
        rhs[b_k * ndir] = -(a0 + baum * vP[k, 0])
        if ndir == 2:
            rhs[b_k * ndir + 1] = -(a1 + baum * vP[k, 1])
    lam = _min_norm_solve(W, rhs)
    for col in range(ns * ndir):
        lc = lam[col]
        for a in range(3):
            Vdot[a] += lc * u_Vdot[col, a]
            wdot[a] += lc * u_wdot[col, a]
        for j in range(n):
            etadot[j] += lc * u_etadot[col, j]
    for a_i in range(ns):
        i = tips[a_i]
        ftx = lam[a_i * ndir]
        fty = lam[a_i * ndir + 1] if ndir == 2 else 0.0
        aux[i, A_FTX] = ftx
        aux[i, A_FTY] = fty
        aux[i, A_MARGIN] = aux[i, A_MARGIN] - math.sqrt(ftx * ftx + fty * fty)


@njit(cache=True)
def project_to_stick(t, y, fpar, ipar, J0, sp_ptr, sp_idx, sp_val, psi, theta, xc, regime, eref, aux, work):
    """Remove the slip velocity of every sticking tip by the smallest change of the speeds
    in the kinetic-energy metric: du = -M^-1 G^T (G M^-1 G^T)^-1 v_t. Returns the kinetic
    energy change (J); used only when |v_t| is already below the stick tolerance."""
    n = ipar[I_N]
    planar = ipar[I_PLANAR]
    dy = np.empty(y.shape[0])
    dynamics(t, y, fpar, ipar, J0, sp_ptr, sp_idx, sp_val, psi, theta, xc, regime, eref, dy, aux, work)
    (r, R, q, V, w, eta, Jm, B, Ainv, f_r, f_e, F, wdot, etadot, Vdot,
     s_tip, sd_tip, th_tip, vP, u_wdot, u_etadot, u_Vdot, sv, Amat) = work
    tips, ns = _sticking_tips(regime, aux)
    if ns == 0:
        return 0.0
    ndir = 1 if planar else 2
    W = _stick_matrix(n, planar, R, s_tip, psi, theta, Ainv, B, fpar[F_MASS], fpar[F_RTIP],
                      tips, ns, u_Vdot, u_wdot, u_etadot)
    rhs = np.zeros(ns * ndir)
    for b_k in range(ns):
        for d in range(ndir):
            rhs[b_k * ndir + d] = -vP[tips[b_k], d]
    lam = _min_norm_solve(W, rhs)
    dV = np.zeros(3)
    dw = np.zeros(3)
    de = np.zeros(n)
    for col in range(ns * ndir):
        for a in range(3):
            dV[a] += lam[col] * u_Vdot[col, a]
            dw[a] += lam[col] * u_wdot[col, a]
        for j in range(n):
            de[j] += lam[col] * u_etadot[col, j]
    # kinetic energy change = lam . (v_t + 1/2 W lam) with v_t = -W lam: -1/2 lam . W lam
    dke = 0.0
    for a_ in range(ns * ndir):
        for b_ in range(ns * ndir):
            dke -= 0.5 * lam[a_] * W[a_, b_] * lam[b_]
    if planar:
        y[3 + n] += dV[0]
        y[4 + n] += dV[2]
        y[5 + n] += dw[1]
        for j in range(n):
            y[6 + n + j] += de[j]
    else:
        for a in range(3):
            y[7 + n + a] += dV[a]
            y[10 + n + a] += dw[a]
        for j in range(n):
            y[13 + n + j] += de[j]
    return dke


@njit(cache=True)
def energies(y, fpar, ipar, J0, sp_ptr, sp_idx, sp_val, psi, xc, work, out):
    """out = (kinetic, elastic strain, gravity potential m g z, stored Hertz energy), all J."""
    n = ipar[I_N]
    planar = ipar[I_PLANAR]
    r, R, q, V, w, eta, Jm, B = work[0], work[1], work[2], work[3], work[4], work[5], work[6], work[7]
    unpack(y, n, planar, r, R, q, V, w, eta)
    m = fpar[F_MASS]
    inertia_matrix(n, q, J0, sp_ptr, sp_idx, sp_val, Jm, B)
    kin = 0.5 * m * (V[0] ** 2 + V[1] ** 2 + V[2] ** 2)
    for a in range(3):
        for b in range(3):
            kin += 0.5 * w[a] * Jm[a, b] * w[b]
    for j in range(n):
        kin += (w[0] * B[0, j] + w[1] * B[1, j] + w[2] * B[2, j]) * eta[j] + 0.5 * m * eta[j] ** 2
    el = 0.0
    for e in range(sp_ptr[3], sp_ptr[4]):
        el += 0.5 * q[sp_idx[e, 0]] * sp_val[e] * q[sp_idx[e, 1]]
    hz = 0.0
    s = np.empty(3)
    for i in range(2):
        tip_offset(i, xc, psi, q, n, s)
        pen = fpar[F_RTIP] - (r[2] + R[2, 0] * s[0] + R[2, 1] * s[1] + R[2, 2] * s[2])
        if pen > 0.0:
            hz += 0.4 * fpar[F_K] * pen * pen * math.sqrt(pen)
    out[0] = kin
    out[1] = el
    out[2] = m * fpar[F_G] * r[2]
    out[3] = hz
