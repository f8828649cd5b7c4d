"""The co-simulation's step policy (a pure object) and re-running one CoSimulation.

Policy checks use closed forms of the currents the policy is built for: an exponential
approach I(t) = I_inf (1 - exp(-t / tau)) (an L/R rise after a make) and a ramp.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from coupling.core.policy import StepPolicy, end_derivatives, end_rate

H = 5e-6  # s


def policy(**kw) -> StepPolicy:
    return StepPolicy(macro_step=kw.pop("macro_step", H), free_step=kw.pop("free_step", 1e-3), **kw)


def exponential(t, i_inf=2.0, tau=1e-4):
    return i_inf * (1.0 - np.exp(-t / tau))


def test_saturating_extrapolation_lands_on_the_asymptote_of_an_exponential():
    """I + I' tau = I_inf exactly for an exponential approach: with the horizon at its time
    constant the extrapolation never overshoots, however long the step."""
    tau, i_inf = 1e-4, 2.0
    t0 = 0.3 * tau
    i0 = float(exponential(t0, i_inf, tau))
    slope = i_inf / tau * math.exp(-t0 / tau)
    for elapsed in (tau, 3 * tau, 100 * tau):
        assert StepPolicy.extrapolate(i0, slope, elapsed, horizon=tau) == pytest.approx(i_inf, rel=1e-12)
    # without the horizon the linear extrapolation overshoots the asymptote
    assert StepPolicy.extrapolate(i0, slope, 3 * tau) > 1.5 * i_inf


def test_end_rate_gives_the_derivative_and_the_time_constant_of_an_exponential():
    tau = 1e-4
    t = np.linspace(0.0, 0.5 * tau, 8)
    i = exponential(t, tau=tau)
    rate, scale = end_rate(t, i, span=H)
    exact = 2.0 / tau * math.exp(-t[-1] / tau)
    assert rate == pytest.approx(exact, rel=0.05)  # a one-sided difference: O(dt) error
    assert scale == pytest.approx(tau, rel=0.1)     # |I'/I''| = tau for an exponential


def test_end_rate_of_a_ramp_has_no_finite_time_scale_and_too_few_points_give_none():
    t = np.linspace(0.0, 1e-5, 6)
    rate, scale = end_rate(t, 3.0 + 1e4 * t, span=H)
    assert rate == pytest.approx(1e4, rel=1e-9)
    assert scale > 1e3 * H  # curvature ~ round-off: nothing limits the step
    assert end_rate(t[:1], t[:1], span=H) == (0.0, math.inf)


def test_slope_extrapolation_is_second_order_in_the_step():
    """Extrapolating with end_rate's slope: the error falls ~4x per halving of the step."""
    tau = 1e-4
    errors = []
    for dt in (8e-6, 4e-6, 2e-6):
        t = np.linspace(0.0, 4 * dt, 5) + 0.2 * tau  # the circuit's points of the last steps
        i = exponential(t, tau=tau)
        rate, scale = end_rate(t, i, span=dt)
        guess = StepPolicy.extrapolate(float(i[-1]), rate, dt, scale)
        errors.append(abs(guess - float(exponential(t[-1] + dt, tau=tau))))
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.3)
    assert errors[1] / errors[2] == pytest.approx(4.0, rel=0.3)


def test_end_derivatives_are_exact_on_a_parabola_and_its_extrapolation_too():
    """end_derivatives: the last chord's slope and the change of slope (the second derivative
    of the parabola through the last three points) are a parabola's slope at the last point
    and its curvature, to round-off, on uneven points; extrapolating along them lands on the
    parabola. With too few points there is no curvature."""
    a, b, c = 0.3, -2e3, 4e7  # i = a + b t + c t^2
    t = np.array([0.0, 3e-6, 4e-6, 9e-6])
    i = a + b * t + c * t * t
    rate, curvature = end_derivatives(t, i, span=H)
    # the chord's slope over the last interval is the derivative at its midpoint, not its end:
    # rate + curvature x half the chord's length is the end's slope
    assert rate + 0.5 * curvature * (t[-1] - t[-2]) == pytest.approx(b + 2 * c * t[-1], rel=1e-9)
    assert curvature == pytest.approx(2 * c, rel=1e-9)
    h = 6e-6
    guess = StepPolicy.extrapolate(float(i[-1]), rate + 0.5 * curvature * (t[-1] - t[-2]), h, curvature=curvature)
    assert guess == pytest.approx(a + b * (t[-1] + h) + c * (t[-1] + h) ** 2, rel=1e-12)
    assert end_derivatives(t[:2], i[:2], span=H)[1] is None
    assert end_derivatives(t[:1], i[:1], span=H) == (0.0, None)


