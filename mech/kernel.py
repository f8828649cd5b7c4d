"""Compiled right-hand side of the floating-frame bar with tip contact and friction.

State layout (3D):     r(3) quat(4) q(n) | V(3) w(3) eta(n) | [armature] | quadratures(NQ)
State layout (planar): x z phi q(n)      | vx vz wy eta(n)  | [armature] | quadratures(NQ)
[armature]: its travel q_a (m or rad) and rate, in models that have one (mech/armature.py);
a model without a bar (an armature alone) is q_a, dq_a/dt | quadratures.
r, V: centre of mass in the world frame (z up, m, m/s); quat: body->world (scalar
first); phi: rotation about world y; w: body angular velocity (rad/s); q, eta: modal
coordinates (m) and speeds (m/s). Quadratures integrate dissipation and contact work
so the energy audit and Stronge's restitution come out of the same integration.

Equations (see docs/mechanics.md for the derivation):
    m dV/dt = F
    [J  B ] [dw/dt  ]   [tau - w x h - dJ/dt w                                    ]
    [B' mI] [deta/dt] = [Q - K q - C eta + 1/2 w' dJ/dq_j w + 2 w . sum_k S_jk eta_k]
with h = J w + B eta. Each contact row is a pair: a contact point of the bar (a sphere of
radius R centred on a material point: an end cap x_i = -+(L/2 - R) on the axis, or a
rivet) and the fixed contact it strikes, a plane z = C_Z facing up (below the bar, as the
block z = 0) or down (above it); the point's penetration, normal force and repulsion act
along that plane's normal. Stick is an exact constraint (zero slip velocity of the contact
point), its force solved each evaluation.

All functions here are numba-compiled; their Python sources (``.py_func``) are the
readable reference and are tested against the compiled versions.
"""

from __future__ import annotations

import math

import numpy as np

from . import (
    armature as _armature, contact_laws as _contact_laws, friction as _friction, rotations as _rotations,
    travel_spring as _travel_spring,
)
from .jit import njit, njit_borrowing
from .inertia import (held_modal_terms, inertia_matrix, inertia_matrix_sparse, inertia_terms, inertia_terms_sparse,
                      schur_complement)
from .kernel_layout import (  # noqa: F401  (re-exported: the kernel's own names)
    F_MASS, F_G, F_K, F_C, F_BETA, F_GAMMA, F_MAX_RATIO, F_RTIP, D_VALUE, D_SLOPE, D_T0, K_MU, K_REPULSION,
    F_VREG, F_BAUM, F_VBOUND, F_PIV_K, F_PIV_C, F_PIV_T0, F_PIV_PHI0, F_PIV_SIGN, C_Z, C_N, MAX_PAIRS,
    quadrature_rows,
    N_FPAR, I_N, I_PLANAR, I_FRICTION, I_MOUNT, I_NLOAD, I_INERTIA, N_IPAR, INERTIA_GRAM,
    INERTIA_SPARSE, FRICTION_NONE, FRICTION_EXACT, FRICTION_REGULARIZED, MOUNT_FREE, MOUNT_CLAMP,
    MOUNT_PIVOT, C_K, C_C, C_R, C_ON, LOAD_FORCE, LOAD_SPRING, LOAD_TRAVEL_SPRING, L_KIND, L_POINT, L_BODY, L_DX,
    L_DY, L_DZ, L_T0, L_TN, L_AX, L_AY, L_AZ, L_K, L_C, L_L0, L_R0, L_KS, L_FLOOR, L_ZBACK, L_S0, L_SN, L_ARM, L_Q0, N_LOAD, FREE, SLIP, STICK,
    Q_DNORMAL, Q_DFRICTION, Q_DMODAL, Q_WCOMP, Q_IMPULSE, Q_WIN, Q_DLOAD, NQ_FREE, NQ, A_Y,
    A_YDOT, A_FN, A_FTX, A_FTY, A_VTX, A_VTY, A_MARGIN, NAUX, EV_CONTACT, EV_CLIP, EV_SLIP,
    EV_STICK, EV_COMPRESSION, NEV_TIP, NEV, EA_REST, EA_POLE, EA_CARD, EA_SEAT, MOUNT_NONE, I_ARMATURE,
    I_ARM_DRIVE,
    I_ARM_CARD, I_ARM_NGAIN, AP_MASS, AP_TRAVEL, AP_RATE, AP_PRELOAD, AP_STOP_K, AP_STOP_C, AP_DAMPING, AP_LEVER,
    AP_FREE, AP_CARD_K, AP_CARD_C, AP_CARD_Z0, AP_HMAX, N_ARM, NEV_ARM, EA_TURN, BAR_HELD,
    state_sizes, armature_offset,
)

# the pure-Python laws and layout, compiled for the loop (their modules stay numba-free)
layout = njit(cache=True)(state_sizes)
arm_offset = njit(cache=True)(armature_offset)
quad_rows = njit(cache=True)(quadrature_rows)
normal_force = njit(cache=True)(_contact_laws.normal_force)
friction_limit = njit(cache=True)(_friction.friction_limit)
regularized_scale = njit(cache=True)(_friction.regularized_scale)
slip_direction = njit(cache=True)(_friction.slip_direction)
scaled_rebound = njit(cache=True)(_contact_laws.scaled_rebound)  # the damping calibration's impact
stop_force = njit(cache=True)(_armature.stop_force)
return_force = njit(cache=True)(_armature.return_force)
travel_force = njit_borrowing(_travel_spring.travel_force)
travel_work = njit_borrowing(_travel_spring.travel_work)
stick_rate = njit(cache=True)(_travel_spring.stick_rate)
gain_at = njit_borrowing(_armature.gain_at)


quat_to_matrix = njit_borrowing(_rotations.quat_to_matrix)


@njit_borrowing
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
def make_work(n):
    """A tuple of scratch arrays for ``dynamics`` (kept out of the hot loop's allocations)."""
    return (
        np.zeros(3), np.zeros((3, 3)), np.zeros(n), np.zeros(3), np.zeros(3), np.zeros(n),  # r R q V w eta
        np.zeros((3, 3)), np.zeros((3, n)), np.zeros((3, 3)),  # J B Ainv
        np.zeros(3), np.zeros(n), np.zeros(3),  # f_r f_e F
        np.zeros(3), np.zeros(n), np.zeros(3),  # wdot etadot Vdot
        # per contact row (at most MAX_PAIRS): s_tip sdot_tip theta_dot_tip (body), vP (world)
        np.zeros((MAX_PAIRS, 3)), np.zeros((MAX_PAIRS, 3)), np.zeros((MAX_PAIRS, 3)),
        np.zeros((MAX_PAIRS, 3)),
        # unit responses wdot etadot Vdot: 2 tangential directions per sticking row
        np.zeros((2 * MAX_PAIRS, 3)), np.zeros((2 * MAX_PAIRS, n)), np.zeros((2 * MAX_PAIRS, 3)),
        # small vectors: a point force and moment (0-2, 3-5), an armature's terms (6-10), a
        # load or card point's world position and velocity (12-14, 15-17); Schur complement
        np.zeros(18), np.zeros((3, 3)),
    )


