"""Normal contact laws: Hertz stiffness, damping laws and their calibration to a restitution.

Pure functions (SI units). ``normal_force`` is also compiled into the kernel (mech.kernel),
which calls it inside the integration loop; here it is plain Python, the readable reference.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache


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


def _scaled_restitution(c_hat: float, beta: float) -> float:
    """Restitution of y'' = -(y^1.5 + c_hat y^beta y')^+, y(0) = 0, y'(0) = 1 (dimensionless).

    Any single impact m y'' = -(k y^1.5 + c y^beta y')^+ at speed v0 reduces to this with
    y in units of delta* = (m v0^2/k)^(2/5), time in delta*/v0 and
    c_hat = c v0 delta*^(beta - 1.5) / k.
    """

    def rhs(_, s):
        y, v = s
        yp = max(y, 0.0)
        f = yp**1.5 + c_hat * yp**beta * v
        return [v, -max(f, 0.0)]

    def force_gone(_, s):  # the force stays zero once it clips during restitution
        y, v = s
        return y**1.5 + c_hat * y**beta * v if y > 0 else v

    force_gone.terminal = True
    force_gone.direction = -1

    def left(_, s):
        return s[0]

    left.terminal = True
    left.direction = -1
    from scipy.integrate import solve_ivp  # lazily: only a restitution calibration needs it

    sol = solve_ivp(rhs, (0.0, 50.0), [0.0, 1.0], method="DOP853", rtol=1e-11, atol=1e-13,
                    events=[force_gone, left], first_step=1e-4)
    return float(-sol.y[1, -1])


@lru_cache(maxsize=256)
def _scaled_damping(restitution: float, beta: float) -> float:
    """c_hat giving ``restitution`` in the dimensionless single impact (root-find, cached)."""
    from scipy.optimize import brentq

    if restitution >= 1.0:
        return 0.0
    f = lambda log_c: _scaled_restitution(math.exp(log_c), beta) - restitution
    lo, hi = math.log(1e-8), math.log(1e4)
    if f(hi) > 0:
        raise ValueError(
            f"contact.restitution = {restitution!r}: too small to reach with this damping law"
        )
    return math.exp(brentq(f, lo, hi, xtol=1e-12, rtol=1e-12))


def calibrate_damping(law: str, restitution: float, speed: float, stiffness: float,
                      mass: float) -> float:
    """c that makes a single impact of ``mass`` (kg) at ``speed`` (m/s) rebound with ``restitution``.

    Energy balance of the single-impact problem, solved by root-finding; exact to the
    integration tolerance (1e-11). Units of c: N s/m^2 (paper, beta = 1), N s/m^2.5 (others).
    """
    beta = 1.0 if law == "paper" else 1.5
    c_hat = _scaled_damping(float(restitution), beta)
    dstar = (mass * speed**2 / stiffness) ** 0.4
    return c_hat * stiffness / (speed * dstar ** (beta - 1.5))


def single_impact_restitution(law: str, damping: float, speed: float, stiffness: float,
                              mass: float) -> float:
    """Restitution of one impact of ``mass`` at ``speed`` with damping c (the inverse of calibrate)."""
    beta = 1.0 if law == "paper" else 1.5
    dstar = (mass * speed**2 / stiffness) ** 0.4
    return _scaled_restitution(damping * speed * dstar ** (beta - 1.5) / stiffness, beta)