def test_after_a_jump_the_step_is_a_short_probe_with_the_current_held():
    p = policy()
    t_next, slope = p.plan(1e-3, 1e-3 + H, 1.0, touching=True, jumped=True, current=2.0, rate=5e4, scale=1e-7)
    assert slope == 0.0
    assert t_next - 1e-3 == pytest.approx(H * H / p.probe_time)
    assert p.probe < H  # shorter than a macro step: the held current's error is O(H^2)


def test_a_fast_current_shrinks_the_step_to_half_its_time_scale_but_not_below_the_probe():
    p = policy()
    t = 2e-3
    # L/R = 1 us rise: the step shrinks to half the time scale
    t_next, slope = p.plan(t, t + H, 1.0, touching=True, jumped=False, current=1.0, rate=1e6, scale=1e-6)
    assert slope == 1e6 and t_next - t == pytest.approx(0.5e-6)
    # a 1 ns time scale: the probe step is the floor
    t_next, _ = p.plan(t, t + H, 1.0, touching=True, jumped=False, current=1.0, rate=1e9, scale=1e-9)
    assert t_next - t == pytest.approx(p.probe)
    # a current that would change by less than change_fraction over the step: full step
    t_next, _ = p.plan(t, t + H, 1.0, touching=True, jumped=False, current=1.0, rate=1.0, scale=1e-6)
    assert t_next == t + H
    # both tips free: the current is not exchanged, no limit
    t_next, _ = p.plan(t, t + 1e-3, 1.0, touching=False, jumped=False, current=1.0, rate=1e6, scale=1e-6)
    assert t_next == t + 1e-3


def test_base_step_lengths_and_no_sliver_at_the_end():
    p = policy()
    assert p.base_end(0.0, 1.0, touching=True) == H
    assert p.base_end(0.0, 1.0, touching=False) == 1e-3
    t_end = 10 * H + 1e-4 * H  # a step would leave 1e-4 H: the step takes it
    assert p.base_end(9 * H, t_end, touching=True) == t_end
    assert p.base_end(9.5 * H, t_end, touching=True) == t_end


def test_a_step_is_cut_at_a_make_inside_it_and_after_a_probe_at_its_start():
    p = policy()
    t, t_next = 1e-3, 1e-3 + H
    assert p.aligned_end(t, t_next, t + 0.3 * H) == t + 0.3 * H
    assert p.aligned_end(t, t_next, t) == pytest.approx(t + p.probe)
    assert p.aligned_end(t, t_next, t_next) is None  # at its end: the step already ends there
    assert p.aligned_end(t, t + p.probe, t) is None  # already a probe step


def test_a_make_a_sliver_from_a_steps_edge_counts_as_there():
    """With the circuit's shortest step as ``resolution`` (here 2.4e-12 s, the default
    relay's sliver), a make 5e-15 s after the step's start is at its start (a probe step,
    no femtosecond step for ngspice) and one 3e-15 s before its end is at its end (the step
    is kept); without, each cuts the step there (the guard is 1e-9 macro steps, 5e-15 s)."""
    t, t_next = 1e-3, 1e-3 + H
    plain, sliver = policy(), policy(resolution=2.4e-12)
    assert plain.aligned_end(t, t_next, t + 5.1e-15) == t + 5.1e-15
    assert sliver.aligned_end(t, t_next, t + 5.1e-15) == pytest.approx(t + sliver.probe)
    assert plain.aligned_end(t, t_next, t_next - 5.1e-15) == t_next - 5.1e-15
    assert sliver.aligned_end(t, t_next, t_next - 5.1e-15) is None
    assert sliver.guard == 2.4e-12 and plain.guard == pytest.approx(1e-9 * H)


@pytest.mark.parametrize("field, value", [("macro_step", 0.0), ("free_step", 1e-9), ("probe_time", math.nan),
                                          ("change_fraction", -1.0), ("circuit_points", 0), ("circuit_points", 2.0),
                                          ("point_fraction", 0.0), ("point_fraction", math.nan),
                                          ("resolution", -1e-12), ("resolution", math.inf)])
