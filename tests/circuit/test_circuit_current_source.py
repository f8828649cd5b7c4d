"""A supply in constant-current mode (CurrentSource) against closed forms, at makes and breaks, with arcs.

Closed forms (SI), with R = wiring + load resistance + contact, R_out || C_out the supply's output:
- closed: the loop takes I_set R_out / (R_out + R);
- opening, no arc, no loop inductance: the output voltage follows the RC charge
  v(t) = I_set R_out + (v0 - I_set R_out) exp(-(t - t_b) / (R_out C)) until the clamp
  holds it at the compliance voltage (CurrentSource.open_voltage);
- a make discharges C_out into the loop: v(t) = v_ss + (v0 - v_ss) exp(-t / (C (R_out || R)));
- an arc forms at a break only if the supply lifts the gap to U_min while the gap is armed
  (I_set t_form / C >= U_min roughly), and then holds I_set through it as long as the arc
  voltage stays below the compliance: with a column gradient it goes out at the gap
  d* = (v_src - U_min - (R_arc + R_loop) I_min) / E_col.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from circuit import (
    ArcModel,
    ContactSchedule,
    CurrentSource,
    DCSource,
    InductiveLoad,
    ResistiveLoad,
    SimulationOptions,
    SwitchCircuit,
    Wiring,
    run_transient,
)

OPTIONS = SimulationOptions(max_step=1e-6)
R_CLOSED = 0.01  # ohm, the schedule's closed contact


def _circuit(source: CurrentSource, *, load=0.1, wire_r=0.01, wire_l=0.0, c_contact=0.0, arc=None) -> SwitchCircuit:
    return SwitchCircuit(source, ResistiveLoad(load), wiring=Wiring(wire_r, wire_l), contact_capacitance=c_contact,
                         arc=arc)


def _at(df, t: float) -> dict:
    k = min(int(np.searchsorted(df.time.to_numpy(), t)), len(df) - 1)
    return df.iloc[k]


def test_netlist_has_the_source_its_output_and_the_clamp():
    src = CurrentSource(2.0, 15.0, 1e-6, 1e4)
    text = str(_circuit(src).build())
    lines = {line.split()[0]: line for line in text.splitlines()[1:] if line.strip()}
    assert lines["Isource"] == "Isource 0 src 2.0"  # into src
    assert lines["Rsource_out"] == "Rsource_out src 0 10000.0"
    assert lines["Csource_out"] == "Csource_out src 0 1e-06"
    assert lines["Dclamp"].startswith("Dclamp src clamp switchsim_clamp")
    # the clamp source sits one diode drop (at I_set, IS = 1e-12 A, 27 degC) below V_comp
    vt = 8.617333262e-5 * 300.15
    assert float(lines["Vclamp"].split()[-1]) == pytest.approx(15.0 - vt * math.log1p(2.0 / 1e-12), rel=1e-12)
    assert "Vsource" not in lines


def test_closed_contact_carries_i_set_less_the_output_resistance_share():
    src = CurrentSource(1.0, 20.0, 1e-6, 100.0)  # a poor regulator: 100 ohm, so the share is visible
    c = _circuit(src)
    df = run_transient(c, ContactSchedule(((0.0, 1.0),), closed_resistance=R_CLOSED), 2e-3, options=OPTIONS)
    r_loop = 0.01 + 0.1 + R_CLOSED
    i = df.load_current.to_numpy()[df.time.to_numpy() > 1e-3]
    assert np.max(np.abs(i / (src.current * src.output_resistance / (src.output_resistance + r_loop)) - 1)) < 1e-6
    assert abs(i[-1] - src.current) > 1e-4  # the share is there (1.2e-3), and the closed form has it


def test_open_contact_rises_to_compliance_with_the_output_rc():
    src = CurrentSource(1.0, 20.0, 1e-6, 50.0)  # I R_out = 50 V: the rise is visibly exponential
    c = _circuit(src)
    t_b = 2e-4
    df = run_transient(c, ContactSchedule(((0.0, t_b),), closed_resistance=R_CLOSED, edge_time=1e-9), 1e-3,
                       options=SimulationOptions(max_step=2e-7), extra=("src",))
    t, v = df.time.to_numpy(), df.src.to_numpy()
    r_loop = 0.01 + 0.1 + R_CLOSED
    v0 = src.current / (1 / src.output_resistance + 1 / r_loop)
    assert _at(df, t_b - 1e-6).src == pytest.approx(v0, rel=1e-6)
    tau = src.output_resistance * src.output_capacitance
    rc = src.current * src.output_resistance + (v0 - src.current * src.output_resistance) * np.exp(-(t - t_b) / tau)
    rising = (t > t_b + 1e-7) & (rc < src.compliance_voltage - 0.5)  # below the clamp's knee
    assert rising.sum() > 20
    assert np.max(np.abs(v[rising] - rc[rising])) < 1e-3 * src.compliance_voltage
    # reaches the compliance when the RC charge would cross it, then holds it
    t_star = t_b - tau * math.log(1 - (src.compliance_voltage - v0) / (src.current * src.output_resistance - v0))
    held = t > t_star + 5e-6
    assert np.max(np.abs(v[held] - src.open_voltage(1e-12))) < 1e-5
    assert np.all(v <= src.compliance_voltage + 1e-6)  # never above it (no loop inductance)


def test_clamp_voltage_follows_the_diode_law_below_full_current():
    """CV mode: the clamp takes I_set - V/R_out; at 20 V on 40 ohm that is half, V_T ln 2 below V_comp."""
    src = CurrentSource(1.0, 20.0, 1e-6, 40.0)
    expected = 20.0 + src.thermal_voltage * math.log((1.0 - 20.0 / 40.0) / 1.0)
    assert src.open_voltage() == pytest.approx(expected, abs=1e-4)
    df = run_transient(_circuit(src), 0.0, 1e-4, options=OPTIONS, extra=("src",))  # the operating point
    assert df.src.iloc[-1] == pytest.approx(src.open_voltage(1e-12), abs=1e-6)


def test_a_make_discharges_the_output_capacitance_into_the_loop():
    src = CurrentSource(1.0, 20.0, 1e-6, 1e4)
    df = run_transient(_circuit(src), ContactSchedule(((1e-4, 1.0),), closed_resistance=R_CLOSED, edge_time=1e-9),
                       2e-4, options=SimulationOptions(max_step=1e-8), extra=("src",))
    r_loop = 0.01 + 0.1 + R_CLOSED
    g = 1 / src.output_resistance + 1 / r_loop
    v_ss, v0 = src.current / g, src.open_voltage(1e-12)
    tau = src.output_capacitance / g
    t, i = df.time.to_numpy(), df.load_current.to_numpy()
    after = (t > 1e-4 + 5e-9) & (t < 1e-4 + 5 * tau)
    expected = (v_ss + (v0 - v_ss) * np.exp(-(t[after] - 1e-4) / tau)) / r_loop
    assert after.sum() > 10
    assert np.max(np.abs(i[after] / expected - 1)) < 2e-2
    assert i.max() <= v0 / r_loop * (1 + 1e-6)  # the peak: C_out's voltage over the loop
    assert i[-1] == pytest.approx(v_ss / r_loop, rel=1e-6)


@pytest.mark.parametrize("arc", [None, ArcModel(), ArcModel(column_gradient=2e3)])
def test_converges_at_every_make_and_break_with_loop_inductance(arc):
    """1 uH wiring and 100 pF across the gap ring at each break and at each make (C_out through
    the wiring): ngspice must converge at all of them, and the loop settles to the closed forms."""
    src = CurrentSource(1.0, 20.0, 10e-9, 1e4)
    makes, breaks = [0.0, 2.5e-4, 5e-4], [1.5e-4, 4e-4]
    schedule = ContactSchedule.from_events(makes, breaks, closed_resistance=R_CLOSED, opening_speed=0.5)
    c = _circuit(src, wire_l=1e-6, c_contact=100e-12, arc=arc)
    df = run_transient(c, schedule, 7e-4, options=OPTIONS, extra=("src",))
    r_loop = 0.01 + 0.1 + R_CLOSED
    i_closed = src.current * src.output_resistance / (src.output_resistance + r_loop)
    for a in makes:  # the L-C_out ring of the make (2 A, decay time 2 L / R = 17 us) is down to 3e-4 A
        assert _at(df, a + 1.45e-4).load_current == pytest.approx(i_closed, rel=1e-3)
    for b in breaks:  # and the L-C_contact ring of the break
        row = _at(df, b + 0.95e-4)
        assert abs(row.arc_current) < 1e-6
        assert row.src == pytest.approx(src.open_voltage(), abs=0.05)


def test_arc_holds_the_current_when_the_supply_lifts_the_gap_fast_enough():
    """No loop inductance: at a break the set current charges C_out + C_contact at I/C. With 10 nF
    the gap reaches U_min in 0.12 us, inside the 1 us formation time: the arc forms and burns at
    U_min + R_arc I, carrying I_set less what R_out takes, for as long as the contact stays open."""
    arc = ArcModel()
    src = CurrentSource(1.0, 20.0, 10e-9, 1e4)
    assert src.current * arc.formation_time / src.output_capacitance > 2 * arc.min_voltage
    t_b = 1e-4
    df = run_transient(_circuit(src, arc=arc), ContactSchedule(((0.0, t_b),), closed_resistance=R_CLOSED), 4e-4,
                       options=OPTIONS, extra=("src",))
    t = df.time.to_numpy()
    burning = t > t_b + 5e-6
    i_arc, v = df.arc_current.to_numpy()[burning], df.contact_voltage.to_numpy()[burning]
    u_arc = arc.min_voltage + arc.resistance * i_arc
    assert np.max(np.abs(v - u_arc)) < 1e-3
    v_src = u_arc + i_arc * 0.11
    assert np.max(np.abs(i_arc - (src.current - v_src / src.output_resistance))) < 1e-4
    assert np.all(df.src.to_numpy()[burning] < src.compliance_voltage - 1.0)  # CC mode throughout


def test_no_arc_when_the_output_capacitance_holds_the_voltage_down():
    """1 uF: I_set t_form / C = 1 V, far below U_min: the capacitor takes the current, no arc forms, and
    the voltage rises to the compliance with the RC charge."""
    arc = ArcModel()
    src = CurrentSource(1.0, 20.0, 1e-6, 1e4)
    assert src.current * arc.formation_time / src.output_capacitance < arc.min_voltage / 2
    df = run_transient(_circuit(src, arc=arc), ContactSchedule(((0.0, 1e-4),), closed_resistance=R_CLOSED), 2e-4,
                       options=OPTIONS, extra=("src",))
    assert np.max(np.abs(df.arc_current.to_numpy())) < 1e-6
    assert df.contact_voltage.iloc[-1] == pytest.approx(src.open_voltage(1e-12), abs=1e-4)


def test_arc_goes_out_where_its_voltage_meets_the_compliance():
    """With a column gradient the arc voltage grows with the gap; the supply follows it up to the
    compliance, then the clamp takes the current from the arc and it goes out at I_min:
    d* = (v_src - U_min - (R_arc + R_loop) I_min) / E_col, v_src ~ V_comp."""
    arc = ArcModel(column_gradient=2e3)
    src = CurrentSource(1.0, 20.0, 10e-9, 1e4)
    speed, t_b = 1.0, 5e-5
    schedule = ContactSchedule(((0.0, t_b),), closed_resistance=R_CLOSED, opening_speed=speed)
    df = run_transient(_circuit(src, arc=arc), schedule, 5e-3, options=OPTIONS, extra=("src",))
    t, i_arc = df.time.to_numpy(), df.arc_current.to_numpy()
    on = np.flatnonzero(np.abs(i_arc) >= arc.min_current)
    t_out = t[on[-1]]
    r_loop = 0.11
    v_src = df.src.to_numpy()[on[-1]]
    assert abs(v_src - src.compliance_voltage) < 0.3  # the clamp holds the output there
    d_star = (v_src - arc.min_voltage - (arc.resistance + r_loop) * arc.min_current) / arc.column_gradient
    assert speed * (t_out - t_b) == pytest.approx(d_star, rel=2e-3)
    assert np.all(np.abs(i_arc[t > t_out + 1e-5]) < 1e-6)  # out for good (no re-ignition voltage set)
    assert df.contact_voltage.iloc[-1] == pytest.approx(src.open_voltage(1e-12), abs=1e-3)


@pytest.mark.parametrize("kwargs, message", [
    ({"current": 0.0}, "circuit.current = 0 A is out of range"),
    ({"current": -1.0}, "circuit.current"),
    ({"compliance_voltage": 0.0}, "circuit.compliance_voltage"),
    ({"output_capacitance": 0.0}, "circuit.output_capacitance"),
    ({"output_resistance": -5.0}, "circuit.output_resistance"),
])
def test_bad_current_source_values(kwargs, message):
    with pytest.raises(ValueError, match=message):
        CurrentSource(**kwargs)


def test_compliance_below_the_closed_loop_drop_and_non_resistive_loads_are_refused():
    with pytest.raises(ValueError, match="compliance_voltage = 5 V is below .* = 12.01 V"):
        SwitchCircuit(CurrentSource(1.0, 5.0), ResistiveLoad(12.0), wiring=Wiring(0.01, 0.0))
    with pytest.raises(ValueError, match="CurrentSource drives a ResistiveLoad"):
        SwitchCircuit(CurrentSource(), InductiveLoad())
    SwitchCircuit(DCSource(), InductiveLoad())  # a voltage source still drives any load
