"""Forces that follow their travel ([[force]] travel and share tables): statics, the work they
put in, bad input.

The rig of tests/mech/test_mech_travel_springs.py: a rigid steel arm on a hinge without
stiffness, a linear spring at its free end to an anchor 1 m straight below, the force at the
same point pressing straight down. The force's travel is the point's drop, computed here
from the arm's angle by the rigid geometry, not by the force's code.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from mech.scene import scene_from_dict
from mech.solver import ImpactSolver

from test_mech_travel_springs import LEVER, arm

F = 3.0  # N: the force's magnitude
K = 2000.0  # N/m: the spring that carries it
A, B = 1.0e-3, 1.5e-3  # m: the force's full share up to A, none beyond B (a finger at the key's stop)
LIMIT = dict(travel=[0.0, A, B], share=[1.0, 1.0, 0.0])


def drop(states: np.ndarray) -> np.ndarray:
    """m: the force's point's drop below its start per state row (x, z, angle, ...): the
    hinge + R_y(angle) (-LEVER, 0, 0)."""
    z = states[:, 1] + LEVER * np.sin(states[:, 2])
    return z[0] - z


def test_a_force_that_follows_its_travel_settles_where_the_spring_takes_its_share():
    """A 3 N force whose share falls linearly from 1 at A to 0 at B, on a spring of 2000 N/m
    (which alone would go to 1.5 mm, past B): the static balance K x = F (B - x) / (B - A)
    gives x = F B / (K (B - A) + F) = 1.125 mm, between A and B. The dashpot (8 % of
    critical) rings the arm down within 0.2 s to far below 1e-6 of x; the force's travel
    (the point's drop) and the spring's differ by the arc's (x / 1 m)^2 / 2; within 1e-6."""
    doc = arm([dict(stiffness=K, damping=0.5)], [dict(magnitude=F, **LIMIT)], gap=5e-3, t_end=0.2)
    solver = ImpactSolver(scene_from_dict(doc))
    solver.advance(0.2)
    x = drop(solver.result().states)
    expected = F * B / (K * (B - A) + F)
    assert A < expected < B
    assert x[-1] == pytest.approx(expected, rel=1e-6)


def test_the_work_of_a_force_that_follows_its_travel_is_put_in_and_the_audit_closes():
    """A finger pressing to 3 N over 20 ms and releasing over 20 ms, stopped by its share at
    the key's travel (the spring alone would take it past B): its work in the audit
    (work_in, the kernel's quadrature of F . v) against the trapezoidal rule on the records
    of value(t) share(x) dx (x the rigid geometry's drop; 1e-4: the trapezoids'
    error on records 20 us apart, O(h^2) and O(h) at the force's kinks: measured 6e-6, against 8e-4 on
    records 200 us apart), and the audit's relative residual below
    100 times the run's rtol (the conservation tests' bound). The travel stays below B."""
    press = dict(time=[0.0, 0.02, 0.04], value=[0.0, F, 0.0], **LIMIT)
    doc = arm([dict(stiffness=K, damping=0.5)], [press], gap=5e-3, t_end=0.05)
    solver = ImpactSolver(scene_from_dict(doc))
    for t in np.linspace(0.0, 0.05, 2501)[1:]:  # a record every 20 us: fine enough for the trapezoids
        solver.advance(t)
    res = solver.result()
    x = drop(res.states)
    force = np.interp(res.t, press["time"], press["value"]) * np.interp(x, LIMIT["travel"], LIMIT["share"])
    work = float(np.sum(0.5 * (force[1:] + force[:-1]) * np.diff(x)))
    assert x.max() > A and x.max() < B  # (the share acted)
    assert res.energy_columns["work_in"][-1] == pytest.approx(work, rel=1e-4)
    assert res.energy["relative_residual"] < 100 * 1e-6
    assert not res.flags


@pytest.mark.parametrize("entry, words", [
    (dict(magnitude=1.0, travel=[0.0, 2e-4, 1e-4], share=[1.0, 1.0, 0.0]), "force[0].travel[2] = 0.0001: travels must increase"),
    (dict(magnitude=1.0, travel=[0.0, 1e-4], share=[1.0, 0.5, 0.0]), "force[0].share: 3 shares for 2 travels"),
    (dict(magnitude=1.0, travel=[0.0, 1e-4], share=[1.0, 1.5]), "force[0].share[1] = 1.5: allowed range is [0.0, 1.0]"),
    (dict(magnitude=1.0, travel=[0.0, 1e-4]), "force[0].share: missing"),
    (dict(magnitude=1.0, share=[1.0, 0.0]), "force[0].travel: missing"),
    (dict(magnitude=1.0, travel=[1e-4], share=[1.0]), "force[0].travel = [0.0001]: 1 point(s)"),
    (dict(magnitude=1.0, travel=[0.0, "a"], share=[1.0, 0.0]), "force[0].travel = [0.0, 'a']: expected a list"),
    (dict(magnitude=1.0, travel=[0.0, 1e-4], share=[1.0, math.nan]), "force[0].share[1] = nan"),
    (dict(magnitude=1.0, frame="body", travel=[0.0, 1e-4], share=[1.0, 0.0]), "force[0].frame = 'body' is not allowed"),
])
def test_a_bad_travel_table_of_a_force_is_refused_in_one_line_naming_the_key(entry, words):
    with pytest.raises(ValueError) as err:
        scene_from_dict(arm([dict(stiffness=K)], [entry]))
    message = str(err.value)
    assert words in message and "\n" not in message