def test_bad_policy_values_are_named(field, value):
    with pytest.raises(ValueError, match=field):
        policy(**{field: value})


def test_the_circuits_step_in_a_macro_step_is_its_share_and_a_fraction_of_the_time_constant():
    """circuit_step: the macro step over circuit_points (none at one point: ngspice's own
    steps), and point_fraction of the coil's time constant where one is given (inf where the
    coil's flux is steady); the smaller of the two."""
    p = policy(circuit_points=4, point_fraction=0.0125)
    assert p.circuit_step(1e-3, 1.2e-3) == pytest.approx(5e-5)
    assert p.circuit_step(1e-3, 1.2e-3, time_constant=3e-3) == pytest.approx(3.75e-5)
    assert p.circuit_step(1e-3, 1.02e-3, time_constant=3e-3) == pytest.approx(5e-6)
    assert policy().circuit_step(0.0, 1e-3) == math.inf  # the contact's rules: ngspice's own steps
    assert policy(point_fraction=0.1).circuit_step(0.0, 1e-3, time_constant=2e-3) == pytest.approx(2e-4)


def test_policy_follows_the_scene_coupling_options():
    from coupling.core.scene import CouplingOptions

    p = StepPolicy.from_options(CouplingOptions(macro_step=4e-6, max_macro_step=2e-4))
    assert (p.macro_step, p.free_step) == (4e-6, 2e-4)
    p = StepPolicy.from_options(CouplingOptions(scheme="jacobi", macro_step=4e-6, max_macro_step=2e-4))
    assert p.free_step == 4e-6  # jacobi exchanges every macro step
    coil = StepPolicy.from_options(CouplingOptions()).for_coil(
        CouplingOptions(coil_step_points=3, coil_point_fraction=0.05), floor=1e-4)
    assert (coil.circuit_points, coil.point_fraction, coil.current_floor) == (3, 0.05, 1e-4)


SHORT_COUPLED = """
[bar]
length = 0.3
diameter = 0.01
tip_radius = 0.005
modes = 0
[initial]
height = 0.0002
angle_deg = 60.0
velocity = [0.2, 0.0, -0.5]
[solver]
t_end = 0.0012
[tribology]
source = "illustrative"
[circuit]
template = "inductive"
voltage = 24.0
load_resistance = 10.0
load_inductance = 1e-3
snubber = { resistance = 47.0, capacitance = 47e-9 }
[coupling]
macro_step = 1e-5
[output]
plots = false
"""


def test_one_cosimulation_runs_again_with_the_same_result_and_leaves_ngspice_free():
    """A sweep worker runs many scenes in one process: a second run of the same CoSimulation
    (and a run after a failed one) gives the same waveforms, mu log and statistics."""
    import tomllib

    from circuit import get_session
    from coupling import CoSimulation, CoupledRunError
    from coupling.core.scene import scene_from_dict

    scene = scene_from_dict(tomllib.loads(SHORT_COUPLED))
    sim = CoSimulation(scene)
    first = sim.run()
    log_first = list(sim.mu_log)
    assert get_session().owner is None  # the Stepper released ngspice
    # a failing run in between (the mechanics runs out of steps inside a macro step)
    failing = scene.set("solver.max_steps", 3)
    with pytest.raises(CoupledRunError):
        CoSimulation(failing).run()
    assert get_session().owner is None
    second = sim.run()
    assert sim.mu_log == log_first
    for key in ("macro_steps", "aligned_steps", "contact_steps"):
        assert second.stats[key] == first.stats[key]
    assert second.summary["bounce"] == first.summary["bounce"]
    np.testing.assert_array_equal(second.waveforms.contact_voltage.to_numpy(),
                                  first.waveforms.contact_voltage.to_numpy())


def test_steps_grow_while_a_contact_stays_closed_and_restart_after_a_jump():
    p = policy()
    assert p.base_end(0.0, 1.0, touching=True, previous=H) == pytest.approx(2 * H)
    assert p.base_end(0.0, 1.0, touching=True, previous=3 * H) == pytest.approx(p.growth_cap * H)  # capped
    assert p.base_end(0.0, 1.0, touching=True, previous=p.probe) == H  # after a probe: the macro step
    assert p.base_end(0.0, 1.0, touching=True, previous=0.0) == H  # the last step made or broke a contact
    assert p.base_end(0.0, 1.0, touching=False, previous=H) == 1e-3  # free flight: the free step as before
    # steady: the change rule of plan() over the span
    assert p.steady(current=1.0, rate=1.0, span=1e-4)
    assert not p.steady(current=1.0, rate=1e3, span=1e-4)