@njit_borrowing
def frame_still(mount, w):
    """Whether the bar's frame does not turn: a clamped bar (the clamp gives it no angular
    acceleration; a scene cannot start it turning). Its inertia terms are then -K q - C eta
    and its kinetic energy has no w J w or w B eta: every other term is an exact zero
    (dynamics, energies)."""
    return mount == MOUNT_CLAMP and w[0] == 0.0 and w[1] == 0.0 and w[2] == 0.0


@njit_borrowing
def drive_at(t, drive, row):
    """Value of the drive channel in row ``row`` at t (s): linear in time within a step."""
    return drive[row, D_VALUE] + drive[row, D_SLOPE] * (t - drive[row, D_T0])


@njit_borrowing
def mu_at(t, drive, row):
    """N^gamma: the friction coefficient in drive row ``row`` at t (s), clipped at zero."""
    mu = drive_at(t, drive, row)
    return mu if mu > 0.0 else 0.0


@njit_borrowing
def _add_force_at(p, s0, s1, s2, Fw, Mw, R, psi, theta, n, F, f_r, f_e):
    """Generalized forces of world force Fw at point p (body position s) plus world moment Mw."""
    for a in range(3):
        F[a] += Fw[a]
    # body components: Fb = R^T Fw, Mb = R^T Mw
    fb0 = R[0, 0] * Fw[0] + R[1, 0] * Fw[1] + R[2, 0] * Fw[2]
    fb1 = R[0, 1] * Fw[0] + R[1, 1] * Fw[1] + R[2, 1] * Fw[2]
    fb2 = R[0, 2] * Fw[0] + R[1, 2] * Fw[1] + R[2, 2] * Fw[2]
    mb0 = R[0, 0] * Mw[0] + R[1, 0] * Mw[1] + R[2, 0] * Mw[2]
    mb1 = R[0, 1] * Mw[0] + R[1, 1] * Mw[1] + R[2, 1] * Mw[2]
    mb2 = R[0, 2] * Mw[0] + R[1, 2] * Mw[1] + R[2, 2] * Mw[2]
    f_r[0] += s1 * fb2 - s2 * fb1 + mb0
    f_r[1] += s2 * fb0 - s0 * fb2 + mb1
    f_r[2] += s0 * fb1 - s1 * fb0 + mb2
    for j in range(n):
        f_e[j] += (psi[p, j, 0] * fb0 + psi[p, j, 1] * fb1 + psi[p, j, 2] * fb2
                   + theta[p, j, 0] * mb0 + theta[p, j, 1] * mb1 + theta[p, j, 2] * mb2)


@njit_borrowing
def _add_point_force(i, Fw, Mw, R, s_tip, psi, theta, n, F, f_r, f_e):
    """Generalized forces of world force Fw at contact cap centre i plus world moment Mw."""
    _add_force_at(i, s_tip[i, 0], s_tip[i, 1], s_tip[i, 2], Fw, Mw, R, psi, theta, n, F, f_r, f_e)


@njit_borrowing
def load_point_motion(p, xc, psi, r, R, q, V, w, eta, n, x, v):
    """World position x (m) and velocity v (m/s) of load point p; returns nothing."""
    s0 = xc[p, 0]
    s1 = xc[p, 1]
    s2 = xc[p, 2]
    d0 = 0.0
    d1 = 0.0
    d2 = 0.0
    for j in range(n):
        s0 += psi[p, j, 0] * q[j]
        s1 += psi[p, j, 1] * q[j]
        s2 += psi[p, j, 2] * q[j]
        d0 += psi[p, j, 0] * eta[j]
        d1 += psi[p, j, 1] * eta[j]
        d2 += psi[p, j, 2] * eta[j]
    vb0 = w[1] * s2 - w[2] * s1 + d0
    vb1 = w[2] * s0 - w[0] * s2 + d1
    vb2 = w[0] * s1 - w[1] * s0 + d2
    for a in range(3):
        x[a] = r[a] + R[a, 0] * s0 + R[a, 1] * s1 + R[a, 2] * s2
        v[a] = V[a] + R[a, 0] * vb0 + R[a, 1] * vb1 + R[a, 2] * vb2
    return s0, s1, s2


@njit_borrowing
def anchor_height(ld, load, qa):
    """m: world z of spring ``ld``'s anchor end, for the armature at q = qa when the end is
    on it (moved down by its lever times q - q0), else fixed."""
    if load[ld, L_ARM] != 0.0:
        return load[ld, L_AZ] - load[ld, L_ARM] * (qa - load[ld, L_Q0])
    return load[ld, L_AZ]


@njit_borrowing
def spring_length(ld, load, x, qa=0.0):
    """Length (m) of spring ``ld`` with its bar end at world point x (the armature at q = qa)."""
    d0 = x[0] - load[ld, L_AX]
    d1 = x[1] - load[ld, L_AY]
    d2 = x[2] - anchor_height(ld, load, qa)
    return math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)


@njit_borrowing
def _load_force(t, ld, load, tabs, r, R, q, V, w, eta, psi, theta, xc, n, F, f_r, f_e, Fw, Mw, x, v, y, dy,
                qa=0.0, va=0.0):
    """Add load ``ld`` (actuator force, spring-dashpot or force-travel spring) to the
    generalized forces; a spring with hysteresis writes its stick force's rate into dy.
    qa, va: the armature's q and rate (a spring whose anchor end it carries); x, v (3,):
    scratch for the load point's world position and velocity.

    Returns (power the actuator puts in, W; power the dashpot and the hysteresis dissipate,
    W; the spring's reaction on the armature along q, N or N m: lever times the world z of
    its force on the bar, 0 for a load on the frame).
    """
    p = int(load[ld, L_POINT])
    s0, s1, s2 = load_point_motion(p, xc, psi, r, R, q, V, w, eta, n, x, v)
    Mw[0] = 0.0
    Mw[1] = 0.0
    Mw[2] = 0.0
    p_in = 0.0
    p_diss = 0.0
    if load[ld, L_KIND] == LOAD_FORCE:
        mag = table_value(tabs, int(load[ld, L_T0]), int(load[ld, L_TN]), t)
        d0 = load[ld, L_DX]
        d1 = load[ld, L_DY]
        d2 = load[ld, L_DZ]
        if load[ld, L_BODY] != 0.0:
            for a in range(3):
                Fw[a] = mag * (R[a, 0] * d0 + R[a, 1] * d1 + R[a, 2] * d2)
        else:
            if load[ld, L_SN] > 0.0:  # follows its travel along d (world frame only)
                mag *= table_value(tabs, int(load[ld, L_S0]), int(load[ld, L_SN]),
                                   d0 * x[0] + d1 * x[1] + d2 * x[2] - load[ld, L_L0])
            Fw[0] = mag * d0
            Fw[1] = mag * d1
            Fw[2] = mag * d2
        p_in = Fw[0] * v[0] + Fw[1] * v[1] + Fw[2] * v[2]
    else:
        length = spring_length(ld, load, x, qa)
        if length > 0.0:
            e0 = (x[0] - load[ld, L_AX]) / length
            e1 = (x[1] - load[ld, L_AY]) / length
            e2 = (x[2] - anchor_height(ld, load, qa)) / length
        else:
            e0 = 0.0
            e1 = 0.0
            e2 = 0.0
        ldot = v[0] * e0 + v[1] * e1 + v[2] * e2
        if load[ld, L_ARM] != 0.0:  # the anchor end moves down with the armature at lever x va
            ldot += load[ld, L_ARM] * va * e2
        if load[ld, L_KIND] == LOAD_SPRING:
            f = -(load[ld, L_K] * (length - load[ld, L_L0]) + load[ld, L_C] * ldot)
        else:
            x_t = load[ld, L_L0] - length
            t0 = int(load[ld, L_T0])
            tn = int(load[ld, L_TN])
            f = travel_force(x_t, tabs, t0, tn)
            back = int(load[ld, L_ZBACK])
            if back > 0:  # the branches' mean plus the stick force (mech/travel_spring.py)
                release = travel_force(x_t, tabs, int(load[ld, L_R0]), tn)
                zi = y.shape[0] - back
                z = y[zi]
                ks = load[ld, L_KS]
                zdot = stick_rate(z, -ldot, 0.5 * (f - release), load[ld, L_FLOOR], ks)
                dy[zi] = zdot
                p_diss += z * (-ldot - zdot / ks)
                f = 0.5 * (f + release) + z
            f -= load[ld, L_C] * ldot
        Fw[0] = f * e0
        Fw[1] = f * e1
        Fw[2] = f * e2
        p_diss += load[ld, L_C] * ldot * ldot
    _add_force_at(p, s0, s1, s2, Fw, Mw, R, psi, theta, n, F, f_r, f_e)
    # the reaction -Fw on the anchor end, which moves by (0, 0, -lever) per unit of q
    return p_in, p_diss, load[ld, L_ARM] * Fw[2]


