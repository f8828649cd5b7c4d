"""Generalized friction law |F_t| = mu F_n^(1-gamma) and its low-load limit.

For gamma > 0 the ratio |F_t|/F_n = mu F_n^-gamma grows without bound as F_n -> 0 at
every touchdown and lift-off, although |F_t| itself goes to zero. The law comes from
tribometer loads of newtons; at millinewtons a film-lubricated contact does not show
friction ratios above one, and ratios past 4/3 put a sliding rod in the Painleve/jam
regime, where the outcome would be set by the regularization of the law and not by the
film. So below the load F_0 = (mu / r_max)^(1/gamma) the friction is taken proportional to
F_n with the ratio r_max (default 1): limit = min(mu F_n^(1-gamma), r_max F_n). This is
continuous in F_n, Lipschitz at F_n = 0 and equal to the power law above F_0 (0.19 N for
mu = 0.31 N^0.7, gamma = 0.7). r_max = inf restores the bare power law for comparison.
"""

from __future__ import annotations

import math


def friction_limit(normal_force: float, mu: float, gamma: float, max_ratio: float) -> float:
    """N: largest friction force the contact can carry, min(mu F_n^(1-gamma), r_max F_n).

    normal_force: N (>= 0). mu: N^gamma. gamma: -. max_ratio: - (may be inf).
    """
    if normal_force <= 0.0:
        return 0.0
    power = mu * normal_force ** (1.0 - gamma)
    capped = max_ratio * normal_force
    return power if power < capped else capped


def transition_force(mu: float, gamma: float, max_ratio: float) -> float:
    """N: load below which the friction ratio is capped at ``max_ratio`` (0 if never, inf if always)."""
    if math.isinf(max_ratio) or mu == 0.0:
        return 0.0
    if gamma == 0.0:
        return math.inf if mu > max_ratio else 0.0
    return (mu / max_ratio) ** (1.0 / gamma)


def regularized_scale(slip_speed: float, regularization_speed: float) -> float:
    """-: the factor |v_t| / sqrt(|v_t|^2 + v_s^2) of the regularized law (speeds in m/s)."""
    return slip_speed / math.sqrt(slip_speed * slip_speed + regularization_speed * regularization_speed)
