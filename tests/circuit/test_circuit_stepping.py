"""The stepping API: a prescribed bounce schedule against the one-shot PWL run, determinism, step bookkeeping."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from circuit import COLUMNS, SessionBusyError, Stepper, run_pwl_reference, run_transient

from circuit_scenes import BOUNCE_BREAKS, BOUNCE_T_END


def step_through(circuit, schedule, options, macro_step):
    with Stepper(circuit, BOUNCE_T_END, options) as stepper:
        t = 0.0
        while not stepper.finished:
            t_next = min(t + macro_step, BOUNCE_T_END)
            stepper.advance(t_next, schedule, schedule.breakpoints(t, t_next))
            t = t_next
        return stepper.results()


def opening_peaks(df: pd.DataFrame) -> np.ndarray:
    t, v = df.time.to_numpy(), df.contact_voltage.to_numpy()
    return np.array([v[(t >= tb) & (t <= tb + 3e-6)].max() for tb in BOUNCE_BREAKS])


def peak_times(df: pd.DataFrame) -> np.ndarray:
    t, v = df.time.to_numpy(), df.contact_voltage.to_numpy()
    out = []
    for tb in BOUNCE_BREAKS:
        window = (t >= tb) & (t <= tb + 3e-6)
        out.append(t[window][np.argmax(v[window])])
    return np.array(out)


@pytest.fixture(scope="module")
def reference(ringing_circuit, bounce_schedule, bounce_options):
    return run_pwl_reference(ringing_circuit, bounce_schedule, BOUNCE_T_END, options=bounce_options)


@pytest.mark.parametrize("macro_step", [2e-6, 10e-6])
def test_bounce_schedule_stepped_matches_pwl_reference(
    macro_step, reference, ringing_circuit, bounce_schedule, bounce_options
):
    stepped = step_through(ringing_circuit, bounce_schedule, bounce_options, macro_step)
    # Opening spikes: 24 V + 2 A * sqrt(1 uH / 100 pF) ~ 224 V less damping; same peak
    # value (0.2 %) and same time (5 ns, a 16 MHz ringing period is 63 ns).
    assert np.all(opening_peaks(reference) > 200.0)
    np.testing.assert_allclose(opening_peaks(stepped), opening_peaks(reference), rtol=2e-3)
    np.testing.assert_allclose(peak_times(stepped), peak_times(reference), rtol=0, atol=5e-9)
    # On a 10 us grid away from the 5 us after each ramp corner (where the ringing
    # phase differs by a few ns): same waveform to 1 mV and 0.1 mA.
    grid = np.arange(0.0, BOUNCE_T_END, 10e-6)
    quiet = np.ones_like(grid, dtype=bool)
    for corner in bounce_schedule.breakpoints():
        quiet &= ~((grid >= corner) & (grid < corner + 5e-6))
    for column, tol in (("contact_voltage", 1e-3), ("load_current", 1e-4)):
        a = np.interp(grid, stepped.time, stepped[column])
        b = np.interp(grid, reference.time, reference[column])
        assert np.max(np.abs(a - b)[quiet]) < tol, column
    # The contact state is the schedule's.
    assert stepped.contact_resistance.min() == pytest.approx(0.01)
    assert np.isinf(stepped.contact_resistance.iloc[0])


def test_repeated_runs_are_bit_identical(ringing_circuit, bounce_schedule, bounce_options):
    first = step_through(ringing_circuit, bounce_schedule, bounce_options, 10e-6)
    # Something else in between must not leak into the next run.
    run_transient(ringing_circuit, 0.5, 50e-6, options=bounce_options)
    second = step_through(ringing_circuit, bounce_schedule, bounce_options, 10e-6)
    assert list(first.columns) == list(COLUMNS)
    for column in COLUMNS:
        assert np.array_equal(first[column].to_numpy(), second[column].to_numpy()), column


def test_one_shot_callback_run_is_deterministic_and_matches_reference(
    reference, ringing_circuit, bounce_schedule, bounce_options
):
    a = run_transient(ringing_circuit, bounce_schedule, BOUNCE_T_END, options=bounce_options)
    b = run_transient(ringing_circuit, bounce_schedule, BOUNCE_T_END, options=bounce_options)
    assert np.array_equal(a.contact_voltage.to_numpy(), b.contact_voltage.to_numpy())
    np.testing.assert_allclose(opening_peaks(a), opening_peaks(reference), rtol=2e-3)


def test_step_results_cover_the_step(ringing_circuit, bounce_schedule, bounce_options):
    with Stepper(ringing_circuit, 0.4e-3, bounce_options) as stepper:
        assert math.isnan(stepper.contact_current)
        first = stepper.advance(0.2e-3, bounce_schedule, bounce_schedule.breakpoints(0.0, 0.2e-3))
        second = stepper.advance(0.3e-3, bounce_schedule, bounce_schedule.breakpoints(0.2e-3, 0.3e-3))
        frame = second.frame()
        assert frame.time.iloc[0] == first.t_end  # the closed interval [t_start, t_end]
        assert frame.time.iloc[-1] == pytest.approx(0.3e-3, rel=1e-12)
        assert second.points == len(frame) - 1
        assert second.contact_current == frame.contact_current.iloc[-1]
        assert stepper.contact_current == second.contact_current
        # Closed with 0.01 ohm at 0.2 ms: 24 V over 12.06 ohm; open at 0.3 ms (break at 0.25 ms).
        assert first.load_current == pytest.approx(24.0 / 12.06, rel=1e-4)
        assert first.contact_voltage == pytest.approx(0.01 * 24.0 / 12.06, rel=1e-3)
        assert second.contact_current == pytest.approx(0.0, abs=1e-9)
        assert second.contact_voltage == pytest.approx(24.0, rel=1e-4)
        whole = stepper.results()
        assert np.array_equal(whole.time.to_numpy()[-len(frame):], frame.time.to_numpy())
        # the step's columns as floats: the same doubles as its arrays, each call its own list
        for name, values in second.arrays().items():
            floats = second.floats(name)
            assert floats == values.tolist() and floats is not second.floats(name)
            assert all(type(x) is float for x in floats)
        # ... and several at once, each list the caller's own too
        names = tuple(second.arrays())
        lists = second.float_columns(names)
        assert lists == [second.floats(name) for name in names]
        assert all(a is not b for a, b in zip(lists, second.float_columns(names)))
    # After close the results stay readable.
    assert stepper.results().time.iloc[-1] == pytest.approx(0.3e-3, rel=1e-12)
    assert second.frame().time.iloc[-1] == pytest.approx(0.3e-3, rel=1e-12)
    assert first.floats("load_current") == first.reader("load_current").tolist()
    assert first.float_columns(("time", "load_current")) == [first.reader("time").tolist(),
                                                             first.reader("load_current").tolist()]


def test_macro_landing_does_not_reset_the_integration(ringing_circuit, bounce_options):
    """Landing on macro times is not a breakpoint: a quiet stretch takes few extra points."""
    with Stepper(ringing_circuit, 1e-3, bounce_options) as stepper:
        for k in range(1, 101):
            stepper.advance(k * 10e-6, 100.0)
        stepped_points = stepper.stats["points"]
    one_shot = run_transient(ringing_circuit, 100.0, 1e-3, options=bounce_options)
    assert stepped_points <= len(one_shot) + 100 + 5


def test_advance_validates_times_and_breakpoints(ringing_circuit, bounce_options):
    with Stepper(ringing_circuit, 100e-6, bounce_options) as stepper:
        with pytest.raises(ValueError, match="t_next"):
            stepper.advance(0.0, 1.0)
        with pytest.raises(ValueError, match="t_next"):
            stepper.advance(200e-6, 1.0)
        with pytest.raises(ValueError, match="breakpoint"):
            stepper.advance(10e-6, 1.0, breakpoints=[20e-6])
        with pytest.raises(TypeError, match="conductance"):
            stepper.advance(10e-6, "closed")
        stepper.advance(100e-6, 1.0)
        assert stepper.finished
        with pytest.raises(ValueError, match="finished"):
            stepper.advance(100e-6, 1.0)


def test_one_ngspice_per_process_is_guarded(ringing_circuit, bounce_options):
    stepper = Stepper(ringing_circuit, 100e-6, bounce_options)
    try:
        with pytest.raises(SessionBusyError):
            Stepper(ringing_circuit, 100e-6, bounce_options)
        with pytest.raises(SessionBusyError):
            run_transient(ringing_circuit, 1.0, 100e-6, options=bounce_options)
    finally:
        stepper.close()
    # Released: the next run works, and a forgotten Stepper does not block forever.
    forgotten = Stepper(ringing_circuit, 100e-6, bounce_options)
    del forgotten
    assert len(run_transient(ringing_circuit, 1.0, 100e-6, options=bounce_options)) > 10


@pytest.mark.parametrize("delta", [2.6e-17, 1e-13, 4e-11, 1e-10, 1e-9])
def test_a_make_just_after_the_macro_time_restarts_the_integration(ringing_circuit, delta):
    """ngspice drops a breakpoint closer than CKTminBreak = 5e-5 TMAX (5e-11 s here) after
    its current time. A make 2.6e-17 s after a macro time (t accumulated as t + H) had its
    10 ns ramp taken in one step; now ngspice restarts at the macro time (a breakpoint
    there), as at the make itself: the first step is a fraction of the ramp."""
    from circuit import ContactSchedule, SimulationOptions

    t0 = 0.4e-3
    schedule = ContactSchedule(((0.0, 0.1e-3), (t0 + delta, math.inf)), closed_resistance=0.01)
    with Stepper(ringing_circuit, 0.41e-3, SimulationOptions(max_step=1e-6)) as stepper:
        stepper.advance(t0, schedule, schedule.breakpoints(0.0, t0))
        step = stepper.advance(0.41e-3, schedule, schedule.breakpoints(t0, 0.41e-3))
        times = step.frame().time.to_numpy()
    assert times[0] == t0
    assert times[1] - t0 < 2e-9  # measured 0.87 ns (2.6e-17 to 4e-11), 0.1 and 1 ns; was 10 ns
    # The ramp is resolved: several points inside it.
    assert np.sum((times > t0) & (times < t0 + delta + 10e-9)) >= 3


def test_a_make_at_the_macro_time_itself_restarts_the_integration_when_asked(ringing_circuit):
    """A make a sliver (1e-15 s) after the macro time, where no step can land, given as no
    breakpoint: ``advance(..., restart=True)`` makes ngspice restart at its current time,
    order 1 with a short first step, as at a breakpoint; without it ngspice's next step
    takes the make's 10 ns ramp whole."""
    from circuit import ContactSchedule, SimulationOptions

    t0 = 0.4e-3
    schedule = ContactSchedule(((0.0, 0.1e-3), (t0 + 1e-15, math.inf)), closed_resistance=0.01)
    first = {}
    for restart in (False, True):
        with Stepper(ringing_circuit, 0.41e-3, SimulationOptions(max_step=1e-6)) as stepper:
            stepper.advance(t0, schedule, schedule.breakpoints(0.0, t0))
            step = stepper.advance(0.41e-3, schedule, (), restart=restart)
            times = step.frame().time.to_numpy()
        assert times[0] == t0
        first[restart] = times[1] - t0
        if restart:
            assert np.sum((times > t0) & (times < t0 + 10e-9)) >= 3  # the ramp resolved
    assert first[True] < 2e-9 < first[False]


