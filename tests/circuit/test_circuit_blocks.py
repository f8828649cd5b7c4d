"""Contacts as blocks: one circuit holds several, each with its own input channels and columns."""

from __future__ import annotations

import pytest
from PySpice.Spice.Netlist import Circuit

from circuit import NetlistCircuit, SimulationOptions, Stepper, add_contact
from circuit.blocks import ContactBlock

# A double-break bridge: two contacts in series in one loop (SI units).
E, R_LOAD = 10.0, 10.0
BRIDGE = """bridge
V1 supply 0 10
XCONTACT_A supply mid
XCONTACT_B mid load
VLOAD load l2 0
Rload l2 0 10
"""
OPTIONS = SimulationOptions(max_step=1e-6)


def test_two_contacts_in_series_conduct_only_when_both_are_closed():
    """Ohm's law through the series loop: I = E / (R + 1/G_a + 1/G_b) when both are closed,
    and only the leakage of the open one otherwise."""
    g_a, g_b = 1.0, 2.0
    with Stepper(NetlistCircuit(BRIDGE), 3e-6, OPTIONS) as stepper:
        assert set(stepper.inputs) == {"contact_a.conductance", "contact_b.conductance"}
        both = stepper.advance(1e-6, inputs={"contact_a.conductance": g_a, "contact_b.conductance": g_b})
        one = stepper.advance(2e-6, inputs={"contact_a.conductance": g_a, "contact_b.conductance": 0.0},
                              breakpoints=[1e-6 + 1e-12])
        none = stepper.advance(3e-6, inputs={"contact_a.conductance": 0.0, "contact_b.conductance": 0.0})
        waves = stepper.results()
    closed = E / (R_LOAD + 1.0 / g_a + 1.0 / g_b)
    assert both.values["load_current"] == pytest.approx(closed, rel=1e-9)
    assert both.values["contact_voltage_a"] == pytest.approx(closed / g_a, rel=1e-6)
    assert both.values["contact_voltage_b"] == pytest.approx(closed / g_b, rel=1e-6)
    # open b: the loop carries the 1e-12 S leakage of b, and b holds the whole supply
    assert abs(one.values["load_current"]) < 2e-11
    assert one.values["contact_voltage_b"] == pytest.approx(E, rel=1e-6)
    assert abs(none.values["load_current"]) < 2e-11
    assert list(waves.columns) == ["time", "load_current"] + [
        f"{name}_{c}" for c in "ab" for name in ("contact_voltage", "contact_current", "contact_resistance",
                                                 "contact_conductance", "arc_current")]


def test_a_pyspice_circuit_holds_named_contacts_and_the_unnamed_one_keeps_its_names():
    c = Circuit("two contacts")
    c.V("1", "s", c.gnd, 5.0)
    add_contact(c, "s", "m", name="first")
    add_contact(c, "m", "l", name="second")
    c.R("load", "l", c.gnd, 5.0)
    names = {n.lower() for n in c.element_names}
    assert {"vcontact_first_g", "vcontact_second_g", "bcontact_first", "vcontact_second"} <= names
    with Stepper(c, 1e-6, OPTIONS) as stepper:
        step = stepper.advance(1e-6, inputs={"contact_first.conductance": 1.0, "contact_second.conductance": 1.0})
    assert step.values["contact_current_first"] == pytest.approx(5.0 / 7.0, rel=1e-9)
    single = Circuit("one")
    add_contact(single, "a", "b")
    assert {"vcontact", "vcontact_g", "bcontact"} <= {n.lower() for n in single.element_names}


def test_inputs_are_checked_by_name_before_anything_runs():
    with Stepper(NetlistCircuit(BRIDGE), 1e-6, OPTIONS) as stepper:
        with pytest.raises(ValueError, match="this circuit has 2 contacts: give each its input channels"):
            stepper.advance(1e-6, 1.0)
        with pytest.raises(ValueError, match="inputs contact_c.conductance: this circuit's input channels are"):
            stepper.advance(1e-6, inputs={"contact_a.conductance": 1.0, "contact_b.conductance": 1.0,
                                          "contact_c.conductance": 1.0})
        with pytest.raises(TypeError, match="needs the input contact_b.conductance"):
            stepper.advance(1e-6, inputs={"contact_a.conductance": 1.0})
        assert stepper.time == 0.0  # nothing ran


def test_block_names_are_checked():
    with pytest.raises(ValueError, match=r"ContactBlock.name = 'n o': a name is a letter"):
        ContactBlock("n o", "a", "b")
    with pytest.raises(ValueError, match=r"ContactBlock.node_b = 'b c': a node name"):
        ContactBlock("no", "a", "b c")