def test_growing_steps_in_a_closed_contact_change_no_checked_metric():
    """The default relay over 3 ms (bounces, then 1.5 ms closed with the blade ringing
    under the rising armature force): steps that grow while the contact stays closed agree
    with steps held at the macro step within run --check's tolerances on every metric and
    on the waveforms, in a fraction of the macro steps."""
    import dataclasses

    from coupling import CoSimulation, builtin_scene
    from coupling.app.accuracy import compare, metrics_of, tip_intervals

    scene = builtin_scene("relay_force").update({"solver.t_end": 0.003})
    runs = {}
    for cap in (1.0, 4.0):
        sim = CoSimulation(scene)
        sim.policy = dataclasses.replace(sim.policy, growth_cap=cap)
        runs[cap] = sim.run()
    held, grown = runs[1.0], runs[4.0]
    diff = compare(metrics_of(held), metrics_of(grown), tip_intervals(held), tip_intervals(grown))
    assert diff["moved"] == [], diff
    assert grown.stats["macro_steps"] < 0.6 * held.stats["macro_steps"]
    t = np.linspace(0.0, 0.003, 3001)
    for name, scale in (("contact_voltage", 24.0), ("load_current", 2.4)):
        a = np.interp(t, held.waveform_columns["time"], held.waveform_columns[name])
        b = np.interp(t, grown.waveform_columns["time"], grown.waveform_columns[name])
        assert np.sqrt(np.mean((a - b) ** 2)) < 1e-3 * scale, name
    # the motion: the contact force from the mechanics' own records (steps of ~1 us)
    ha, hb = held.mechanics.history, grown.mechanics.history
    a, b = np.interp(t, ha.time, ha.normal_force_0), np.interp(t, hb.time, hb.normal_force_0)
    assert np.sqrt(np.mean((a - b) ** 2)) < 1e-3 * 1.5


def test_the_tail_carries_the_last_points_across_steps_and_forgets_them_at_a_jump():
    """A circuit signal observed a step at a time, each step's first point the previous
    step's last (as a step's reader gives them), one new point a step: the tail's rate and
    time scale are those of the exponential approach, which needs points of several steps
    (two points alone give the cautious scale |I| / |dI/dt|, tau (e^x - 1) here); after a
    jump only the last point is left, and no rate."""
    from coupling.core.exchange import Tail

    tau, dt = 1e-4, 1e-6
    t = np.arange(0.0, 0.5 * tau, dt)
    tail = Tail()
    for k in range(1, len(t)):
        tail.observe(t[k - 1:k + 1], exponential(t[k - 1:k + 1], tau=tau), jumped=False)
    rate, scale = tail.rate(H)
    slope = 2.0 / tau * math.exp(-t[-1] / tau)
    # one-sided differences over dt: both off by dt / (2 tau) (the derivative half a point back)
    assert rate == pytest.approx(slope, rel=dt / tau)
    assert scale == pytest.approx(tau, rel=dt / tau)
    tail.observe(t[-1:] + dt, exponential(t[-1:] + dt, tau=tau), jumped=True)
    assert tail.rate(H) == (0.0, math.inf)


@pytest.mark.parametrize("speed, accel", [(0.3, 0.0), (0.0, 40.0), (0.3, 40.0), (1e-9, 1e4)])
def test_the_gap_rules_time_is_when_the_gap_has_closed_by_its_room(speed, accel):
    """gap_time(room, v, a) is the t at which v t + a t^2 / 2 reaches room: room / v without
    acceleration, sqrt(2 room / a) from rest (the armature leaving its stop, where a rule on
    the speed alone saw no time scale at all: on the changeover example it let the coil's
    steps grow to 570 us in the armature's flight and left its operate time 8 us late)."""
    from coupling.core.exchange import gap_time

    room = 2e-4
    t = gap_time(room, speed, accel)
    assert speed * t + 0.5 * accel * t * t == pytest.approx(room, rel=1e-12)
    if accel == 0.0:
        assert t == pytest.approx(room / speed, rel=1e-15)
    if speed == 0.0:
        assert t == pytest.approx(math.sqrt(2.0 * room / accel), rel=1e-15)
    assert gap_time(room, 0.0, 0.0) == math.inf and gap_time(0.0, speed, accel) == 0.0


