"""The relay's armature: a rigid body on its own coordinate q (plunger or clapper), driven by
the drive channel "armature.force" times a gain table, with a return spring, one-sided
spring-dashpot stops and a card that pushes the contact spring, in the same ODE as the bar.

Physics checked against closed forms: the spring-mass motion under a constant force
(travel time and arrival speed), the linear spring-dashpot bounce on a stop (restitution
and contact time, clipped and the textbook forms), the return spring's preload holding the
armature below the drive that overcomes it, the linear force field of a linear gain table,
the card's statics against the Euler-Bernoulli cantilever (plunger, and a clapper with a
lever), the energy audit with a ramped drive, stops and card (residual shrinking with the
tolerance, the drive's work against an independent quadrature), and a held relay's static
equilibrium against the cantilever's flexibility. Also the interface (dense output, events,
summary, history) and bad input.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
from scipy.optimize import brentq

from mech.contact_laws import hertz_stiffness
from mech.scene import scene_from_dict, scene_to_dict
from mech.solver import ImpactSolver

# The plunger solenoid of issue 19: a steel armature of radius 5 mm and length 26 mm
# (7853 kg/m^3) with a 10 g load, 5 mm to 0.25 mm of working gap, stops 1e11 N/m, 400 N s/m
SOLENOID_MASS = 7853.0 * math.pi * 0.005**2 * 0.026 + 0.010  # kg
TRAVEL = 0.005 - 0.00025  # m
K_STOP, C_STOP = 1e11, 400.0


def solenoid(**over) -> dict:
    arm = dict(kind="plunger", mass=SOLENOID_MASS, travel=TRAVEL, stop_stiffness=K_STOP, stop_damping=C_STOP)
    arm.update(over)
    return {"armature": arm, "solver": dict(t_end=0.05, rtol=1e-9)}


def run(doc: dict, drive=None, t_end: float | None = None, keep_dense: bool = False):
    """The solver after one step to t_end (the scene's) under a constant (or (start, end)) drive."""
    solver = ImpactSolver(scene_from_dict(copy.deepcopy(doc)), keep_dense=keep_dense)
    t_end = doc["solver"]["t_end"] if t_end is None else t_end
    solver.advance(t_end, None if drive is None else {"armature.force": drive})
    return solver


def stop_events(result, stop: str, kind: str) -> list:
    return [e for e in result.events if e.get("stop") == stop and e["kind"] == f"armature_stop_{kind}"]


# --- the armature alone ------------------------------------------------------------------

@pytest.mark.parametrize("preload, rate", [(0.0, 0.0), (1.5, 400.0)], ids=["no spring", "return spring"])
def test_constant_force_carries_the_armature_to_the_pole_as_the_spring_mass_closed_form(preload, rate):
    """m q'' = F - P - k q from rest at q = 0: q(t) = (F - P)/k (1 - cos(w t)), w^2 = k/m (k = 0:
    q = (F - P) t^2 / 2m); it reaches the pole stop d at t_d = acos(1 - k d/(F - P)) / w
    with v^2 = (2 (F - P) d - k d^2) / m. It starts at q = 0 (pressed into the rest stop by
    P / k_stop instead, the stop's push as it unloads would put it ~1e-7 s ahead). Tolerance
    1e-7: the free flight's integration error at rtol 1e-9 (measured below 1e-9)."""
    F, m, d = 5.0, SOLENOID_MASS, TRAVEL
    res = run(solenoid(spring_preload=preload, spring_rate=rate, initial_position=0.0), F).result()
    if rate > 0.0:
        w = math.sqrt(rate / m)
        t_d = math.acos(1.0 - rate * d / (F - preload)) / w
    else:
        t_d = math.sqrt(2.0 * m * d / (F - preload))
    v_d = math.sqrt((2.0 * (F - preload) * d - rate * d * d) / m)
    arm = res.armature
    assert arm["first_arrival"] == pytest.approx(t_d, rel=1e-7)
    assert arm["arrival_speed"] == pytest.approx(v_d, rel=1e-7)


def clipped_dashpot(zeta: float, omega: float) -> tuple[float, float]:
    """(restitution, contact time s) of a mass on a linear spring-dashpot that only pushes
    (F = k x + c x' clipped at 0; Schwager and Poeschel, Granular Matter 9 (2007) 465): the
    force vanishes at omega_d t* = pi - atan(2 zeta sqrt(1 - zeta^2) / (1 - 2 zeta^2)), the
    mass then leaves at its speed there, x'(t*) = v0 e^(-zeta omega t*) (cos omega_d t* -
    zeta / sqrt(1 - zeta^2) sin omega_d t*), and separates after x(t*) / |x'(t*)| more."""
    s = math.sqrt(1.0 - zeta * zeta)
    wd = omega * s
    t_star = (math.pi - math.atan2(2.0 * zeta * s, 1.0 - 2.0 * zeta * zeta)) / wd
    decay = math.exp(-zeta * omega * t_star)
    v = decay * (math.cos(wd * t_star) - zeta / s * math.sin(wd * t_star))  # per unit v0
    x = decay * math.sin(wd * t_star) / wd
    return -v, t_star + x / -v


@pytest.mark.parametrize("damping", [C_STOP, None], ids=["solenoid stop, zeta 0.004", "zeta 0.2"])
def test_a_bounce_on_the_pole_stop_has_the_spring_dashpot_restitution_and_contact_time(damping):
    """Thrown at the pole stop at v0 (no drive, no spring): the stop is a linear spring-dashpot
    (w = sqrt(k/m), zeta = c / (2 sqrt(k m))) that only pushes. Its rebound and contact time
    agree with the clipped closed form (clipped_dashpot) to 1e-6 (rtol 1e-9; the contact
    takes about ten steps, each within rtol of the speed); and, for the solenoid's zeta, with
    the textbook's e = exp(-zeta pi / sqrt(1 - zeta^2)), t_c = pi / w_d within 4 zeta^2: the
    clipping (the force would pull in the last 2 zeta / w_d of the textbook's half period)
    changes both by 2 zeta^2 + O(zeta^3). At zeta = 0.2 the two differ by 8 % in e, and the
    run follows the clipped form."""
    m, k = SOLENOID_MASS, K_STOP
    c = damping if damping is not None else 0.2 * 2.0 * math.sqrt(k * m)
    v0 = 1.2
    res = run(solenoid(stop_damping=c, initial_position=TRAVEL - 1e-5, initial_speed=v0), t_end=2e-5).result()
    (start,), (end,) = stop_events(res, "pole", "start"), stop_events(res, "pole", "end")
    assert start["armature_velocity"] == pytest.approx(v0, rel=1e-12)
    e_run = -end["armature_velocity"] / start["armature_velocity"]
    t_run = end["time"] - start["time"]
    omega = math.sqrt(k / m)
    zeta = c / (2.0 * math.sqrt(k * m))
    e_clip, t_clip = clipped_dashpot(zeta, omega)
    assert e_run == pytest.approx(e_clip, rel=1e-6)
    assert t_run == pytest.approx(t_clip, rel=1e-6)
    e_book = math.exp(-zeta * math.pi / math.sqrt(1.0 - zeta * zeta))
    t_book = math.pi / (omega * math.sqrt(1.0 - zeta * zeta))
    if damping is not None:
        assert e_run == pytest.approx(e_book, rel=4.0 * zeta * zeta)
        assert t_run == pytest.approx(t_book, rel=4.0 * zeta * zeta)
    else:
        assert abs(e_run / e_book - 1.0) > 0.05


@pytest.mark.parametrize("fraction", [0.95, 1.05])
def test_the_return_spring_holds_the_armature_on_its_rest_stop_below_the_preload(fraction):
    """Preload P presses the armature onto its rest stop, where it starts seated (held at the
    stop's surface while pressed); a drive ramped in 1 ms to F below P leaves it there; above
    P it leaves the stop when the ramp passes P (t_P = t_r P / F, to 1e-9 s: the press is
    P - F(t), the event is located on it) and reaches the pole at the closed form of the
    force F(t) - P, linear in time to t_r and constant after (to 1e-6)."""
    P, t_r, m, d = 2.0, 1e-3, SOLENOID_MASS, TRAVEL
    F = fraction * P
    solver = ImpactSolver(scene_from_dict(solenoid(spring_preload=P)))
    solver.advance(t_r, {"armature.force": (0.0, F)})
    solver.advance(0.08)
    res = solver.result()
    q = res.history_columns["armature_position"]
    if fraction < 1.0:
        assert not stop_events(res, "rest", "end") and res.armature["first_arrival"] is None
        assert np.all(q == 0.0)
        return
    t_p = t_r * P / F
    assert stop_events(res, "rest", "end")[0]["time"] == pytest.approx(t_p, abs=1e-9)
    slope = F / t_r  # N/s
    v_r = slope * (t_r - t_p) ** 2 / (2.0 * m)
    q_r = slope * (t_r - t_p) ** 3 / (6.0 * m)
    a = (F - P) / m
    t_d = t_r + (-v_r + math.sqrt(v_r * v_r + 2.0 * a * (d - q_r))) / a
    assert res.armature["first_arrival"] == pytest.approx(t_d, rel=1e-6)


def test_a_linear_gain_table_gives_the_closed_form_motion_of_a_linear_force_field():
    """A constant drive F0 times gain(q) = g0 + g1 q (a five-point table of a straight line:
    its monotone cubics are that line) against a return spring P + k q: m q'' = (F0 g0 - P)
    + (F0 g1 - k) q, a negative stiffness lam = F0 g1 - k > 0 (as a magnet's), so q(t) =
    (F0 g0 - P) / lam (cosh(sqrt(lam/m) t) - 1): the arrival time at the pole and the speed
    there (v^2 = (2 f0 d + lam d^2) / m) to 1e-7 (as the constant force's; from q = 0)."""
    m, d = SOLENOID_MASS, TRAVEL
    F0, g0, g1, P, k = 4.0, 1.0, 400.0, 1.0, 200.0
    position = np.linspace(0.0, d, 5)
    doc = solenoid(spring_preload=P, spring_rate=k, initial_position=0.0,
                   force_gain=dict(position=position.tolist(), gain=(g0 + g1 * position).tolist()))
    res = run(doc, F0).result()
    f0, lam = F0 * g0 - P, F0 * g1 - k
    t_d = math.acosh(1.0 + lam * d / f0) / math.sqrt(lam / m)
    v_d = math.sqrt((2.0 * f0 * d + lam * d * d) / m)
    assert res.armature["first_arrival"] == pytest.approx(t_d, rel=1e-7)
    assert res.armature["arrival_speed"] == pytest.approx(v_d, rel=1e-7)


def test_a_magnet_like_gain_table_is_the_monotone_cubic_through_its_points():
    """A gain table shaped as a magnet's h(g) ~ 1 / g^2 (nine points, steep towards the pole):
    the drive's work on the way to the pole, F0 times the integral of the table's monotone
    cubic interpolant (SciPy's PchipInterpolator, an independent implementation), less the
    return spring's, is the kinetic energy it arrives with (to 1e-7: the integration at rtol
    1e-9). A piecewise-linear interpolant of the same points would put in 20 % more."""
    from scipy.interpolate import PchipInterpolator

    m, d, F0, P, k = SOLENOID_MASS, TRAVEL, 1e-4, 0.5, 100.0
    position = np.linspace(0.0, d, 9)
    gain = 1.0 / (d + 2.5e-4 - position) ** 2
    doc = solenoid(spring_preload=P, spring_rate=k, initial_position=0.0,
                   force_gain=dict(position=position.tolist(), gain=gain.tolist()))
    res = run(doc, F0).result()
    work = F0 * float(PchipInterpolator(position, gain).integrate(0.0, d)) - (P * d + 0.5 * k * d * d)
    assert 0.5 * m * res.armature["arrival_speed"] ** 2 == pytest.approx(work, rel=1e-7)
    assert F0 * np.trapezoid(gain, position) > 1.1 * (work + P * d + 0.5 * k * d * d)


def test_a_clapper_turns_under_a_torque_as_its_closed_form():
    """A clapper (inertia I about its hinge, travel in rad) under a constant torque T from rest,
    no spring: theta(t) = T t^2 / 2I to the pole at theta_d (to 1e-7, as the plunger's)."""
    inertia, travel, T = 2e-6, 0.08, 0.01
    doc = {"armature": dict(kind="clapper", inertia=inertia, travel=travel, stop_stiffness=50.0,
                            stop_damping=1e-4), "solver": dict(t_end=0.02, rtol=1e-9)}
    res = run(doc, T).result()
    assert res.armature["first_arrival"] == pytest.approx(math.sqrt(2.0 * inertia * travel / T), rel=1e-7)
    assert res.armature["arrival_speed"] == pytest.approx(math.sqrt(2.0 * T * travel / inertia), rel=1e-7)


# --- the armature and its card on the contact spring -------------------------------------

CUBE = dict(youngs_modulus=128e9, poisson_ratio=0.3, density=8250.0)  # the relay's blade, CuBe C17200
E_BLADE, I_BLADE = 128e9, 0.003 * 0.0003**3 / 12
CLAMP, CARD_AT, RIVET_AT = 0.015, 0.0075, 0.0015  # m from tip 0
PLUNGER = dict(kind="plunger", mass=5e-3, travel=1e-3, stop_stiffness=1e9, stop_damping=2000.0,
               spring_rate=200.0, spring_preload=0.2, card_position=CARD_AT, card_lever=1.0,
               card_free_travel=2e-4, card_stiffness=2e5, card_damping=2.0)
CLAPPER = dict(kind="clapper", inertia=1e-6, travel=0.1, stop_stiffness=1e3, stop_damping=0.03,
               spring_rate=0.02, spring_preload=0.002, card_position=CARD_AT, card_lever=0.008,
               card_free_travel=2e-4, card_stiffness=2e5, card_damping=2.0)


def relay(arm: dict, bending: int = 8, gap: float = 3e-3, t_end: float = 0.012, rtol: float = 1e-8) -> dict:
    """The default relay's CuBe blade (15 x 3 x 0.3 mm, clamped at its tip-1 end, a rivet on
    the axis 1.5 mm from tip 0, ``gap`` above a plane silver contact), no gravity, pushed
    at its middle by the armature's card; the blade's modes damped at 0.3 to settle."""
    return {"bar": dict(length=CLAMP, width=0.003, thickness=0.0003, tip_radius=0.0016, **CUBE,
                        modes={"axial": 1, "bending": bending}, modal_damping=0.3),
            "mount": dict(kind="clamp", position=CLAMP),
            "rivet": [dict(position=RIVET_AT, radius=0.0015, youngs_modulus=76e9, poisson_ratio=0.37)],
            "block": dict(youngs_modulus=76e9, poisson_ratio=0.37),
            "armature": dict(arm), "initial": dict(height=gap),
            "contact": dict(law="hunt_crossley", restitution=0.5, reference_speed=0.3),
            "solver": dict(t_end=t_end, rtol=rtol), "environment": dict(gravity=0.0)}


def flexibility(x1: float, x2: float) -> float:
    """m/N: an Euler-Bernoulli cantilever's deflection at x1 under a unit force at x2 (both
    from the clamp): x^2 (3 X - x) / (6 E I), x the nearer, X the farther."""
    x, big = min(x1, x2), max(x1, x2)
    return x * x * (3.0 * big - x) / (6.0 * E_BLADE * I_BLADE)


def pushed(doc: dict, drive: float, ramp: float = 2e-3) -> ImpactSolver:
    solver = ImpactSolver(scene_from_dict(doc))
    solver.advance(ramp, {"armature.force": (0.0, drive)})
    solver.advance(doc["solver"]["t_end"])
    return solver


@pytest.mark.parametrize("arm, drive", [(PLUNGER, 10.0), (CLAPPER, 0.1)], ids=["plunger", "clapper with a lever"])
def test_the_card_bends_the_blade_as_a_cantilever_under_the_card_force(arm, drive):
    """The drive seats the armature on its pole stop (q = travel); its card, lever x travel -
    free travel down from the blade's rest, presses the blade at a = 7.5 mm from the clamp
    (the blade clear of its contact). At rest the blade's deflection there, lever q - free -
    P / k_card from the card's compression, is P a^3 / (3 E I) of the card force P. The
    modal basis is the only approximation: its static flexibility at a point converges as
    (bending modes)^-3 (docs/mechanics.md, section 8), so the error falls about 8-fold from
    6 to 12 modes (5 to 11 accepted: the asymptote is not reached exactly) and is within
    1e-4 at 12 (measured 4.2e-5 for both; 2.9e-4 at 6)."""
    a = CLAMP - CARD_AT
    errors = []
    for bending in (6, 12):
        solver = pushed(relay(arm, bending), drive)
        h = solver.result().history_columns
        q, P = h["armature_position"][-1], h["card_force"][-1]
        assert q == arm["travel"] and solver.armature_closed[4] == 1.0  # seated on the pole stop
        deflection = arm["card_lever"] * q - arm["card_free_travel"] - P / arm["card_stiffness"]
        errors.append(deflection / (P * a**3 / (3.0 * E_BLADE * I_BLADE)) - 1.0)
    assert 5.0 < errors[0] / errors[1] < 11.0
    assert abs(errors[1]) < 1e-4


def relay_statics(arm: dict, gap: float, k_hertz: float) -> tuple[float, float]:
    """(card force P, contact force R), N, of the blade at rest with the armature on its pole
    stop, from the cantilever's flexibility: the blade's deflection at the card,
    P c_aa - R c_ab, is the card's travel less its compression, lever d - free - P / k_card;
    at the rivet, P c_ab - R c_bb, the gap plus the Hertz penetration (R / k)^(2/3)."""
    a, b = CLAMP - CARD_AT, CLAMP - RIVET_AT
    c_aa, c_ab, c_bb = flexibility(a, a), flexibility(a, b), flexibility(b, b)
    travel = arm["card_lever"] * arm["travel"] - arm["card_free_travel"]

    def card(R):  # P from the card's compatibility for a given R
        return (travel + R * c_ab) / (c_aa + 1.0 / arm["card_stiffness"])

    R = brentq(lambda R: card(R) * c_ab - R * c_bb - gap - (R / k_hertz) ** (2.0 / 3.0), 0.0, 100.0)
    return card(R), R


def test_a_closed_relay_is_held_at_the_statics_of_its_card_and_contact_until_the_drive_changes():
    """The armature seated on its pole stop presses the blade through its card onto the fixed
    contact (gap 0.4 mm): the relay comes to rest and is held (ImpactSolver.holds), its card
    and contact forces those of the cantilever's flexibility (relay_statics) to 5e-4: the
    12-mode basis's statics converge as in the card's test (measured 2.4e-4 and 2.6e-4;
    2.2e-3 and 2.4e-3 with 6 modes). A new drive that keeps the armature pressed on its
    pole does not end the hold (the seated armature's card travel, and so everything the
    blade feels, does not depend on the drive: a relay held closed while its coil current
    settles); a drive below the card's reaction lifts it off the pole."""
    gap = 4e-4
    doc = relay(PLUNGER, bending=12, gap=gap, t_end=0.015)
    solver = pushed(doc, 30.0)
    k_h = hertz_stiffness(0.0015, 76e9, 0.37, 76e9, 0.37)
    P, R = relay_statics(PLUNGER, gap, k_h)
    assert len(solver.holds) == 1 and solver.at_rest
    h = solver.result().history_columns
    assert h["card_force"][-1] == pytest.approx(P, rel=5e-4)
    assert solver.contact_now()[0, 2] == pytest.approx(R, rel=5e-4)
    steps = int(solver.stats[0])  # solver steps so far
    solver.advance(0.025, {"armature.force": (30.0, 25.0)})  # still pressing it onto the pole: held on
    assert len(solver.holds) == 1 and solver.at_rest and solver.armature_closed[4] == 1.0
    assert int(solver.stats[0]) == steps  # nothing integrated while held
    assert solver.contact_now()[0, 2] == pytest.approx(R, rel=5e-4)
    press = 25.0 - PLUNGER["spring_preload"] - PLUNGER["spring_rate"] * PLUNGER["travel"] - P
    solver.advance(0.03, {"armature.force": 25.0 - 1.5 * press})  # the card pushes it back off the pole
    res = solver.result()
    assert stop_events(res, "pole", "end")[-1]["time"] == pytest.approx(0.025)
    assert solver.armature_now()[0] < PLUNGER["travel"]


def make_and_release(rtol: float):
    """The relay closed by a drive ramped up in 2 ms and held for 4 ms, then ramped down in
    1 ms to zero: the armature flies to its pole stop and bounces there, the card closes the
    contact, the blade bounces and settles; on release the return spring and the card throw
    the armature back to its rest stop, where it bounces and is seated."""
    doc = relay(PLUNGER, bending=4, gap=4e-4, t_end=0.012, rtol=rtol)
    doc["armature"]["stop_damping"] = 200.0  # a bouncing armature: zeta 0.045
    solver = ImpactSolver(scene_from_dict(doc))
    solver.advance(2e-3, {"armature.force": (0.0, 30.0)})
    solver.advance(6e-3)
    solver.advance(7e-3, {"armature.force": (30.0, 0.0)})
    solver.advance(0.012)
    return solver.result()


def test_the_energy_audit_closes_with_the_armature_its_stops_card_and_a_ramped_drive():
    """Every term of the armature enters the audit (its kinetic energy, the return spring,
    stops and card stored and dissipated, the drive's work as work put in, the ringing
    removed where it is seated): the residual is integration error, so it shrinks with the
    tolerance (more than 30-fold from rtol 1e-7 to 1e-9, to below 1e-7 of the energy
    scale), as it would not with a term missing. And the drive's work agrees with an
    independent route: the trapezoid rule on the recorded steps of F(t) dq/dt (the steps
    resolve it to 1e-3 of its size)."""
    results = [make_and_release(rtol) for rtol in (1e-7, 1e-9)]
    residuals = [r.energy["relative_residual"] for r in results]
    assert residuals[1] < 1e-7 and residuals[1] < residuals[0] / 30.0
    fine = results[1]
    kinds = [e["kind"] for e in fine.events]
    for kind in ("armature_stop_start", "armature_stop_end", "card_start", "card_end", "contact_start",
                 "contact_end", "armature_seat"):
        assert kind in kinds
    assert sum(e.get("stop") == "rest" and e["kind"] == "armature_stop_start" for e in fine.events) >= 2
    h = fine.history_columns
    t = h["time"]
    drive = np.interp(t, [0.0, 2e-3, 6e-3, 7e-3], [0.0, 30.0, 30.0, 0.0])
    power = drive * h["armature_velocity"]
    work = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))])
    size = np.max(np.abs(h["work_in"]))
    assert size > 1e4 * residuals[1] * fine.energy_scale
    np.testing.assert_allclose(h["work_in"], work, rtol=0.0, atol=1e-3 * size)


