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
    # After close the results stay readable.
    assert stepper.results().time.iloc[-1] == pytest.approx(0.3e-3, rel=1e-12)
    assert second.frame().time.iloc[-1] == pytest.approx(0.3e-3, rel=1e-12)


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
