"""A run's memory follows what it keeps: the history thinned as it is made (contacts,
phases and the checks' extremes unchanged), the dense output of one macro step, a
MemoryError turned into a failed run with its partial result, a contact sunk beyond its
cap stopped, and every scene value that could overflow refused naming the key written."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import mech
from mech.kernel_layout import A_Y
from mech.recorder import CHUNK, MEMORY_LIMIT, Recorder, history_memory, row_bytes
from mech.scene import scene_from_dict
from mech.solver import ImpactSolver, MechSolverError


def drop(rows: int, t_end: float = 0.05):
    """The mechanics default (the source paper's steel link, 3D, bouncing), keeping ``rows``."""
    base = mech.default_scene()
    return dataclasses.replace(base, solver=dataclasses.replace(base.solver, history_rows=rows, t_end=t_end))


@pytest.fixture(scope="module")
def full_and_thinned():
    return ImpactSolver(drop(100_000)).run(), ImpactSolver(drop(1000)).run()


def test_a_thinned_history_is_a_subset_of_every_step_with_the_same_contacts_and_extremes(full_and_thinned):
    """9 588 steps kept in 1 000 rows' worth. The stepper's room ends where it would without
    thinning (counted in rows recorded), so both runs take the same steps in one process,
    and every comparison is exact: the thinned history is a subset of the full one's rows,
    and the contact table, the phases and every extreme the checks read are the same."""
    full, thin = full_and_thinned
    assert thin.thinning is not None and thin.thinning["rows_dropped"] > 0.5 * len(full.t)
    assert len(thin.t) < 0.25 * len(full.t)
    h = thin.solver["history"]
    assert h["rows"] == len(thin.t) and h["resolution"] > 0 and 0 < h["thinned_until"] < 0.05
    # of the thinned span, one row per interval of the grid, plus the event and regime rows
    span_rows = int(np.count_nonzero(thin.t <= h["thinned_until"]))
    assert span_rows <= h["thinned_until"] / h["resolution"] + 4 * (len(thin.events) + 2) + 2
    k = np.searchsorted(full.t, thin.t)
    np.testing.assert_array_equal(full.t[k], thin.t)
    np.testing.assert_array_equal(full.states[k], thin.states)
    np.testing.assert_array_equal(full.regimes[k], thin.regimes)
    assert full.events == thin.events
    for key, column in full.contact_columns.items():
        np.testing.assert_array_equal(thin.contact_columns[key], column)
    for key, column in full.phase_columns.items():
        assert list(thin.phase_columns[key]) == list(column)
    # the deepest penetration is at the first impact, long thinned away: kept as an extreme
    assert np.max(thin.aux[:, :, A_Y]) < full.deepest_penetration == thin.deepest_penetration
    assert (thin.max_kinetic, thin.max_speed, thin.max_abs_residual, thin.energy_scale) == (
        full.max_kinetic, full.max_speed, full.max_abs_residual, full.energy_scale)
    assert thin.energy == full.energy and thin.flags == full.flags


def test_thinning_keeps_the_peak_force_of_the_rows_it_drops():
    rec = Recorder(state_size=1, capacity=16)
    for k, f in enumerate([0.0, 5.0, 1.0, 7.0, 2.0, 3.0]):
        aux = np.zeros((2, 8))
        aux[0, 2] = f  # A_FN
        rec.append(float(k), np.zeros(1), aux, np.zeros(2, np.int64), np.zeros(0))
    keep = np.array([True, False, True, False, False, True])
    assert rec.thin(keep) == 3 and rec.n == 3
    assert list(rec.t[:3]) == [0.0, 2.0, 5.0]
    # each kept row's peak: the largest over the rows back to the kept row before it
    assert list(rec.fmax[:3, 0]) == [0.0, 5.0, 7.0]


def test_after_a_release_the_dense_buffer_holds_only_the_later_steps():
    scene = drop(100_000, t_end=2e-3)
    solver = ImpactSolver(scene, keep_dense=True)
    solver.advance(1e-3)
    first = solver.contact_series(np.linspace(0.0, 1e-3, 7))
    solver.release_dense()
    with pytest.raises(ValueError, match="released"):
        solver.contact_series([0.5e-3])
    solver.advance(2e-3)
    later = solver.contact_series(np.linspace(1e-3, 2e-3, 5))
    # the same instants from a solver that never released anything
    ref = ImpactSolver(scene, keep_dense=True)
    ref.advance(1e-3)
    ref.advance(2e-3)
    np.testing.assert_array_equal(ref.contact_series(np.linspace(0.0, 1e-3, 7)), first)
    np.testing.assert_array_equal(ref.contact_series(np.linspace(1e-3, 2e-3, 5)), later)
    rec = solver.recorder
    assert 0 < rec.dense_base < rec.n
    rows, dense = rec.free_rows()
    assert len(rows[0]) == len(dense[0])  # a stepper filling one never overruns the other


def test_running_out_of_memory_is_a_failed_run_with_its_partial_result(monkeypatch):
    """The recorder cannot grow past 8 192 rows: the run ends in one line and keeps what it
    computed (a default drop takes ~9 600 steps)."""
    grow = Recorder.grow

    def limited(self, cap):
        if cap > 8192:
            raise MemoryError("Unable to allocate 128. MiB for an array")
        grow(self, cap)

    monkeypatch.setattr(Recorder, "grow", limited)
    solver = ImpactSolver(drop(100_000))
    with pytest.raises(MechSolverError) as info:
        solver.run()
    message = str(info.value)
    assert "out of memory" in message and "MemoryError" in message and "\n" not in message
    partial = info.value.partial_result
    assert partial is not None and len(partial.t) >= 8000 and partial.t[-1] == pytest.approx(info.value.t)


def test_a_contact_sunk_beyond_its_cap_stops_the_run_at_once():
    """A blade pressed by 5 MN (the audit's relay case, on a steel blade): its rivet sinks
    past its 1.5 mm radius within the first millisecond; the run stops there."""
    doc = {
        "bar": dict(length=0.02, width=0.003, thickness=0.0003, tip_radius=0.0016, youngs_modulus=210e9,
                    poisson_ratio=0.3, density=7850.0, modes={"axial": 1, "bending": 4}),
        "mount": dict(kind="clamp", position=0.02),
        "rivet": [dict(position=0.0015, radius=0.0015)],
        "force": [dict(position=0.01, time=[0.0, 0.003], value=[0.0, 5e6])],
        "initial": dict(height=1e-4), "contact": dict(law="hunt_crossley", restitution=0.5),
        "solver": dict(t_end=0.005), "environment": dict(gravity=0.0),
    }
    with pytest.raises(MechSolverError) as info:
        ImpactSolver(scene_from_dict(doc)).run()
    err = info.value
    assert "contact point 0" in str(err) and "0.0015 m radius" in str(err) and err.t < 1e-3
    assert err.partial_result.deepest_penetration > 1.5e-3


def test_a_history_that_could_not_fit_in_memory_is_refused_naming_its_key():
    scene = mech.default_scene()
    big = dataclasses.replace(scene, bar=dataclasses.replace(scene.bar, axial_modes=40, bending_modes=40),
                              solver=dataclasses.replace(scene.solver, history_rows=10_000_000))
    with pytest.raises(ValueError) as info:
        ImpactSolver(big)
    assert "solver.history_rows = 10000000" in str(info.value) and "GiB" in str(info.value)
    # the estimate: the rows twice while they double, a stepper's room (CHUNK) twice, the
    # result's copy, each row 8 x (21 + 262) bytes (state: 13 + 2 x 120 modes + 9 quadratures)
    assert history_memory(262, 10_000_000) == (3 * 10_000_000 + 2 * CHUNK) * 8 * (21 + 262) > MEMORY_LIMIT
    assert row_bytes(262) == 8 * (21 + 262)


@pytest.mark.parametrize("section, key, value, named", [
    ("bar", "length", 1e300, "bar.length = 1e+300"),
    ("bar", "diameter", 1e300, "bar.diameter = 1e+300"),  # (was: tip_radius, half the section ...)
    ("bar", "density", 1e-3, "bar.density = 0.001"),
    ("initial", "velocity", [0.0, 0.0, -1e300], "initial.velocity[2] = -1e+300"),
    ("initial", "angular_velocity", [1e300, 0.0, 0.0], "initial.angular_velocity[0] = 1e+300"),
    ("solver", "t_end", 1e300, "solver.t_end = 1e+300"),
    ("solver", "energy_tolerance", 1e300, "solver.energy_tolerance = 1e+300"),
    ("solver", "energy_tolerance", 0.01, "solver.energy_tolerance = 0.01"),
    ("solver", "max_steps", 10**9, "solver.max_steps = 1000000000"),
    ("solver", "history_rows", 10, "solver.history_rows = 10"),
    ("environment", "gravity", 1e300, "environment.gravity = 1e+300"),
])
def test_a_value_that_would_overflow_or_run_unbounded_is_refused_naming_the_key(section, key, value, named):
    with pytest.raises(ValueError) as info:
        scene_from_dict({section: {key: value}})
    message = str(info.value)
    assert named in message and "allowed range" in message or "whole number in" in message
    assert "\n" not in message


@pytest.mark.parametrize("doc, named", [
    ({"force": [{"position": 0.1, "magnitude": 1e300}]}, "force[0].magnitude = 1e+300"),
    ({"force": [{"position": 0.1, "time": [0.0, 1e300], "value": [0.0, 1.0]}]}, "force[0].time[1] = 1e+300"),
    ({"mount": {"kind": "clamp", "position": 0.3, "base_motion": {"time": [0.0, 1e-3],
                                                                  "displacement": [[0, 0, 0], [0, 0, -1e300]]}},
      "initial": {"velocity": [0, 0, 0], "angle_deg": 0.0}}, "mount.base_motion[1][2] = -1e+300"),
])
def test_loads_and_travels_that_would_overflow_are_refused(doc, named):
    with pytest.raises(ValueError) as info:
        scene_from_dict(doc)
    assert named in str(info.value)


def test_a_tip_cap_smaller_than_the_section_names_half_its_diagonal():
    """A rectangular section's edge lies half its diagonal from the axis: the cap must span
    that (the message said 'half the section width' while it computed the diagonal)."""
    w, t = 0.003, 0.0003
    with pytest.raises(ValueError) as info:
        scene_from_dict({"bar": {"width": w, "thickness": t, "tip_radius": 0.001, "length": 0.02}})
    message = str(info.value)
    assert "half the section's diagonal" in message and repr(0.5 * math.hypot(w, t)) in message


def test_the_buffers_a_history_outgrew_are_freed():
    """A coupled run keeps its dense output: the recorder's buffers grow as the steps come,
    and each grown buffer replaces the last. The compiled route's argument checks had
    held the last 256 tuples of the views the solver passed (fresh ones each call), and
    with them every buffer those views were cut from: a run kept about twice the memory
    its history needs (a run whose steps collapsed reached 11 GB against its 4 GiB
    bound). Once grown past them, the first buffers are garbage."""
    import gc
    import weakref

    solver = ImpactSolver(drop(100_000, t_end=0.004), keep_dense=True, capacity=64)
    rec = solver.recorder
    first = [weakref.ref(a) for a in (rec.t, rec.y, rec.dense_coef)]
    for k in range(1, 21):
        solver.advance(2e-4 * k, {})
    assert rec.capacity > 64 and rec.n > 64
    gc.collect()
    assert [ref() is None for ref in first] == [True, True, True]



def test_a_thinned_armature_run_keeps_the_energy_audit_of_every_step():
    """The relay blade of tests/mech/test_mech_armature.py pushed by a plunger's card (the
    drive ramped up over 2 ms, the armature seated on its pole): the armature's kinetic and
    stop energy are part of the audit, so the rows thinned away must be audited with them
    (and with the ringing its seats remove credited), as the result audits its own rows.
    Same steps in one process (see above): the largest residual of the thinned run is that
    of every step, within the energy tolerance. Without the armature's terms the dropped
    rows' residual was the armature's energy (a changeover relay at 30 modes reported 0.16)."""
    from test_mech_armature import PLUNGER, relay

    def run(rows):
        doc = relay(PLUNGER, t_end=0.006, rtol=1e-7)
        doc["solver"]["history_rows"] = rows
        solver = ImpactSolver(scene_from_dict(doc))
        for k in range(1, 13):  # macro steps of 0.5 ms, as a co-simulation thins between them
            solver.advance(k * 5e-4, {"armature.force": (min(k - 1, 4) * 2.5, min(k, 4) * 2.5)})
            solver.release_dense()
        return solver.result()

    full, thin = run(1_000_000), run(1000)
    assert thin.thinning is not None and thin.thinning["rows_dropped"] > 0.5 * len(full.t)
    assert full.max_abs_residual <= full.model.scene.solver.energy_tolerance * full.energy_scale
    assert thin.max_abs_residual == full.max_abs_residual
    assert thin.energy == full.energy and thin.flags == full.flags == []
