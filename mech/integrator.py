"""Compiled Dormand-Prince 5(4) loop with dense output and event location.

One call integrates until ``t_stop``, the first event, a full record buffer or a
failure, and returns to Python, which switches regimes and restarts. Events are
located on the 4th-order continuous extension by the Illinois method; the returned
time is the end of the final bracket, so the state is on the new side of the event.

Why compiled: a measurement on this kind of machine gave 40-150 us of Python per solve_ivp step against ~1 us
for this right-hand side; benchmarks/bench_mech.py re-measures the ratio.
"""

from __future__ import annotations

import math

import numpy as np

from .jit import njit, njit_borrowing
from .kernel import (
    A_FN, A_MARGIN, A_VTX, A_VTY, A_Y, A_YDOT, EV_CLIP, EV_COMPRESSION, EV_CONTACT, EV_SLIP, EV_STICK,
    C_C, C_K, C_N, C_ON, C_R, C_Z, F_BETA, F_VBOUND, F_VREG, FRICTION_EXACT, I_FRICTION, I_N, I_PLANAR, NAUX,
    NEV_TIP, SLIP, STICK, AP_HMAX, AP_TRAVEL, EA_CARD, EA_POLE, EA_REST, EA_SEAT, EA_TURN, I_ARM_CARD, I_MOUNT,
    MOUNT_NONE, NEV_ARM, arm_offset, dynamics, load_point_motion, normal_force, unpack,
)
from .friction import REVERSAL_DEADBAND
from .kernel_layout import (  # noqa: F401  (re-exported: the integrator's status codes)
    BUFFER_FULL, DONE, EVENT, MAX_STEPS, NOT_FINITE, STATUS_TEXT, STEP_TOO_SMALL,
)

# Dormand-Prince tableau (Hairer, Norsett & Wanner, Solving ODEs I, Table 5.2).
C2, C3, C4, C5 = 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0
A21 = 1.0 / 5.0
A31, A32 = 3.0 / 40.0, 9.0 / 40.0
A41, A42, A43 = 44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0
A51, A52, A53, A54 = 19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0
A61, A62, A63, A64, A65 = 9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0
A71, A73, A74, A75, A76 = 35.0 / 384.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0
E1, E3, E4, E5, E6, E7 = 71.0 / 57600.0, -71.0 / 16695.0, 71.0 / 1920.0, -17253.0 / 339200.0, 22.0 / 525.0, -1.0 / 40.0
D1, D3, D4 = -12715105075.0 / 11282082432.0, 87487479700.0 / 32700410799.0, -10690763975.0 / 1880347072.0
D5, D6, D7 = 701980252875.0 / 199316789632.0, -1453857185.0 / 822651844.0, 69997945.0 / 29380423.0


@njit_borrowing
def dense_eval(coef, theta, out):
    """State at fraction ``theta`` of a step from its 5 x N continuous-extension coefficients."""
    t1 = 1.0 - theta
    for i in range(coef.shape[1]):
        out[i] = coef[0, i] + theta * (coef[1, i] + t1 * (coef[2, i] + theta * (coef[3, i] + t1 * coef[4, i])))


@njit_borrowing
def _dense_coefficients(y, ynew, h, k1, k3, k4, k5, k6, k7, coef):
    """Continuous-extension coefficients of a step from y to ynew (Hairer's contd5)."""
    for i in range(y.shape[0]):
        coef[0, i] = y[i]
        coef[1, i] = ynew[i] - y[i]
        coef[2, i] = h * k1[i] - coef[1, i]
        coef[3, i] = coef[1, i] - h * k7[i] - coef[2, i]
        coef[4, i] = h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i])


@njit_borrowing
def event_values(y, aux, sv, eref, mdl, g, arm=None):
    """Event function values into g (kernel_layout.event_count of the model's contact rows):
    the contact rows' (events_from_aux) from a dynamics evaluation's aux, then the
    armature's (armature_events) from the state y and what that evaluation left in its
    scratch vector ``sv`` (the dynamics' work[22]); 1 (never crossing) without an armature
    (arm None: kernel.dynamics)."""
    events_from_aux(aux, eref, mdl, g)
    if arm is not None:
        armature_events(y, sv, mdl, arm, g)
    else:
        for k in range(g.shape[0] - NEV_ARM, g.shape[0]):
            g[k] = 1.0