@njit_borrowing
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


@njit_borrowing
def _add_rotational_coupling(n, m, w, eta, cL, Jm, B, f_r, Amat, Ainv):
    """Add a held bar's H_j (cL[:, n+1:], kg m) to B(q): the angular momentum gains H eta,
    f_r = -w x h - dJ/dt w gains -w x (H eta), and the Schur complement J - B B'/m is redone.
    (H only moves h: its q-independence leaves the modal forces as they are.)"""
    h0 = 0.0
    h1 = 0.0
    h2 = 0.0
    for j in range(n):
        B[0, j] += cL[0, n + 1 + j]
        B[1, j] += cL[1, n + 1 + j]
        B[2, j] += cL[2, n + 1 + j]
        h0 += cL[0, n + 1 + j] * eta[j]
        h1 += cL[1, n + 1 + j] * eta[j]
        h2 += cL[2, n + 1 + j] * eta[j]
    f_r[0] -= w[1] * h2 - w[2] * h1
    f_r[1] -= w[2] * h0 - w[0] * h2
    f_r[2] -= w[0] * h1 - w[1] * h0
    schur_complement(n, m, Jm, B, Amat, Ainv)


@njit_borrowing
def _solve_mounted(mount, F, f_r, f_e, Ainv, B, m, n, Vdot, wdot, etadot):
    """Accelerations from generalized forces for the bar as held by ``mount``.

    free: m dV/dt = F and the rotation/modal block; pivot: the frame origin stays put, the
    rotation/modal block as for the free bar (planar: only w_y moves); clamp: the frame
    moves with the base (no acceleration between base breakpoints), only the modes move.
    """
    if mount == MOUNT_FREE:
        for a in range(3):
            Vdot[a] = F[a] / m
    else:
        for a in range(3):
            Vdot[a] = 0.0
    if mount == MOUNT_CLAMP:
        for a in range(3):
            wdot[a] = 0.0
        for j in range(n):
            etadot[j] = f_e[j] / m
    else:
        _solve_accel(f_r, f_e, Ainv, B, m, n, wdot, etadot)


@njit_borrowing
def table_value(tabs, start, count, t):
    """Linear interpolation in a time table stored as tabs[0, start:start+count] (times,
    s) and tabs[1, ...] (values); constant beyond its ends."""
    if count == 1 or t <= tabs[0, start]:
        return tabs[1, start]
    last = start + count - 1
    if t >= tabs[0, last]:
        return tabs[1, last]
    lo = start
    hi = last
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if tabs[0, mid] <= t:
            lo = mid
        else:
            hi = mid
    f = (t - tabs[0, lo]) / (tabs[0, hi] - tabs[0, lo])
    return tabs[1, lo] + f * (tabs[1, hi] - tabs[1, lo])


@njit_borrowing
def _tip_accel(k, R, s_tip, psi, theta, n, Rtip, Vdot, wdot, etadot, out):
    """World acceleration of contact row k's contact point from (Vdot, wdot, etadot), no
    velocity terms; Rtip: the point's signed offset from the cap's centre along -z (the
    cap's radius times its fixed contact's normal, C_N)."""
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


@njit_borrowing
def armature_terms(t, qa, va, pen_card, pen_card_rate, ipar, apar, again, closed, drive, out):
    """The armature's generalized force and powers, into out (4,): the force along q (N, or
    N m for a clapper: the drive times the gain table, the return spring, the viscous
    damping, the stops and the card's reaction), the card's force on the bar (N, >= 0,
    along world -z at its point), the drive's power (W) and the power the dashpots of the
    stops and card and the viscous damping dissipate (W).

    qa, va: q (m or rad) and its rate; pen_card (m): how far the card has pressed past the
    bar's point, and its rate (m/s) (0 without a card). closed (3,): 1.0 for each of the
    rest stop, pole stop and card (kernel_layout EA_*) the solver has found closed; an
    open one exerts nothing, whatever its penetration inside a step."""
    row = ipar[I_ARM_DRIVE]
    f_drive = drive_at(t, drive, row) * gain_at(qa, again, ipar[I_ARM_NGAIN])
    c_v = apar[AP_DAMPING]
    f = f_drive - return_force(qa, apar[AP_RATE], apar[AP_PRELOAD]) - c_v * va
    d = c_v * va * va
    k = apar[AP_STOP_K]
    if closed[EA_REST] != 0.0 and qa < 0.0:  # on the rest stop, penetration -q
        fs = stop_force(-qa, -va, k, apar[AP_STOP_C])
        f += fs
        d += (fs + k * qa) * (-va)
    pen = qa - apar[AP_TRAVEL]
    if closed[EA_POLE] != 0.0 and pen > 0.0:  # on the pole stop
        fs = stop_force(pen, va, k, apar[AP_STOP_C])
        f -= fs
        d += (fs - k * pen) * va
    fc = 0.0
    if ipar[I_ARM_CARD] >= 0 and closed[EA_CARD] != 0.0 and pen_card > 0.0:
        kc = apar[AP_CARD_K]
        fc = stop_force(pen_card, pen_card_rate, kc, apar[AP_CARD_C])
        f -= apar[AP_LEVER] * fc
        d += (fc - kc * pen_card) * pen_card_rate
    out[0] = f
    out[1] = fc
    out[2] = f_drive * va
    out[3] = d