# --- the interface -----------------------------------------------------------------------

def test_the_dense_output_gives_the_armature_between_the_steps():
    """Segment.armature(t) is the 4th-order dense output: on its way to the pole on the return
    spring, q = (F - P) / k (1 - cos w t), which it gives between the steps to 1e-10 of the
    travel (rtol 1e-9: the error control holds q to 2.4e-15 m absolute and 1e-9 relative
    at the steps, and the continuous extension keeps that order inside them; measured
    1.7e-12); at the steps' ends it is the history, and armature_now the state at the
    segment's end."""
    F, P, k, m = 5.0, 1.5, 400.0, SOLENOID_MASS
    w = math.sqrt(k / m)
    solver = ImpactSolver(scene_from_dict(solenoid(spring_preload=P, spring_rate=k, initial_position=0.0)),
                          keep_dense=True)
    segment = solver.advance(6e-3, {"armature.force": F})
    times = np.linspace(0.0, 6e-3, 101)
    got = np.array([segment.armature(t) for t in times])
    np.testing.assert_allclose(got[:, 0], (F - P) / k * (1.0 - np.cos(w * times)), rtol=0.0, atol=1e-10 * TRAVEL)
    np.testing.assert_allclose(got[:, 1], (F - P) / k * w * np.sin(w * times), rtol=0.0,
                               atol=1e-10 * TRAVEL * w)
    h = solver.result().history_columns
    at_steps = np.array([segment.armature(t) for t in h["time"]])  # (y0 + (y1 - y0) at a step's end)
    np.testing.assert_allclose(at_steps[:, 0], h["armature_position"], rtol=1e-13, atol=1e-18)
    np.testing.assert_allclose(at_steps[:, 1], h["armature_velocity"], rtol=1e-13, atol=1e-15)
    assert solver.armature_now() == (h["armature_position"][-1], h["armature_velocity"][-1])
    assert segment.armature(6e-3) == pytest.approx(solver.armature_now(), rel=1e-13)