def test_the_coils_gap_rule_keeps_the_changeovers_operate_time_within_its_tolerance():
    """The changeover example (max_macro_step 1 ms) up to its operate transfer, at the default
    step rules and with every rule halved once and twice: the operate time converges at the
    coupling's second order or faster (measured 4.5: 0.36 then 0.016 us, with the steps'
    approach to the armature's unseat; 1.97 before it), and the default rules' is within 1 us
    of the twice-halved run's (measured 0.38 us; 0.49 before the approach, 1.25 with psi^2's
    curvature rule alone, whose longer step over the unseat the approach removed). The gap rule once took the
    armature's speed alone: from its slow start the steps grew to 200-570 us and the operate
    time came out 9.1 us late (5.9390 against 5.9299 ms). With psi^2 extrapolated along the
    chord of the last points instead of the secant of their parabola the default rules' error
    was 2.75 us; before ngspice's steps were bounded through the coil's rise
    (coupling.coil_step_points, coil_point_fraction) it sat 1.3 us from a twice-halved run
    whose own sequence was not monotone (the circuit's error there, which halving the macro
    steps did not reduce, partly cancelled the coupling's)."""
    from pathlib import Path

    from coupling import load_scene, run
    from coupling.app.accuracy import refined_steps

    scene = load_scene(Path(__file__).resolve().parents[2] / "examples" / "changeover_relay.toml")
    scene = scene.set("solver.t_end", 0.013)
    once = refined_steps(scene)[1]
    twice = refined_steps(once)[1]
    base, mid, ref = (run(s).relay["operate_time"] for s in (scene, once, twice))
    assert None not in (base, mid, ref)
    assert math.log2(abs(base - mid) / abs(mid - ref)) > 1.5, (base, mid, ref)
    assert abs(base - ref) <= 1e-6, (base, ref)


def test_a_stationary_point_of_the_watched_signal_bounds_the_step_by_its_curvature():
    """Where the signal v(t) = v0 + c (t - t0)^2 / 2 is stationary (a ringing coil's psi^2 at an
    extremum or a zero of psi) its slope vanishes, and the change rule on the slope alone lets
    the whole proposed step pass. With the curvature the step is tsf sqrt(2 (|v0| + floor) /
    |c|), over which the parabola moves by exactly tsf^2 (|v0| + floor): the time the curvature
    takes to change the signal by its size, scaled as the slope's rule scales its time scale."""
    floor, tsf = 1e-3, 0.1
    p = policy(current_floor=floor, time_scale_fraction=tsf)
    v0, c, t = 2e-3, 4000.0, 1e-3
    proposed = t + 1e-3
    blind, _ = p.plan(t, proposed, 1.0, touching=True, jumped=False, current=v0, rate=0.0, scale=math.inf)
    assert blind == proposed
    end, slope = p.plan(t, proposed, 1.0, touching=True, jumped=False, current=v0, rate=0.0, scale=math.inf,
                        curvature=c)
    h = end - t
    assert slope == 0.0 and h == pytest.approx(tsf * math.sqrt(2.0 * (v0 + floor) / c), rel=1e-12)
    assert 0.5 * c * h * h == pytest.approx(tsf ** 2 * (v0 + floor), rel=1e-12)
    # a curvature whose parabola stays within the change rule over the step changes nothing
    gentle = 0.5 * p.change_fraction * (v0 + floor) / (proposed - t) ** 2
    assert p.plan(t, proposed, 1.0, touching=True, jumped=False, current=v0, rate=0.0, scale=math.inf,
                  curvature=gentle)[0] == proposed
    # nor below the probe
    assert p.plan(t, proposed, 1.0, touching=True, jumped=False, current=0.0, rate=0.0, scale=math.inf,
                  curvature=1e30)[0] == pytest.approx(t + p.probe, rel=1e-12)


