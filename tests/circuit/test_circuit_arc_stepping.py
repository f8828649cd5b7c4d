"""The arc model under co-simulation stepping: any macro step, makes and breaks while an arc
burns, rejected trial steps, knife-edge perturbations, a current-dependent contact.

Scene (the reported failures): 24 V / 0.05 ohm source, 1 uH wiring, 12 ohm load, 100 pF
across the contact, default ArcModel (12 V, 0.4 A, 0.05 ohm), four bounces. After the
first break the arc burns through every open interval at (E - U_min) / (R_source +
R_load + R_arc) = 0.99174 A, and dies at every make (the contact shorts it). SI units.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from circuit import (
    ArcModel,
    ContactSchedule,
    DCSource,
    InductiveLoad,
    ResistiveLoad,
    SimulationOptions,
    Stepper,
    SwitchCircuit,
    Wiring,
    run_transient,
)
from circuit.arc import ArcState

E, R_SOURCE, R_LOAD, R_CLOSED = 24.0, 0.05, 12.0, 0.005
ARC = ArcModel()
BURNING = (E - ARC.min_voltage) / (R_SOURCE + R_LOAD + ARC.resistance)  # 0.99174 A
BOUNCES = ((0.995e-3, 1.064e-3), (1.224e-3, 1.306e-3), (1.492e-3, 1.572e-3), (2.048e-3, 2.127e-3))
T_END = 3e-3
MACRO_STEPS = [None, 1e-6, 2e-6, 1e-5, 1e-4]  # None: one-shot
FACTOR = "(0.6+0.4*exp(-min(max(abs(I),0),5)/1.7))"  # contact_current_factor g(I)
# A crawl (the SW model with a current factor took 1e-14 s steps) fails fast instead of hanging.
OPTIONS = SimulationOptions(wall_timeout=60.0)


def scene(factor: str | None = None, arc: ArcModel = ARC) -> SwitchCircuit:
    return SwitchCircuit(DCSource(E, R_SOURCE), ResistiveLoad(R_LOAD), wiring=Wiring(0.0, 1e-6),
                         contact_capacitance=100e-12, arc=arc, contact_current_factor=factor)


def bounce_schedule(intervals=BOUNCES) -> ContactSchedule:
    return ContactSchedule(tuple(intervals), closed_resistance=R_CLOSED)


def stepped(circuit, schedule, t_end, macro_step, options=OPTIONS):
    """Fixed macro steps with the schedule's breakpoints (None: one-shot)."""
    if macro_step is None:
        return run_transient(circuit, schedule, t_end, options=options)
    with Stepper(circuit, t_end, options) as stepper:
        t = 0.0
        while not stepper.finished:
            t_next = min(t + macro_step, t_end)
            stepper.advance(t_next, schedule, schedule.breakpoints(t, t_next))
            t = t_next
        return stepper.results()


def coupled_like(circuit, schedule, t_end, contact_step=2e-6, free_step=1e-4, tail=20e-6, options=OPTIONS):
    """Like coupling.core.master: short steps in contact (and for ``tail`` after a break), long
    steps in free flight, each step ending exactly at the next make or break."""
    events = sorted({t for pair in schedule.intervals for t in pair})

    def touching(t):
        return any(make - 1e-15 <= t < brk + tail for make, brk in schedule.intervals)

    with Stepper(circuit, t_end, options) as stepper:
        t = 0.0
        while not stepper.finished:
            t_next = min(t + (contact_step if touching(t) else free_step), t_end)
            inside = [e for e in events if t + 1e-15 < e < t_next - 1e-15]
            if inside:
                t_next = inside[0]
            stepper.advance(t_next, schedule, schedule.breakpoints(t, t_next))
            t = t_next
        return stepper.results()


def open_intervals(schedule, settle=3e-6):
    """(start, end) of each open interval after the first break, less the arc's formation."""
    iv = schedule.intervals
    return [(b0 + settle, m1 - 1e-7) for (_, b0), (m1, _) in zip(iv[:-1], iv[1:])]