@pytest.mark.parametrize("delta", [5e-12, 1.2e-10, 2e-9])
def test_a_break_just_before_the_macro_time_is_a_point_with_the_closed_current(ringing_circuit, delta):
    """A break ``delta`` before the end of its macro step (the mechanics' step cut at a
    break ends a round-off past it; the coupled run's conductance drops there at once) is
    a point of the waveform, where the contact's left limit holds: still closed, 24 V over
    the source, load and contact (12.06 ohm). Through ngspice's `stop when` pauses a break
    within CKTminBreak (5e-11 s here) of the macro time was stepped over (the pause's condition
    merged with the break's breakpoint), and the current at the break was read from the
    point before it."""
    from circuit import SimulationOptions

    t_break = 0.3e-3

    def conductance(t):
        return 100.0 if t < t_break else 0.0

    with Stepper(ringing_circuit, 0.32e-3, SimulationOptions(max_step=1e-6)) as stepper:
        stepper.advance(0.29e-3, conductance)
        step = stepper.advance(t_break + delta, conductance, [t_break])
        frame = step.frame()
        after = stepper.advance(0.32e-3, conductance).frame()
    times = frame.time.to_numpy()
    assert t_break in times, f"nearest point {times[np.argmin(abs(times - t_break))] - t_break:+.3g} s from the break"
    at = frame[frame.time == t_break].iloc[0]
    assert at.contact_conductance == 100.0  # the left limit: still closed
    # the wiring's inductance has long settled 0.3 ms after the start
    assert at.contact_current == pytest.approx(24.0 / 12.06, rel=1e-6)
    assert times[-1] == pytest.approx(t_break + delta, rel=1e-12)
    # and the contact is open from the next point on: the wiring's current rings into the
    # 100 pF across it
    assert (after.contact_conductance.to_numpy()[1:] == 0.0).all()
    assert frame.contact_conductance.to_numpy()[-1] == 0.0