@njit_borrowing
def armature_events(y, sv, mdl, arm, g):
    """The armature's event functions into g[rows NEV_TIP:], each positive while open (1 where
    the model has none of it, never crossing): the rest stop q, the pole stop travel - q
    (-1 while seated on it: held closed), the card's gap to the bar (m); while a stop is
    closed and the armature not seated, its speed (a turn); while seated, the force
    pressing it onto its stop. The card's penetration and the force on the armature are
    those the dynamics evaluation of state y left in sv (kernel._armature_on_bar; seated
    at a stop's surface, the stop itself adds nothing to the force). (Only sv is passed,
    not the dynamics' whole work tuple: a compiled call takes a tuple's arrays one by one.)"""
    ipar = mdl[1]
    apar, _, closed = arm
    nev = g.shape[0]
    base = nev - NEV_ARM
    for k in range(base, nev):
        g[k] = 1.0
    off = arm_offset(ipar[I_N], ipar[I_PLANAR], ipar[I_MOUNT])
    qa = y[off]
    seated = closed[EA_SEAT] != 0.0
    g[base + EA_REST] = -1.0 if seated and closed[EA_REST] != 0.0 else qa
    g[base + EA_POLE] = -1.0 if seated and closed[EA_POLE] != 0.0 else apar[AP_TRAVEL] - qa
    if seated:
        g[base + EA_SEAT] = sv[6] if closed[EA_POLE] != 0.0 else -sv[6]
    elif closed[EA_REST] != 0.0 or closed[EA_POLE] != 0.0:
        g[base + EA_TURN] = y[off + 1]
    if ipar[I_ARM_CARD] >= 0:
        g[base + EA_CARD] = -sv[10]


@njit_borrowing
def events_from_aux(aux, eref, mdl, g):
    """The contact rows' event function values into g[:rows NEV_TIP] from a dynamics
    evaluation's aux."""
    beta = mdl[0][F_BETA]
    vres = mdl[0][F_VREG]
    cpar = mdl[9]
    for i in range(cpar.shape[0]):
        k_h = cpar[i, C_K]
        c_h = cpar[i, C_C]
        pen = aux[i, A_Y]
        pp = pen if pen > 0.0 else 0.0
        g[NEV_TIP * i + EV_CONTACT] = pen
        g[NEV_TIP * i + EV_CLIP] = k_h * pp ** (1.5 - beta) + c_h * aux[i, A_YDOT]
        # the slip stops or reverses past a dead band (mech/friction.py REVERSAL_DEADBAND of the
        # speed resolution F_VREG = solver.stick_velocity_tol), where slip_direction turns to e_ref
        g[NEV_TIP * i + EV_SLIP] = (aux[i, A_VTX] * eref[i, 0] + aux[i, A_VTY] * eref[i, 1]
                                    + REVERSAL_DEADBAND * vres)
        g[NEV_TIP * i + EV_STICK] = aux[i, A_MARGIN]
        g[NEV_TIP * i + EV_COMPRESSION] = aux[i, A_YDOT]


@njit_borrowing
def _active(k, g_old, g_new, regime, fmodel):
    """Whether event k is watched in a step with end values g_old, g_new."""
    if k >= regime.shape[0] * NEV_TIP:
        return True  # the armature's: its stops and card, always (constant where absent)
    i = k // NEV_TIP
    kind = k % NEV_TIP
    if kind == EV_CONTACT:
        return True
    in_contact = g_old[NEV_TIP * i] > 0.0 and g_new[NEV_TIP * i] > 0.0
    if kind == EV_CLIP or kind == EV_COMPRESSION:
        return in_contact
    if fmodel != FRICTION_EXACT or not in_contact:
        return False
    if kind == EV_SLIP:
        return regime[i] == SLIP
    return regime[i] == STICK


@njit_borrowing
def armature_step_bound(arm, hcap):
    """The step bound (s) with the armature's stop or card closed and the armature not seated:
    within the explicit method's accurate range, AP_HMAX = 1 / their highest rate (beyond
    |lambda h| ~ 1 its steps amplify the contact's ringing, which the error estimate then
    holds only at ~100 times the tolerance: a pressed armature lifted off spuriously)."""
    apar, _, closed = arm
    if closed[EA_SEAT] == 0.0 and (closed[EA_REST] != 0.0 or closed[EA_POLE] != 0.0 or closed[EA_CARD] != 0.0):
        if hcap > apar[AP_HMAX]:
            return apar[AP_HMAX]
    return hcap