def test_the_armature_in_any_order_of_times_is_the_dense_state():
    """Segment.armature keeps each dense step's coefficients once asked: at times asked back
    and forth across the steps (as ngspice's rejected trial points and the coil's samples
    ask), and again in order, it is the armature's two components of Segment.state, the
    compiled evaluation of the same polynomial (rtol 1e-14: a few roundings apart)."""
    solver = ImpactSolver(scene_from_dict(solenoid(spring_preload=1.5, spring_rate=400.0, initial_position=0.0)),
                          keep_dense=True)
    segment = solver.advance(6e-3, {"armature.force": 5.0})
    a = solver.model.armature_index
    times = np.random.default_rng(7).permutation(np.linspace(0.0, 6e-3, 301))
    for t in np.concatenate([times, np.sort(times)]):
        want = segment.state(float(t))[a:a + 2]
        np.testing.assert_allclose(segment.armature(float(t)), want, rtol=1e-14, atol=1e-30)


def test_channels_history_summary_and_events_name_the_armature():
    blade = ImpactSolver(scene_from_dict(relay(PLUNGER)))
    assert blade.drive_names == ("mu.0", "repulsion.0", "armature.force")
    alone = ImpactSolver(scene_from_dict(solenoid()))
    assert alone.drive_names == ("armature.force",)
    with pytest.raises(ValueError, match=r"drives\['armature\.force'\] = nan: must be a finite number"):
        alone.advance(1e-3, {"armature.force": math.nan})
    with pytest.raises(ValueError, match="no armature"):
        ImpactSolver(scene_from_dict({"solver": dict(t_end=1e-3)})).armature_now()
    res = make_and_release(1e-7)
    h = res.history_columns
    for column in ("armature_position", "armature_velocity", "card_force", "work_in", "normal_force_0"):
        assert len(h[column]) == len(res.t)
    arm = res.to_summary()["armature"]
    starts = stop_events(res, "pole", "start")
    assert arm["first_arrival"] == starts[0]["time"] and arm["last_arrival"] == starts[-1]["time"]
    assert arm["pole_bounces"] == len(starts) - 1 and arm["left_pole"] > arm["last_arrival"]
    assert arm["arrival_speed"] == starts[0]["armature_velocity"] > 0.0
    alone_res = run(solenoid(initial_position=0.0), 5.0, t_end=2e-3).result()
    assert set(alone_res.history_columns) >= {"time", "armature_position", "armature_velocity", "work_in", "residual"}
    assert "x" not in alone_res.history_columns and len(alone_res.contact_columns["tip"]) == 0
    assert alone_res.to_summary()["armature"]["first_arrival"] is None


