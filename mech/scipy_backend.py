"""scipy.integrate.solve_ivp as an alternative stepper for the same model and regimes.

Same right-hand side, same events, same regime logic as the compiled DOPRI5 loop; only
the stepping differs (mech.stepping: the protocol both implement). Used as the speed
baseline (Radau, benchmarks/bench_mech.py) and as an independent integration route in the
tests (DOP853, Radau).
"""

from __future__ import annotations

import numpy as np

from .compiled import dynamics, event_values
from .kernel_layout import (
    A_FN, A_Y, A_YDOT, D_VALUE, DONE, EV_CLIP, EV_COMPRESSION, EV_SLIP, EV_STICK, EVENT, FREE, FRICTION_EXACT,
    I_FRICTION, NAUX, NEV_TIP, NOT_FINITE, SLIP, STICK,
)

from .stepping import Outcome

METHODS = ("RK45", "DOP853", "Radau", "BDF", "LSODA")


class ScipyStepper:
    """solve_ivp with ``method`` as a stepper (mech.stepping.Stepper)."""

    def __init__(self, method: str):
        if method not in METHODS:
            raise ValueError(f"backend method = {method!r}: allowed values are {', '.join(METHODS)}")
        self.method = method

    def segment(self, state, t_goal: float) -> Outcome:
        return Outcome(*scipy_segment(state, t_goal, self.method))