@njit_borrowing
def _rk_stages(t, y, h, k1, k2, k3, k4, k5, k6, k7, ytmp, ynew, mdl,
               regime, eref, aux_stage, aux_new, work, arm):
    """One Dormand-Prince step of size h from (t, y) with k1 = f(t, y): ynew and the stages;
    k7 = f(t + h, ynew) with its aux in aux_new (first-same-as-last)."""
    N = y.shape[0]
    for i in range(N):
        ytmp[i] = y[i] + h * A21 * k1[i]
    dynamics(t + C2 * h, ytmp, mdl, regime, eref, k2, aux_stage, work, arm)
    for i in range(N):
        ytmp[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i])
    dynamics(t + C3 * h, ytmp, mdl, regime, eref, k3, aux_stage, work, arm)
    for i in range(N):
        ytmp[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i])
    dynamics(t + C4 * h, ytmp, mdl, regime, eref, k4, aux_stage, work, arm)
    for i in range(N):
        ytmp[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i])
    dynamics(t + C5 * h, ytmp, mdl, regime, eref, k5, aux_stage, work, arm)
    for i in range(N):
        ytmp[i] = y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i])
    dynamics(t + h, ytmp, mdl, regime, eref, k6, aux_stage, work, arm)
    for i in range(N):
        ynew[i] = y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i])
    dynamics(t + h, ynew, mdl, regime, eref, k7, aux_new, work, arm)


