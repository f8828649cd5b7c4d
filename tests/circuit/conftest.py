"""Fixtures of the circuit tests: the bounce schedule, a ringing circuit, options (SI units)."""

from __future__ import annotations

import pytest

from circuit import ContactSchedule, DCSource, ResistiveLoad, SimulationOptions, SwitchCircuit, Wiring
from circuit_scenes import BOUNCE_BREAKS, BOUNCE_MAKES


@pytest.fixture(scope="session")
def bounce_schedule() -> ContactSchedule:
    return ContactSchedule.from_events(BOUNCE_MAKES, BOUNCE_BREAKS, closed_resistance=0.01, edge_time=10e-9)


@pytest.fixture(scope="session")
def ringing_circuit() -> SwitchCircuit:
    """24 V, 2 A resistive load, 1 uH wiring, 100 pF across the contact: rings at ~16 MHz on opening."""
    return SwitchCircuit(DCSource(24.0, 0.05), ResistiveLoad(12.0), wiring=Wiring(0.0, 1e-6), contact_capacitance=100e-12)


@pytest.fixture(scope="session")
def bounce_options() -> SimulationOptions:
    return SimulationOptions(max_step=1e-6, reltol=1e-4)
