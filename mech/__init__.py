"""Mechanical impact solver: a flexible bar striking a massive block.

Floating-frame bar (rigid motion + free-free modes), Hertz contact with damping at both
tips, generalized friction |F_t| = mu F_n^(1-gamma) with exact stick/slip/separation
switching, repeated impacts and an energy audit. SI units throughout.

    from mech import default_scene, simulate
    result = simulate(default_scene())
    result.contacts, result.history, result.energy
"""

from .parameters import Bar, Block, Contact, Friction, Initial, MechScene, SolverOptions
from .results import ImpactResult
from .scene import default_scene, load_scene, scene_from_dict, scene_to_dict
from .solver import CoupledStates, ImpactSolver, MechSolverError, Segment


def simulate(scene: MechScene, **solver_options) -> ImpactResult:
    """Run ``scene`` to ``scene.solver.t_end`` and return its ImpactResult."""
    return ImpactSolver(scene, **solver_options).run()


__all__ = [
    "Bar", "Block", "Contact", "Friction", "Initial", "MechScene", "SolverOptions",
    "CoupledStates", "ImpactResult", "ImpactSolver", "MechSolverError", "Segment",
    "default_scene", "load_scene", "scene_from_dict", "scene_to_dict", "simulate",
]