@pytest.mark.parametrize("delta", [4.6e-15, 1e-13, 2e-11, 1e-9])
def test_a_make_just_after_the_macro_time_discharges_the_contact_capacitance_as_the_closed_form(
        ringing_circuit, delta):
    """The open contact's 100 pF holds 24 V; at the make its conductance grows as
    G = a (t - t_make), a = 1e11 S/s. The wiring's 1 uH carries nothing over the ~30 ps
    the charge takes to leave, so dV/dt = -G V / C: V = V0 exp(-a s^2 / 2C) and the
    contact's current a s V peaks at V0 sqrt(a C) exp(-1/2) = 46.0 A, s = sqrt(C / a)
    after the make, having passed C V0 = 2.4 nC within the first ns. Through ngspice's
    `stop when` pauses a make within CKTminBreak (5e-11 s here) after the macro time was
    not a breakpoint (it merged with the one at the macro time), and ngspice's first step
    (14 ns on the bridge contactor, where it was found) passed the whole discharge: a peak
    of 2.0 A, no point in the first ns."""
    from circuit import SimulationOptions

    a, capacitance, v0 = 1e11, 100e-12, 24.0
    t0 = 0.4e-3
    t_make = t0 + delta

    def conductance(t):
        return 0.0 if t <= t_make else min(100.0, a * (t - t_make))

    with Stepper(ringing_circuit, 0.41e-3, SimulationOptions(max_step=1e-6)) as stepper:
        stepper.advance(t0, conductance)
        frame = stepper.advance(t0 + 2.5e-7, conductance, [t_make]).frame()
        stepper.advance(0.41e-3, conductance)
    t, i = frame.time.to_numpy(), frame.contact_current.to_numpy()
    assert i.max() == pytest.approx(v0 * math.sqrt(a * capacitance) * math.exp(-0.5), rel=0.02)
    first = (t >= t_make) & (t <= t_make + 1e-9)
    assert np.trapezoid(i[first], t[first]) == pytest.approx(capacitance * v0, rel=0.02)


