"""The changeover template's inductive throws (circuit.ChangeoverCircuit with load_inductance).

Closed forms of the throw's R-L loop: after NO makes, its current rises as
I (1 - exp(-t / tau)) with tau = L / R (R the loop's resistance, the contact's 1/G
included); at NO's break the flyback diode takes the inductor's current, holds the
contact's voltage within a diode drop of the supply, and the energy 1/2 L I^2 that was in
the inductor goes into the load resistor and the diode. SI units.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from circuit import (ChangeoverCircuit, DCSource, FlybackDiode, ResistiveLoad, SimulationOptions, Stepper,
                     Wiring)

V_S, R_S, R_W, R_L, L_NO = 24.0, 0.05, 0.01, 12.0, 10e-3
G_CLOSED = 100.0  # S: a closed contact (0.01 ohm)
R_LOOP = R_S + R_W + 1.0 / G_CLOSED + R_L


def changeover(**fields) -> ChangeoverCircuit:
    fields = dict(dict(load_inductance=L_NO, nc_load_inductance=0.0), **fields)
    return ChangeoverCircuit(DCSource(V_S, R_S), ResistiveLoad(R_L), Wiring(R_W, 0.0), contact_capacitance=1e-10,
                             contact_names=("NO", "NC"), **fields)


def test_the_inductive_throw_rises_with_its_time_constant():
    """NO makes at t1 (NC open): its current follows the R-L loop's closed form to ngspice's
    accuracy at TMAX 2 us (1e-3 of the final current); NC, open, carries only leakage."""
    t1, t_end = 0.1e-3, 3e-3

    def g_no(t):
        return G_CLOSED if t >= t1 else 0.0

    with Stepper(changeover(), t_end, SimulationOptions(max_step=2e-6)) as stepper:
        stepper.advance(t1, inputs={"contact_NO.conductance": g_no, "contact_NC.conductance": 0.0})
        stepper.advance(t_end, inputs={"contact_NO.conductance": g_no, "contact_NC.conductance": 0.0})
        w = stepper.results()
    tau, final = L_NO / R_LOOP, V_S / R_LOOP
    after = w["time"].to_numpy() >= t1 + 5e-6
    t = w["time"].to_numpy()[after]
    expected = final * (1.0 - np.exp(-(t - t1) / tau))
    assert np.max(np.abs(w["contact_current_NO"].to_numpy()[after] - expected)) < 1e-3 * final
    assert np.max(np.abs(w["contact_current_NC"].to_numpy())) < 1e-9


@pytest.mark.parametrize("nc_inductance", [0.0, 5e-3])
def test_the_flyback_takes_the_inductors_energy_at_the_break(nc_inductance):
    """NO closed from the start (I0 = V / R), opened at t1: the diode across NO's load clamps
    the contact's voltage at the supply plus its forward drop (~1 V at 2 A), and the energy
    1/2 L I0^2 goes into R_L and the diode (their dissipation integrated over the
    freewheeling, to 1e-5: trapezoidal sums over ngspice's points at TMAX 2 us, ~400 a
    time constant, err ~ (h / tau)^2 / 12 ~ 1e-6). A diode sits only
    across an inductive throw."""
    t1, t_end = 0.05e-3, 8.0e-3
    circuit = changeover(flyback=FlybackDiode(), nc_load_inductance=nc_inductance)
    deck = str(circuit.build())
    assert "Dflyback_no" in deck and ("Dflyback_nc" in deck) is (nc_inductance > 0.0)

    def g_no(t):
        return G_CLOSED if t < t1 else 0.0

    with Stepper(circuit, t_end, SimulationOptions(max_step=2e-6)) as stepper:
        stepper.advance(t1, inputs={"contact_NO.conductance": g_no, "contact_NC.conductance": 0.0})
        stepper.advance(t_end, inputs={"contact_NO.conductance": g_no, "contact_NC.conductance": 0.0})
        w = stepper.results(extra=("load_no", "load_no_l"))
    i0 = V_S / R_LOOP
    t = w["time"].to_numpy()
    after = t > t1
    v_contact = w["contact_voltage_NO"].to_numpy()
    assert np.max(v_contact[after]) < V_S + 1.5  # clamped: the supply plus a diode drop
    assert np.max(v_contact[after]) > V_S + 0.5  # (and the diode does conduct)
    # the inductor's current after the break: through R_L, from load_no_l to load_no
    i_l = (w["load_no"].to_numpy() - w["load_no_l"].to_numpy()) / R_L
    assert i_l[np.searchsorted(t, t1) - 1] == pytest.approx(i0, rel=1e-3)
    v_diode = -w["load_no"].to_numpy()  # the diode from ground to throw_no (= load_no: 0 V probe between)
    power = R_L * i_l ** 2 + v_diode * i_l
    k = np.searchsorted(t, t1)
    dissipated = float(np.sum(0.5 * (power[k + 1:] + power[k:-1]) * np.diff(t[k:])))
    assert dissipated == pytest.approx(0.5 * L_NO * i0 ** 2, rel=1e-5)
    assert abs(i_l[-1]) < 1e-3 * i0  # (the freewheeling is over by t_end: tau = L / R_L = 0.83 ms, and the diode drop ends it sooner)


@pytest.mark.parametrize("fields, words", [
    (dict(load_inductance=-1e-3), "circuit.load_inductance"),
    (dict(nc_load_inductance=math.inf), "circuit.nc_load_inductance"),
    (dict(load_inductance=0.0, flyback=FlybackDiode()), "circuit.flyback is set but both throws are resistive"),
])
def test_bad_inductive_throws_are_one_line_naming_the_key(fields, words):
    base = dict(load_inductance=L_NO, nc_load_inductance=0.0)
    base.update(fields)
    with pytest.raises(ValueError) as err:
        ChangeoverCircuit(contact_names=("NO", "NC"), **base)
    assert words in str(err.value) and "\n" not in str(err.value)