def test_a_step_approaches_the_armatures_unseat_by_halves_and_ends_a_macro_step_past_it():
    """The mechanics find the seated armature leaving its stop at t_u inside a step (with the
    drive extrapolated over it): the step ends halfway there while t_u is more than a macro
    step H ahead, else H past t_u, and is kept where it ends before that."""
    p = policy()
    t = 1e-3
    assert p.approach_end(t, t + 1e-3, t + 400e-6) == pytest.approx(t + 200e-6, rel=1e-12)
    assert p.approach_end(t, t + 1e-3, t + 0.5 * H) == pytest.approx(t + 1.5 * H, rel=1e-12)
    assert p.approach_end(t, t + 1.2 * H, t + 0.5 * H) is None
    lead, steps = 600e-6, 0  # from a 600 us lead down to one macro step: log2(600 / 5) halvings
    while (end := p.approach_end(t, t + 1e-3, t + lead)) is not None and end - t < lead:
        lead -= end - t
        steps += 1
    assert steps == math.ceil(math.log2(600e-6 / H)) and 0.5 * H < lead <= H


def test_the_coils_time_scale_at_a_zero_of_its_flux_is_the_curvatures_not_zero():
    """A released coil ringing through a zero of its flux linkage, psi = A sin(w t) with A a
    tenth of the rated psi: psi^2's slope vanishes at the zero and |rate / curvature| with
    it, though psi^2 is ~0 there and its curvature, 2 A^2 w^2, moves it by the rated value
    only in sqrt(2 (psi^2 + rated) / curvature) ~ 7 / w. The step rules' scale is at least
    BEND_FRACTION of that; the drive's extrapolation horizon keeps |rate / curvature|."""
    from types import SimpleNamespace

    import numpy as np

    from coupling.core.exchange import CoilLink
    from coupling.core.policy import BEND_FRACTION

    rated, w = 0.036, 2 * math.pi * 3.5e3  # Wb (the default relay's psi at its rated current), rad/s
    link = CoilLink("coil", magnet=None, rest_gap=5e-4, floor=rated ** 2)
    link.separable = True  # (psi^2 is the signal, as for a flux-tube magnet)
    p = policy()
    t_zero = 1e-3
    for k, end in enumerate((t_zero - 3e-6, t_zero - 1e-6, t_zero + 0.5e-7)):
        times = np.array([end - 2e-6, end - 1e-6, end])
        psi = 0.1 * rated * np.sin(w * (times - t_zero))
        step = SimpleNamespace(float_columns=lambda names, times=times, psi=psi:
                               [(times if name == "time" else psi).tolist() for name in names],
                               values={"coil_flux_linkage": float(psi[-1])})
        seg = SimpleNamespace(t_start=times[0], t_end=end, armature=lambda s: (0.0, 0.0))
        link.observe(step, seg, p)
    curvature = 2 * (0.1 * rated) ** 2 * w ** 2
    bend = math.sqrt(2 * (link.value + rated ** 2) / curvature)
    assert link.bound_by == "curvature"
    assert link.scale == pytest.approx(BEND_FRACTION * bend, rel=0.05)
    assert link.horizon == pytest.approx(abs(link.rate / link.curvature), rel=1e-9)
    assert link.horizon < 1e-2 * link.scale  # (what the step rules took before: the steps fell to the probe)


def test_a_pair_of_tails_keeps_what_each_would_keep_alone():
    """Tail.observe_pair (the coil's psi^2 and psi, over the same times) keeps the points that
    observe_floats keeps on each tail alone: steps whose first point repeats the last one,
    a point no later than the one before it, more points than the tail holds."""
    from coupling.core.exchange import Tail

    steps = [[0.0, 1e-6], [1e-6, 2e-6, 3e-6], [3e-6, 3e-6, 5e-6], [5e-6, 4.5e-6, 6e-6, 7e-6],
             [7e-6] + [7e-6 + 1e-7 * k for k in range(1, 11)]]
    alone, psi_alone, first, second = Tail(), Tail(), Tail(), Tail()
    for k, t in enumerate(steps):
        v = [math.sin(1e5 * s) + k for s in t]
        w = [x * x for x in v]
        alone.observe_floats(t, w, False)
        psi_alone.observe_floats(t, v, False)
        first.observe_pair(second, t, w, v)
        assert (first.t, first.v, second.t, second.v) == (alone.t, alone.v, psi_alone.t, psi_alone.v)
        assert first.derivatives(1e-6) == alone.derivatives(1e-6)