@njit(cache=True)
def integrate(t, y, t_stop, h, tol, mdl, regime, eref, ev_sign, rec, dense, first, dense_first, room, store_dense,
              max_steps, work, stats, arm=None):
    """Advance y (in place) from t (s) towards t_stop (s), starting with step h (s; 0: choose).

    tol: (hmax s, rtol, atol per component, relmask per component: 1 where rtol applies).
    mdl: the model arrays with the drive (model.BarModel.kernel_arrays); regime and eref:
    the regimes and reference slip directions (read only); ev_sign: the side of each watched
    event function, updated at each accepted step.
    rec: (t, y, aux, fmax) buffers, written from row ``first`` on, ``room`` rows at most;
    dense: (t0, h, coef) likewise from row ``dense_first``, written only with store_dense
    (mech.recorder.Recorder.free_window: the recorder's whole buffers, the same tuples at
    every call, which the Python side's argument check passes by identity, where the
    free rows as views were seven new arrays to check at every segment).
    Returns (status, t, h_next, n_records, event_index); after an event, h_next is the
    step size in use before the step was cut at the event. Every accepted step is recorded
    (time, state, per-tip aux and the largest normal force seen at the step's ends and
    three interior points); with store_dense, also the step's dense-output coefficients.
    stats (int64[4]) accumulates: accepted steps, rejected steps, rhs evaluations, events.
    arm: None, or the armature's arrays (kernel.dynamics: an argument of its own, so that a
    model without an armature runs code compiled without it).
    """
    hmax, rtol, atol, relmask = tol
    # (the free rows as views, cut as Recorder.free_rows cuts them; a slice past a buffer's
    # end ends at it: the one-row dense scratch when the dense output is not kept)
    end = first + room
    rec_t = rec[0][first:end]
    free = (rec_t, rec[1][first:end], rec[2][first:end], rec[3][first:end])
    dense_end = dense_first + room
    free_dense = (dense[0][dense_first:dense_end], dense[1][dense_first:dense_end], dense[2][dense_first:dense_end])
    N = y.shape[0]
    rows = mdl[9].shape[0]  # contact rows
    nev = rows * NEV_TIP + NEV_ARM
    fpar = mdl[0]
    fmodel = mdl[1][I_FRICTION]
    sv = work[22]  # (the dynamics' scratch vector: what the armature's events read)
    k1 = np.empty(N)
    k2 = np.empty(N)
    k3 = np.empty(N)
    k4 = np.empty(N)
    k5 = np.empty(N)
    k6 = np.empty(N)
    k7 = np.empty(N)
    ytmp = np.empty(N)
    ynew = np.empty(N)
    coef = np.empty((5, N))
    aux_stage = np.empty((rows, NAUX))
    aux_old = np.empty((rows, NAUX))
    aux_new = np.empty((rows, NAUX))
    g_old = np.empty(nev)
    g_new = np.empty(nev)
    g_mid = np.empty(nev)
    ymid = np.empty(N)
    yrec = np.empty(N)  # the record's interior states (_record)
    frec = np.empty((rows, 2))
    max_rec = rec_t.shape[0]
    n_rec = 0
    facold = 1e-4

    dynamics(t, y, mdl, regime, eref, k1, aux_old, work, arm)
    stats[2] += 1
    event_values(y, aux_old, sv, eref, mdl, g_old, arm)
    if h <= 0.0:  # initial step from the derivative scale (Hairer's heuristic, simplified)
        d0 = 0.0
        d1 = 0.0
        for i in range(N):
            sc = atol[i] + rtol * relmask[i] * abs(y[i])
            d0 += (y[i] / sc) ** 2
            d1 += (k1[i] / sc) ** 2
        d0 = math.sqrt(d0 / N)
        d1 = math.sqrt(d1 / N)
        h = 0.01 * d0 / d1 if (d0 > 1e-5 and d1 > 1e-5) else 1e-6
        h = min(h, hmax)
    reject = False
    while True:
        if t >= t_stop or t_stop - t <= 4e-16 * max(1.0, abs(t)):
            return DONE, t_stop, h, n_rec, -1  # what is left is below round-off of t
        if n_rec >= max_rec:
            return BUFFER_FULL, t, h, n_rec, -1
        if stats[0] + stats[1] >= max_steps:
            return MAX_STEPS, t, h, n_rec, -1
        # The contact-time bound on the step matters only where a contact point could
        # reach its fixed contact within the step: far from it, it needs gap / v_bound to
        # arrive (v_bound bounds every point's approach speed from the energy available).
        # A switched-off contact row (a held bar with one contact) does not count. (The gap
        # taken is the largest of the rows', as the two-point model always took it: the
        # nearer point's bound is then left to the error control.)
        gap = -aux_old[0, A_Y]
        for i in range(1, rows):
            if mdl[9][i, C_ON] != 0.0 and -aux_old[i, A_Y] > gap:
                gap = -aux_old[i, A_Y]
        hcap = hmax
        if gap > 0.0 and 0.5 * gap / fpar[F_VBOUND] > hmax:
            hcap = 0.5 * gap / fpar[F_VBOUND]
        if arm is not None:
            hcap = armature_step_bound(arm, hcap)
        if h > hcap:
            h = hcap
        last = False
        h_want = h  # the controller's step, kept across a last step clipped to t_stop
        if t + h >= t_stop:
            h = t_stop - t
            last = True
        if not last and (h < 1e-15 * max(1.0, abs(t)) or h < 1e-18):
            return STEP_TOO_SMALL, t, h, n_rec, -1  # (a last step clipped to t_stop may be tiny)
        _rk_stages(t, y, h, k1, k2, k3, k4, k5, k6, k7, ytmp, ynew, mdl, regime, eref, aux_stage, aux_new, work, arm)
        stats[2] += 6
        err = 0.0
        finite = True
        for i in range(N):
            e = h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i])
            big = abs(y[i]) if abs(y[i]) > abs(ynew[i]) else abs(ynew[i])
            sc = atol[i] + rtol * relmask[i] * big
            err += (e / sc) ** 2
            if not math.isfinite(ynew[i]):
                finite = False
        err = math.sqrt(err / N)
        if not finite or not err < math.inf:
            # (a NaN estimate, from a stage that left the motion, compares false with 1:
            # it had accepted a 1.7 ms step through a contact, and every step after it
            # failed on the garbage state)
            if h < 1e-14:
                return NOT_FINITE, t, h, n_rec, -1
            h *= 0.1
            reject = True
            stats[1] += 1
            continue
        # PI step-size control (Hairer's DOPRI5 constants)
        fac11 = err ** 0.17 if err > 0.0 else 0.0
        fac = fac11 / facold ** 0.04 if facold > 0.0 else fac11
        fac = max(0.1, min(5.0, fac / 0.9))
        hnew = h / fac
        if err > 1.0:
            hnew = h / min(5.0, fac11 / 0.9)
            reject = True
            stats[1] += 1
            h = hnew
            continue
        # accepted: events
        facold = max(err, 1e-4)
        event_values(ynew, aux_new, sv, eref, mdl, g_new, arm)
        _dense_coefficients(y, ynew, h, k1, k3, k4, k5, k6, k7, coef)
        first_k = -1
        h_continue = h
        first_theta = 2.0
        first_theta_lo = 0.0
        g_lo_dense = 0.0
        for k in range(nev):
            if not _active(k, g_old, g_new, regime, fmodel):
                continue
            s = ev_sign[k]
            if s == 0.0 or not (s * g_new[k] < 0.0 or g_new[k] == 0.0):
                continue
            # Illinois on theta in [0, 1]; keep (a, ga) on the old side, (b, gb) on the new side.
            a = 0.0
            ga = g_old[k] if s * g_old[k] > 0.0 else s * 1e-300
            b = 1.0
            gb = g_new[k]
            side = 0
            for _ in range(200):
                if (b - a) * h <= 4e-16 * max(abs(t), 1e-9) + 1e-18:
                    break
                tc = b - gb * (b - a) / (gb - ga) if gb != ga else 0.5 * (a + b)
                if not (a < tc < b):
                    tc = 0.5 * (a + b)
                dense_eval(coef, tc, ymid)
                dynamics(t + tc * h, ymid, mdl, regime, eref, ytmp, aux_stage, work, arm)
                stats[2] += 1
                event_values(ymid, aux_stage, sv, eref, mdl, g_mid, arm)
                gc = g_mid[k]
                if s * gc > 0.0:
                    a = tc
                    ga = gc
                    if side == -1:
                        gb *= 0.5
                    side = -1
                else:
                    b = tc
                    gb = gc
                    if side == 1:
                        ga *= 0.5
                    side = 1
            if b < first_theta:
                first_theta = b
                first_k = k
                first_theta_lo = a
                g_lo_dense = ga if s * ga > 0.0 else s * 1e-300
        if first_k >= 0:
            tev = t + first_theta * h
            if first_theta >= 1.0:
                tev = t + h
                for i in range(N):
                    ymid[i] = ynew[i]
            else:
                # Retake the step so that it ends at the event: the dense output carries the
                # error of a step that straddles a kink (e.g. the Hertz force at y = 0). The
                # retaken step's own end must be on the new side, so the root is refined on
                # G(theta) = g(RK step of theta h) between the dense root and the full step.
                s_ev = ev_sign[first_k]
                lo = first_theta_lo
                g_lo = g_lo_dense
                hi = 1.0
                g_hi = g_new[first_k]
                trial = first_theta
                side = 0
                found = False
                for _ in range(40):
                    _rk_stages(t, y, trial * h, k1, k2, k3, k4, k5, k6, k7, ytmp, ymid, mdl,
                               regime, eref, aux_stage, aux_new, work, arm)
                    stats[2] += 6
                    event_values(ymid, aux_new, sv, eref, mdl, g_mid, arm)
                    gt = g_mid[first_k]
                    if s_ev * gt < 0.0:
                        hi = trial
                        g_hi = gt
                        found = True
                        if (hi - lo) * h <= 1e-3 * h * 1e-6 + 4e-16 * max(abs(t), 1e-9) or side == 0:
                            break
                        if side == 1:
                            g_lo *= 0.5
                        side = 1
                    else:
                        lo = trial
                        g_lo = gt
                        found = False
                        if side == -1:
                            g_hi *= 0.5
                        side = -1
                    if (hi - lo) * h <= 4e-16 * max(abs(t), 1e-9) + 1e-18:
                        break
                    trial = hi - g_hi * (hi - lo) / (g_hi - g_lo) if g_hi != g_lo else 0.5 * (lo + hi)
                    if not (lo < trial < hi):
                        trial = 0.5 * (lo + hi)
                if not found:  # the last trial ended on the old side: retake at hi
                    _rk_stages(t, y, hi * h, k1, k2, k3, k4, k5, k6, k7, ytmp, ymid, mdl,
                               regime, eref, aux_stage, aux_new, work, arm)
                    stats[2] += 6
                hh = hi * h
                h_continue = h
                tev = t + hh
                _dense_coefficients(y, ymid, hh, k1, k3, k4, k5, k6, k7, coef)
                h = hh
                first_theta = 1.0
            dynamics(tev, ymid, mdl, regime, eref, ytmp, aux_new, work, arm)
            stats[2] += 1
            _record(n_rec, t, h, tev, ymid, aux_new, aux_old, coef, free, free_dense, store_dense, mdl, first_theta,
                    yrec, frec, work)
            n_rec += 1
            for i in range(N):
                y[i] = ymid[i]
            stats[0] += 1
            stats[3] += 1
            return EVENT, tev, h_continue, n_rec, first_k
        _record(n_rec, t, h, t + h, ynew, aux_new, aux_old, coef, free, free_dense, store_dense, mdl, 1.0,
                yrec, frec, work)
        n_rec += 1
        stats[0] += 1
        for k in range(nev):
            if g_new[k] != 0.0:
                ev_sign[k] = 1.0 if g_new[k] > 0.0 else -1.0
        for i in range(N):
            y[i] = ynew[i]
            k1[i] = k7[i]
        for i in range(rows):
            for c_ in range(NAUX):
                aux_old[i, c_] = aux_new[i, c_]
        for k in range(nev):
            g_old[k] = g_new[k]
        t = t + h if not last else t_stop
        if reject:
            hnew = min(hnew, h)
            reject = False
        if last and h < 0.5 * h_want and hnew < h_want:
            # a step clipped well short by t_stop says little about the next: going on from a
            # round-off sliver (a redone coupling step ending 5e-16 s before its event) with
            # the sliver's own step failed as 'step size too small'
            hnew = h_want
        h = hnew


