"""The mcu_input template (circuit.McuInput): a switch read by a microcontroller pin behind a
pull resistor, a series resistor and a capacitor, against the closed forms of its RC network.

With the contact closed at R_c the pin relaxes towards the divider level with
tau = (R_series + R_pull || R_c) C_in and the pull resistor carries Vcc / (R_pull + R_c);
opened, the pin relaxes towards the open level (Vcc pulled up, 0 pulled down) with
tau = (R_pull + R_series) C_in. The contact's capacitance is 0 here so that the network is
first order; a resistive contact (1 kOhm) makes the divider visible.
"""

from __future__ import annotations

import numpy as np
import pytest

from circuit import ContactSchedule, McuInput, SimulationOptions, run_transient

VCC, R_PULL, R_SERIES, C_IN, R_CLOSED = 3.3, 10e3, 2.2e3, 4.7e-9, 1e3
T_MAKE, T_BREAK, T_END = 50e-6, 250e-6, 600e-6
MAX_STEP = 0.2e-6


def _run(pull: str, **fields):
    circuit = McuInput(voltage=VCC, pull=pull, pull_resistance=R_PULL, series_resistance=R_SERIES,
                       input_capacitance=C_IN, contact_capacitance=0.0, **fields)
    schedule = ContactSchedule(((T_MAKE, T_BREAK),), closed_resistance=R_CLOSED, edge_time=0.0)
    return run_transient(circuit, schedule, T_END, options=SimulationOptions(max_step=MAX_STEP), extra=("pin", "sw"))


def pin_exact(t: np.ndarray, pull: str, r_series: float = R_SERIES, c_in: float = C_IN) -> np.ndarray:
    """The pin's closed form: open level, then the divider's with tau_make, then back with tau_break."""
    divider = R_CLOSED / (R_PULL + R_CLOSED) if pull == "up" else R_PULL / (R_PULL + R_CLOSED)
    v_open, v_closed = (VCC, VCC * divider) if pull == "up" else (0.0, VCC * divider)
    tau_make = (r_series + R_PULL * R_CLOSED / (R_PULL + R_CLOSED)) * c_in
    tau_break = (R_PULL + r_series) * c_in
    closed = v_closed + (v_open - v_closed) * np.exp(-(np.clip(t, T_MAKE, T_BREAK) - T_MAKE) / tau_make)
    v_break = v_closed + (v_open - v_closed) * np.exp(-(T_BREAK - T_MAKE) / tau_make)
    return np.where(t > T_BREAK, v_open + (v_break - v_open) * np.exp(-(t - T_BREAK) / tau_break), closed)


@pytest.mark.parametrize("pull", ["up", "down"])
def test_pin_relaxes_with_the_divider_and_its_time_constants(pull):
    w = _run(pull)
    t, pin = w.time.to_numpy(), w.pin.to_numpy()
    # ngspice's gear at RELTOL 1e-4, steps <= tau / 60: measured within 2.1e-5 Vcc (1e-4 allowed:
    # RELTOL of the node voltage, the accuracy ngspice is asked for)
    assert np.max(np.abs(pin - pin_exact(t, pull))) < 1e-4 * VCC
    # the same waveform with either time constant 10 % off is far outside that
    for wrong in (dict(r_series=1.1 * R_SERIES), dict(c_in=1.1 * C_IN)):
        assert np.max(np.abs(pin - pin_exact(t, pull, **wrong))) > 1e-2 * VCC


