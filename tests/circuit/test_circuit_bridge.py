"""The double-break bridge template (circuit.BridgeCircuit) and a netlist's series contacts.

Closed forms of the DC loop: the two contacts in series conduct V_s / (R_s + R_w + R_L +
1/G_a + 1/G_b) when both are closed and only the open contact's leakage otherwise; names
and arrangement checked before anything runs. SI units.
"""

from __future__ import annotations

import numpy as np
import pytest

from circuit import BridgeCircuit, DCSource, NetlistCircuit, ResistiveLoad, SimulationOptions, Stepper, Wiring

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