@njit(cache=True)
def armature_force(t, y, mdl, arm):
    """N (N m for a clapper): the force on the armature along q at t (s) in state y, of
    everything but its stops: the drive times the gain, the return spring, the viscous
    damping and the card's reaction. Seated on a stop, this presses it there (towards the
    pole: the pole stop; its negative: the rest stop). arm: the model's armature arrays."""
    ipar, psi, xc, drive = mdl[1], mdl[6], mdl[8], mdl[14]
    apar, again, aclosed = arm
    n = ipar[I_N]
    planar = ipar[I_PLANAR]
    off = arm_offset(n, planar, ipar[I_MOUNT])
    qa = y[off]
    va = y[off + 1]
    load, tabs, theta = mdl[11], mdl[12], mdl[7]
    pc = ipar[I_ARM_CARD]
    carried = False  # springs the armature carries (L_ARM): their reaction is on it too
    for ld in range(ipar[I_NLOAD]):
        carried = carried or load[ld, L_ARM] != 0.0
    r = np.empty(3)
    R = np.empty((3, 3))
    q = np.empty(n)
    V = np.empty(3)
    w = np.empty(3)
    eta = np.empty(n)
    if pc >= 0 or carried:  # (both need the bar's state; an armature alone has none)
        unpack(y, n, planar, r, R, q, V, w, eta)
    pen_c = 0.0
    rate_c = 0.0
    if pc >= 0:
        x = np.empty(3)
        v = np.empty(3)
        load_point_motion(pc, xc, psi, r, R, q, V, w, eta, n, x, v)
        pen_c, rate_c = card_penetration(qa, va, x[2], v[2], apar)
    open_stops = np.zeros(NEV_ARM)
    open_stops[EA_CARD] = aclosed[EA_CARD]
    terms = np.empty(4)
    armature_terms(t, qa, va, pen_c, rate_c, ipar, apar, again, open_stops, drive, terms)
    f = terms[0]
    if carried:
        dy = np.empty(y.shape[0])
        for ld in range(ipar[I_NLOAD]):
            if load[ld, L_ARM] != 0.0:
                _, _, f_l = _load_force(t, ld, load, tabs, r, R, q, V, w, eta, psi, theta, xc, n, np.zeros(3),
                                        np.zeros(3), np.zeros(n), np.zeros(3), np.zeros(3), np.empty(3),
                                        np.empty(3), y, dy, qa, va)
                f += f_l
    return f


@njit_borrowing
def card_penetration(qa, va, z, vz, apar):
    """(m, m/s): how far the card has pressed past the bar's card point, and its rate. The card
    hangs card_free_travel above the point's height at the start (AP_CARD_Z0) when q = 0
    and moves down (world -z) by lever x q; z, vz: the point's world height (m) and rate."""
    return apar[AP_LEVER] * qa - apar[AP_FREE] - (apar[AP_CARD_Z0] - z), apar[AP_LEVER] * va + vz


@njit_borrowing
def _armature_alone(t, y, ipar, arm, drive, dy, aux, sv):
    """dynamics of a model without a bar: the armature's two states, its quadratures (the
    drive's work, the dissipation), its terms into sv[6:11] as beside a bar
    (_armature_on_bar), and the contact rows of aux switched off."""
    apar, again, closed = arm
    for i in range(aux.shape[0]):
        for c_ in range(NAUX):
            aux[i, c_] = 0.0
        aux[i, A_Y] = -1e3
    terms = sv[6:10]
    armature_terms(t, y[0], y[1], 0.0, 0.0, ipar, apar, again, closed, drive, terms)
    sv[10] = 0.0
    if closed[EA_SEAT] != 0.0:  # seated on its stop: held there
        dy[0] = 0.0
        dy[1] = 0.0
    else:
        dy[0] = y[1]
        dy[1] = terms[0] / apar[AP_MASS]
    for k in range(N_ARM, dy.shape[0]):
        dy[k] = 0.0
    dy[N_ARM + Q_WIN] = terms[2]
    dy[N_ARM + Q_DLOAD] = terms[3]


@njit_borrowing
def _armature_on_bar(t, y, n, planar, mount, ipar, arm, drive, xc, psi, theta,
                     r, R, q, V, w, eta, F, f_r, f_e, Fw, Mw, sv):
    """The armature beside a bar (dynamics): its terms into sv[6:10] (armature_terms) and the
    card's penetration into sv[10] (for the events: mech.integrator.armature_events), its
    card's force on the bar's point (down, world -z) into the bar's generalized forces.
    Returns (the drive's power, the dissipated power), W."""
    apar, again, aclosed = arm
    off = arm_offset(n, planar, mount)
    qa = y[off]
    va = y[off + 1]
    pc = ipar[I_ARM_CARD]
    pen_c = 0.0
    pen_c_rate = 0.0
    s0 = 0.0
    s1 = 0.0
    s2 = 0.0
    if pc >= 0:
        xcard = sv[12:15]
        vcard = sv[15:18]
        s0, s1, s2 = load_point_motion(pc, xc, psi, r, R, q, V, w, eta, n, xcard, vcard)
        pen_c, pen_c_rate = card_penetration(qa, va, xcard[2], vcard[2], apar)
    terms = sv[6:10]
    armature_terms(t, qa, va, pen_c, pen_c_rate, ipar, apar, again, aclosed, drive, terms)
    sv[10] = pen_c
    if terms[1] > 0.0:
        Fw[0] = 0.0
        Fw[1] = 0.0
        Fw[2] = -terms[1]
        Mw[0] = 0.0
        Mw[1] = 0.0
        Mw[2] = 0.0
        _add_force_at(pc, s0, s1, s2, Fw, Mw, R, psi, theta, n, F, f_r, f_e)
    return terms[2], terms[3]


@njit_borrowing
def _armature_rates(y, base, arm, sv, dy):
    """The armature's two rates into dy[base:base + 2] (its force in sv[6], _armature_on_bar);
    held while seated."""
    apar, _, aclosed = arm
    if aclosed[EA_SEAT] != 0.0:
        dy[base] = 0.0
        dy[base + 1] = 0.0
    else:
        dy[base] = y[base + 1]
        dy[base + 1] = sv[6] / apar[AP_MASS]


