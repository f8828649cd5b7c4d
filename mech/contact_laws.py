"""Normal contact laws: Hertz stiffness, force, impact and the damping laws' closed forms.

Pure functions (SI units) that import nothing of mech: ``normal_force`` and
``scaled_rebound`` are also compiled into the kernel (mech.kernel), which calls them
inside the integration loop; here they are plain Python, the readable reference. The
calibration of a damping to a restitution, which root-finds on the compiled
``scaled_rebound``, is mech.damping_calibration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


# t_c = 2.943275 delta_max / v0 for an undamped Hertz impact: 2 int_0^1 (1 - x^2.5)^-1/2 dx
# = 0.8 B(0.4, 0.5), B the Euler beta function
HERTZ_TIME_FACTOR = 0.8 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)


def effective_modulus(e1: float, nu1: float, e2: float, nu2: float) -> float:
    """Pa: E* = 1 / ((1 - nu1^2)/E1 + (1 - nu2^2)/E2)."""
    return 1.0 / ((1.0 - nu1**2) / e1 + (1.0 - nu2**2) / e2)


def hertz_stiffness(radius: float, e1: float, nu1: float, e2: float, nu2: float) -> float:
    """N/m^1.5: sphere of ``radius`` (m) on a half-space, k = (4/3) E* sqrt(R).

    Equals the paper's k = 0.424 sqrt(R)/(h1 + h2), h = (1 - nu^2)/(pi E), up to its
    rounding of 4/(3 pi) to 0.424.
    """
    return 4.0 / 3.0 * effective_modulus(e1, nu1, e2, nu2) * math.sqrt(radius)


def normal_force(y: float, ydot: float, k: float, c: float, beta: float) -> float:
    """N: F_n = k y^1.5 + c y^beta dy/dt for penetration y > 0 (m), clipped at 0."""
    if y <= 0.0:
        return 0.0
    f = k * y * math.sqrt(y) + c * y**beta * ydot
    return f if f > 0.0 else 0.0


@dataclass(frozen=True)
class HertzImpact:
    """Closed-form undamped Hertz impact of a rigid mass: penetration m, force N, time s."""

    max_penetration: float
    peak_force: float
    contact_time: float


def hertz_impact(mass: float, stiffness: float, speed: float) -> HertzImpact:
    """Rigid ``mass`` (kg) at normal ``speed`` (m/s) on F = k y^1.5 (k in N/m^1.5).

    delta_max = (5 m v0^2 / (4 k))^(2/5), F_max = k delta_max^1.5, t_c = 2.943275 delta_max / v0.
    """
    dmax = (5.0 * mass * speed**2 / (4.0 * stiffness)) ** 0.4
    return HertzImpact(dmax, stiffness * dmax**1.5, HERTZ_TIME_FACTOR * dmax / speed)


# Hunt-Crossley-type laws write the damping as c = chi k / v0 with beta = 1.5; their
# published chi(e) are approximations (measured: target 0.6 gives 0.712, 0.756, 0.577).
_CHI_FORMULAS = {
    "hunt_crossley": lambda e: 1.5 * (1.0 - e),
    "lankarani_nikravesh": lambda e: 0.75 * (1.0 - e * e),
    "flores": lambda e: 8.0 * (1.0 - e) / (5.0 * e),
}


def damping_formula(law: str, restitution: float, speed: float, stiffness: float) -> float:
    """c (N s/m^2.5) from the law's own closed form c = chi(e) k / v0 (approximate by design)."""
    if law not in _CHI_FORMULAS:
        raise ValueError(f"law = {law!r}: closed forms exist for {', '.join(_CHI_FORMULAS)}")
    return _CHI_FORMULAS[law](restitution) * stiffness / speed


def scaled_rebound(c_hat: float, beta: float) -> float:
    """Rebound speed of the dimensionless single impact y'' = -(y^1.5 + c_hat y^beta y')^+,
    y(0) = 0, y'(0) = 1: the restitution (see mech.damping_calibration for the scaling).

    Plain Python and also compiled (mech.kernel; mech.compiled exports it): the
    calibration (mech.damping_calibration) root-finds c_hat with some fifty of these
    solves. Classical Runge-Kutta with step doubling (local error <= 1e-14 of the unit speed; the step shrinks by
    itself where y^1.5 is not smooth, at the first touch). The impact is over when the
    force clips to zero during restitution (with y'' = 0 it stays zero: y^beta y' keeps
    its sign as y falls) or the mass leaves y = 0; the step that gets there is bisected
    down to round-off, and the speed there is returned (the force, hence y'', is zero
    at that point, so the speed does not depend on where in time it is taken).
    """

    def accel(y, v):
        f = y * math.sqrt(y) + c_hat * y**beta * v if y > 0.0 else 0.0
        return -f if f > 0.0 else 0.0

    def step(y, v, h):
        k1y, k1v = v, accel(y, v)
        k2y, k2v = v + 0.5 * h * k1v, accel(y + 0.5 * h * k1y, v + 0.5 * h * k1v)
        k3y, k3v = v + 0.5 * h * k2v, accel(y + 0.5 * h * k2y, v + 0.5 * h * k2v)
        k4y, k4v = v + h * k3v, accel(y + h * k3y, v + h * k3v)
        return (y + h * (k1y + 2.0 * k2y + 2.0 * k3y + k4y) / 6.0,
                v + h * (k1v + 2.0 * k2v + 2.0 * k3v + k4v) / 6.0)

    def over(y, v):
        if y <= 0.0:
            return v < 0.0
        return y * math.sqrt(y) + c_hat * y**beta * v <= 0.0

    tol = 1e-14
    y = 0.0
    v = 1.0
    h = 1e-3
    for _ in range(10_000_000):
        y1, v1 = step(y, v, h)
        ym, vm = step(y, v, 0.5 * h)
        y2, v2 = step(ym, vm, 0.5 * h)
        err = max(abs(y2 - y1), abs(v2 - v1)) / 15.0
        if err > tol and h > 1e-12:
            h *= max(0.2, 0.9 * (tol / err) ** 0.2)
            continue
        if not over(y2, v2):
            y = y2
            v = v2
            h *= min(4.0, 0.9 * (tol / err) ** 0.2) if err > 0.0 else 4.0
            continue
        lo = 0.0
        hi = h
        v_end = v2
        while hi - lo > 1e-16 * (1.0 + hi):
            mid = 0.5 * (lo + hi)
            if mid <= lo or mid >= hi:
                # no double between them: above h ~ 1.1 their spacing (2.2e-16) never gets
                # below the bound, and the bisection went on for ever (a heavily damped
                # impact coasts to its end in steps of order 1: restitution 0.05 hung)
                break
            yn, vn = step(y, v, mid)
            if over(yn, vn):
                hi = mid
                v_end = vn
            else:
                lo = mid
        return -v_end
    return math.nan