def test_a_scene_with_an_armature_round_trips_through_its_dict():
    for doc in (relay(CLAPPER), solenoid(force_gain=dict(position=[0.0, TRAVEL], gain=[1.0, 2.0]))):
        scene = scene_from_dict(doc)
        assert scene_from_dict(scene_to_dict(scene)) == scene


@pytest.mark.parametrize("change, message", [
    ({"armature": dict(PLUNGER, mass=-0.01)}, r"armature\.mass = -0\.01: must be > 0"),
    ({"armature": dict(PLUNGER, initial_position=2e-3)},
     r"armature\.initial_position = 0\.002: must lie between the rest stop \(0\) and the pole stop"),
    ({"armature": dict(PLUNGER, card_free_travel=1.5e-3)},
     r"armature\.card_free_travel = 0\.0015: the card would never"),
    ({"armature": dict(PLUNGER, card_position=0.02)}, r"armature\.card_position = 0\.02: must lie on the bar"),
    ({"armature": dict(PLUNGER, force_gain=dict(position=[0.0, 6e-4, 5e-4, 1e-3], gain=[1.0, 2.0, 3.0, 4.0]))},
     r"armature\.force_gain\.position\[2\] = 0\.0005: positions must increase strictly"),
    ({"armature": dict(PLUNGER, force_gain=dict(position=[0.0, 5e-4], gain=[1.0, 2.0]))},
     r"armature\.force_gain\.position = \[0\.0 \.\.\. 0\.0005\]: must cover the travel"),
    ({"armature": dict(PLUNGER, mass=None, inertia=1e-6)}, r"armature\.inertia: a plunger has a mass"),
    ({"armature": dict(CLAPPER, card_lever=None)}, r"armature\.card_lever: needed with armature\.card_position"),
    ({"armature": dict(kind="none", travel=1e-3)}, r"armature\.travel: an armature needs armature\.kind"),
    ({"armature": dict(PLUNGER, kind="solenoid")}, r"armature\.kind = 'solenoid': allowed values"),
])
def test_bad_armature_input_is_one_line_naming_the_key(change, message):
    doc = relay(PLUNGER)
    doc.update(change)
    doc["armature"] = {k: v for k, v in doc["armature"].items() if v is not None}
    with pytest.raises(ValueError, match=message) as err:
        scene_from_dict(doc)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("doc, message", [
    ({"armature": dict(PLUNGER), "solver": {}}, r"armature\.card_position: the card pushes the contact spring"),
    ({"armature": dict(PLUNGER, card_position=None, card_lever=None, card_stiffness=None, card_free_travel=0.0,
                       card_damping=0.0), "block": {}},
     r"\[block\]: this scene has an \[armature\] and no \[bar\]"),
    ({"armature": dict(kind="none"), "solver": {}}, r"bar: a scene without a bar is an armature alone"),
])
def test_an_armature_alone_has_no_card_nor_what_belongs_to_the_bar(doc, message):
    doc = copy.deepcopy(doc)
    doc["armature"] = {k: v for k, v in doc["armature"].items() if v is not None}
    with pytest.raises(ValueError, match=message):
        scene_from_dict(doc)
