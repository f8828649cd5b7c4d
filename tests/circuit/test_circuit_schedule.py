"""ContactSchedule as G(t), as breakpoints and as PWL vertices; the left-limit wrapper."""

from __future__ import annotations

import math

import numpy as np
import pytest

from circuit import ContactSchedule, SimulationOptions, run_pwl_reference, run_transient, left_limited
from circuit.contact import snapped

from circuit_scenes import BOUNCE_BREAKS, BOUNCE_MAKES


def test_conductance_ramps_and_plateaus():
    s = ContactSchedule(((1e-3, 2e-3),), closed_resistance=0.5, edge_time=1e-6)
    assert s(0.0) == 0.0 and s(1e-3) == 0.0
    assert s(1e-3 + 0.5e-6) == pytest.approx(1.0)  # half of 2 S
    assert s(1.5e-3) == 2.0
    assert s(2e-3 - 0.25e-6) == pytest.approx(0.5)
    assert s(2e-3) == 0.0 and s(3e-3) == 0.0
    assert s.breakpoints() == (1e-3, 1e-3 + 1e-6, 2e-3 - 1e-6, 2e-3)
    assert s.breakpoints(1.5e-3, 2e-3) == (2e-3 - 1e-6, 2e-3)


def test_from_events_and_initially_closed():
    s = ContactSchedule.from_events(BOUNCE_MAKES, BOUNCE_BREAKS)
    assert len(s.intervals) == 6 and math.isinf(s.intervals[-1][1])
    assert s(1.0) == 100.0  # stays closed after the last make
    closed = ContactSchedule(((0.0, 1e-3),), edge_time=1e-6)
    assert closed(0.0) == 100.0  # closed from the start: no make ramp
    with pytest.raises(ValueError, match="makes need"):
        ContactSchedule.from_events([1e-3], [2e-3, 3e-3])


def test_resistance_as_function_of_time_since_make():
    s = ContactSchedule(((1e-3, 3e-3),), closed_resistance=lambda tau: 0.01 + 0.1 * math.exp(-tau / 1e-4), edge_time=0.0)
    assert s(1e-3) == pytest.approx(1 / 0.11)
    assert s(2e-3) == pytest.approx(1 / (0.01 + 0.1 * math.exp(-10)))
    with pytest.raises(ValueError, match="edge_time > 0"):
        s.pwl_points(4e-3, resistance_step=1e-5)
    ramped = ContactSchedule(((1e-3, 3e-3),), closed_resistance=lambda tau: 0.01 + 0.1 * math.exp(-tau / 1e-4))
    with pytest.raises(ValueError, match="resistance_step"):
        ramped.pwl_points(4e-3)
    t, g = ramped.pwl_points(4e-3, resistance_step=1e-5)
    assert np.all(np.diff(t) > 0) and t[0] == 0.0 and t[-1] == 4e-3
    np.testing.assert_allclose(g, [ramped(x) for x in t])


def test_pwl_points_are_exact_for_constant_resistance():
    s = ContactSchedule.from_events(BOUNCE_MAKES, BOUNCE_BREAKS, closed_resistance=0.01, edge_time=1e-8)
    t, g = s.pwl_points(2e-3)
    assert len(t) == 2 + 4 * 5 + 2  # ends, four corners per bounce, the last make's two
    probe = np.linspace(0, 2e-3, 20001)
    np.testing.assert_allclose(np.interp(probe, t, g), [s(x) for x in probe], atol=1e-9)


def test_resistance_function_schedule_stepped_matches_sampled_pwl():
    from circuit import DCSource, ResistiveLoad, SwitchCircuit, Wiring

    circuit = SwitchCircuit(DCSource(12.0, 0.0), ResistiveLoad(1.0), wiring=Wiring(0.0, 0.0), contact_capacitance=0.0)
    s = ContactSchedule(((10e-6, 90e-6),), closed_resistance=lambda tau: 0.1 + 1.0 * math.exp(-tau / 20e-6), edge_time=1e-7)
    opts = SimulationOptions(max_step=0.5e-6)
    exact = run_transient(circuit, s, 100e-6, options=opts)
    sampled = run_pwl_reference(circuit, s, 100e-6, options=opts, resistance_step=0.5e-6)
    grid = np.linspace(12e-6, 88e-6, 200)
    a = np.interp(grid, exact.time, exact.load_current)
    b = np.interp(grid, sampled.time, sampled.load_current)
    np.testing.assert_allclose(a, b, rtol=2e-3)  # linear-in-G sampling every 0.5 us
    # Resistive circuit: at every ngspice point the current follows the resistance law,
    # to the Newton tolerance (reltol).
    exact = run_transient(circuit, s, 100e-6, options=SimulationOptions(max_step=0.5e-6, reltol=1e-6))
    t = exact.time.to_numpy()
    closed = (t > 10.1e-6) & (t < 89.9e-6)
    law = 12.0 / (1.0 + 0.1 + np.exp(-(t[closed] - 10e-6) / 20e-6))
    np.testing.assert_allclose(exact.load_current.to_numpy()[closed], law, rtol=2e-6)


def test_left_limited_takes_the_value_before_a_jump_only_at_the_breakpoint():
    jump = lambda t: 0.0 if t < 1e-3 else 5.0  # noqa: E731 - a step at 1 ms
    g = left_limited(jump, [1e-3], span=1e-5)
    assert g(1e-3) == 0.0
    assert g(1e-3 + 2 * math.ulp(1e-3)) == 0.0  # ngspice's landing, up to rounding
    assert g(1e-3 + 1e-12) == 5.0
    assert g(0.9e-3) == 0.0
    assert left_limited(jump, [], 1e-5) is jump


def test_a_jump_closer_to_the_pause_than_ngspice_resolves_is_taken_at_the_pause():
    """A jump 1e-13 s before a macro time t_stop: beyond the landing tolerance (1e-9 of the
    5 us step), within ``merge`` (ngspice's CKTminBreak, here 1.2e-8 s). With it the jump
    lands on t_stop, whose value is still the one before the jump (its left limit); without,
    it stays where it is and ngspice would be left a 1e-13 s step after it."""
    b, t_stop = 1e-3 - 1e-13, 1e-3
    jump = lambda t: 0.0 if t < b else 5.0  # noqa: E731
    assert snapped([b], t_stop, 5e-6) == [b]
    assert snapped([b], t_stop, 5e-6, merge=1.2e-8) == [t_stop]
    assert snapped([t_stop - 2e-8], t_stop, 5e-6, merge=1.2e-8) == [t_stop - 2e-8]  # farther: kept
    g = left_limited(jump, [b], 5e-6, t_stop, merge=1.2e-8)
    assert g(t_stop) == 0.0 and g(t_stop + 1e-12) == 5.0