@njit_borrowing
def _record(n_rec, t_start, h, t_end, y_end, aux_end, aux_start, coef, rec, dense, store_dense, mdl, theta_end,
            ymid, forces, work):
    """Store an accepted step in row n_rec of rec (and its dense-output coefficients in
    dense when kept); its peak normal force is sampled at both ends and 3 interior points.
    ymid (N,), forces (rows, 2) and the dynamics' work tuple: scratch for those points."""
    rec_t, rec_y, rec_aux, rec_fmax = rec
    dense_t0, dense_h, dense_coef = dense
    if store_dense:
        dense_t0[n_rec] = t_start
        dense_h[n_rec] = h
        for a_ in range(5):
            for i in range(coef.shape[1]):
                dense_coef[n_rec, a_, i] = coef[a_, i]
    rec_t[n_rec] = t_end
    N = y_end.shape[0]
    for i in range(N):
        rec_y[n_rec, i] = y_end[i]
    rows = aux_end.shape[0]
    touching = False
    for i in range(rows):
        for c_ in range(NAUX):
            rec_aux[n_rec, i, c_] = aux_end[i, c_]
        rec_fmax[n_rec, i] = max(aux_end[i, A_FN], aux_start[i, A_FN])
        if aux_end[i, A_Y] > 0.0 or aux_start[i, A_Y] > 0.0:
            touching = True
    if touching:
        sv = work[22]
        for f in (0.25, 0.5, 0.75):
            dense_eval(coef, f * theta_end, ymid)
            # the normal forces alone: no right-hand side
            pair_forces_into(ymid, mdl, forces, work[0], work[1], work[2], work[3], work[4], work[5],
                             sv[12:15], sv[15:18])
            for i in range(rows):
                if forces[i, 0] > rec_fmax[n_rec, i]:
                    rec_fmax[n_rec, i] = forces[i, 0]


