"""Force-travel springs ([[spring]] travel and force tables): statics, snap-through, the linear case, bad input.

The rig: a rigid steel arm (modes = 0, no gravity) on a hinge without stiffness at its
end, a spring at its free end (tip 0, a lever LEVER from the hinge) to an anchor 1 m
straight below that point, so its travel is the point's drop to within (drop / 1 m)^2.
The travel is computed here from the arm's angle by the rigid geometry, not from the
spring's code.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from mech.scene import scene_from_dict
from mech.solver import ImpactSolver

STEEL = dict(youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)
LEVER = 0.05  # m: the arm's length, hinge to the spring's point
TIP_R = 0.0025  # m: its tip cap's radius (the arm's axis lies GAP + TIP_R above the block)


def arm(springs, forces=(), gap=1e-3, t_end=0.05, rtol=1e-6):
    """The rig's scene: the arm GAP above the block, level and at rest."""
    doc = {"bar": dict(length=LEVER, diameter=2 * TIP_R, tip_radius=TIP_R, modes=0, **STEEL),
           "mount": dict(kind="pivot", position=LEVER),
           "spring": [dict(anchor=[-LEVER, 0.0, -1.0], position=0.0, **sp) for sp in springs],
           "initial": dict(height=gap), "environment": dict(gravity=0.0),
           "solver": dict(t_end=t_end, rtol=rtol)}
    if forces:
        doc["force"] = [dict(position=0.0, direction=[0.0, 0.0, -1.0], **f) for f in forces]
    return doc


def travel(states: np.ndarray) -> np.ndarray:
    """m: the spring's compression per state row (x, z, angle, ...), from the rigid arm's
    geometry: its point at the hinge + R_y(angle) (-LEVER, 0, 0)."""
    z0 = states[0, 1]
    phi = states[:, 2]
    x = -LEVER * np.cos(phi)
    z = states[:, 1] + LEVER * np.sin(phi)
    rest = 1.0 + z0
    return rest - np.hypot(x + LEVER, z + 1.0)


def table_integral(xs, fs, upto: float) -> float:
    """J: the integral of the linear interpolant through (xs, fs) from 0 to ``upto`` (inside
    the table), by the trapezoidal rule on 20001 points: exact for a piecewise-linear
    integrand up to the pieces the grid cuts, below 1e-6 of it here."""
    grid = np.linspace(0.0, upto, 20001)
    return float(np.trapezoid(np.interp(grid, xs, fs), grid))


# --- statics ----------------------------------------------------------------------------

STIFFENING = dict(travel=[0.0, 2e-4, 4e-4, 6e-4, 8e-4], force=[0.0, 0.5, 0.8, 1.4, 3.0])


def test_a_quasi_static_press_traces_the_table():
    """The issue's check: a force ramp (0 to 2.5 N in 1 s) presses the spring's point
    slowly, so the spring holds the press at every moment, F(t) = f(travel(t)) (the arm
    and the spring act at the same point, the hinge has no stiffness). What else the arm
    feels, the dashpot c dtravel/dt and the inertia, is below 0.2 % of the force from 0.5 N
    on (c = 1 N s/m at ~1 mm/s, the arm's first period ~6 ms against the ramp's 1 s,
    rung down by the dashpot's 20 % of critical); within 1 % of the table at every record
    past 0.2 s (F > 0.5 N)."""
    doc = arm([dict(STIFFENING, damping=1.0)], [dict(time=[0.0, 1.0], value=[0.0, 2.5])], t_end=1.0)
    solver = ImpactSolver(scene_from_dict(doc))
    solver.advance(1.0)
    res = solver.result()
    x = travel(res.states)
    pressed = 2.5 * res.t
    table = np.interp(x, STIFFENING["travel"], STIFFENING["force"])
    late = res.t > 0.2
    assert late.sum() > 50 and x[-1] > 6e-4  # (the press reached the table's steep end)
    assert np.max(np.abs(table[late] / pressed[late] - 1.0)) < 0.01
    assert not any(e["kind"] == "contact_start" for e in solver.events)


# --- snap-through -----------------------------------------------------------------------

# a bistable dome from the start (travel 0): pushes back before, pulls in after a barrier
# it has just crossed (force -0.1 N at the start), so nothing but its stored energy moves
# the arm onto the block
DOME = dict(travel=[-3e-4, -1.5e-4, 0.0, 3e-4, 8e-4, 1.5e-3], force=[0.0, 1.0, -0.1, -1.0, -0.4, 2.0])


