"""Templates build printable netlists with the contact and named nodes; bad parameters fail early."""

from __future__ import annotations

import math

import numpy as np
import pytest
from PySpice.Spice.Netlist import Circuit

from circuit import (
    ArcModel,
    CapacitiveLoad,
    ContactSchedule,
    DCSource,
    FlybackDiode,
    InductiveLoad,
    NetlistCircuit,
    ResistiveLoad,
    SimulationOptions,
    Snubber,
    SwitchCircuit,
    Wiring,
    add_contact,
    run_transient,
)


def test_the_package_gives_every_name_it_lists_those_imported_on_first_use_too():
    """circuit/__init__.py imports the templates, the netlist circuit, the schedule and the
    one-shot runs on first use (PEP 562): each listed name is still there, and in dir()."""
    import circuit
    import circuit.templates

    assert all(getattr(circuit, name) is not None for name in circuit.__all__)
    assert set(circuit.__all__) <= set(dir(circuit))
    assert circuit.SwitchCircuit is circuit.templates.SwitchCircuit
    with pytest.raises(AttributeError, match="module 'circuit' has no attribute 'Nothing'"):
        circuit.Nothing  # noqa: B018


def test_full_template_netlist_has_contact_and_named_nodes():
    circuit = SwitchCircuit(
        DCSource(24.0, 0.1),
        InductiveLoad(24.0, 10e-3),
        snubber=Snubber(100.0, 100e-9),
        flyback=FlybackDiode(),
        arc=ArcModel(breakdown_voltage=300.0),
    )
    text = str(circuit.build())
    lines = {line.split()[0]: line for line in text.splitlines()[1:] if line.strip()}
    assert lines["Vcontact_g"] == "Vcontact_g contact_g 0 external"  # no value: ngspice 39 segfaults on one
    assert lines["Bcontact"].startswith("Bcontact contact_s contact_b")
    assert lines["Ccontact"] == "Ccontact contact_a contact_b 1e-10"
    assert lines["Csnubber"] == "Csnubber snubber contact_b 1e-07"
    assert lines["Dflyback"] == "Dflyback 0 contact_b switchsim_flyback"
    assert lines["Vload"] == "Vload contact_b load 0"
    assert lines["Lload"] == "Lload load_l 0 0.01"
    # The arc path: a dead-zone conductor enabled by the arc state, which Python sets
    # between accepted points (the breakdown voltage lives in ArcState, not the netlist).
    assert lines["Barc"].startswith("Barc arc_p contact_b i=V(arc_on)*(uramp(V(arc_p,contact_b)-12.0)")
    assert lines["Iarc_on"] == "Iarc_on 0 arc_on external"


def test_zero_series_elements_keep_the_contact_node():
    circuit = SwitchCircuit(DCSource(5.0, 0.0), ResistiveLoad(5.0), wiring=Wiring(0.0, 0.0), contact_capacitance=0.0)
    text = str(circuit.build())
    assert "Vwire_short src contact_a 0" in text
    df = run_transient(circuit, 1.0, 10e-6, options=SimulationOptions(max_step=1e-6))
    assert df.load_current.iloc[-1] == pytest.approx(5.0 / 6.0, rel=1e-9)


def test_flyback_diode_freewheels_the_coil_current():
    """With the diode the opening voltage is E plus a diode drop, and the coil current decays through it.

    (Wiring inductance left out: its current would ring into the contact capacitance.)
    """
    circuit = SwitchCircuit(
        DCSource(24.0, 0.0), InductiveLoad(24.0, 10e-3), wiring=Wiring(0.01, 0.0), flyback=FlybackDiode()
    )
    schedule = ContactSchedule(((0.0, 1e-3),), closed_resistance=0.01)
    df = run_transient(circuit, schedule, 1.5e-3, options=SimulationOptions(max_step=1e-6))
    t = df.time.to_numpy()
    after = t > 1e-3 + 2e-6
    v = df.contact_voltage.to_numpy()[after]
    assert np.all((v > 24.0) & (v < 26.0))
    i = df.load_current.to_numpy()[after]
    assert np.all(np.diff(i) < 0) and i[0] > 0.9 * (24.0 / 24.01) * (1 - math.exp(-1e-3 * 24.01 / 10e-3))


def test_capacitive_inrush_peak():
    # No contact capacitance: with an ideal source its discharge at the make is an impulse.
    circuit = SwitchCircuit(
        DCSource(24.0, 0.0), CapacitiveLoad(0.5, 100e-6, 1e3), wiring=Wiring(0.0, 0.0), contact_capacitance=0.0
    )
    schedule = ContactSchedule(((10e-6, math.inf),), closed_resistance=0.01, edge_time=0.0)
    df = run_transient(circuit, schedule, 200e-6, options=SimulationOptions(max_step=1e-7))
    assert df.load_current.max() == pytest.approx(24.0 / 0.51, rel=2e-3)


