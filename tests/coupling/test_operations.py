"""A run as a sequence of operations: what each make and each break did (SI units)."""

from __future__ import annotations

import numpy as np
import pytest

from coupling import builtin_scene, run
from coupling.core.metrics import MetricSettings, bounce_metrics, operations

W = 1e-3  # s, the settle window
# a make at 1 ms with three bounces (0.1, 0.05 and 0.02 ms open), held from 1.4 ms to 6 ms, then a
# break with one chatter closure (6.1-6.12 ms), an arc burning from 6.12 ms to 6.5 ms, open to 10 ms
CLOSED = [(1.0e-3, 1.1e-3), (1.2e-3, 1.3e-3), (1.35e-3, 1.38e-3), (1.4e-3, 6.0e-3), (6.1e-3, 6.12e-3)]
T_END = 10e-3
I_CLOSED, V_ARC = 2.0, 12.0


def waveform():
    """A fine grid; the loop current is I_CLOSED while closed and while the arc burns; the
    contact voltage is 0.01 V closed, the arc's 12 V while it burns, 24 V open."""
    t = np.linspace(0.0, T_END, 200_001)
    closed = np.zeros_like(t, bool)
    for a, b in CLOSED:
        closed |= (t >= a) & (t <= b)
    burning = (t > 6.12e-3) & (t < 6.5e-3)
    v = np.where(closed, 0.01, np.where(burning, V_ARC, 24.0))
    i_contact = np.where(closed, I_CLOSED, 0.0)
    i_arc = np.where(burning, I_CLOSED, 0.0)
    return t, v, i_contact + i_arc, i_contact, i_arc


def test_a_make_and_a_break_against_the_waveform_they_were_made_from():
    t, v, loop, ic, ia = waveform()
    (op,) = operations(CLOSED, T_END, t, v, loop, ic, ia, MetricSettings(settle_window=W), min_arc_current=0.4)
    make, brk = op["make"], op["break"]
    assert make["time"] == 1.0e-3 and make["bounces"] == 3 and make["settled"]
    assert make["bounce_time"] == pytest.approx(0.4e-3) and make["settle_time"] == pytest.approx(0.4e-3)
    # closed from the first make to one window into the held closure (2.4 ms), less the openings
    closed_time = (1.4e-3 + W - 1.0e-3) - 0.1e-3 - 0.05e-3 - 0.02e-3
    assert make["peak_current"] == I_CLOSED
    assert make["i2t"] == pytest.approx(I_CLOSED ** 2 * closed_time, rel=1e-3)
    assert make["make_energy"] == pytest.approx(0.01 * I_CLOSED * closed_time, rel=1e-3)
    assert make["arc_energy"] == 0.0  # no arc in the bounces
    assert brk["time"] == 6.0e-3 and brk["current_at_break"] == I_CLOSED and brk["complete"]
    assert brk["arc_duration"] == pytest.approx(0.38e-3, rel=1e-3)
    assert brk["arc_energy"] == pytest.approx(V_ARC * I_CLOSED * 0.38e-3, rel=1e-3)
    assert brk["peak_voltage"] == 24.0


def test_an_arc_still_burning_at_the_end_is_an_incomplete_break_with_the_time_it_needs():
    """The arc current falls linearly at 1 A/ms from 2 A: at the run's end (6.9 ms, 0.8 ms
    into the arc) it carries 1.2 A and needs (1.2 - 0.4) A / (1 A/ms) = 0.8 ms more."""
    t_end = 6.9e-3
    t = np.linspace(0.0, t_end, 100_001)
    closed = (t >= 1e-3) & (t <= 6.1e-3)
    burning = t > 6.1e-3
    i_arc = np.where(burning, 2.0 - 1e3 * (t - 6.1e-3), 0.0)
    v = np.where(closed, 0.01, 12.0)
    (op,) = operations([(1e-3, 6.1e-3)], t_end, t, v, np.where(closed, 2.0, i_arc), np.where(closed, 2.0, 0.0),
                       i_arc, MetricSettings(settle_window=W), min_arc_current=0.4)
    assert not op["break"]["complete"]
    assert op["break"]["more_time_needed"] == pytest.approx(0.8e-3, rel=1e-3)