@njit(cache=True)
def dense_contact(times, t_valid, dense_t0, dense_h, dense_coef, regimes, mdl,
                  eref, work, out, arm=None):
    """Per contact row penetration (m), rate (m/s) and normal force (N) at sorted ``times``
    from the stored dense output; out has shape (len(times), rows, 3)."""
    N = dense_coef.shape[2]
    rows = out.shape[1]
    y = np.empty(N)
    dy = np.empty(N)
    aux = np.empty((rows, NAUX))
    k = 0
    n = t_valid.shape[0]
    for m in range(times.shape[0]):
        t = times[m]
        while k < n - 1 and t_valid[k] < t:
            k += 1
        dense_eval(dense_coef[k], (t - dense_t0[k]) / dense_h[k], y)
        dynamics(t, y, mdl, regimes[k], eref, dy, aux, work, arm)
        for i in range(rows):
            out[m, i, 0] = aux[i, A_Y]
            out[m, i, 1] = aux[i, A_YDOT]
            out[m, i, 2] = aux[i, A_FN]


@njit_borrowing
def dense_force_scratch_size(n_state, n_modes, rows):
    """Length of the float64 scratch vector of dense_tip_forces and dense_pair_forces for a
    state of n_state components, n_modes modes and ``rows`` contact rows: the state, each
    row's (force, penetration), and kernel.unpack's r, R, q, V, w, eta and a contact point's
    position and velocity (pair_forces_into's x, v). (mech.compiled.dense_force_arguments
    makes it by the same formula, on the Python side; a test compares the two.)"""
    return n_state + 2 * rows + 2 * n_modes + 24