def test_user_pyspice_circuit_with_add_contact():
    c = Circuit("mine")
    c.V("s", "p", c.gnd, 12.0)
    add_contact(c, "p", "q")
    c.V("load", "q", "r", 0)
    c.R("l", "r", c.gnd, 6.0)
    df = run_transient(c, 2.0, 10e-6, options=SimulationOptions(max_step=1e-6))
    assert df.load_current.iloc[-1] == pytest.approx(12.0 / 6.5, rel=1e-9)
    assert df.contact_voltage.iloc[-1] == pytest.approx(0.5 * 12.0 / 6.5, rel=1e-9)


def test_netlist_convention_expands_xcontact_and_reads_the_load_probe(tmp_path):
    path = tmp_path / "relay.cir"
    path.write_text("relay\nV1 s 0 12\nR1 s a 1\nXCONTACT a b\nVLOAD b c 0\nRl c 0 11\n.end\n")
    circuit = NetlistCircuit.from_file(path, arc=ArcModel())
    text = circuit.netlist()
    assert "XCONTACT" not in text and "Bcontact contact_s b" in text and "Barc arc_p b" in text
    assert circuit.probes.load_current == "VLOAD#branch"
    df = run_transient(circuit, 100.0, 10e-6, options=SimulationOptions(max_step=1e-6))
    assert df.load_current.iloc[-1] == pytest.approx(12.0 / 12.01, rel=1e-9)


@pytest.mark.parametrize(
    "text, message",
    [
        ("t\nV1 a 0 1\nR1 a 0 1\n", "must contain a contact line, 'XCONTACT node_a node_b'"),
        ("t\nV1 a 0 1\nXCONTACT a b\nXCONTACT b 0\n", "a second contact line XCONTACT"),
        ("t\nV1 a 0 1\nXCONTACT_no a b\nXCONTACT_NO b 0\n", "a second contact line XCONTACT_NO"),
        ("t\nV1 a 0 1\nXCONTACT a b\nXCONTACT_nc b 0\n", "names each one"),
        ("t\nV1 a 0 1\nXCONTACT_1 a b\n", "a letter followed by"),
        ("t\nV1 a 0 1\nXCONTACT a\n", "XCONTACT node_a node_b"),
        ("t\nV1 a 0 1\nXCONTACT a b\n.tran 1u 1m\n", "analysis"),
        ("t\nV1 a 0 1\nXCONTACT a b\nVarc b 0 0\n", "reserved"),
        ("t\nV1 a 0 1\nXCONTACT a b\nR1 b contact_g 1\n", "reserved"),
    ],
)
def test_netlist_convention_errors(text, message):
    with pytest.raises(ValueError, match=message):
        NetlistCircuit(text)


def test_second_external_source_is_refused():
    circuit = NetlistCircuit("t\nV1 a 0 1\nXCONTACT a b\nV2 b 0 external\n")
    with pytest.raises(ValueError, match="EXTERNAL"):
        run_transient(circuit, 1.0, 1e-6)


@pytest.mark.parametrize(
    "build, match",
    [
        (lambda: DCSource(voltage=-5.0), r"circuit\.voltage = -5 V is out of range: allowed 0 < value <= 100000 V"),
        (lambda: DCSource(source_resistance=-1.0), r"circuit\.source_resistance = -1 ohm"),
        (lambda: Wiring(wiring_inductance=2.0), r"circuit\.wiring_inductance = 2 H is out of range"),
        (lambda: ResistiveLoad(0.0), r"circuit\.load_resistance = 0 ohm"),
        (lambda: InductiveLoad(24.0, 0.0), r"circuit\.load_inductance = 0 H"),
        (lambda: CapacitiveLoad(load_capacitance=math.nan), r"circuit\.load_capacitance = nan F: must be finite"),
        (lambda: Snubber(capacitance=1.0), r"circuit\.snubber\.capacitance = 1 F is out of range"),
        (lambda: FlybackDiode(emission_coefficient=9.0), r"circuit\.flyback\.emission_coefficient = 9"),
        (lambda: SwitchCircuit(contact_capacitance=100.0), r"circuit\.contact_capacitance = 100 F is out of range"),
        (lambda: SwitchCircuit(contact_capacitance="100p"), r"circuit\.contact_capacitance = '100p': must be a real number"),
        (lambda: SwitchCircuit(flyback=FlybackDiode()), r"circuit\.flyback .* InductiveLoad"),
        (lambda: SwitchCircuit(load=Snubber()), r"SwitchCircuit\.load = "),
        (lambda: SimulationOptions(method="euler"), r"circuit\.method = 'euler'"),
        (lambda: SimulationOptions(max_step=0.0), r"circuit\.max_step = 0 s"),
        (lambda: ContactSchedule(((2e-3, 1e-3),)), r"circuit\.schedule\.make/break\[0\]"),
        (lambda: ContactSchedule(((1e-3, 2e-3), (1.5e-3, 3e-3))), r"must increase and not overlap"),
        (lambda: ContactSchedule(((1e-3, 1e-3 + 5e-9),)), r"at least its ramps"),
        (lambda: ContactSchedule(((1e-3, 2e-3),), closed_resistance=0.0), r"circuit\.schedule\.closed_resistance = 0 ohm"),
    ],
)
def test_bad_parameters_name_field_value_and_range(build, match):
    with pytest.raises(ValueError, match=match):
        build()
