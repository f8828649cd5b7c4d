"""The double-break bridge template (circuit.BridgeCircuit) and a netlist's series contacts.

Closed forms of the DC loop: the two contacts in series conduct V_s / (R_s + R_w + R_L +
1/G_a + 1/G_b) when both are closed and only the open contact's leakage otherwise; names
and arrangement checked before anything runs. SI units.
"""

from __future__ import annotations

import numpy as np
import pytest

from circuit import (BridgeCircuit, DCSource, FlybackDiode, InductiveLoad, NetlistCircuit, ResistiveLoad,
                     SimulationOptions, Stepper, Wiring)

V_S, R_S, R_W, R_L = 24.0, 0.05, 0.01, 12.0
LEAK = 1e-12  # S: each open contact's leakage (DEFAULT_LEAKAGE)


def bridge() -> BridgeCircuit:
    return BridgeCircuit(DCSource(V_S, R_S), ResistiveLoad(R_L), Wiring(R_W, 0.0), contact_capacitance=0.0,
                         contact_names=("a", "b"))


@pytest.mark.parametrize("g_a, g_b", [(50.0, 100.0), (50.0, 0.0), (0.0, 100.0), (0.0, 0.0)])
def test_the_loop_conducts_only_through_both_contacts(g_a, g_b):
    """Each contact's own conductance channel: the steady loop current is the series closed
    form, to ngspice's RELTOL 1e-4 (closed) or the leakage's scale (open: 24 V across 1e12
    ohm, 2.4e-11 A, within ABSTOL 1e-12 A)."""
    with Stepper(bridge(), 1e-4, SimulationOptions()) as stepper:
        step = stepper.advance(1e-4, inputs={"contact_a.conductance": g_a, "contact_b.conductance": g_b})
        i = float(step.values["load_current"])
    g = [x + LEAK for x in (g_a, g_b)]
    expected = V_S / (R_S + R_W + R_L + 1.0 / g[0] + 1.0 / g[1])
    if g_a and g_b:
        assert i == pytest.approx(expected, rel=1e-4)
    else:
        assert abs(i - expected) < 2e-12


def test_each_contact_has_its_own_elements_and_columns():
    c = bridge()
    deck = str(c.build())
    for name in ("a", "b"):
        assert f"Vcontact_{name}_g" in deck
    assert [b.label for b in c.contacts] == ["contact_a", "contact_b"]
    assert c.contacts[0].node_b == c.contacts[1].node_a  # (one chain: a's far node is b's near one)
    assert "contact_voltage_b" in c.probes.column_names


@pytest.mark.parametrize("names", [("a",), ("a", "a"), ("a", "A"), ("a", "b_2"), ("a", "")])
def test_bad_contact_names_are_refused(names):
    with pytest.raises(ValueError) as err:
        BridgeCircuit(contact_names=names)
    assert "BridgeCircuit.contact_names" in str(err.value) and "\n" not in str(err.value)


BASE = "title\nV1 src 0 36\nR1 src a 0.05\n{}\nVLOAD b load 0\nRL load 0 12\n"


@pytest.mark.parametrize("lines, arrangement", [
    ("XCONTACT_A a m\nXCONTACT_B m b\nCA a m 1e-10\nCB m b 1e-10", "series"),
    ("XCONTACT_A m a\nXCONTACT_B m b\nRs a s 100\nCs s b 1e-7", "series"),  # (a snubber across both)
    ("XCONTACT_A a m\nXCONTACT_B m b\nCm m 0 1e-10", None),  # the inner node reaches ground
    ("XCONTACT_A a b\nXCONTACT_B a b", None),  # in parallel
    ("XCONTACT_A a b", None),  # one contact
])
def test_a_netlist_is_a_bridge_when_its_contacts_form_one_chain(lines, arrangement):
    assert NetlistCircuit(BASE.format(lines)).arrangement == arrangement


# --- an inductive load (load_inductance): a contactor switching a coil or motor ---------------

L_LOAD = 10e-3  # H
G_CLOSED = 100.0  # S: each closed contact (0.01 ohm)
R_LOOP = R_S + R_W + 2.0 / G_CLOSED + R_L


def inductive_bridge(**fields) -> BridgeCircuit:
    fields = dict(dict(load_inductance=L_LOAD), **fields)
    return BridgeCircuit(DCSource(V_S, R_S), ResistiveLoad(R_L), Wiring(R_W, 0.0), contact_capacitance=1e-10,
                         contact_names=("a", "b"), **fields)