def test_a_command_while_a_run_is_paused_is_refused_and_a_run_left_open_is_stopped(ringing_circuit, bounce_options):
    """The transient is one ngspice `run`, paused inside its time loop between macro steps:
    a command then would run inside that loop, so it is refused; a Stepper dropped without
    close leaves its run paused, and the next circuit's load stops it first. The second run
    is the same as a run in a fresh session."""
    from circuit.errors import SessionBusyError
    from circuit.ngspice import get_session

    stepper = Stepper(ringing_circuit, 0.4e-3, bounce_options)
    stepper.advance(0.2e-3, 1.0)
    with pytest.raises(SessionBusyError, match="paused inside a transient"):
        get_session().command("rusage all")
    del stepper  # never closed: its run stays paused
    with Stepper(ringing_circuit, 0.4e-3, bounce_options) as again:
        again.advance(0.2e-3, 1.0)
        again.advance(0.4e-3, 1.0)
        first = again.results()
        # the run has ended: commands are ngspice's again
        assert any("Rejected timepoints" in line for line in get_session().command("rusage all"))
    with Stepper(ringing_circuit, 0.4e-3, bounce_options) as fresh:
        fresh.advance(0.2e-3, 1.0)
        fresh.advance(0.4e-3, 1.0)
        second = fresh.results()
    for column in first.columns:
        assert np.array_equal(first[column].to_numpy(), second[column].to_numpy()), column


