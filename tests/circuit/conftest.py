"""Shared circuits and schedules for the circuit tests (SI units)."""

from __future__ import annotations

import pytest

from circuit import ContactSchedule, DCSource, ResistiveLoad, SimulationOptions, SwitchCircuit, Wiring

# A make at 0.1 ms followed by five bounces (five breaks, six makes) within 2 ms.
BOUNCE_MAKES = (0.10e-3, 0.30e-3, 0.55e-3, 0.73e-3, 0.87e-3, 0.96e-3)
BOUNCE_BREAKS = (0.25e-3, 0.50e-3, 0.70e-3, 0.85e-3, 0.95e-3)
BOUNCE_T_END = 2e-3


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