def test_episodes_split_where_the_contact_stays_open_a_settle_window():
    """Two operations: the second make comes 2 ms after the first break."""
    closed = [(1e-3, 3e-3), (5e-3, 5.1e-3), (5.2e-3, 8e-3)]
    ops = operations(closed, 10e-3, settings=MetricSettings(settle_window=W))
    assert [set(op) for op in ops] == [{"make", "break"}, {"make", "break"}]
    assert ops[1]["make"]["time"] == 5e-3 and ops[1]["make"]["bounces"] == 1
    assert ops[1]["break"]["time"] == 8e-3
    # the run's top-level bounce keys are the first make's
    b = bounce_metrics(closed, 10e-3, False, settings=MetricSettings(settle_window=W))
    assert b["bounces"] == 0 and b["first_make"] == 1e-3 and b["settled"] and b["settle_time"] == 0.0


def test_the_relay_cycle_makes_as_the_force_driven_relay_does():
    """relay_cycle is relay_force closed, held and opened: its make operation and its
    top-level bounce keys equal the make-only relay_force's (they were mixed with the break:
    7 bounces, 5.6 ms of 'bounce time')."""
    make_only = run(builtin_scene("relay_force"))
    cycle = run(builtin_scene("relay_cycle"))
    (op,) = cycle.operations
    # the two force tables are the same up to the opening but written with other points,
    # which moves the located events by round-off (7.6e-12 s of 0.77 ms measured)
    assert op["make"]["bounce_time"] == pytest.approx(make_only.bounce["total_bounce_time"], rel=1e-6)
    assert op["make"]["bounces"] == make_only.bounce["bounces"]
    assert cycle.bounce["bounces"] == make_only.bounce["bounces"]
    assert cycle.bounce["settle_time"] == pytest.approx(make_only.bounce["settle_time"], rel=1e-6)
    assert op["break"]["complete"] and op["break"]["arc_duration"] > 0.0
    # the break starts at the first separation, before the chatter the final opening follows
    assert op["break"]["time"] < cycle.bounce["final_opening"]["break_time"]


def test_a_breaks_peak_voltage_is_its_recovery_transient_after_the_arc():
    """The default relay's break: the arc burns near its ~20 V (12 V + 2e4 V/m of gap) and
    goes out at I_min, chopping that current in the wiring's 1 uH with 100 pF across the gap.
    The loop then rings the open contact about the supply V: from the arc's voltage U_arc
    with the chopped I_min in L, its amplitude is at most sqrt((V - U_arc)^2 + (I_min Z0)^2),
    Z0 = sqrt(L/C) = 100 ohm (less with the load's damping). The break's peak voltage is that
    recovery transient, as the openings table's final opening says, not the arc's voltage
    (the peak was taken to the arc's end only: 20 V)."""
    result = run(builtin_scene("default"))
    assert result.status == "ok", result.message
    circuit = result.scene.circuit.circuit
    v, z0 = circuit.source.voltage, (circuit.wiring.wiring_inductance / circuit.contact_capacitance) ** 0.5
    arc = circuit.arc
    brk = result.operations[0]["break"]
    w = result.waveform_columns
    burning = (w["time"] >= brk["time"]) & (np.abs(w["arc_current"]) > arc.min_current)
    u_arc = float(np.max(np.abs(w["contact_voltage"][burning])))  # the arc's largest voltage
    bound = v + ((v - arc.min_voltage) ** 2 + (arc.min_current * z0) ** 2) ** 0.5
    assert u_arc < v < brk["peak_voltage"] <= bound
    assert brk["peak_voltage"] == result.bounce["peak_final_opening_voltage"]