def assert_burns_through_open_intervals(df, schedule, rtol=1e-4):
    t, i_arc, v = df.time.to_numpy(), df.arc_current.to_numpy(), df.contact_voltage.to_numpy()
    for start, end in open_intervals(schedule):
        window = (t > start) & (t < end)
        assert window.sum() >= 2
        np.testing.assert_allclose(i_arc[window], BURNING, rtol=rtol, err_msg=f"open interval {start}-{end} s")
        np.testing.assert_allclose(v[window], ARC.min_voltage + ARC.resistance * i_arc[window], atol=1e-3)


def assert_dies_while_closed(df, schedule):
    t, i_arc = df.time.to_numpy(), df.arc_current.to_numpy()
    for make, brk in schedule.intervals:
        closed = (t > make + 1e-6) & (t < brk - 1e-7)
        assert np.max(np.abs(i_arc[closed])) < 1e-6  # the 1 GOhm floor of the path: 1e-11 A


def burning_edges(df, threshold=0.5):
    on = (np.abs(df.arc_current.to_numpy()) > threshold).astype(int)
    return df.time.to_numpy()[1:][np.diff(on) != 0]


@pytest.fixture(scope="module")
def bounce_runs():
    schedule = bounce_schedule()
    return {h: stepped(scene(), schedule, T_END, h) for h in MACRO_STEPS}


@pytest.mark.parametrize("macro_step", MACRO_STEPS, ids=lambda h: "one-shot" if h is None else f"H={h:g}")
def test_arc_burns_through_every_open_interval_at_any_macro_step(bounce_runs, macro_step):
    """The reported failures: at H = 2 us 'timestep too small' at the make at 1.224 ms."""
    df = bounce_runs[macro_step]
    schedule = bounce_schedule()
    assert df.time.iloc[-1] == pytest.approx(T_END, rel=1e-12)
    assert_burns_through_open_intervals(df, schedule)
    assert_dies_while_closed(df, schedule)
    # No arc before the first make: the gap was never armed.
    assert np.max(np.abs(df.arc_current.to_numpy()[df.time.to_numpy() < BOUNCES[0][0]])) < 1e-6


@pytest.mark.parametrize("macro_step", MACRO_STEPS[1:], ids=lambda h: f"H={h:g}")
def test_stepped_arc_matches_the_one_shot_run(bounce_runs, macro_step):
    reference, df = bounce_runs[None], bounce_runs[macro_step]
    # The arc forms at each break and dies at each make at the same instants (ns: the
    # edges lie in the 10 ns ramps; measured <= 0.3 ns).
    edges, edges_ref = burning_edges(df), burning_edges(reference)
    assert len(edges_ref) == 2 * (len(BOUNCES) - 1) + 1
    assert len(edges) == len(edges_ref)
    np.testing.assert_allclose(edges, edges_ref, rtol=0, atol=2e-9)
    # Away from the 5 us after each ramp corner: the same waveform (measured <= 1e-6).
    grid = np.arange(0.0, T_END, 1e-6)
    quiet = np.ones_like(grid, dtype=bool)
    for corner in bounce_schedule().breakpoints():
        quiet &= ~((grid >= corner - 0.2e-6) & (grid < corner + 5e-6))
    for column, atol in (("arc_current", 1e-5), ("contact_voltage", 1e-5), ("load_current", 1e-5)):
        ours = np.interp(grid, df.time, df[column])[quiet]
        theirs = np.interp(grid, reference.time, reference[column])[quiet]
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=atol, err_msg=column)


@pytest.mark.parametrize("offset", [0.0, -77, -1e-9, 0.7e-6, 1.3e-6],
                         ids=["make at the macro time", "77 ulp before it", "1 ns before it",
                              "inside the step", "early in the step"])
