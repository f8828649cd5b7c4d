"""The damping of a contact law calibrated to a restitution: c from a target e, e from a c.

The single-impact problem in its dimensionless form (mech.contact_laws.scaled_rebound) is
integrated by its compiled twin (mech.compiled) and root-found; SI units.
"""

from __future__ import annotations

import math
from functools import lru_cache

from .compiled import scaled_rebound


@lru_cache(maxsize=256)
def _scaled_damping(restitution: float, beta: float) -> float:
    """c_hat giving ``restitution`` in the dimensionless single impact (cached).

    The restitution falls monotonically with c_hat; the root in log c_hat is found by the
    Illinois method (regula falsi that halves the stale end's value) to 1e-13.
    """
    if restitution >= 1.0:
        return 0.0

    def excess(log_c):
        return scaled_rebound(math.exp(log_c), beta) - restitution

    lo, hi = math.log(1e-8), math.log(1e4)
    f_lo, f_hi = excess(lo), excess(hi)
    if f_hi > 0.0:
        raise ValueError(
            f"contact.restitution = {restitution!r}: too small to reach with this damping law"
        )
    if f_lo < 0.0:
        raise ValueError(f"contact.restitution = {restitution!r}: too close to 1 for a calibrated damping")
    side = 0
    x = lo
    for _ in range(200):
        x = (lo * f_hi - hi * f_lo) / (f_hi - f_lo)
        f_x = excess(x)
        if f_x == 0.0 or hi - lo < 1e-13 * (1.0 + abs(x)):
            break
        if f_x < 0.0:
            hi, f_hi = x, f_x
            if side == -1:
                f_lo *= 0.5
            side = -1
        else:
            lo, f_lo = x, f_x
            if side == 1:
                f_hi *= 0.5
            side = 1
    return math.exp(x)


def calibrate_damping(law: str, restitution: float, speed: float, stiffness: float,
                      mass: float) -> float:
    """c that makes a single impact of ``mass`` (kg) at ``speed`` (m/s) rebound with ``restitution``.

    The single-impact problem integrated (``scaled_rebound``, local error 1e-14) and
    root-found. Units of c: N s/m^2 (paper, beta = 1), N s/m^2.5 (others).
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
    return float(scaled_rebound(damping * speed * dstar ** (beta - 1.5) / stiffness, beta))