@njit_borrowing
def dynamics(t, y, mdl, regime, eref, dy, aux, work, arm=None):
    """Time derivative of the state into ``dy``; per-contact-row quantities into ``aux`` (rows, NAUX).

    mdl: the model arrays and, last, the drive (model.BarModel.kernel_arrays: each contact
    point's friction coefficient and repulsion and the armature's force over time, set by
    the caller, found through the model's index array cdrive and ipar[I_ARM_DRIVE]; the
    model's arrays never change). regime: (rows,) FREE/SLIP/STICK per
    contact row (friction bookkeeping; the normal force always follows the
    penetration). eref: (rows, 2) reference slip direction per contact row.
    arm: None, or the armature's arrays (model.BarModel.kernel_armature: its parameters
    AP_*, its gain table, its contacts' states EA_*). An argument of its own, not in mdl:
    numba compiles the kernel once for None, where every armature branch is removed
    before the code is generated, so a model without an armature runs the code it ran
    before the armature existed (measured: in mdl, the same branches, never taken, made
    the default scene's run 10 % slower).
    """
    fpar, ipar, J0, sp_ptr, sp_idx, sp_val, psi, theta, xc, cpar, cL, load, tabs, cdrive, drive = mdl
    if arm is not None:
        if ipar[I_MOUNT] == MOUNT_NONE:
            _armature_alone(t, y, ipar, arm, drive, dy, aux, work[22])
            return
    n = ipar[I_N]
    planar = ipar[I_PLANAR]
    fmodel = ipar[I_FRICTION]
    mount = ipar[I_MOUNT]
    (r, R, q, V, w, eta, Jm, B, Ainv, f_r, f_e, F, wdot, etadot, Vdot,
     s_tip, sd_tip, th_tip, vP, u_wdot, u_etadot, u_Vdot, sv, Amat) = work
    unpack(y, n, planar, r, R, q, V, w, eta)
    m = fpar[F_MASS]
    beta = fpar[F_BETA]

    # Inertia, centrifugal, gyroscopic, stiffness and damping terms (mech/inertia.py):
    # the Gram-product route for the analytic free-free basis, the sparse-list route for a
    # finite-element basis (its families are orthogonal in the full mass, rivets' rotary
    # inertia included, not in the plain product the Gram route relies on); a bar whose
    # frame does not turn needs only their stiffness and damping terms
    if frame_still(mount, w):
        d_modal = held_modal_terms(n, q, eta, sp_ptr, sp_idx, sp_val, f_e, f_r, sv)
    else:
        if ipar[I_INERTIA] == INERTIA_GRAM:
            d_modal = inertia_terms(n, m, q, eta, w, J0, sp_ptr, sp_idx, sp_val, Jm, B, f_e, sv, f_r, Amat, Ainv)
        else:
            d_modal = inertia_terms_sparse(n, m, q, eta, w, J0, sp_ptr, sp_idx, sp_val, Jm, B, f_e, sv, f_r,
                                           Amat, Ainv)
        if mount != MOUNT_FREE:
            _add_rotational_coupling(n, m, w, eta, cL, Jm, B, f_r, Amat, Ainv)
    F[0] = 0.0
    F[1] = 0.0
    F[2] = -m * fpar[F_G]
    # Gravity on the rotation and the modes through the first moments about the frame
    # origin (c + L q: zero for a free bar about its centroid with free-free modes).
    gb0 = -fpar[F_G] * R[2, 0]
    gb1 = -fpar[F_G] * R[2, 1]
    gb2 = -fpar[F_G] * R[2, 2]
    c0 = cL[0, 0]
    c1 = cL[1, 0]
    c2 = cL[2, 0]
    for j in range(n):
        c0 += cL[0, j + 1] * q[j]
        c1 += cL[1, j + 1] * q[j]
        c2 += cL[2, j + 1] * q[j]
        f_e[j] += cL[0, j + 1] * gb0 + cL[1, j + 1] * gb1 + cL[2, j + 1] * gb2
    f_r[0] += c1 * gb2 - c2 * gb1
    f_r[1] += c2 * gb0 - c0 * gb2
    f_r[2] += c0 * gb1 - c1 * gb0
    d_load = 0.0
    if mount == MOUNT_PIVOT:
        # torsion spring and damper about the hinge (body y): the preload turns the free
        # end towards the block (F_PIV_SIGN: the sense of that turn in phi)
        sg = fpar[F_PIV_SIGN]
        th = sg * (y[2] - fpar[F_PIV_PHI0])
        thd = sg * w[1]
        f_r[1] += sg * (fpar[F_PIV_T0] - fpar[F_PIV_K] * th - fpar[F_PIV_C] * thd)
        d_load += fpar[F_PIV_C] * thd * thd
    gam = fpar[F_GAMMA]
    maxr = fpar[F_MAX_RATIO]
    d_normal = 0.0
    d_friction = 0.0
    w_drive = 0.0  # power of the driven forces on the contact points (repulsion), W
    n_stick = 0
    Fw = sv[0:3]
    Mw = sv[3:6]
    rows = cpar.shape[0]
    for i in range(rows):
        if cpar[i, C_ON] == 0.0:
            # no such contact point: a far gap that never closes
            for c_ in range(NAUX):
                aux[i, c_] = 0.0
            aux[i, A_Y] = -1e3
            for a in range(3):
                s_tip[i, a] = 0.0
                vP[i, a] = 0.0
            continue
        k_h = cpar[i, C_K]
        c_h = cpar[i, C_C]
        Rtip = cpar[i, C_R]
        sg = cpar[i, C_N]  # the fixed contact's normal: +1 facing up, -1 facing down
        rs = sg * Rtip  # the contact point: the cap's centre + (0, 0, -rs)
        # cap centre: body position, velocity; section rotation rate
        s_tip[i, 0] = xc[i, 0]
        s_tip[i, 1] = xc[i, 1]
        s_tip[i, 2] = xc[i, 2]
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
        # contact point P = centre + (0, 0, -rs): v_P = v_c + Omega x (0, 0, -rs)
        vP[i, 0] = vc0 - ow1 * rs
        vP[i, 1] = vc1 + ow0 * rs
        vP[i, 2] = vc2
        pen = Rtip - sg * (zc - cpar[i, C_Z])
        pdot = -sg * vc2
        fn = normal_force(pen, pdot, k_h, c_h, beta)
        aux[i, A_Y] = pen
        aux[i, A_YDOT] = pdot
        aux[i, A_FN] = fn
        aux[i, A_FTX] = 0.0
        aux[i, A_FTY] = 0.0
        aux[i, A_VTX] = vP[i, 0]
        aux[i, A_VTY] = vP[i, 1]
        lim = 0.0
        if fmodel != FRICTION_NONE:
            lim = friction_limit(fn, mu_at(t, drive, cdrive[i, K_MU]), gam, maxr)
        aux[i, A_MARGIN] = lim
        if pen > 0.0:
            d_normal += (fn - k_h * pen * math.sqrt(pen)) * pdot
        if fn > 0.0:
            Fw[0] = 0.0
            Fw[1] = 0.0
            Fw[2] = sg * fn
            Mw[0] = 0.0
            Mw[1] = 0.0
            Mw[2] = 0.0
            _add_point_force(i, Fw, Mw, R, s_tip, psi, theta, n, F, f_r, f_e)
            ftx = 0.0
            fty = 0.0
            if fmodel == FRICTION_EXACT and regime[i] == SLIP:
                # Friction opposes the slip velocity; below the speed resolution (F_VREG:
                # solver.stick_velocity_tol) its direction blends from the reference
                # direction, and past the reference (only in trial stages of a step that
                # crosses the slip event) it is mirrored about it, so a stop keeps friction
                # along the reference and the slip speed goes through zero for the event to
                # see (mech/friction.py slip_direction)
                dxs, dys = slip_direction(vP[i, 0], vP[i, 1], eref[i, 0], eref[i, 1], fpar[F_VREG])
                ftx = -lim * dxs
                fty = -lim * dys
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
                # moment of the friction force about the sphere centre: (0,0,-rs) x Ft
                Mw[0] = rs * fty
                Mw[1] = -rs * ftx
                Mw[2] = 0.0
                _add_point_force(i, Fw, Mw, R, s_tip, psi, theta, n, F, f_r, f_e)
                aux[i, A_FTX] = ftx
                aux[i, A_FTY] = fty
                d_friction -= ftx * vP[i, 0] + fty * vP[i, 1]
                aux[i, A_MARGIN] = lim - math.sqrt(ftx * ftx + fty * fty)
        if pen > 0.0:
            # a driven force on the touching contact point along its fixed contact's normal,
            # away from it (Holm's electrodynamic repulsion of the constriction): it acts
            # through the contact point, so it has no moment about the cap centre; its power
            # is work put in (Q_WIN)
            rep = drive_at(t, drive, cdrive[i, K_REPULSION])
            if rep != 0.0:
                Fw[0] = 0.0
                Fw[1] = 0.0
                Fw[2] = sg * rep
                Mw[0] = 0.0
                Mw[1] = 0.0
                Mw[2] = 0.0
                _add_point_force(i, Fw, Mw, R, s_tip, psi, theta, n, F, f_r, f_e)
                w_drive += Fw[2] * vP[i, 2]

    w_in = w_drive
    nload = ipar[I_NLOAD]
    qa = 0.0
    va = 0.0
    if arm is not None:
        off = arm_offset(n, planar, mount)
        qa = y[off]
        va = y[off + 1]
    f_arm = 0.0  # the reaction on the armature of the springs it carries
    for ld in range(nload):
        w_in_l, d_l, f_l = _load_force(t, ld, load, tabs, r, R, q, V, w, eta, psi, theta, xc, n, F, f_r, f_e,
                                       Fw, Mw, sv[12:15], sv[15:18], y, dy, qa, va)
        w_in += w_in_l
        d_load += d_l
        f_arm += f_l

    if arm is not None:
        w_arm, d_arm = _armature_on_bar(t, y, n, planar, mount, ipar, arm, drive, xc, psi, theta,
                                        r, R, q, V, w, eta, F, f_r, f_e, Fw, Mw, sv)
        w_in += w_arm
        d_load += d_arm
        sv[6] += f_arm

    _solve_mounted(mount, F, f_r, f_e, Ainv, B, m, n, Vdot, wdot, etadot)

    if n_stick > 0:
        _apply_stick(fpar, n, planar, mount, R, w, eta, s_tip, sd_tip, th_tip, vP, regime, aux,
                     psi, theta, Ainv, B, m, cpar, Vdot, wdot, etadot, u_Vdot, u_wdot, u_etadot)

    if mount == MOUNT_CLAMP:
        # power of the clamp's reaction on the bar: (dP/dt - F) . V_base with the
        # momentum P = m V + R (L eta) (the clamp does not turn)
        for a in range(3):
            ra = -F[a]
            for j in range(n):
                ra += (R[a, 0] * cL[0, j + 1] + R[a, 1] * cL[1, j + 1] + R[a, 2] * cL[2, j + 1]) * etadot[j]
            w_in += ra * V[a]

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
    if arm is not None:
        if arm[2].shape[0] > BAR_HELD and arm[2][BAR_HELD] != 0.0:
            # held at rest in flight (its speeds zero, its accelerations the static
            # equilibrium's residue): the bar's modes then set no step, the armature's do
            for k in range(base):
                dy[k] = 0.0
        _armature_rates(y, base, arm, sv, dy)
        base += N_ARM
    dy[base + Q_DNORMAL] = d_normal
    dy[base + Q_DFRICTION] = d_friction
    dy[base + Q_DMODAL] = d_modal
    if dy.shape[0] >= base + NQ:
        dy[base + Q_WIN] = w_in
        dy[base + Q_DLOAD] = d_load
    for i in range(rows):
        p = aux[i, A_FN] * aux[i, A_YDOT]
        q_comp, q_rest, q_imp = quad_rows(i)
        dy[base + q_comp] = p if p > 0.0 else 0.0
        dy[base + q_rest] = p if p < 0.0 else 0.0
        dy[base + q_imp] = aux[i, A_FN]


