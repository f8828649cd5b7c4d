"""Independent integration routes agree: the compiled DOPRI5 against scipy's DOP853 and
Radau on the same right-hand side and events, chunked advance() against run(), the dense
output against the records; failures and energy flags are reported, never hidden."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import mech
from mech import CoupledStates, ImpactSolver, MechSolverError

COLUMNS_TIME = ["t_start", "t_end"]


def default_truncated(t_end: float, rtol: float, **solver_changes):
    """The default scene (3D, 3 modes per family, damped contact, gamma = 0.7 friction),
    stopped after its first bounces."""
    base = mech.default_scene()
    # pinned to 3 modes per family (the default before modes = "auto"): these tests compare
    # integration routes on a fixed model, not the mode count
    bar = dataclasses.replace(base.bar, axial_modes=3, bending_modes=3)
    return dataclasses.replace(base, bar=bar, solver=dataclasses.replace(base.solver, rtol=rtol, t_end=t_end,
                                                                         **solver_changes))


def assert_same_contacts(a, b, time_rtol=1e-6, rtol=1e-4, energetic_rtol=1e-4):
    """Same contacts; the energetic (Stronge) restitution gets its own tolerance: it is the
    ratio of the work quadratures split at maximum compression, an integrand kink that is not
    an event, so it converges more slowly than the rest (2e-5 at rtol 1e-8, 4e-6 at 1e-10
    between two routes)."""
    ca, cb = a.contacts, b.contacts
    assert len(ca) == len(cb) >= 1
    assert list(ca.tip) == list(cb.tip)
    np.testing.assert_allclose(ca[COLUMNS_TIME], cb[COLUMNS_TIME], rtol=time_rtol)
    np.testing.assert_allclose(ca.impulse, cb.impulse, rtol=rtol)
    np.testing.assert_allclose(ca.kinematic_restitution, cb.kinematic_restitution, rtol=rtol)
    np.testing.assert_allclose(ca.energetic_restitution, cb.energetic_restitution, rtol=energetic_rtol)


@pytest.fixture(scope="module")
def dopri5_run():
    return ImpactSolver(default_truncated(2.5e-3, 1e-10)).run()


def test_compiled_dopri5_agrees_with_scipy_dop853_on_the_default_scene(dopri5_run):
    # Four bounces with slip turns and force clipping (2.5 ms). Both routes at rtol 1e-10:
    # different methods, step controls and event locators. (At 1e-9 a stick/slip decision
    # is not yet resolved: the two routes' contact times differ by ~2.5e-10 s, at 1e-10 and
    # 1e-11 by ~1.5e-12 s, measured; the end-state bound below then compared two errors.)
    dop853 = ImpactSolver(default_truncated(2.5e-3, 1e-10), backend="scipy:DOP853").run()
    assert len(dopri5_run.contacts) == 4
    assert_same_contacts(dopri5_run, dop853)
    # the state at the end, in free flight after the bounces, to 1e-6 of the error scales
    # (Hertz penetration for positions and modes, impact speed for speeds)
    scales = dopri5_run.model.atol / dopri5_run.model.scene.solver.rtol
    assert np.all(np.abs(dop853.states[-1] - dopri5_run.states[-1]) <= 1e-6 * scales + 1e-6 * np.abs(dopri5_run.states[-1]))
    # the dissipation quadratures
    for key in ("normal_dissipation", "friction_dissipation"):
        assert dop853.energy[key] == pytest.approx(dopri5_run.energy[key], rel=1e-4)


def test_compiled_dopri5_agrees_with_scipy_radau_on_the_first_two_bounces(dopri5_run):
    radau = ImpactSolver(default_truncated(1.4e-3, 1e-7), backend="scipy:Radau").run()
    assert len(radau.contacts) == 2
    reference = dopri5_run.contacts.iloc[:2]
    c = radau.contacts
    np.testing.assert_allclose(c[COLUMNS_TIME], reference[COLUMNS_TIME], rtol=1e-6)
    for col in ("impulse", "kinematic_restitution", "energetic_restitution"):
        np.testing.assert_allclose(c[col], reference[col], rtol=1e-4, err_msg=col)


def test_advance_in_macro_steps_gives_the_result_of_one_run():
    # rtol 1e-10: at 1e-9 each route's contact times are ~1e-8 (relative) off the converged
    # ones (measured against rtol 1e-12), the size of the tolerance below, which would then
    # compare two errors; at 1e-10 the two routes agree to ~7e-10
    scene = default_truncated(2.5e-3, 1e-10)
    one_run = ImpactSolver(scene).run()
    solver = ImpactSolver(scene)
    segments = []
    # 25 macro steps of 0.1 ms, like the coupling; every step ends exactly at its target
    for k in range(1, 26):
        seg = solver.advance(k * 1e-4)
        assert seg.t_end == solver.t == pytest.approx(k * 1e-4, rel=1e-15)
        segments.append(seg)
    chunked = solver.result()
    # each macro step ends with a truncated step: the two runs take different steps and
    # agree to the integration tolerance
    assert_same_contacts(one_run, chunked, time_rtol=1e-8, rtol=1e-6)
    scales = chunked.model.atol / scene.solver.rtol
    assert np.all(np.abs(chunked.states[-1] - one_run.states[-1]) <= 1e-6 * scales + 1e-6 * np.abs(one_run.states[-1]))
    # The segments' events are the run's events, each in the segment that contains it.
    events = [ev for seg in segments for ev in seg.events]
    assert [e["kind"] for e in events] == [e["kind"] for e in chunked.events]
    for seg in segments:
        assert all(seg.t_start <= e["time"] <= seg.t_end for e in seg.events)


def test_segment_dense_output_matches_the_recorded_history():
    scene = default_truncated(1.4e-3, 1e-8)
    solver = ImpactSolver(scene, keep_dense=True)
    seg = solver.advance(1.4e-3)
    res = solver.result()
    # At the record times the dense output is the step's end state.
    for k in range(1, len(res.t), 7):
        y = seg.state(res.t[k])
        scale = np.maximum(np.abs(res.states[k]), 1e-300)
        assert np.max(np.abs(y - res.states[k]) / np.maximum(scale, np.abs(res.model.atol[: len(y)]))) < 1e-9
        contact = seg.contact(res.t[k])
        np.testing.assert_allclose(contact[:, 2], res.aux[k, :, 2], rtol=1e-8, atol=1e-9 * res.peak_force.max())
    # Between records the contact force is continuous; its maximum is the recorded peak
    # (sampled at five points per step, so it may lie a little below: (h/t_c)^2-small).
    c = res.contacts.iloc[0]
    ts = np.linspace(c.t_start, c.t_end, 2000)
    force = np.array([seg.normal_force(t) for t in ts])
    assert force.max() == pytest.approx(c.peak_force, rel=1e-4)
    assert np.all(force >= 0.0)
    assert np.max(np.abs(np.diff(force))) < 0.05 * c.peak_force
    with pytest.raises(ValueError, match="outside the segment"):
        seg.state(1.5e-3)


def test_solver_failure_raises_with_time_state_and_partial_result():
    scene = default_truncated(5e-3, 1e-6, max_steps=50)
    solver = ImpactSolver(scene)
    with pytest.raises(MechSolverError, match="too many steps") as info:
        solver.run()
    err = info.value
    assert 0.0 < err.t < 5e-3
    assert set(err.state) >= {"pos", "vel", "omega", "q", "eta"}
    partial = err.partial_result
    assert partial is not None and partial.t[-1] == pytest.approx(err.t)
    assert partial.stats["steps"] <= 50
    np.testing.assert_allclose(err.state["pos"], partial.states[-1, :3])


def test_energy_residual_above_the_tolerance_is_flagged():
    scene = default_truncated(1.4e-3, 1e-6)
    res = mech.simulate(scene)
    assert res.flags == []
    tight = default_truncated(1.4e-3, 1e-6, energy_tolerance=1e-12)
    flagged = mech.simulate(tight)
    assert any("energy residual" in f for f in flagged.flags)
    assert flagged.energy["relative_residual"] > 1e-12
    assert "energy residual" in " ".join(flagged.to_summary()["flags"])


def test_backend_choices_are_validated():
    scene = default_truncated(1e-3, 1e-6)
    with pytest.raises(ValueError, match="backend"):
        ImpactSolver(scene, backend="scipy:Euler")
    with pytest.raises(ValueError, match="keep_dense"):
        ImpactSolver(scene, backend="scipy:Radau", keep_dense=True)
    states = CoupledStates(np.zeros(1), np.ones(1), lambda t, z, c: np.zeros(1), lambda t, z: 0.3)
    with pytest.raises(ValueError, match="coupled"):
        ImpactSolver(scene, coupled=states)


def test_coupled_states_integrate_in_the_same_solve_as_the_mechanics():
    """An extra state z' = total normal force integrates the normal impulse; a constant
    friction coefficient equal to the scene's leaves the mechanics unchanged."""
    scene = default_truncated(1.4e-3, 1e-8)
    plain = ImpactSolver(scene, backend="scipy:DOP853").run()
    mu = scene.friction.mu
    states = CoupledStates(initial=np.zeros(1), atol=np.array([1e-12]),
                           rhs=lambda t, z, contact: np.array([contact[:, 2].sum()]),
                           friction_coefficient=lambda t, z: mu)
    coupled = ImpactSolver(scene, backend="scipy:DOP853", coupled=states).run()
    # the extra state enters the error norm, so the steps differ at the tolerance level
    assert_same_contacts(plain, coupled, time_rtol=1e-7, rtol=1e-5)
    assert coupled.extra_states[-1, 0] == pytest.approx(coupled.contacts.impulse.sum(), rel=1e-6)


def test_advance_stopping_at_each_make_and_break_gives_the_result_of_one_run():
    """stop_at_switch ends a segment at the first contact start or end: the segments end
    exactly at the one run's contact times, and going on from there gives its contacts."""
    scene = default_truncated(2.5e-3, 1e-10)
    one_run = ImpactSolver(scene).run()
    solver = ImpactSolver(scene)
    ends = []
    while solver.t < 2.5e-3:
        seg = solver.advance(2.5e-3, stop_at_switch=True)
        ends.append(seg.t_end)
        if seg.t_end < 2.5e-3:
            assert seg.events[-1]["kind"] in ("contact_start", "contact_end") and seg.events[-1]["time"] == seg.t_end
    switches = sorted(one_run.contacts.t_start.tolist() + one_run.contacts.t_end.tolist())
    np.testing.assert_allclose(ends[:-1], switches, rtol=1e-8)
    assert ends[-1] == 2.5e-3
    assert_same_contacts(one_run, solver.result(), time_rtol=1e-8, rtol=1e-6)
