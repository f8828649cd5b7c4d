"""The solver core's internal interface: the history recorder, the model that a run never
changes, and the friction coefficient passed in per step (the drive) rather than written
into the model."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import mech
from mech import ImpactSolver
from mech.model import build_model
from mech.recorder import Recorder


def sliding_scene(mu: float, t_end: float = 1.6e-3):
    """The default scene (a tilted 3D drop with gamma = 0.7 friction), 3 modes per family,
    stopped after its first three contacts (0.99-1.57 ms): the tip slides, so mu shapes the motion."""
    base = mech.default_scene()
    bar = dataclasses.replace(base.bar, axial_modes=3, bending_modes=3)
    return dataclasses.replace(base, bar=bar, friction=dataclasses.replace(base.friction, mu=mu),
                               solver=dataclasses.replace(base.solver, t_end=t_end))


def test_recorder_keeps_every_row_through_growth_and_truncation():
    rng = np.random.default_rng(4)
    rec = Recorder(state_size=3, n_extra=1, capacity=2, keep_dense=True)
    rows = []
    for k in range(37):  # grows 2 -> 64, five times
        t, y, aux, reg, ext = float(k), rng.normal(size=3), rng.normal(size=(2, 8)), rng.integers(0, 3, 2), [k]
        rec.append(t, y, aux, reg, np.array(ext, float))
        rows.append((t, y, aux, reg))
    assert rec.n == 37 and rec.capacity == 64
    cols = rec.columns()
    np.testing.assert_array_equal(cols["t"], [r[0] for r in rows])
    np.testing.assert_array_equal(cols["states"], [r[1] for r in rows])
    np.testing.assert_array_equal(cols["aux"], [r[2] for r in rows])
    np.testing.assert_array_equal(cols["regimes"], [r[3] for r in rows])
    np.testing.assert_array_equal(cols["peak_force"], [r[2][:, 2] for r in rows])  # A_FN of a point
    t0, h, coef = rec.dense()
    np.testing.assert_array_equal(coef[:, 0], cols["states"])  # a point's dense output is its state
    rec.truncate(10)
    rec.append(99.0, np.zeros(3), np.zeros((2, 8)), np.zeros(2, np.int64), np.zeros(1))
    assert rec.n == 11 and rec.columns()["t"][-1] == 99.0
    np.testing.assert_array_equal(rec.columns()["t"][:10], np.arange(10.0))
    with pytest.raises(ValueError, match="n = 12"):
        rec.truncate(12)
    # a stepper writes into free_rows from n on; commit counts them with their regime
    (t_rows, y_rows, _, _), _ = rec.free_rows()
    t_rows[:2] = (100.0, 101.0)
    y_rows[:2] = 1.0
    rec.commit(2, np.array([2, 1]))
    assert list(rec.columns()["t"][-3:]) == [99.0, 100.0, 101.0]
    assert rec.columns()["regimes"][-1].tolist() == [2, 1]


def test_free_window_is_free_rows_as_buffers_and_offsets():
    """The compiled stepper gets the free rows as the recorder's buffers and where they start
    (free_window): cut there, they are free_rows' views, row for row, with and without the
    dense output and after the buffers grew; the buffers' tuples are the same objects while
    the buffers are (the argument check passes them by identity)."""
    for keep_dense in (True, False):
        rec = Recorder(state_size=3, n_extra=1, capacity=4, keep_dense=keep_dense)
        first_tuples = None
        for k in range(11):  # grows 4 -> 8 -> 16
            rec.reserve(1)
            bufs, dense, first, dense_first, room = rec.free_window()
            rows, dense_rows = rec.free_rows()
            cuts = [b[first:first + room] for b in bufs] + [b[dense_first:dense_first + room] for b in dense]
            for cut, view in zip(cuts, rows + dense_rows):  # the same rows of the same memory
                assert cut.shape == view.shape and cut.strides == view.strides
                assert cut.__array_interface__["data"] == view.__array_interface__["data"]
            again = rec.free_window()
            assert again[0] is bufs and again[1] is dense
            if first_tuples is None:
                first_tuples = (bufs, dense)
            rec.append(float(k), np.full(3, k), np.zeros((2, 8)), np.zeros(2, np.int64), np.zeros(1))
        assert rec.capacity == 16 and rec.free_window()[0] is not first_tuples[0]  # new buffers, a new tuple


def test_a_run_leaves_its_model_as_built():
    solver = ImpactSolver(sliding_scene(0.3), keep_dense=True)
    fresh = build_model(sliding_scene(0.3))
    solver.advance(1.0e-3, mu=0.9)
    solver.advance(1.3e-3, mu=(0.9, 0.05))
    solver.advance(1.6e-3)
    # the solver's friction coefficient moved (and held its value after the ramp) ...
    assert solver.drives_now() == pytest.approx({"mu.0": 0.05, "mu.1": 0.05, "repulsion.0": 0.0, "repulsion.1": 0.0})
    for got, built in zip(solver.model.arrays[:-1], fresh.arrays[:-1]):  # ... its model did not
        np.testing.assert_array_equal(got, built)
    with pytest.raises(dataclasses.FrozenInstanceError):
        solver.model.max_step = 1.0


def test_mu_given_per_step_is_the_mu_the_motion_feels():
    """A scene with mu = 0.8 advanced with mu = 0.25 moves exactly as the scene with 0.25, and
    not as with 0.8 (the kernel reads the drive, not the model)."""
    given = ImpactSolver(sliding_scene(0.8))
    given.advance(1.6e-3, mu=0.25)
    same, other = ImpactSolver(sliding_scene(0.25)).run(), ImpactSolver(sliding_scene(0.8)).run()
    got = given.result()
    assert any(e["kind"] in ("slip_turn", "stick", "slip") for e in same.events)  # friction acts in this window
    np.testing.assert_array_equal(got.states[-1], same.states[-1])
    assert not np.allclose(other.states[-1], same.states[-1], rtol=1e-6, atol=0.0)


def test_restore_returns_to_the_friction_coefficient_of_its_checkpoint():
    solver = ImpactSolver(sliding_scene(0.3), keep_dense=True)
    solver.advance(1.0e-3, mu=0.6)
    cp = solver.checkpoint()
    first = solver.advance(1.6e-3)
    end_first = solver.y.copy()
    solver.advance(1.6e-3 + 1e-9, mu=0.02)  # another mu after the checkpoint ...
    solver.restore(cp)  # ... is forgotten with the rows after it
    second = solver.advance(1.6e-3)
    np.testing.assert_array_equal(solver.y, end_first)
    assert [e["time"] for e in first.events] == [e["time"] for e in second.events]