@njit(cache=True)
def _sticking_tips(regime, aux):
    tips = np.empty(regime.shape[0], np.int64)
    ns = 0
    for i in range(regime.shape[0]):
        if regime[i] == STICK and aux[i, A_FN] > 0.0:
            tips[ns] = i
            ns += 1
    return tips, ns


@njit(cache=True)
def symmetric_eigen(A):
    """(eigenvalues, eigenvectors as columns) of a small symmetric matrix, by cyclic Jacobi
    rotations. Why not np.linalg.eigh or lstsq (or a matrix product): numba reaches LAPACK
    and BLAS through SciPy, whose import (~0.2 s) a run of a few milliseconds of work should
    not pay; the stick matrices here are at most 4 x 4, where Jacobi converges in a few
    sweeps to round-off."""
    n = A.shape[0]
    a = A.copy()
    v = np.eye(n)
    scale = 0.0
    for i in range(n):
        for j in range(n):
            scale += a[i, j] * a[i, j]
    for _sweep in range(50):
        off = 0.0
        for i in range(n):
            for j in range(i + 1, n):
                off += a[i, j] * a[i, j]
        if off <= 1e-32 * scale:
            break
        for p in range(n):
            for q in range(p + 1, n):
                if a[p, q] == 0.0:
                    continue
                theta = (a[q, q] - a[p, p]) / (2.0 * a[p, q])
                t = (1.0 if theta >= 0.0 else -1.0) / (abs(theta) + math.sqrt(theta * theta + 1.0))
                c = 1.0 / math.sqrt(t * t + 1.0)
                sn = t * c
                for k in range(n):  # columns p, q of a
                    akp = a[k, p]
                    akq = a[k, q]
                    a[k, p] = c * akp - sn * akq
                    a[k, q] = sn * akp + c * akq
                for k in range(n):  # rows p, q of a
                    apk = a[p, k]
                    aqk = a[q, k]
                    a[p, k] = c * apk - sn * aqk
                    a[q, k] = sn * apk + c * aqk
                for k in range(n):
                    vkp = v[k, p]
                    vkq = v[k, q]
                    v[k, p] = c * vkp - sn * vkq
                    v[k, q] = sn * vkp + c * vkq
    w = np.empty(n)
    for i in range(n):
        w[i] = a[i, i]
    return w, v


@njit(cache=True)
def min_norm_solve(W, rhs):
    """Least-squares, minimum-norm solution of W x = rhs.

    Two stick points of a rigid bar along its axis constrain the same motion: W is then
    singular and the holding forces are statically indeterminate; the minimum-norm
    choice shares them equally (a flexible bar's axial modes make W regular). A rigid bar
    lying on two contacts is that case up to the contacts' height difference dh, which its
    penetrations set: W's smallest singular value over its largest is ~(dh / rho)^2 (rho
    the radius of gyration), and the pitch coupling it carries moves the two slips apart
    by only the pitch rate times dh. The cut-off, 1e-7 (dh < ~3e-4 rho: 27 um on a 0.3 m
    bar), treats such a pair as the colinear one. At 1e-10 the rank decision followed the
    micrometre penetrations of a rigid bar coming to rest from step to step: its holding
    forces jumped between the shared and a huge opposed pair, and 3 million stick/slip
    events took the run nowhere (measured on the 2 deg, 1 mm, e = 0.5, mu = 0.3 drop:
    8145 steps and 363 events to rest with this cut-off).
    """
    s, U = symmetric_eigen(W)
    cut = 1e-7 * max(np.max(np.abs(s)), 1e-300)
    n = W.shape[0]
    x = np.zeros(n)
    for k in range(n):
        if s[k] > cut:
            c = 0.0
            for i in range(n):
                c += U[i, k] * rhs[i]
            for i in range(n):
                x[i] += (c / s[k]) * U[i, k]
    return x