@pytest.mark.parametrize("macro_step", [1e-6, 2e-6, 1e-5, 1e-4])
def test_make_while_an_arc_burns(offset, macro_step):
    """A make shorts a burning 1 A arc: it dies within the 10 ns ramp, wherever the make
    falls in the macro step (77 ulp before a 2 us macro time was the reported abort)."""
    t_break = 0.1e-3
    t_grid = 0.4e-3  # a macro time
    t_make = t_grid + (offset * math.ulp(t_grid) if offset == -77 else offset)
    schedule = ContactSchedule(((0.0, t_break), (t_make, math.inf)), closed_resistance=R_CLOSED)
    df = stepped(scene(), schedule, 0.5e-3, macro_step)
    t, i_arc = df.time.to_numpy(), df.arc_current.to_numpy()
    burning = (t > t_break + 3e-6) & (t < t_make)
    np.testing.assert_allclose(i_arc[burning], BURNING, rtol=1e-4)
    assert np.all(np.abs(i_arc[t > t_make + 20e-9]) < 1e-6)
    closed = t > t_make + 10e-6
    assert df.contact_current.to_numpy()[closed] == pytest.approx(E / (R_SOURCE + R_LOAD + R_CLOSED), rel=1e-6)


@pytest.mark.parametrize("early", [1e-14, 1e-11, 1e-9, 1e-7])
def test_a_rejected_trial_step_reaching_a_make_does_not_put_out_the_arc(early):
    """The coupled run's spurious extinction: the mechanics' G(t) became positive slightly
    before the make breakpoint that ends a 100 us free-flight step. ngspice's trial step
    to the make saw the contact closed, the arc went out there, the step was rejected, and
    with the SW switch the retry (at a time with G = 0) started from the rejected, 'off'
    solution: the arc died 30 us before the make. The arc must burn while G = 0."""
    t_make = 1.4924e-3

    def g(t):
        if t < 1.0e-3:
            return 200.0 if 0.9e-3 <= t else 0.0  # closed 0.9-1.0 ms: the arc forms at the break
        return 0.134 if t >= t_make - early else 0.0  # steep, like G_F(F) at first touch

    steps = [(0.9e-3, ()), (1.0e-3, (1.0e-3,)), (1.002e-3, ()), (1.02e-3, ())]
    steps += [(1.02e-3 + k * 1e-4, ()) for k in range(1, 5)] + [(t_make, (t_make,))]
    with Stepper(scene(), t_make, OPTIONS) as stepper:
        for t_next, breakpoints in steps:
            stepper.advance(t_next, g, breakpoints)
        df = stepper.results()
    t, i_arc = df.time.to_numpy(), df.arc_current.to_numpy()
    open_ = (t > 1.0e-3 + 3e-6) & (df.contact_conductance.to_numpy() == 0.0)
    assert open_.sum() > 10
    np.testing.assert_allclose(i_arc[open_], BURNING, rtol=1e-4)
    # ...and it burned until the contact closed (the SW model lost it 30 us before).
    assert t[open_].max() >= t_make - early - 1e-6


@pytest.mark.parametrize("seed", range(4))
def test_knife_edge_perturbations_keep_the_arc_burning(seed):
    """Make/break instants jittered by ~1e-12 relative (the coupled run's failure came and
    went with round-off in the mechanics), stepped like the coupling: same waveform."""
    rng = np.random.default_rng(seed)
    jittered = [(m * (1 + rng.uniform(-1e-12, 1e-12)), b * (1 + rng.uniform(-1e-12, 1e-12))) for m, b in BOUNCES]
    schedule = bounce_schedule(jittered)
    tail = rng.uniform(0.0, 40e-6)
    df = coupled_like(scene(), schedule, T_END, tail=tail)
    base = coupled_like(scene(), bounce_schedule(), T_END, tail=tail)
    assert_burns_through_open_intervals(df, schedule)
    assert_dies_while_closed(df, schedule)
    np.testing.assert_allclose(burning_edges(df), burning_edges(base), rtol=0, atol=2e-9)


