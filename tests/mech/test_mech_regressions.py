"""Regression tests for the regime-switching bugs found while testing mech.

1. Two colinear stick points of a rigid bar: singular stick matrix (now a minimum-norm
   solve of the statically indeterminate holding forces).
2. A stick-limit event re-firing at one instant (the triggered tip now slips).
3. A slipping tip coming to rest not caught (friction now keeps the reference direction
   past zero slip, so the slip event sees the crossing).
4-6. scipy backends: first step beyond a short macro step, clip events in the air,
   peak force between step ends.
Before the fixes each case failed or ran for minutes (Zeno chatter); now they run in seconds.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

import mech
from mech import ImpactSolver

from mech_cases import start_from
from test_mech_friction import MU_SLIDE, T_STOP, lying_bar


def default_truncated(t_end, rtol):
    base = mech.default_scene()
    # pinned to 3 modes per family (the default before modes = "auto"): the regression
    # tests using it are about event and peak-force handling on a fixed model
    bar = dataclasses.replace(base.bar, axial_modes=3, bending_modes=3)
    return dataclasses.replace(base, bar=bar, solver=dataclasses.replace(base.solver, rtol=rtol, t_end=t_end))


# Bug 1: a rigid bar lying on both tips cannot stick on both (singular stick matrix).
@pytest.mark.parametrize("model", ["planar", "3d"])
def test_rigid_sliding_bar_stops_at_v0_over_mu_g_and_then_both_tips_stick(model):
    solver = lying_bar(1.3 * T_STOP, axial_modes=0)
    if model == "3d":
        scene = dataclasses.replace(solver.scene, solver=dataclasses.replace(solver.scene.solver, model="3d"))
        z = solver.y[1]
        solver = ImpactSolver(scene)
        pos = solver.y[solver.model.slices()["pos"]].copy()
        pos[2] = z
        start_from(solver, pos=pos)
    res = solver.run()
    ev = res.event_table
    assert list(ev.kind) == ["stick_start"]
    assert ev.time[0] == pytest.approx(T_STOP, rel=1e-4)
    ph = res.phases
    for i in range(2):
        assert list(ph[ph.tip == i].regime) == ["slip", "stick"]
    h = res.history
    after = h[h.time > 1.01 * T_STOP]
    for i in range(2):
        assert (abs(after[f"friction_x_{i}"]) <= MU_SLIDE * after[f"normal_force_{i}"]).all()


# Bug 2: scipy backends: advance() to a target closer than the last step raises ValueError.
@pytest.mark.parametrize("backend", ["scipy:DOP853", "scipy:Radau"])
def test_scipy_backend_advances_in_macro_steps_shorter_than_its_last_step(backend):
    solver = ImpactSolver(default_truncated(2.5e-3, 1e-6), backend=backend)
    solver.advance(0.5e-3)
    solver.advance(0.5e-3 + 1e-7)  # ValueError: `first_step` exceeds bounds.
    assert solver.t == pytest.approx(0.5e-3 + 1e-7)


# Bug 3: scipy backends fire force-clip events while the tip is in the air.
def test_scipy_backend_reports_force_clip_events_only_in_contact():
    res = ImpactSolver(default_truncated(2.5e-3, 1e-8), backend="scipy:DOP853").run()
    clips = [e for e in res.events if e["kind"].startswith("force_clip")]
    assert all(e["penetration"] > -1e-12 for e in clips), [(e["time"], e["penetration"]) for e in clips]


# Bug 4: scipy backends record the peak force at step ends only (compiled loop: 5 points/step).
def test_scipy_backend_peak_force_is_the_contact_force_maximum():
    scene = default_truncated(1.2e-3, 1e-10)
    solver = ImpactSolver(scene, keep_dense=True)
    seg = solver.advance(1.2e-3)
    c = solver.result().contacts.iloc[0]
    ts = np.linspace(c.t_start, c.t_end, 2001)
    k = int(np.argmax([seg.normal_force(t) for t in ts]))
    true_peak = -minimize_scalar(lambda t: -seg.normal_force(t), bounds=(ts[k - 1], ts[k + 1]),
                                 method="bounded", options=dict(xatol=1e-13)).fun
    dop853 = ImpactSolver(default_truncated(1.2e-3, 1e-8), backend="scipy:DOP853").run()
    assert dop853.contacts.peak_force[0] == pytest.approx(true_peak, rel=1e-4)


def tilted_frictional_drop(angle_deg, velocity, mu, modes, max_steps=5_000_000):
    from mech_cases import make_scene
    return make_scene(bar=dict(axial_modes=modes, bending_modes=modes), contact=dict(restitution=0.7),
                      friction=dict(mu=mu), initial=dict(height=1e-5, angle_deg=angle_deg, velocity=velocity),
                      solver=dict(rtol=1e-8, t_end=1.5e-3, max_steps=max_steps), gravity=9.81)


# Bug 5: a stick_end event keeps the tip stuck when the located margin is within -1e-9 of the
# limit (solver._resolve's threshold): the event fires again at once, thousands of times at
# the same instant, forever when t stops advancing (the paper's basic oblique drop).
@pytest.mark.parametrize("angle_deg, velocity, mu, gamma, modes, height, rtol", [
    (30.0, (0.05, 0.0, -0.5), 0.5, 0.0, 2, 1e-5, 1e-8),  # 4509 stick_end at t = 1.0927 ms, then goes on
    (45.0, (0.0, 0.0, -0.5), 0.3, 0.7, 0, 1e-4, 1e-7),   # touchdown in stick, the loop never ends
    (10.0, (0.0, 0.0, -0.5), 0.3, 0.7, 0, 1e-4, 1e-7),
])
def test_stick_end_switches_the_tip_to_slip_once(angle_deg, velocity, mu, gamma, modes, height, rtol):
    from mech_cases import make_scene
    scene = make_scene(bar=dict(axial_modes=modes, bending_modes=modes), contact=dict(restitution=0.7),
                       friction=dict(mu=mu, gamma=gamma),
                       initial=dict(height=height, angle_deg=angle_deg, velocity=velocity),
                       solver=dict(rtol=rtol, t_end=1.5e-3, max_steps=100_000), gravity=9.81)
    res = mech.simulate(scene)
    ends = [e for e in res.events if e["kind"] == "stick_end"]
    assert len(ends) <= 3, len(ends)
    assert all(e["regime_after"] == "slip" for e in ends)


# Bug 6: a slipping tip whose slip speed reaches zero is never stopped: the slip friction
# follows the actual slip direction, flips inside the steps that straddle v_t = 0, the event
# v_t . e_ref never changes sign at a step end, and the steps shrink to ~1e-12 s.
@pytest.mark.parametrize("angle_deg, velocity, mu", [
    (60.0, (-0.2, 0.0, -0.5), 0.6),   # 1.33 million steps, 20 s for 1 ms without the cap
    (80.0, (-0.3, 0.0, -0.5), 0.3),
])
def test_slipping_tip_coming_to_rest_is_caught_by_the_stick_event(angle_deg, velocity, mu):
    from mech_cases import make_scene
    scene = make_scene(contact=dict(restitution=0.7), friction=dict(mu=mu),
                       initial=dict(height=1e-5, angle_deg=angle_deg, velocity=velocity),
                       solver=dict(rtol=1e-8, t_end=1.0e-3, max_steps=100_000), gravity=9.81)
    res = mech.simulate(scene)  # MechSolverError: too many steps
    kinds = [e["kind"] for e in res.events]
    assert "stick_start" in kinds
    assert res.stats["steps"] < 5000


# Bug 1 again, from a flat landing: a rigid bar touching down on both tips at once.
@pytest.mark.parametrize("vx", [0.0, 0.3])
def test_rigid_bar_landing_flat_with_friction_runs(vx):
    from mech_cases import make_scene
    scene = make_scene(contact=dict(restitution=0.7), friction=dict(mu=0.8),
                       initial=dict(height=1e-4, angle_deg=0.0, velocity=(vx, 0.0, -0.5)),
                       solver=dict(rtol=1e-7, t_end=5e-3, max_steps=100_000), gravity=9.81)
    res = mech.simulate(scene)  # vx = 0: LinAlgError (singular); vx = 0.3: slip_reversal storm
    assert len(res.events) < 100
