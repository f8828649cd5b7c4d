"""The one-contact templates' loads: ``ResistiveLoad``, ``InductiveLoad`` (R + L in series),
``CapacitiveLoad`` (series R, then C with a bleed resistor across it)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Union

from ..validation import check_range, scene_key


@dataclass(frozen=True)
class ResistiveLoad:
    """Resistive load: load_resistance, ohm."""

    SECTION: ClassVar[str] = "circuit"
    load_resistance: float = scene_key(12.0, unit="ohm", doc="changeover: NO's load")

    def __post_init__(self) -> None:
        check_range(self.SECTION, "load_resistance", self.load_resistance, "ohm", 1e-6, 1e9)


@dataclass(frozen=True)
class InductiveLoad:
    """Series R-L load (relay coil, motor winding): load_resistance (ohm), load_inductance (H)."""

    SECTION: ClassVar[str] = "circuit"
    load_resistance: float = scene_key(24.0, unit="ohm")
    load_inductance: float = scene_key(
        10e-3, unit="H", doc="inductive; bridge: the load's inductance, changeover: NO's, in series with "
        "`load_resistance` (0: resistive)")

    def __post_init__(self) -> None:
        check_range(self.SECTION, "load_resistance", self.load_resistance, "ohm", 1e-6, 1e9)
        check_range(self.SECTION, "load_inductance", self.load_inductance, "H", 0.0, 100.0, low_open=True)


@dataclass(frozen=True)
class CapacitiveLoad:
    """Inrush load: series load_resistance (ohm), then load_capacitance (F) with bleed_resistance (ohm) across it.

    The bleed resistor is the load's steady consumption and gives the capacitor a DC
    path, so the operating point is defined with the contact open.
    """

    SECTION: ClassVar[str] = "circuit"
    load_resistance: float = scene_key(0.5, unit="ohm")
    load_capacitance: float = scene_key(100e-6, unit="F", doc="capacitive")
    bleed_resistance: float = scene_key(1e3, unit="ohm", doc="capacitive")

    def __post_init__(self) -> None:
        name = self.SECTION
        check_range(name, "load_resistance", self.load_resistance, "ohm", 1e-6, 1e9)
        check_range(name, "load_capacitance", self.load_capacitance, "F", 0.0, 1.0, low_open=True)
        check_range(name, "bleed_resistance", self.bleed_resistance, "ohm", 1e-3, 1e12)


Load = Union[ResistiveLoad, InductiveLoad, CapacitiveLoad]