@pytest.mark.parametrize("seed", range(3))
def test_perturbed_bounce_times_under_coupling_steps(seed):
    """Larger (1e-3 relative) changes of the bounce instants and of the free-flight
    stepping: the arc always burns through the open intervals."""
    rng = np.random.default_rng(100 + seed)
    jittered = [(m * (1 + rng.uniform(-1e-3, 1e-3)), b * (1 + rng.uniform(-1e-3, 1e-3))) for m, b in BOUNCES]
    schedule = bounce_schedule(jittered)
    df = coupled_like(scene(), schedule, T_END, contact_step=float(rng.choice([1e-6, 2e-6, 5e-6])),
                      free_step=float(rng.uniform(20e-6, 100e-6)), tail=rng.uniform(0.0, 40e-6))
    assert_burns_through_open_intervals(df, schedule)
    assert_dies_while_closed(df, schedule)


def _g(current: float) -> float:
    return 0.6 + 0.4 * math.exp(-min(max(abs(current), 0.0), 5.0) / 1.7)


@pytest.mark.parametrize("macro_step", [None, 2e-6, 1e-4], ids=["one-shot", "H=2e-06", "H=0.0001"])
def test_arc_with_a_current_dependent_contact(macro_step):
    """With contact_current_factor the SW model never converged while closed (the arc
    branch current was round-off above ABSTOL) and crawled at 1e-14 s steps."""
    schedule = bounce_schedule()
    df = stepped(scene(FACTOR), schedule, T_END, macro_step)
    assert_burns_through_open_intervals(df, schedule)
    assert_dies_while_closed(df, schedule)
    # Closed: I = E / (R_source + R_load + g(I) R_closed), solved inside ngspice.
    expected = brentq(lambda i: i - E / (R_SOURCE + R_LOAD + _g(i) * R_CLOSED), 0.0, 3.0)
    t = df.time.to_numpy()
    for make, brk in BOUNCES:
        closed = (t > make + 20e-6) & (t < brk - 1e-7)
        np.testing.assert_allclose(df.contact_current.to_numpy()[closed], expected, rtol=1e-6)


def test_arc_with_a_current_dependent_contact_under_coupling_steps():
    schedule = bounce_schedule()
    df = coupled_like(scene(FACTOR), schedule, T_END)
    reference = stepped(scene(FACTOR), schedule, T_END, None)
    assert_burns_through_open_intervals(df, schedule)
    np.testing.assert_allclose(burning_edges(df), burning_edges(reference), rtol=0, atol=2e-9)


# -- extinction at I_min and breakdown, stepped (the closed forms are in test_circuit_arc) --

COIL = SwitchCircuit(DCSource(10.0, 0.0), InductiveLoad(5.0, 1e-3), wiring=Wiring(0.0, 0.0),
                     contact_capacitance=100e-12, arc=ARC)
OPENING = ContactSchedule(((0.0, 0.1e-3),), closed_resistance=0.01)


def _extinction(df):
    t, i_arc = df.time.to_numpy(), np.abs(df.arc_current.to_numpy())
    k = int(np.argmax((t > 0.1e-3 + 1e-6) & (i_arc < 1e-4)))
    return t[k - 1], i_arc[k - 1]


@pytest.mark.parametrize("macro_step", [1e-6, 2e-6, 1e-5, 1e-4])
def test_extinction_at_the_minimum_current_when_stepped(macro_step):
    options = SimulationOptions(max_step=1e-6, wall_timeout=60.0)
    t_ref, i_ref = _extinction(stepped(COIL, OPENING, 0.4e-3, None, options))
    t_ext, i_ext = _extinction(stepped(COIL, OPENING, 0.4e-3, macro_step, options))
    assert i_ext == pytest.approx(ARC.min_current, rel=1e-4)
    assert i_ext == pytest.approx(i_ref, rel=1e-4)
    assert t_ext == pytest.approx(t_ref, abs=2e-3 * (t_ref - 0.1e-3))


