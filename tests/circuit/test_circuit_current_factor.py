"""A contact whose resistance depends on its own current: ngspice solves R_c(I) without lag."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from circuit import DCSource, ResistiveLoad, SimulationOptions, SwitchCircuit, Wiring, run_transient

FLOOR, SCALE = 0.6, 1.7  # g(I) = r + (1 - r) exp(-|I|/I_c): the illustrative fit's current family
FACTOR = f"({FLOOR}+{1 - FLOOR}*exp(-abs(I)/{SCALE}))"


def g(current: float) -> float:
    return FLOOR + (1.0 - FLOOR) * math.exp(-abs(current) / SCALE)


@pytest.mark.parametrize("g_force", [2.0, 20.0])
def test_steady_current_solves_the_implicit_divider(g_force):
    """DC divider: I = V / (R_series + g(I)/G_F). The closed form is the root of that equation."""
    volts, r_load, r_source = 5.0, 1.0, 0.2
    circuit = SwitchCircuit(DCSource(volts, r_source), ResistiveLoad(r_load), wiring=Wiring(0.0, 0.0),
                            contact_capacitance=0.0, contact_current_factor=FACTOR)
    wave = run_transient(circuit, g_force, 2e-6, options=SimulationOptions(max_step=1e-7))
    expected = brentq(lambda i: i - volts / (r_source + r_load + g(i) / g_force), 0.0, volts / (r_source + r_load))
    last = wave.iloc[-1]
    assert last.contact_current == pytest.approx(expected, rel=1e-6)
    # the reported resistance is the effective one, g(I)/G_F, not 1/G_F
    assert last.contact_resistance == pytest.approx(g(expected) / g_force, rel=1e-6)
    assert last.contact_voltage == pytest.approx(expected * g(expected) / g_force, rel=1e-6)


def test_factor_expression_is_validated_before_running():
    with pytest.raises(ValueError, match="contact_current_factor"):
        SwitchCircuit(contact_current_factor="(1+abs(I)")
    with pytest.raises(ValueError, match="contact_current_factor"):
        SwitchCircuit(contact_current_factor="")


def test_factor_of_one_changes_nothing():
    """g = 1 must reproduce the plain contact bit for bit in the waveform's physics."""
    base = SwitchCircuit(DCSource(24.0, 0.05), ResistiveLoad(12.0), wiring=Wiring(0.0, 1e-6))
    same = SwitchCircuit(DCSource(24.0, 0.05), ResistiveLoad(12.0), wiring=Wiring(0.0, 1e-6),
                         contact_current_factor="1+0*I")
    opts = SimulationOptions(max_step=1e-7)
    a = run_transient(base, 50.0, 5e-6, options=opts)
    b = run_transient(same, 50.0, 5e-6, options=opts)
    np.testing.assert_allclose(np.interp(a.time, b.time, b.contact_current), a.contact_current, rtol=1e-6, atol=1e-9)


def test_closed_contact_voltage_is_accurate_at_the_default_reltol():
    """The closed contact's mV voltage sits between two nodes near the supply voltage, each
    converged to RELTOL of its own size; the reported voltage (the element's I/G with the
    branch current) must match a RELTOL 1e-8 reference to ~RELTOL, where the bare node
    difference was off by 4 % (measured)."""
    circ = SwitchCircuit(DCSource(24.0, 0.05), ResistiveLoad(12.0), wiring=Wiring(0.0, 1e-6),
                         contact_capacitance=100e-12)
    g = lambda t: 0.0 if t < 1e-5 else 50.0 + 40.0 * math.sin(2e5 * t)
    ref = run_transient(circ, g, 1e-4, options=SimulationOptions(max_step=1e-7, reltol=1e-8), breakpoints=[1e-5])
    w = run_transient(circ, g, 1e-4, options=SimulationOptions(reltol=1e-4), breakpoints=[1e-5])
    c = w[w.time > 1.1e-5]
    v_ref = np.interp(c.time, ref.time, ref.contact_voltage)
    assert np.max(np.abs(c.contact_voltage / v_ref - 1.0)) < 5e-4
    # open before the make: the node difference, the full supply voltage
    assert w.contact_voltage[w.time < 9e-6].iloc[-1] == pytest.approx(24.0, rel=1e-9)