def test_the_inductive_loop_rises_with_its_time_constant_once_both_contacts_close():
    """a closes at t1, b at t2 > t1. Between them the loop is open but for b's 100 pF: a's
    make steps the voltage on C_b from V/2 (the two open contacts' capacitances in series) to
    V, and the L-C rings with amplitude (V/2) sqrt(C/L) = 1.2 mA (damping R / (2 sqrt(L/C)) =
    6e-4: bounded by it to 1 %). Once both are closed the loop's current follows
    I + (i(t2) - I) exp(-(t - t2) / tau), tau = L / R with both contacts' 1/G in R, to 1e-3 of
    the final current (ngspice at TMAX 2 us, ~400 points a time constant)."""
    t1, t2, t_end = 0.1e-3, 0.3e-3, 5.0e-3

    def g_a(t):
        return G_CLOSED if t >= t1 else 0.0

    def g_b(t):
        return G_CLOSED if t >= t2 else 0.0

    inputs = {"contact_a.conductance": g_a, "contact_b.conductance": g_b}
    with Stepper(inductive_bridge(), t_end, SimulationOptions(max_step=2e-6)) as stepper:
        stepper.advance(t2, inputs=inputs)
        stepper.advance(t_end, inputs=inputs)
        w = stepper.results()
    t, i = w["time"].to_numpy(), w["load_current"].to_numpy()
    assert np.max(np.abs(i[t < t1 - 1e-9])) < 1e-9  # (both open: the leakage, 24 V over 2e12 ohm)
    assert np.max(np.abs(i[t < t2 - 1e-9])) < 1.01 * 0.5 * V_S * np.sqrt(1e-10 / L_LOAD)
    tau, final = L_LOAD / R_LOOP, V_S / R_LOOP
    after = t >= t2 + 5e-6
    i2 = i[np.searchsorted(t, t2)]
    expected = final + (i2 - final) * np.exp(-(t[after] - t2) / tau)
    assert np.max(np.abs(i[after] - expected)) < 1e-3 * final
    assert i[-1] > 0.99 * final  # (the rise is over: 5.6 time constants)


def test_the_flyback_takes_the_inductors_energy_when_the_bridge_breaks():
    """Both contacts closed from the start (I0 = V / R), b opened at t1: the diode from ground to
    contact_b takes the inductor's current, the voltage across the whole bridge stays within a
    diode drop of the supply (~1 V at 2 A), and the energy 1/2 L I0^2 goes into R_L and the
    diode (their dissipation integrated over the freewheeling, to 1e-5: trapezoidal sums at
    TMAX 2 us, ~400 points a time constant, err ~ (h / tau)^2 / 12 ~ 1e-6). The contacts'
    probes still read the loop: open, the bridge carries only its leakage and the 100 pF."""
    t1, t_end = 0.05e-3, 8.0e-3
    circuit = inductive_bridge(flyback=FlybackDiode())
    assert "Dflyback" in str(circuit.build())

    def g_b(t):
        return G_CLOSED if t < t1 else 0.0

    inputs = {"contact_a.conductance": G_CLOSED, "contact_b.conductance": g_b}
    with Stepper(circuit, t_end, SimulationOptions(max_step=2e-6)) as stepper:
        stepper.advance(t1, inputs=inputs)
        stepper.advance(t_end, inputs=inputs)
        w = stepper.results(extra=("load", "load_l"))
    i0 = V_S / R_LOOP
    t = w["time"].to_numpy()
    k = np.searchsorted(t, t1)
    after = t > t1
    v_bridge = w["contact_voltage_a"].to_numpy() + w["contact_voltage_b"].to_numpy()
    assert V_S + 0.5 < np.max(v_bridge[after]) < V_S + 1.5  # clamped: the supply plus a diode drop
    i_l = (w["load"].to_numpy() - w["load_l"].to_numpy()) / R_L  # the inductor's current, through R_L
    assert i_l[k - 1] == pytest.approx(i0, rel=1e-3)
    v_diode = -w["load"].to_numpy()  # (the diode from ground to contact_b = load: a 0 V probe between)
    power = R_L * i_l ** 2 + v_diode * i_l
    dissipated = float(np.sum(0.5 * (power[k + 1:] + power[k:-1]) * np.diff(t[k:])))
    assert dissipated == pytest.approx(0.5 * L_LOAD * i0 ** 2, rel=1e-5)
    assert abs(i_l[-1]) < 1e-3 * i0  # (freewheeling over by t_end: tau = L / R_L = 0.83 ms)
    assert np.max(np.abs(w["contact_current_b"].to_numpy()[t > t1 + 20e-6])) < 1e-6


@pytest.mark.parametrize("fields, words", [
    (dict(load_inductance=-1e-3), "circuit.load_inductance"),
    (dict(load_inductance=float("nan")), "circuit.load_inductance"),
    (dict(load_inductance=0.0, flyback=FlybackDiode()), "circuit.flyback is set but the bridge's load is resistive"),
    (dict(load=InductiveLoad(12.0, 1e-3)), "circuit.load_inductance"),
    (dict(contact_capacitance=0.0), "circuit.contact_capacitance = 0 F"),
])
def test_bad_inductive_bridges_are_one_line_naming_the_key(fields, words):
    base = dict(load=ResistiveLoad(R_L), load_inductance=L_LOAD, contact_names=("a", "b"))
    base.update(fields)
    with pytest.raises(ValueError) as err:
        BridgeCircuit(**base)
    assert words in str(err.value) and "\n" not in str(err.value)