@njit(cache=True)
def _rest_projection_solve(W, rhs, vres):
    """Multipliers lam of the projection W lam = rhs that brings slip speeds below the
    speed resolution vres (m/s, solver.stick_velocity_tol) to zero, restricted to the
    directions it can remove cheaply.

    W = G M^-1 G^T (1/kg); rhs: minus the slip speeds (m/s), each <= vres. Along an
    eigenvector u_k of W (eigenvalue s_k) the projection removes (u_k . rhs)^2 / (2 s_k) of
    kinetic energy. A slip combination the bar can only remove by a large change of its
    motion (s_k near 0: a rigid bar lying on two contacts, whose slip speeds differ by its
    pitch rate times their height difference) is not rest but motion, and is left alone:
    a direction is kept only while its energy is within what a slip at the resolution
    carries, vres^2 / 2 times the sum of the contacts' effective masses 1/W_ii. (A
    least-squares cut-off at 1e-10 kept such a direction: measured, one projection of
    +-3.7e-8 m/s slips on a rigid bar coming to rest changed its pitch rate by 0.04 rad/s
    and removed 1.2e-6 J, five orders above that bound.)
    """
    nc = W.shape[0]
    bound = 0.0
    for i in range(nc):
        if W[i, i] > 0.0:
            bound += vres * vres / W[i, i]
    s, U = symmetric_eigen(W)
    lam = np.zeros(nc)
    for k in range(nc):
        if s[k] <= 0.0:
            continue
        c = 0.0
        for i in range(nc):
            c += U[i, k] * rhs[i]
        if c * c > bound * s[k]:
            continue
        for i in range(nc):
            lam[i] += (c / s[k]) * U[i, k]
    return lam


@njit(cache=True)
def _stick_matrix(n, planar, mount, R, s_tip, psi, theta, Ainv, B, m, cpar, tips, ns, u_Vdot, u_wdot, u_etadot):
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
            Mw[0] = cpar[i, C_N] * cpar[i, C_R] * Fw[1]
            Mw[1] = -cpar[i, C_N] * cpar[i, C_R] * Fw[0]
            Mw[2] = 0.0
            _add_point_force(i, Fw, Mw, R, s_tip, psi, theta, n, Fz, f_r, f_e)
            _solve_mounted(mount, Fz, f_r, f_e, Ainv, B, m, n, u_Vdot[col], u_wdot[col], u_etadot[col])
            for b_k in range(ns):
                k = tips[b_k]
                _tip_accel(k, R, s_tip, psi, theta, n, cpar[k, C_N] * cpar[k, C_R], u_Vdot[col], u_wdot[col],
                           u_etadot[col], acc)
                for d2 in range(ndir):
                    W[b_k * ndir + d2, col] = acc[d2]
    return W


@njit(cache=True)
def _apply_stick(fpar, n, planar, mount, R, w, eta, s_tip, sd_tip, th_tip, vP, regime, aux,
                 psi, theta, Ainv, B, m, cpar, Vdot, wdot, etadot, u_Vdot, u_wdot, u_etadot):
    """Solve the stick constraint forces: tangential acceleration of each sticking contact
    point = -baumgarte * its slip velocity; add their accelerations and record them in aux."""
    tips, ns = _sticking_tips(regime, aux)
    if ns == 0:
        return
    ndir = 1 if planar else 2
    W = _stick_matrix(n, planar, mount, R, s_tip, psi, theta, Ainv, B, m, cpar, tips, ns, u_Vdot, u_wdot, u_etadot)
    rhs = np.zeros(ns * ndir)
    acc = np.zeros(3)
    baum = fpar[F_BAUM]
    # free tangential acceleration incl. velocity-product terms:
    # R (2 w x sdot + w x (w x s)) + (R (w x theta_dot)) x (0, 0, -Rtip)
    for b_k in range(ns):
        k = tips[b_k]
        Rtip = cpar[k, C_N] * cpar[k, C_R]  # (signed: the contact point is the centre + (0, 0, -Rtip))
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
    lam = min_norm_solve(W, rhs)
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
def project_to_stick(t, y, mdl, regime, eref, aux, work, arm=None):
    """Remove the slip velocity of every sticking tip by the smallest change of the speeds
    in the kinetic-energy metric: du = -M^-1 G^T (G M^-1 G^T)^-1 v_t, in the directions a
    slip at rest can be removed in (_rest_projection_solve). Returns the kinetic energy
    change (J, -1/2 lam . W lam); used only when |v_t| is already below the stick tolerance."""
    fpar, ipar, cpar = mdl[0], mdl[1], mdl[9]
    psi, theta = mdl[6], mdl[7]
    n = ipar[I_N]
    planar = ipar[I_PLANAR]
    dy = np.empty(y.shape[0])
    dynamics(t, y, mdl, regime, eref, dy, aux, work, arm)
    (r, R, q, V, w, eta, Jm, B, Ainv, f_r, f_e, F, wdot, etadot, Vdot,
     s_tip, sd_tip, th_tip, vP, u_wdot, u_etadot, u_Vdot, sv, Amat) = work
    tips, ns = _sticking_tips(regime, aux)
    if ns == 0:
        return 0.0
    ndir = 1 if planar else 2
    W = _stick_matrix(n, planar, ipar[I_MOUNT], R, s_tip, psi, theta, Ainv, B, fpar[F_MASS], cpar,
                      tips, ns, u_Vdot, u_wdot, u_etadot)
    rhs = np.zeros(ns * ndir)
    for b_k in range(ns):
        for d in range(ndir):
            rhs[b_k * ndir + d] = -vP[tips[b_k], d]
    lam = _rest_projection_solve(W, rhs, fpar[F_VREG])
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
def armature_energy(qa, va, pen_card, apar, has_card):
    """(kinetic, stored) energy of the armature (J): 1/2 m v^2; the return spring's
    preload q + rate q^2 / 2, the stops' and the card's k pen^2 / 2."""
    k = apar[AP_STOP_K]
    stored = apar[AP_PRELOAD] * qa + 0.5 * apar[AP_RATE] * qa * qa
    if qa < 0.0:
        stored += 0.5 * k * qa * qa
    pen = qa - apar[AP_TRAVEL]
    if pen > 0.0:
        stored += 0.5 * k * pen * pen
    if has_card and pen_card > 0.0:
        stored += 0.5 * apar[AP_CARD_K] * pen_card * pen_card
    return 0.5 * apar[AP_MASS] * va * va, stored