@pytest.mark.parametrize("macro_step", [2e-6, 1e-4])
def test_breakdown_reignitions_when_stepped(macro_step):
    arc = ArcModel(breakdown_voltage=300.0)
    coil = SwitchCircuit(DCSource(10.0, 0.0), InductiveLoad(5.0, 1e-3), wiring=Wiring(0.0, 0.0),
                         contact_capacitance=100e-12, arc=arc)
    options = SimulationOptions(max_step=1e-6, wall_timeout=60.0)
    counts = []
    for h in (None, macro_step):
        df = stepped(coil, OPENING, 0.4e-3, h, options)
        assert df.contact_voltage.max() == pytest.approx(300.0, abs=0.5)
        counts.append(len(burning_edges(df, 1e-4)))
    assert counts[0] == counts[1] > 20


# -- the state machine itself (no ngspice) --

class FakeRun:
    """Feeds ArcState accepted points: time, contact conductance, arc current, gap voltage."""

    def __init__(self, arc: ArcModel, closed_at_zero: bool):
        self.state = ArcState(arc, "varc#branch", "a", "b", "contact_g")
        self.state.start(closed_at_zero)

    def point(self, t, g, current=0.0, voltage=0.0):
        values = {"varc#branch": current, "a": voltage, "b": 0.0, "contact_g": g}
        return self.state.accepted(t, None, lambda names: [values[n] for n in names])


def test_state_rules_at_accepted_points():
    run = FakeRun(ARC, closed_at_zero=True)
    assert run.state.burning  # closed at t = 0: armed
    run.point(1e-5, 100.0)
    run.point(2e-5, 100.0)  # the break, a breakpoint: G there is the left limit
    step, land = run.point(2e-5 + 1e-9, 0.0, current=0.0)
    assert run.state.burning and land == pytest.approx(2e-5 + ARC.formation_time, rel=1e-12)
    run.point(2e-5 + 0.5e-6, 0.0, current=0.9)  # the arc forms within the window
    run.point(land, 0.0, current=0.9)  # window over, |i| >= I_min: keeps burning
    assert run.state.burning
    run.point(land + 1e-6, 0.0, current=0.7)
    step, _ = run.point(land + 2e-6, 0.0, current=0.5)  # falling towards I_min at 0.2 A/us: shorter steps
    assert step == pytest.approx((0.75 * 0.1 + 1e-5 * 0.4) / (0.2 / 1e-6))
    run.point(land + 3e-6, 0.0, current=0.3999)
    assert not run.state.burning and run.state.value == 0.0  # below I_min: out
    run.point(land + 4e-6, 0.0, current=1e-6, voltage=5000.0)
    assert not run.state.burning  # no breakdown voltage: never re-ignites


def extinction_shortfall(ripple: float, period: float, end: float, cap: float) -> float:
    """A break's arc current falling towards I_min at c = 50 A/s on average, its rate swinging
    between (1 - ripple) and (1 + ripple) times that with ``period`` (s): i = I_min + c (end -
    t) - d sin(w t), d = ripple c / w. Stepped as the arc's bound allows, each step at most
    ``cap`` (s), until the arc goes out (asserted); returns i / I_min - 1 at that first point
    below I_min."""
    run = FakeRun(ARC, closed_at_zero=True)
    i_min, c, w = ARC.min_current, 50.0, 2 * math.pi / period  # A, A/s, rad/s
    d = ripple * c / w

    def current(t):
        return i_min + c * (end - t) - d * math.sin(w * t)

    run.point(1e-6, 100.0)
    run.point(2e-6, 100.0)  # the break
    _, land = run.point(2e-6 + 1e-9, 0.0, current=current(2e-6 + 1e-9))
    t = land
    step, _ = run.point(t, 0.0, current=current(t))
    for _ in range(10_000):
        if not run.state.burning:
            break
        t += min(step, cap)
        step, _ = run.point(t, 0.0, current=current(t))
    assert not run.state.burning
    return current(t) / i_min - 1.0


