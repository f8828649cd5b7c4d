"""The planar model against the 3D model on a planar scene, invariance under a rotation
of the whole scene about the vertical, and the choice of model."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mech import ImpactSolver, simulate
from mech.kernel import quat_to_matrix

from mech_cases import make_scene

RTOL = 1e-9


def rotation_z(deg: float) -> np.ndarray:
    a = math.radians(deg)
    return np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0], [0.0, 0.0, 1.0]])


def flexible_planar_scene(model: str = "auto", azimuth: float = 0.0, velocity=(0.3, 0.0, -1.0),
                          angular_velocity=(0.0, 5.0, 0.0)):
    """30 deg flexible bar (3 modes per family), damped contact, gamma = 0.7 friction, gravity:
    four bounces with slip turns and reversals within 6 ms. Vectors are given at azimuth 0
    and rotated with the scene."""
    Rz = rotation_z(azimuth)
    return make_scene(bar=dict(axial_modes=3, bending_modes=3), contact=dict(restitution=0.8),
                      friction=dict(mu=0.3, gamma=0.7),
                      initial=dict(height=1e-3, angle_deg=30.0, azimuth_deg=azimuth,
                                   velocity=tuple(Rz @ velocity), angular_velocity=tuple(Rz @ angular_velocity)),
                      solver=dict(rtol=RTOL, t_end=6e-3, model=model), gravity=9.80665)


def run_dense(scene):
    """Result and the dense trajectory over the whole run."""
    solver = ImpactSolver(scene, keep_dense=True)
    segment = solver.advance(scene.solver.t_end)
    res = solver.result()
    res.segment = segment
    return res


@pytest.fixture(scope="module")
def planar_run():
    return run_dense(flexible_planar_scene())


@pytest.fixture(scope="module")
def three_d_run():
    return run_dense(flexible_planar_scene(model="3d"))


def world_state(res, t: float) -> dict:
    """World-frame position, velocity, angular velocity and modal coordinates by name at t,
    from the run's dense output (4th order, so comparisons are not limited by the records)."""
    model = res.model
    y = res.segment.state(t)
    sl = model.slices()
    modes = {f"{f}{k}": y[sl["q"]][j] for j, (f, k) in enumerate(zip(model.basis.families, model.basis.orders))}
    if model.planar:
        Rz = rotation_z(math.degrees(model.azimuth))
        x, z = y[sl["pos"]]
        vx, vz = y[sl["vel"]]
        return dict(pos=Rz @ [x, 0.0, z], vel=Rz @ [vx, 0.0, vz], omega=Rz @ [0.0, y[sl["omega"]][0], 0.0], **modes)
    R = np.empty((3, 3))
    quat_to_matrix(*y[sl["quat"]], R)
    return dict(pos=y[sl["pos"]], vel=y[sl["vel"]], omega=R @ y[sl["omega"]], **modes)


def compare_trajectories(reference, other, rotation=np.eye(3)):
    """The other run's dense state at the reference's record times, rotated back.

    Absolute tolerances against the scales the error control holds (both runs at RTOL =
    1e-9): positions and modal coordinates to 3e-5 of the Hertz penetration scale (the
    differences measured were ~5e-6 of it), speeds to 1e-6 m/s, spins to 1e-5 rad/s.
    """
    dstar = reference.model.contact.penetration_scale
    tolerances = dict(pos=3e-5 * dstar, vel=1e-6, omega=1e-5)
    # every few records (a few hundred instants), so the Python loop stays cheap
    for t in reference.t[1::max(1, len(reference.t) // 400)]:
        a, b = world_state(reference, t), world_state(other, t)
        for key, atol in tolerances.items():
            np.testing.assert_allclose(b[key], rotation @ a[key], rtol=0, atol=atol, err_msg=f"{key} at t = {t}")
        for name in a:
            if name not in tolerances:
                np.testing.assert_allclose(b[name], a[name], rtol=0, atol=3e-5 * dstar, err_msg=f"{name} at t = {t}")


def compare_contacts(a, b):
    ca, cb = a.contacts, b.contacts
    assert len(ca) == len(cb) >= 3
    assert list(ca.tip) == list(cb.tip)
    # Tolerances from the convergence of the difference with rtol (both models are
    # integrated to RTOL, not to round-off): times are events located to ~1e-9 s;
    # peak forces are sampled at five points per step, restitutions are ratios of
    # quadratures and speeds at events.
    np.testing.assert_allclose(ca.t_start, cb.t_start, rtol=1e-7)
    np.testing.assert_allclose(ca.t_end, cb.t_end, rtol=1e-7)
    np.testing.assert_allclose(ca.impulse, cb.impulse, rtol=1e-5)
    np.testing.assert_allclose(ca.kinematic_restitution, cb.kinematic_restitution, rtol=1e-5)
    np.testing.assert_allclose(ca.energetic_restitution, cb.energetic_restitution, rtol=1e-4)
    np.testing.assert_allclose(ca.peak_force, cb.peak_force, rtol=1e-4)


def test_auto_picks_the_planar_model_for_a_planar_scene(planar_run, three_d_run):
    assert planar_run.solver["model"] == "planar"
    assert three_d_run.solver["model"] == "3d"
    # planar: x, z, pitch + axial and in-plane bending only
    assert planar_run.solver["modes"] == 6 and three_d_run.solver["modes"] == 9


def test_planar_model_gives_the_3d_models_contacts_restitution_and_history(planar_run, three_d_run):
    compare_contacts(planar_run, three_d_run)
    # State along the whole run, compared on the dense output at every planar record.
    compare_trajectories(planar_run, three_d_run)
    h3 = three_d_run.history
    # The 3D model keeps the motion in the plane by itself.
    for col in ("y", "vy", "wx", "wz", "q_bend21", "q_bend22", "q_bend23", "friction_y_0", "slip_vy_0"):
        assert np.max(np.abs(h3[col])) < 1e-12, col
    # The same energy audit
    for key in ("normal_dissipation", "friction_dissipation", "elastic"):
        assert three_d_run.energy[key] == pytest.approx(planar_run.energy[key], rel=1e-4), key


@pytest.mark.parametrize("model", ["auto", "3d"])
def test_scene_rotated_about_the_vertical_gives_the_same_contacts_and_rotated_histories(model, planar_run, three_d_run):
    reference = planar_run if model == "auto" else three_d_run
    azimuth = 37.0
    rotated = run_dense(flexible_planar_scene(model=model, azimuth=azimuth))
    assert rotated.solver["model"] == reference.solver["model"]
    compare_contacts(reference, rotated)
    compare_trajectories(reference, rotated, rotation=rotation_z(azimuth))


@pytest.mark.parametrize("velocity, angular_velocity", [
    ((0.3, 0.05, -1.0), (0.0, 5.0, 0.0)),   # centre of mass leaves the vertical plane
    ((0.3, 0.0, -1.0), (0.0, 5.0, 1.0)),    # spin about the vertical
    ((0.3, 0.0, -1.0), (2.0, 5.0, 0.0)),    # roll about the bar's axis
])
def test_auto_picks_3d_for_out_of_plane_motion_and_planar_is_refused(velocity, angular_velocity):
    scene = flexible_planar_scene(velocity=velocity, angular_velocity=angular_velocity)
    assert not ImpactSolver(scene).planar
    with pytest.raises(ValueError, match="solver.model = 'planar'"):
        ImpactSolver(flexible_planar_scene(model="planar", velocity=velocity, angular_velocity=angular_velocity))


def test_planar_model_forced_on_a_planar_scene_is_accepted():
    assert ImpactSolver(flexible_planar_scene(model="planar")).planar