@njit_borrowing
def energies(y, mdl, work, out, arm=None):
    """out = (kinetic, elastic strain, gravity potential, stored Hertz energy, stored
    energy of springs and the pivot's torsion spring incl. its preload), all J; an
    armature's kinetic energy counts in the first, its return spring's, stops' and card's
    stored energy in the last. work: ``make_work``'s scratch (its contents overwritten).

    Kinetic energy about a frame origin that is not the centroid (held bars):
    1/2 m V.V + V . R (w x (c + L q) + L eta) + 1/2 w J w + w B eta + 1/2 m eta.eta.
    """
    fpar, ipar, J0, sp_ptr, sp_idx, sp_val, psi, theta, xc, cpar, cL, load, tabs, cdrive, drive = mdl
    n = ipar[I_N]
    planar = ipar[I_PLANAR]
    if arm is not None and ipar[I_MOUNT] == MOUNT_NONE:
        kin, stored = armature_energy(y[0], y[1], 0.0, arm[0], False)
        out[0] = kin
        out[1] = 0.0
        out[2] = 0.0
        out[3] = 0.0
        out[4] = stored
        return
    r, R, q, V, w, eta, Jm, B = work[0], work[1], work[2], work[3], work[4], work[5], work[6], work[7]
    x = work[22][12:15]  # a point's world position and velocity
    v = work[22][15:18]
    unpack(y, n, planar, r, R, q, V, w, eta)
    m = fpar[F_MASS]
    kin = 0.5 * m * (V[0] ** 2 + V[1] ** 2 + V[2] ** 2)
    if frame_still(ipar[I_MOUNT], w):
        # 1/2 w J w and w B eta add exact zeros: J and B are not formed (the same bits)
        for j in range(n):
            kin += 0.5 * m * eta[j] ** 2
    else:
        if ipar[I_INERTIA] == INERTIA_GRAM:
            inertia_matrix(n, q, J0, sp_ptr, sp_idx, sp_val, Jm, B)
        else:
            inertia_matrix_sparse(n, q, J0, sp_ptr, sp_idx, sp_val, Jm, B)
        for j in range(n):  # H_j, the q-independent coupling of a held bar's modes (0 when free)
            for a in range(3):
                B[a, j] += cL[a, n + 1 + j]
        for a in range(3):
            for b in range(3):
                kin += 0.5 * w[a] * Jm[a, b] * w[b]
        for j in range(n):
            kin += (w[0] * B[0, j] + w[1] * B[1, j] + w[2] * B[2, j]) * eta[j] + 0.5 * m * eta[j] ** 2
    # first moment c + L q and its body rate L eta
    cq0 = cL[0, 0]
    cq1 = cL[1, 0]
    cq2 = cL[2, 0]
    le0 = 0.0
    le1 = 0.0
    le2 = 0.0
    for j in range(n):
        cq0 += cL[0, j + 1] * q[j]
        cq1 += cL[1, j + 1] * q[j]
        cq2 += cL[2, j + 1] * q[j]
        le0 += cL[0, j + 1] * eta[j]
        le1 += cL[1, j + 1] * eta[j]
        le2 += cL[2, j + 1] * eta[j]
    ub0 = w[1] * cq2 - w[2] * cq1 + le0
    ub1 = w[2] * cq0 - w[0] * cq2 + le1
    ub2 = w[0] * cq1 - w[1] * cq0 + le2
    for a in range(3):
        kin += V[a] * (R[a, 0] * ub0 + R[a, 1] * ub1 + R[a, 2] * ub2)
    el = 0.0
    for e in range(sp_ptr[3], sp_ptr[4]):
        el += 0.5 * q[sp_idx[e, 0]] * sp_val[e] * q[sp_idx[e, 1]]
    hz = 0.0
    for i in range(cpar.shape[0]):
        if cpar[i, C_ON] == 0.0:
            continue
        load_point_motion(i, xc, psi, r, R, q, V, w, eta, n, x, v)  # (contact row i is point i)
        pen = cpar[i, C_R] - cpar[i, C_N] * (x[2] - cpar[i, C_Z])
        if pen > 0.0:
            hz += 0.4 * cpar[i, C_K] * pen * pen * math.sqrt(pen)
    sp = 0.0
    qa = 0.0
    if arm is not None:
        qa = y[arm_offset(n, planar, ipar[I_MOUNT])]
    for ld in range(ipar[I_NLOAD]):
        if load[ld, L_KIND] == LOAD_SPRING:
            load_point_motion(int(load[ld, L_POINT]), xc, psi, r, R, q, V, w, eta, n, x, v)
            ext = spring_length(ld, load, x, qa) - load[ld, L_L0]
            sp += 0.5 * load[ld, L_K] * ext * ext
        elif load[ld, L_KIND] == LOAD_TRAVEL_SPRING:
            load_point_motion(int(load[ld, L_POINT]), xc, psi, r, R, q, V, w, eta, n, x, v)
            travel = load[ld, L_L0] - spring_length(ld, load, x, qa)
            t0 = int(load[ld, L_T0])
            tn = int(load[ld, L_TN])
            u = travel_work(travel, tabs, t0, tn) - travel_work(0.0, tabs, t0, tn)
            back = int(load[ld, L_ZBACK])
            if back > 0:  # the branches' mean and the stick spring
                r0 = int(load[ld, L_R0])
                z = y[y.shape[0] - back]
                u = 0.5 * (u + travel_work(travel, tabs, r0, tn) - travel_work(0.0, tabs, r0, tn))
                u += 0.5 * z * z / load[ld, L_KS]
            sp += u
    if ipar[I_MOUNT] == MOUNT_PIVOT:
        th = fpar[F_PIV_SIGN] * (y[2] - fpar[F_PIV_PHI0])
        sp += 0.5 * fpar[F_PIV_K] * th * th - fpar[F_PIV_T0] * th
    if arm is not None:
        apar = arm[0]
        off = arm_offset(n, planar, ipar[I_MOUNT])
        pc = ipar[I_ARM_CARD]
        pen_c = 0.0
        if pc >= 0:
            load_point_motion(pc, xc, psi, r, R, q, V, w, eta, n, x, v)
            pen_c, _ = card_penetration(y[off], y[off + 1], x[2], v[2], apar)
        ka, ua = armature_energy(y[off], y[off + 1], pen_c, apar, pc >= 0)
        kin += ka
        sp += ua
    out[0] = kin
    out[1] = el
    out[2] = fpar[F_G] * (m * r[2] + R[2, 0] * cq0 + R[2, 1] * cq1 + R[2, 2] * cq2)
    out[3] = hz
    out[4] = sp


@njit(cache=True)
def armature_table(Y, mdl, arm):
    """(records, 6) of the state history Y: the armature's q (m or rad), its rate, the
    card's force on the bar (N), the stops' force on the armature (N or N m, positive
    towards the pole: the rest stop's push), the card's penetration past the bar's point
    (m) and its rate (m/s) (0 without a card)."""
    fpar, ipar, J0, sp_ptr, sp_idx, sp_val, psi, theta, xc, cpar, cL, load, tabs, cdrive, _ = mdl
    apar = arm[0]
    n = ipar[I_N]
    planar = ipar[I_PLANAR]
    mount = ipar[I_MOUNT]
    off = arm_offset(n, planar, mount)
    work = make_work(n)
    r, R, q, V, w, eta = work[0], work[1], work[2], work[3], work[4], work[5]
    x = np.empty(3)
    v = np.empty(3)
    out = np.zeros((Y.shape[0], 6))
    pc = ipar[I_ARM_CARD]
    k = apar[AP_STOP_K]
    c = apar[AP_STOP_C]
    for rec in range(Y.shape[0]):
        y = Y[rec]
        qa = y[off]
        va = y[off + 1]
        fc = 0.0
        if pc >= 0:
            unpack(y, n, planar, r, R, q, V, w, eta)
            load_point_motion(pc, xc, psi, r, R, q, V, w, eta, n, x, v)
            pen_c, rate_c = card_penetration(qa, va, x[2], v[2], apar)
            fc = stop_force(pen_c, rate_c, apar[AP_CARD_K], apar[AP_CARD_C])
            out[rec, 4] = pen_c
            out[rec, 5] = rate_c
        out[rec, 0] = qa
        out[rec, 1] = va
        out[rec, 2] = fc
        out[rec, 3] = stop_force(-qa, -va, k, c) - stop_force(qa - apar[AP_TRAVEL], va, k, c)
    return out


@njit(cache=True)
def energy_table(Y, mdl, arm=None):
    """(records, 5): ``energies`` of every row of the state history Y."""
    n = mdl[1][0]
    work = make_work(n)
    out = np.empty((Y.shape[0], 5))
    e = np.empty(5)
    for k in range(Y.shape[0]):
        energies(Y[k], mdl, work, e, arm)
        out[k] = e
    return out