def test_a_snap_through_releases_the_stored_energy_into_the_contact():
    """The dome alone snaps the arm through its gap of 0.5 mm onto the block. At the contact
    (the record of its contact_start event) the arm's kinetic energy is what the dome
    gave up from the start, -int_0^x f (the work-energy theorem: the integrator's kinetic
    energy against the table's integral by the trapezoidal rule, 1e-4 of it: the run's
    rtol of 1e-6 on a state integrated over ~10^3 steps). The energy audit closes: until the
    contact (the spring's energy, the table's exact integral in the kernel, against the
    kinetic energy its force gave through the integrator) its residual stays below 1e-4 of
    the released energy and shrinks with the tolerance (below 1e-6 at rtol 1e-8: its
    error is the step's over the table's kink at 0.3 mm, which no event marks; a wrong
    stored energy would not shrink); over the whole run, impact and bounces included, the
    audit's relative residual stays below 100 times the coarser rtol (the conservation
    tests' bound; the impacts' share does not shrink as fast), the scale counting what the dome can release (mech.results.energy_scale)."""
    gap = 5e-4
    before_contact = []
    for rtol in (1e-6, 1e-8):
        solver = ImpactSolver(scene_from_dict(arm([DOME], gap=gap, t_end=0.03, rtol=rtol)))
        solver.advance(0.03)
        res = solver.result()
        start = [e for e in solver.events if e["kind"] == "contact_start"]
        assert start, "the dome did not snap the arm onto the block"
        k = int(np.argmin(np.abs(res.t - start[0]["time"])))
        assert res.t[k] == pytest.approx(start[0]["time"], abs=1e-12)
        x = travel(res.states[: k + 1])[-1]
        # (the cap's centre, where it touches, lies TIP_R inside the arm's end: the end
        # drops LEVER / (LEVER - TIP_R) times the gap, to the small angle's (gap / LEVER)^2)
        assert x == pytest.approx(gap * LEVER / (LEVER - TIP_R), rel=1e-3)
        released = -table_integral(DOME["travel"], DOME["force"], x)
        en = res.energy_columns
        assert en["kinetic"][k] == pytest.approx(released, rel=1e-4)
        before_contact.append(np.max(np.abs(en["residual"][: k + 1])) / released)
        assert res.energy["relative_residual"] < 100 * 1e-6
        assert en["normal_dissipation"][-1] > 0.01 * released  # (the contact took energy)
    assert before_contact[0] < 1e-4 and before_contact[1] < 1e-6


# --- hysteresis -------------------------------------------------------------------------

LOOP = dict(STIFFENING, release_force=[0.0, 0.2, 0.4, 0.9, 2.2])


def half_band(x):
    """N: half the gap between LOOP's press and release branches at travel x (m)."""
    return 0.5 * (np.interp(x, LOOP["travel"], LOOP["force"]) - np.interp(x, LOOP["travel"], LOOP["release_force"]))


def test_a_spring_with_hysteresis_presses_on_one_branch_releases_on_the_other_and_dissipates_the_loop():
    """A slow press (0 to 2.5 N in 1 s) and release (to 0.3 N in 1 s) on a spring with a
    press and a release table, no dashpot. Pressed, the force follows the press branch;
    after the turn the spring sticks while the force falls through the band between the
    branches (2 F_h ~ 0.66 N: 0.3 s), then follows the release branch: within 1 % of
    each, pressing past 0.2 s, releasing past 1.4 s. The energy the hysteresis dissipates
    is the work of the band's half-width along the path, int_0^x_max F_h + int_x_end^x_max
    F_h (a Jenkins element's slider, pulled at +-F_h both ways), here by the trapezoidal
    rule on the test's own grid, within 1 % (the smooth element reaches the band's edge
    within ~F_h / k_s, 0.1 % of the span, and its floor where the branches meet); the
    audit's relative residual stays below 100 rtol."""
    doc = arm([LOOP], [dict(time=[0.0, 1.0, 2.0], value=[0.0, 2.5, 0.3])], t_end=2.0)
    solver = ImpactSolver(scene_from_dict(doc))
    solver.advance(2.0)
    res = solver.result()
    x = travel(res.states)
    pressed = np.interp(res.t, [0.0, 1.0, 2.0], [0.0, 2.5, 0.3])
    press = np.interp(x, LOOP["travel"], LOOP["force"])
    release = np.interp(x, LOOP["travel"], LOOP["release_force"])
    up = (res.t > 0.2) & (res.t < 1.0)
    down = res.t > 1.4
    assert up.sum() > 50 and down.sum() > 50
    assert np.max(np.abs(press[up] / pressed[up] - 1.0)) < 0.01
    assert np.max(np.abs(release[down] / pressed[down] - 1.0)) < 0.01
    assert np.max(np.abs(press[down] / pressed[down] - 1.0)) > 0.2  # (the branches do part there)
    top, end = x.max(), x[-1]
    g_in, g_out = np.linspace(0.0, top, 20001), np.linspace(end, top, 20001)
    loop = np.trapezoid(half_band(g_in), g_in) + np.trapezoid(half_band(g_out), g_out)
    assert res.energy_columns["load_dissipation"][-1] == pytest.approx(loop, rel=0.01)
    assert res.energy["relative_residual"] < 100 * 1e-6


