"""Scene builders and closed-form references shared by the mechanics tests (SI units).

Nothing here runs the solver's physics for a reference: the closed forms and the
independent single-degree-of-freedom solves are written out from their textbook
definitions so that they can disagree with the code under test.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.special import beta as beta_function

from mech import Bar, Block, Contact, Friction, ImpactSolver, Initial, MechScene, SolverOptions
from mech.contact_laws import hertz_stiffness


def make_scene(*, bar=None, block=None, contact=None, friction=None, initial=None, solver=None,
               gravity: float = 0.0) -> MechScene:
    """A scene from keyword dicts per section. Defaults differ from the product's default
    scene on purpose: no gravity, elastic contact (c = 0), no friction, a rigid bar, so a
    test states every physical ingredient it relies on."""
    bar_kw = dict(axial_modes=0, bending_modes=0)
    bar_kw.update(bar or {})
    contact_kw = dict(damping=0.0, restitution=None)
    contact_kw.update(contact or {})
    if "restitution" in (contact or {}) and "damping" not in (contact or {}):
        contact_kw["damping"] = None
    friction_kw = dict(mu=0.0)
    friction_kw.update(friction or {})
    return MechScene(
        bar=Bar(**bar_kw), block=Block(**(block or {})), contact=Contact(**contact_kw),
        friction=Friction(**friction_kw), initial=Initial(**(initial or {})),
        solver=SolverOptions(**(solver or {})), gravity=gravity,
    )


def start_from(solver: ImpactSolver, **parts) -> ImpactSolver:
    """Overwrite named parts of the solver's initial state (ImpactSolver.start_from) and
    return the solver."""
    solver.start_from(**parts)
    return solver


def steel_stiffness(radius: float, youngs_modulus: float = 210e9, poisson_ratio: float = 0.3) -> float:
    """N/m^1.5: Hertz k = (4/3) E* sqrt(R) of a steel sphere on the same steel, written out."""
    e_star = youngs_modulus / (2.0 * (1.0 - poisson_ratio**2))
    return 4.0 / 3.0 * e_star * math.sqrt(radius)


# Undamped Hertz impact of a rigid mass: m y'' = -k y^1.5 gives, from energy,
# y'^2 = v0^2 (1 - (y/d)^2.5) with d = (5 m v0^2/(4 k))^(2/5), and the contact time
# t_c = 2 (d/v0) int_0^1 du / sqrt(1 - u^2.5) = 2 (d/v0) (2/5) B(2/5, 1/2) = 2.94320 d/v0.
HERTZ_TIME_FACTOR_EXACT = 2.0 * 0.4 * beta_function(0.4, 0.5)


def hertz_closed_form(mass: float, stiffness: float, speed: float) -> dict:
    """max_penetration (m), peak_force (N), contact_time (s) of the undamped Hertz impact."""
    d = (5.0 * mass * speed**2 / (4.0 * stiffness)) ** 0.4
    return dict(max_penetration=d, peak_force=stiffness * d**1.5,
                contact_time=HERTZ_TIME_FACTOR_EXACT * d / speed)


def hertz_history(mass: float, stiffness: float, speed: float, damping: float = 0.0,
                  beta: float = 1.0, points: int = 4001) -> dict:
    """1-DOF reference m y'' = -(k y^1.5 + c y^beta y')^+ from y = 0, y' = speed, by scipy.

    Returns t (s), y (m), force (N) and the cumulative normal impulse (N s) on a fine grid
    over the contact, and the contact time (s).
    """

    def rhs(_, s):
        y, v, _p = s
        yp = max(y, 0.0)
        f = max(stiffness * yp**1.5 + damping * yp**beta * v, 0.0)
        return [v, -f / mass, f]

    def leave(_, s):
        return s[0]

    leave.terminal = True
    leave.direction = -1
    t_guess = 2.0 * hertz_closed_form(mass, stiffness, speed)["contact_time"]
    sol = solve_ivp(rhs, (0.0, t_guess), [0.0, speed, 0.0], method="DOP853", rtol=1e-12,
                    atol=[1e-16, 1e-14, 1e-14], events=leave, dense_output=True,
                    first_step=t_guess * 1e-6)
    t_c = float(sol.t_events[0][0])
    t = np.linspace(0.0, t_c, points)
    y, v, p = sol.sol(t)
    yp = np.maximum(y, 0.0)
    force = np.maximum(stiffness * yp**1.5 + damping * yp**beta * v, 0.0)
    return dict(t=t, y=y, force=force, impulse=p, contact_time=t_c, rebound_speed=-float(sol.y[1, -1]))


def transverse_inertia(bar: Bar) -> float:
    """kg m^2: moment of inertia of the prismatic bar about a transverse axis through its
    centroid, m L^2/12 + rho L I (the section's own rotary inertia included)."""
    return bar.mass * bar.length**2 / 12.0 + bar.density * bar.length * bar.second_moments[0]


__all__ = [
    "make_scene", "start_from", "steel_stiffness", "hertz_closed_form", "hertz_history",
    "transverse_inertia", "hertz_stiffness", "HERTZ_TIME_FACTOR_EXACT",
]