@njit_borrowing
def _check_scratch(args):
    """Refuse a scratch vector of dense_tip_forces' args shorter than dense_force_scratch_size
    (its cuts would be short: written past, or a reshape refused with numba's own words)."""
    if args[11].shape[0] < dense_force_scratch_size(args[3].shape[2], args[7], args[6].shape[0]):
        raise ValueError("dense_tip_forces, dense_pair_forces: the scratch vector is shorter than "
                         "dense_force_scratch_size")


@njit_borrowing
def _dense_forces_into(t, args, out):
    """``pair_forces`` at time t (s) from the dense output into out (rows, 2), args as
    dense_tip_forces' (its scratch's length checked: _check_scratch); every intermediate
    array is cut from its scratch vector (compiled without reference counts, so cutting it
    costs nothing)."""
    t_valid, dense_t0, dense_h, dense_coef, psi, xc, cpar, n, planar, mount, beta, scratch = args
    N = dense_coef.shape[2]
    n_steps = t_valid.shape[0]
    lo = 0
    hi = n_steps - 1
    while lo < hi:  # first step whose validity ends at or after t
        mid = (lo + hi) // 2
        if t_valid[mid] < t:
            lo = mid + 1
        else:
            hi = mid
    k = lo
    y = scratch[0:N]
    dense_eval(dense_coef[k], (t - dense_t0[k]) / dense_h[k], y)
    r = scratch[N:N + 3]
    R = scratch[N + 3:N + 12].reshape((3, 3))
    V = scratch[N + 12:N + 15]
    w = scratch[N + 15:N + 18]
    x = scratch[N + 18:N + 21]
    v = scratch[N + 21:N + 24]
    q = scratch[N + 24:N + 24 + n]
    eta = scratch[N + 24 + n:N + 24 + 2 * n]
    pair_forces_of(y, n, planar, mount, beta, psi, xc, cpar, out, r, R, q, V, w, eta, x, v)


@njit_borrowing
def _dense_tip_forces(t, args):
    """dense_tip_forces without reference counts (see there)."""
    _check_scratch(args)
    dense_coef, cpar, n, scratch = args[3], args[6], args[7], args[11]
    rows = cpar.shape[0]
    b = dense_coef.shape[2] + 24 + 2 * n  # (the forces' place in the scratch: after _dense_forces_into's)
    pf = scratch[b:b + 2 * rows].reshape((rows, 2))
    _dense_forces_into(t, args, pf)
    gap = 1e300
    for i in range(rows):
        if cpar[i, C_ON] != 0.0 and -pf[i, 1] < gap:
            gap = -pf[i, 1]
    return pf[0, 0], pf[1, 0], gap if gap > 0.0 else 0.0, pf[0, 1], pf[1, 1]