@pytest.mark.parametrize("ripple", [0.0, 0.5, 0.8, 0.95])
def test_an_arc_goes_out_within_resolution_of_i_min_when_its_current_falls_unevenly(ripple):
    """A break's arc current falling towards I_min at a rate that swings between (1 - ripple)
    and (1 + ripple) times its mean (i = I_min + c (T - t) - d sin(w t), a gap opened by a
    ringing blade), stepped as the arc's bound allows (at most 40 us): the arc goes out at the
    first point below I_min, and that point lies within RESOLUTION of I_min, as a steady fall
    does. With the rate of the last step alone a slow step let the next one run 6.75 times
    the remaining distance: out 0.1-0.3 % below I_min (measured; the changeover example's NC
    arc went out 0.27 % below it)."""
    from circuit.arc import RESOLUTION

    assert -RESOLUTION <= extinction_shortfall(ripple, period=50e-6, end=2e-3, cap=40e-6) < 0.0


@pytest.mark.parametrize("end", [4.0e-3, 4.09e-3])
@pytest.mark.parametrize("cap", [25e-6, 35e-6])
@pytest.mark.parametrize("ripple", [0.4, 0.5, 0.6])
def test_an_arc_goes_out_within_resolution_of_i_min_under_a_callers_step_cap(ripple, cap, end):
    """As above, the rate swinging with a blade's ~100 us ringing, but every step also at most
    ``cap`` (a caller's bound on ngspice's steps, as the coupling's for a coil's flux): steps
    of a quarter to a third of the ringing's period meet fast and slow rates in turn, and
    the fall reaches I_min at ``end`` (s) in different phases of the ringing. The arc still
    goes out within RESOLUTION of I_min. With the step before's rate alone (not the fastest
    of the last three steps' whether the approach sped up or slowed) the changeover
    example's NC arc went out 0.2 % below I_min, and all 12 of these cases out of
    RESOLUTION, by up to 0.16 % (measured)."""
    from circuit.arc import RESOLUTION

    assert -RESOLUTION <= extinction_shortfall(ripple, period=100e-6, end=end, cap=cap) < 0.0


def test_a_make_arms_only_after_the_formation_time():
    run = FakeRun(ARC, closed_at_zero=False)
    run.point(1e-5, 0.0)
    step, land = run.point(1e-5 + 1e-9, 50.0)  # made at 1e-5 (the breakpoint, G left limit 0)
    assert not run.state.burning and land == pytest.approx(1e-5 + ARC.formation_time, rel=1e-9)
    run.point(land, 200.0)
    assert run.state.burning


def test_the_armed_filter_switches_at_the_breakpoint_inside_a_long_step():
    """A 2 us step ending 17 fs after a make must not count as 2 us closed."""
    run = FakeRun(ARC, closed_at_zero=False)
    run.point(1.222e-3, 0.0, current=0.99)
    run.state.add_breakpoints([1.224e-3])
    run.point(1.224e-3 + 1.7e-17, 3e-7, current=0.99)
    assert run.state.level < 1e-9
    run.point(1.224e-3 + 10e-9, 200.0, current=1e-11)
    assert not run.state.burning  # shorted by the contact before the gap was armed


def test_breakdown_reignites_an_extinguished_gap():
    run = FakeRun(ArcModel(breakdown_voltage=300.0), closed_at_zero=False)
    run.point(1e-6, 0.0, voltage=100.0)
    step, _ = run.point(2e-6, 0.0, voltage=200.0)  # rising 1e8 V/s towards 300 V
    assert step == pytest.approx((0.75 * 100.0 + 1e-5 * 300.0) / 1e8)
    run.point(3e-6, 0.0, voltage=300.001)
    assert run.state.burning
