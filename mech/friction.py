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


# A slip stops or reverses (the slip event) once its speed against the reference direction
# exceeds this fraction of the speed resolution (solver.stick_velocity_tol): far above
# round-off, so a slip starting from rest with a round-off deceleration does not end at
# once, and far below the resolution, so a stop is still a stop.
REVERSAL_DEADBAND = 1e-3


def slip_direction(vx: float, vy: float, ex: float, ey: float, resolution: float) -> tuple[float, float]:
    """Unit direction (world x, y) of the slip that the exact model's friction opposes.

    v = (vx, vy): the contact point's slip velocity (m/s); e = (ex, ey): the reference
    direction (unit), the slip direction at the last restart; resolution: m/s, the slip
    speed below which a direction is not resolved (solver.stick_velocity_tol).

    On the reference's side (v . e >= 0) and at or above the resolution it is the
    velocity's own direction v/|v|. Below the resolution it turns smoothly from e at v = 0
    (a slip starting from rest goes along the unbalanced holding force) to v/|v| at
    |v| = resolution: v + (resolution - |v|) e, normalized. Why: v/|v| turns the
    transverse velocity at the rate F/(m |v|), which grows without bound as a slip starts
    from rest; following it below the resolution left the direction to round-off and cost
    ~1e-13 s steps (measured: 340k steps for one start of slip of a tilted bar, 3D, rtol
    1e-11). The blend bounds that rate by about F/(m resolution/sqrt 2) and changes the
    friction only while the slip is slower than the speeds the solver resolves.

    Past the reference (v . e < 0: only in trial stages of a step that crosses the slip
    event, which stops the slip or re-references it) v's component along e is mirrored
    first, so the direction is continuous across v . e = 0 in every direction: a slip that
    turns past 90 deg sees v/|v| on both sides, and a slip that stops and would reverse
    keeps friction along e, so its speed goes through zero and the event sees the stop
    (following v/|v| there pins the slip speed at zero inside the step: 1.3 M steps for
    1 ms, measured; flipping the force at a reversal made every step across a stop of a
    planar blade fail its error test: 2198 rejected of 3184 steps on the relay closure).
    """
    along = vx * ex + vy * ey
    if along < 0.0:
        vx -= 2.0 * along * ex
        vy -= 2.0 * along * ey
    speed = math.sqrt(vx * vx + vy * vy)
    if speed >= resolution:
        return vx / speed, vy / speed
    ux = vx + (resolution - speed) * ex
    uy = vy + (resolution - speed) * ey
    norm = math.sqrt(ux * ux + uy * uy)  # >= resolution / sqrt 2: v . e >= 0 here
    return ux / norm, uy / norm