@pytest.mark.parametrize("pull", ["up", "down"])
def test_steady_levels_and_the_pull_resistor_current(pull):
    w = _run(pull)
    t = w.time.to_numpy()
    held = (t > T_BREAK - 5e-6) & (t < T_BREAK)  # 36 make time constants after the make
    divider = R_CLOSED / (R_PULL + R_CLOSED) if pull == "up" else R_PULL / (R_PULL + R_CLOSED)
    # closed: the switch node and the pin at the divider, R_pull carrying Vcc / (R_pull + R_c)
    assert np.allclose(w.sw.to_numpy()[held], VCC * divider, atol=1e-4 * VCC)
    assert np.allclose(w.pin.to_numpy()[held], VCC * divider, atol=1e-4 * VCC)
    assert np.allclose(w.load_current.to_numpy()[held], VCC / (R_PULL + R_CLOSED), rtol=1e-3)
    assert np.allclose(w.contact_current.to_numpy()[held], VCC / (R_PULL + R_CLOSED), rtol=1e-3)
    # the contact voltage is the supply while open, I R_c while closed; positive either way
    before = t < T_MAKE
    assert np.allclose(w.contact_voltage.to_numpy()[before], VCC, rtol=1e-6)
    assert np.allclose(w.contact_voltage.to_numpy()[held], VCC * R_CLOSED / (R_PULL + R_CLOSED), rtol=1e-3)
    # open before the make: only the contact's 1e-12 S leakage draws current, Vcc / (R_pull + 1e12),
    # and moves the pin off the open level by that current times R_pull (33 nV)
    leak = VCC / (R_PULL + 1e12)
    assert np.allclose(w.load_current.to_numpy()[before], leak, rtol=1e-3)
    assert np.allclose(w.pin.to_numpy()[before], VCC - leak * R_PULL if pull == "up" else leak * R_PULL, rtol=1e-3)


def test_no_series_resistor_and_no_capacitor_the_pin_is_the_switch_node():
    """series_resistance = 0 (a 0 V source) and input_capacitance = 0: the pin jumps with the
    contact to the divider and back."""
    w = _run("up", **{})  # the network of the tests above, for comparison
    bare = McuInput(voltage=VCC, pull_resistance=R_PULL, series_resistance=0.0, input_capacitance=0.0,
                    contact_capacitance=0.0)
    schedule = ContactSchedule(((T_MAKE, T_BREAK),), closed_resistance=R_CLOSED, edge_time=0.0)
    b = run_transient(bare, schedule, T_END, options=SimulationOptions(max_step=MAX_STEP), extra=("pin",))
    t = b.time.to_numpy()
    inside = (t > T_MAKE + 1e-9) & (t < T_BREAK)
    assert np.allclose(b.pin.to_numpy()[inside], VCC * R_CLOSED / (R_PULL + R_CLOSED), rtol=1e-4)
    assert np.allclose(b.pin.to_numpy()[t > T_BREAK + 1e-9], VCC, rtol=1e-6)
    assert w.pin.to_numpy()[np.searchsorted(w.time.to_numpy(), T_MAKE + 1e-6)] > 2.0  # the filtered one lags


def test_netlist_places_the_contact_on_the_pull_side():
    up, down = str(McuInput().build()), str(McuInput(pull="down").build())
    assert "Vcontact sw contact_s" in up and "Rpull pull sw" in up and "Cinput pin 0" in up
    assert "Vcontact vcc contact_s" in down and "Rpull sw pull" in down and "Vload pull 0" in down
    assert McuInput().probes.column_names[:4] == ("time", "contact_voltage", "contact_current", "load_current")


@pytest.mark.parametrize("fields, words", [
    (dict(logic_low=2.4), "circuit.logic_low = 2.4 V must be below circuit.logic_high = 2.31 V"),
    (dict(logic_high=3.3), "circuit.logic_high = 3.3 V must be below circuit.voltage = 3.3 V"),
    (dict(pull_resistance=0.0), "circuit.pull_resistance = 0 ohm is out of range"),
    (dict(series_resistance=-5.0), "circuit.series_resistance = -5 ohm is out of range"),
    (dict(input_capacitance=-1e-9), "circuit.input_capacitance = -1e-09 F is out of range"),
    (dict(pull="both"), "circuit.pull = 'both': allowed values"),
])
def test_bad_values_name_the_field(fields, words):
    with pytest.raises(ValueError) as err:
        McuInput(**fields)
    assert words in str(err.value) and "\n" not in str(err.value)