def scipy_segment(solver, t_target: float, method: str):
    """Integrate the integration state ``solver`` (mech.stepping) from its time towards
    t_target (s) with solve_ivp.

    Returns (status, t_new, h_next, n_records, event_index) like the compiled loop and
    writes the accepted steps into the recorder's rows from its ``n`` on.
    """
    from scipy.integrate import solve_ivp  # lazily: only the scipy backends import it

    m = solver.model
    arrays = solver.arrays
    arm = solver.arm
    drive = solver.drive
    mu_rows = m.drive_rows("mu")  # a coupled model's friction coefficient is every contact point's
    regime = solver.regime.copy()
    eref = solver.eref.copy()
    work = solver.work
    rec = solver.recorder
    rows = m.rows
    aux = np.empty((rows, NAUX))
    aux_mid = np.empty((rows, NAUX))
    g = np.empty(m.event_count)
    N = m.state_size
    counter = {"nfev": 0}
    coupled = solver.coupled
    n_ext = coupled.size if coupled is not None else 0

    def fun(t, y):
        dy = np.empty(N + n_ext)
        if coupled is not None:
            drive[mu_rows, D_VALUE] = coupled.friction_coefficient(t, y[N:])
        dynamics(t, y[:N], arrays, regime, eref, dy[:N], aux, work, arm)
        if coupled is not None:
            dy[N:] = coupled.rhs(t, y[N:], aux[:, [A_Y, A_YDOT, A_FN]])
        counter["nfev"] += 1
        return dy

    counter_events = counter  # event evaluations count as right-hand-side evaluations too

    fexact = m.ipar[I_FRICTION] == FRICTION_EXACT

    def make_event(k):
        # the contact points' events (tip i, kind), then the armature's (always watched)
        i, kind = divmod(k, NEV_TIP) if k < m.armature_event_base else (-1, -1)
        seen = {}  # t -> value at the last few times asked (see below)

        def ev(t, y):
            # solve_ivp finds a crossing from the values at the step's two ends (its own
            # states), then brackets the root with brentq on the dense output, which at
            # the step's start is not that state for LSODA and BDF (a Nordsieck history) and
            # may give the other sign (measured: "f(a) and f(b) must have different signs"
            # on a grazing drop). The value at a time already asked is given again, so the
            # bracket has the signs the crossing was found with.
            got = seen.get(t)
            if got is not None:
                return got
            value = _value(t, y)
            if len(seen) >= 4:
                del seen[next(iter(seen))]
            seen[t] = value
            return value

        def _value(t, y):
            dy = np.empty(N)
            if coupled is not None:
                drive[mu_rows, D_VALUE] = coupled.friction_coefficient(t, y[N:])
            dynamics(t, y[:N], arrays, regime, eref, dy, aux, work, arm)
            counter_events["nfev"] += 1
            event_values(y[:N], aux, work[22], eref, arrays, g, arm)
            if kind == EV_SLIP and not (fexact and regime[i] == SLIP):
                return solver.ev_sign[k]
            if kind == EV_STICK and not (fexact and regime[i] == STICK):
                return solver.ev_sign[k]
            if kind in (EV_CLIP, EV_COMPRESSION) and regime[i] == FREE:
                # watched only while the tip touches, by its regime at the restart as in the
                # compiled loop: gated by the penetration of each evaluation instead, they
                # jumped from the constant to their value at a touchdown, and a compression
                # "crossing" located there before the contact's own root ended the segment
                # without a contact start (measured: DOP853 at rtol 1e-11 missed the tilted
                # drop's fifth contact, the tip then 4.6 um inside the block with no force)
                return solver.ev_sign[k]
            if g[k] == 0.0 and t == t_start:
                # solve_ivp counts a zero at t0 as a crossing there and would stop at t0
                # again on every restart; we are on the side the solver's sign says.
                return solver.ev_sign[k] * 1e-300
            return g[k]

        ev.terminal = True
        ev.direction = -solver.ev_sign[k]
        return ev

    t_start = solver.t
    events = [make_event(k) for k in range(m.event_count)]
    rtol = solver.scene.solver.rtol
    # solve_ivp's error test is |err| <= atol + rtol |y| for every component, so positions
    # also get a relative share (the compiled loop holds them to atol alone): the baseline
    # is, if anything, given a looser tolerance than the compiled loop.
    y0 = solver.y.copy() if coupled is None else np.concatenate([solver.y, solver.z])
    atol = m.atol if coupled is None else np.concatenate([m.atol, coupled.atol])
    jac = None
    if coupled is not None and method in ("Radau", "BDF", "LSODA"):
        # Block Jacobian by finite differences: mechanics over its states with steps set by
        # the model's own error scales (sqrt(eps) of atol/rtol: ~1e-12 m for positions,
        # where solve_ivp's sqrt(eps)|y| would be ~1e-10 m and cross the contact boundary
        # near touchdown, sending through G(F(y)) entries of ~1e16 into the stiff circuit
        # rows), and the extra states over themselves. The cross blocks are left to
        # Newton's iteration: the extra states follow the mechanics one way, and mu acts
        # back only weakly.
        scale = np.maximum(np.abs(y0), atol / rtol)
        sqrt_eps = np.sqrt(np.finfo(float).eps)

        def jac(t, y):
            f0 = fun(t, y)
            J = np.zeros((N + n_ext, N + n_ext))
            for block in (range(N), range(N, N + n_ext)):
                for j in block:
                    h = sqrt_eps * max(abs(y[j]), scale[j])
                    yp = y.copy()
                    yp[j] += h
                    fj = fun(t, yp)
                    rows = slice(0, N) if j < N else slice(N, N + n_ext)
                    J[rows, j] = (fj[rows] - f0[rows]) / h
            return J

    extra = {"jac": jac} if jac is not None else {}
    sol = solve_ivp(fun, (solver.t, t_target), y0, method=method, rtol=rtol, dense_output=True, **extra,
                    atol=atol, max_step=m.max_step, events=events,
                    first_step=min(solver.h, m.max_step, t_target - solver.t) if solver.h > 0 else None)
    solver.stats[2] += counter["nfev"]
    n_new = len(sol.t) - 1
    rec.make_room(n_new + 1)  # (never thinned here: the solver holds row indices of this segment)
    n0 = rec.n
    for k in range(1, len(sol.t)):
        y = sol.y[:N, k]
        dy = np.empty(N)
        if coupled is not None:
            drive[mu_rows, D_VALUE] = coupled.friction_coefficient(sol.t[k], sol.y[N:, k])
            rec.ext[n0 + k - 1] = sol.y[N:, k]
        dynamics(sol.t[k], y, arrays, regime, eref, dy, aux, work, arm)
        r = n0 + k - 1
        rec.t[r] = sol.t[k]
        rec.y[r] = y
        rec.aux[r] = aux
        rec.fmax[r] = aux[:, A_FN]
        if np.any(aux[:, A_Y] > 0.0) or np.any(rec.aux[r - 1, :, A_Y] > 0.0 if r > 0 else False):
            # the peak force lies inside a step: sample the dense output as the compiled loop
            # does, then evaluate it once more at the vertex of the parabola through the
            # largest sample and its neighbours (a step that resolves the motion can still
            # be a tenth of the contact: measured, the quarter points alone missed a 925 N
            # peak by 0.7 N on DOP853's steps at rtol 1e-8)
            h = sol.t[k] - sol.t[k - 1]
            samples = np.empty((5, rows))
            samples[0] = rec.aux[r - 1, :, A_FN] if r > 0 else aux[:, A_FN]
            samples[4] = aux[:, A_FN]
            for j, f in enumerate((0.25, 0.5, 0.75), start=1):
                dynamics(sol.t[k - 1] + f * h, sol.sol(sol.t[k - 1] + f * h)[:N], arrays, regime, eref, dy,
                         aux_mid, work, arm)
                samples[j] = aux_mid[:, A_FN]
            peak = samples.max(axis=0)
            for tip in range(rows):
                j = int(np.argmax(samples[:, tip]))
                curvature = samples[j - 1, tip] - 2.0 * samples[j, tip] + samples[j + 1, tip] if 0 < j < 4 else 0.0
                if curvature < 0.0:
                    shift = 0.5 * (samples[j - 1, tip] - samples[j + 1, tip]) / curvature
                    tm = sol.t[k - 1] + 0.25 * (j + shift) * h
                    dynamics(tm, sol.sol(tm)[:N], arrays, regime, eref, dy, aux_mid, work, arm)
                    peak[tip] = max(peak[tip], aux_mid[tip, A_FN])
            rec.fmax[r] = np.maximum(rec.fmax[r], peak)
    solver.stats[0] += n_new
    solver.y[:] = sol.y[:N, -1]
    if coupled is not None:
        solver.z[:] = sol.y[N:, -1]
        drive[mu_rows, D_VALUE] = coupled.friction_coefficient(sol.t[-1], solver.z)
    if not sol.success:
        return NOT_FINITE, float(sol.t[-1]), 0.0, n_new, -1
    h_next = float(sol.t[-1] - sol.t[-2]) if len(sol.t) > 1 else solver.h
    if sol.status == 1:
        hit = [k for k, te in enumerate(sol.t_events) if len(te)]
        solver.stats[3] += 1
        return EVENT, float(sol.t[-1]), h_next, n_new, hit[0]
    return DONE, float(t_target), h_next, n_new, -1