@njit(cache=True)
def dense_tip_forces(t, args):
    """(F_0, F_1, gap, y_0, y_1) at time t (s) from the dense output: the first two contact
    rows' normal force (N), the nearest row's gap (m, 0 when touching; 1e300 without a
    contact point) and the first two's penetration (m) (``tip_forces``): only what a circuit
    needs, without the full right-hand side (the ngspice callbacks ask for it thousands of
    times per run).

    args (mech.compiled.dense_force_arguments, made once per segment): the dense output
    (t_valid, t0, h, coef: s, s, s, the coefficients), what it reads of the model (psi, xc,
    cpar, n, planar, mount, beta: model.BarModel.kernel_arrays' arrays and ipar's and fpar's
    values) and a float64 scratch vector of at least dense_force_scratch_size. (One tuple
    of only those, the same object at every call of a segment, not the 15-array model tuple
    and arrays made per call: the ahead-of-time wrapper converts every array argument at
    every call, ~70 ns each, every array made is an allocation, and each argument is
    checked on the Python side unless it is the previous call's object: of a 2.2 us call,
    ~1.1 us went to those.)"""
    return _dense_tip_forces(t, args)


@njit(cache=True)
def dense_pair_forces(t, args, out):
    """``pair_forces`` at time t (s) from the dense output: out (rows, 2), each contact row's
    normal force (N) and penetration (m); args as ``dense_tip_forces``'."""
    _check_scratch(args)
    _dense_forces_into(t, args, out)


@njit(cache=True)
def tip_forces(y, mdl, out):
    """out = (F_0, F_1, gap, y_0, y_1) of state y: the first two contact rows' normal force
    (N), the nearest row's gap (m, 0 when touching; 1e300 without a contact point) and the
    first two's penetration (m) (pair_forces)."""
    cpar = mdl[9]
    rows = cpar.shape[0]
    pf = np.empty((rows, 2))
    pair_forces(y, mdl, pf)
    gap = 1e300
    for i in range(rows):
        if cpar[i, C_ON] != 0.0 and -pf[i, 1] < gap:
            gap = -pf[i, 1]
    out[0] = pf[0, 0]
    out[1] = pf[1, 0]
    out[2] = gap if gap > 0.0 else 0.0
    out[3] = pf[0, 1]
    out[4] = pf[1, 1]


@njit(cache=True)
def pair_forces(y, mdl, out):
    """out (rows, 2) of state y: each contact row's normal force (N) and penetration (m,
    negative: its gap to its fixed contact), from the kinematics alone (the normal force
    follows the penetration and its rate; no accelerations, so a fraction of a right-hand
    side's cost). A switched-off row, and every row of a model without a bar: 0 and -1e3."""
    n = mdl[1][I_N]
    pair_forces_into(y, mdl, out, np.empty(3), np.empty((3, 3)), np.empty(n), np.empty(3), np.empty(3),
                     np.empty(n), np.empty(3), np.empty(3))


@njit_borrowing
def pair_forces_into(y, mdl, out, r, R, q, V, w, eta, x, v):
    """``pair_forces`` with the bar's state unpacked into r, R, q, V, w, eta (kernel.unpack's
    arrays) and each contact point's world position and velocity into x, v (3,): scratch
    its caller holds (the step's record samples three interior points without allocating)."""
    ipar = mdl[1]
    pair_forces_of(y, ipar[I_N], ipar[I_PLANAR], ipar[I_MOUNT], mdl[0][F_BETA], mdl[6], mdl[8], mdl[9], out,
                   r, R, q, V, w, eta, x, v)


@njit_borrowing
def pair_forces_of(y, n, planar, mount, beta, psi, xc, cpar, out, r, R, q, V, w, eta, x, v):
    """``pair_forces_into`` given only what it reads of the model: its mode count n,
    planar flag and mount kind (ipar's), the Hertz exponent's beta (fpar's) and the arrays
    psi, xc, cpar (mdl[6], [8], [9])."""
    rows = cpar.shape[0]
    if mount == MOUNT_NONE:  # no bar: no contact point
        for i in range(rows):
            out[i, 0] = 0.0
            out[i, 1] = -1e3
        return
    unpack(y, n, planar, r, R, q, V, w, eta)
    for i in range(rows):
        if cpar[i, C_ON] == 0.0:
            out[i, 0] = 0.0
            out[i, 1] = -1e3
            continue
        # the cap centre's world height x[2] and its rate v[2] (contact row i is point i)
        load_point_motion(i, xc, psi, r, R, q, V, w, eta, n, x, v)
        sg = cpar[i, C_N]
        pen = cpar[i, C_R] - sg * (x[2] - cpar[i, C_Z])
        out[i, 0] = normal_force(pen, -sg * v[2], cpar[i, C_K], cpar[i, C_C], beta)
        out[i, 1] = pen