def test_a_paused_transient_is_resumed_only_from_its_own_thread(ringing_circuit, bounce_options):
    """The transient pauses in a greenlet of the thread that started it: another thread gets
    SessionBusyError, to advance it or to load a circuit over it, while that thread lives;
    once it has ended, a new run in this thread starts as in a fresh session."""
    import gc
    import threading

    from circuit.errors import SessionBusyError

    started, release, done = threading.Event(), threading.Event(), threading.Event()
    holder = {}

    def other():
        holder["stepper"] = Stepper(ringing_circuit, 0.4e-3, bounce_options)
        holder["stepper"].advance(0.2e-3, 1.0)
        started.set()
        release.wait(30)
        done.set()  # ends without closing: its run stays paused

    thread = threading.Thread(target=other)
    thread.start()
    assert started.wait(30)
    try:
        with pytest.raises(SessionBusyError, match="another thread"):
            holder["stepper"].advance(0.3e-3, 1.0)
        del holder["stepper"]  # dropped unclosed: the next Stepper may claim ngspice, but not load over the run
        gc.collect()
        with pytest.raises(SessionBusyError, match="another thread"):
            Stepper(ringing_circuit, 0.4e-3, bounce_options)
    finally:
        release.set()
        thread.join(30)
    with Stepper(ringing_circuit, 0.4e-3, bounce_options) as again:
        again.advance(0.2e-3, 1.0)
        again.advance(0.4e-3, 1.0)
        # closed through 1 ohm (1 S): 24 V over 12.05 + 1 ohm
        assert again.finished and again.load_current == pytest.approx(24.0 / 13.05, rel=1e-4)


def test_a_final_step_shorter_than_ngspice_s_end_tolerance_ends_the_run(ringing_circuit, bounce_options):
    """A macro step landing within CKTminBreak of t_end finishes ngspice's analysis; the final
    step after it (5.75 ns in the study that found it) used to 'resume' a finished analysis,
    which ngspice starts over from t = 0 and which read as a Ctrl-C. The run now ends there,
    its last point within the end tolerance, its waveform the same as with one step less."""
    short = 0.5 * bounce_options.end_tolerance(BOUNCE_T_END)
    with Stepper(ringing_circuit, BOUNCE_T_END, bounce_options) as stepper:
        stepper.advance(BOUNCE_T_END / 2, 1.0)
        stepper.advance(BOUNCE_T_END - short, 1.0)
        try:
            stepper.advance(BOUNCE_T_END, 1.0)
        except KeyboardInterrupt as err:  # (would stop the whole test session)
            pytest.fail(f"the final step read as a Ctrl-C: {err}")
        assert stepper.finished
        df = stepper.results()
    assert df.time.iloc[-1] >= BOUNCE_T_END - bounce_options.end_tolerance(BOUNCE_T_END)
    assert (np.diff(df.time.to_numpy()) > 0).all()
    # the stop condition met at the analysis' last point left ngspice's pause request set;
    # the next run (any circuit) must not read it as a Ctrl-C
    try:
        after = run_transient(ringing_circuit, 1.0, 1e-5, options=bounce_options)
    except KeyboardInterrupt as err:
        pytest.fail(f"the next run read the left pause as a Ctrl-C: {err}")
    assert after.time.iloc[-1] == pytest.approx(1e-5)
