"""The compiled mechanics as the Python side calls it: the one place that loads it.

The solver, the results and the scipy backend take every compiled function from here,
never from mech.kernel or mech.integrator directly, and read the kernel's indices from
mech.kernel_layout; so how the compiled code is obtained (numba's just-in-time functions
with their on-disk cache, mech.compiled_cache) is decided in this module alone.
"""

from __future__ import annotations

from .integrator import dense_contact, dense_eval, dense_tip_forces, events_from_aux, integrate
from .kernel import dynamics, energies, energy_table, make_work, project_to_stick

__all__ = [
    "dense_contact", "dense_eval", "dense_tip_forces", "dynamics", "energies", "energy_table",
    "events_from_aux", "integrate", "make_work", "project_to_stick",
]