# --- the linear case --------------------------------------------------------------------

K = 2000.0  # N/m
PRELOAD = 0.3  # N: the linear spring's pull towards its anchor at the start


def test_a_straight_line_table_is_the_linear_spring():
    """A table that is a straight line, push = -PRELOAD + K travel, is the linear spring of
    stiffness K and preload PRELOAD (pulling the arm down at the start), on its points and
    beyond them along its end segments: a force step of
    1 N swings the arm on it (a gap of 5 mm: no contact). The two runs are the same
    physics by two routes through the kernel (the table's segment against k (length -
    rest)): their angles at 20 instants agree to 1e-6 of the swing (the runs' rtol: equal
    to rounding while the adaptive steps stay alike, within the integration error where
    they part). The arm's first contact with the 1 mm gap, the same way, agrees to 1e-9 s."""
    force = [dict(magnitude=1.0)]
    # two points 0.1 mm apart: the arm swings ~1.3 mm, on the line's continuation beyond them
    line = dict(travel=[0.0, 1e-4], force=[-PRELOAD, -PRELOAD + K * 1e-4], damping=0.05)
    linear = dict(stiffness=K, preload=PRELOAD, damping=0.05)
    angles = []
    for spring in (linear, line):
        solver = ImpactSolver(scene_from_dict(arm([spring], force, gap=5e-3, t_end=0.02)))
        angles.append([solver.advance(t) and solver.named_state()["angle"][0] for t in np.linspace(1e-3, 0.02, 20)])
    angles = np.array(angles)
    swing = np.ptp(angles[0])
    assert swing > 0.005  # (rad: the arm swung)
    assert np.max(np.abs(angles[1] - angles[0])) < 1e-6 * swing
    first = []
    for spring in (linear, line):
        solver = ImpactSolver(scene_from_dict(arm([spring], force, t_end=0.02)))
        solver.advance(0.02)
        first.append(next(e["time"] for e in solver.events if e["kind"] == "contact_start"))
    assert abs(first[1] - first[0]) < 1e-9


# --- bad input --------------------------------------------------------------------------

@pytest.mark.parametrize("entry, words", [
    (dict(travel=[0.0, 2e-4, 1e-4], force=[0.0, 1.0, 2.0]), "spring[0].travel[2] = 0.0001: travels must increase"),
    (dict(travel=[0.0, 1e-4], force=[0.0, 1.0, 2.0]), "spring[0].force: 3 forces for 2 travels"),
    (dict(travel=[0.0, 1e-4], force=[0.0, 1.0], stiffness=100.0), "spring[0].stiffness = 100.0"),
    (dict(travel=[0.0, 1e-4], force=[0.0, 1.0], preload=0.1), "spring[0].preload = 0.1"),
    (dict(travel=[0.0, 1e-4]), "spring[0].force: missing"),
    (dict(travel=[1e-4], force=[1.0]), "spring[0].travel = [0.0001]: 1 point(s)"),
    (dict(travel=[0.0, "a"], force=[0.0, 1.0]), "spring[0].travel = [0.0, 'a']: expected a list of numbers"),
    (dict(travel=[0.0, 1e-4], force=[0.0, math.inf]), "spring[0].force[1] = inf"),
    (dict(), "spring[0]: give stiffness"),
    (dict(travel=[0.0, 1e-4], force=[0.0, 1.0], release_force=[0.0, 1.2]), "spring[0].release_force[1] = 1.2: above"),
    (dict(travel=[0.0, 1e-4], force=[0.0, 1.0], release_force=[0.0]), "spring[0].release_force: 1 forces for 2"),
    (dict(travel=[0.0, 1e-4], force=[0.0, 1.0], release_force=[0.0, 1.0]), "spring[0].release_force: equal to"),
    (dict(stiffness=100.0, release_force=[0.0, 1.0]), "spring[0].release_force: a release branch needs"),
])
def test_a_bad_force_travel_table_is_refused_in_one_line_naming_the_key(entry, words):
    with pytest.raises(ValueError) as err:
        scene_from_dict(arm([entry]))
    message = str(err.value)
    assert words in message and "\n" not in message
