"""The kernel's functions compiled without reference counts (mech.jit.njit_borrowing) hand
no array back to their callers.

Such a function does not count the references of the arrays it is given; one that
returned an array (a view of its argument, say) would give its caller a reference the
caller then releases: the array freed while still in use. ``borrowing_violations`` finds
such a signature by its return type (the ahead-of-time build runs it on every function it
compiles afresh, and refuses to build); here it is shown to find one, and run on the
kernel's functions this process has compiled for a right-hand side and the energies (those
numba loads from its on-disk cache register no signature for the functions they call: the
build's check is the complete one).
"""

from __future__ import annotations

import numba
import numpy as np

from mech.jit import BORROWING, borrowing_violations
from mech.kernel import NAUX, dynamics, energies, make_work
from mech.model import build_model

from mech_cases import make_scene


@numba.njit(_nrt=False)
def _returns_its_argument(a):  # (numba itself refuses a new array or a view here)
    a[0] += 1.0
    return a


@numba.njit(_nrt=False)
def _returns_a_pair(a):
    return a[0], a


@numba.njit(_nrt=False)
def _returns_numbers(a):
    a[0] += 1.0
    return a[0], a.shape[0]


def test_a_borrowing_function_that_returns_an_array_is_found():
    a = np.zeros(3)
    _returns_its_argument(a)
    _returns_a_pair(a)
    _returns_numbers(a)
    found = borrowing_violations([_returns_its_argument, _returns_a_pair, _returns_numbers])
    assert len(found) == 2
    assert "_returns_its_argument" in found[0] and "_returns_a_pair" in found[1]


def test_the_kernels_borrowing_functions_return_no_array():
    # a flexible free bar with friction on
    scene = make_scene(bar=dict(axial_modes=2, bending_modes=2), friction=dict(mu=0.3),
                       initial=dict(height=1e-4, angle_deg=20.0, velocity=(0.0, 0.0, -0.5)))
    model = build_model(scene)
    y = model.initial_state()
    work = make_work(model.n)
    dy = np.empty_like(y)
    dynamics(0.0, y, model.arrays, np.zeros(2, np.int64), np.eye(2), dy, np.empty((2, NAUX)), work)
    energies(y, model.arrays, work, np.empty(5))
    assert sum(len(fn.nopython_signatures) for fn in BORROWING) > 0
    assert borrowing_violations() == []
