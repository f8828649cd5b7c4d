"""A switch circuit's optional suppression: the ``Snubber`` (RC across the contact) and the
``FlybackDiode`` (across an inductive load)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from ..validation import check_range, scene_key


@dataclass(frozen=True)
class Snubber:
    """RC snubber across the contact: resistance (ohm) in series with capacitance (F)."""

    SECTION: ClassVar[str] = "circuit.snubber"
    resistance: float = scene_key(100.0, unit="ohm", shown="-")
    capacitance: float = scene_key(100e-9, unit="F", shown="-")

    def __post_init__(self) -> None:
        check_range(self.SECTION, "resistance", self.resistance, "ohm", 0.0, 1e6, low_open=True)
        check_range(self.SECTION, "capacitance", self.capacitance, "F", 0.0, 1e-3, low_open=True)


@dataclass(frozen=True)
class FlybackDiode:
    """Freewheeling diode across an inductive load (ngspice D model: IS in A, N, RS in ohm)."""

    SECTION: ClassVar[str] = "circuit.flyback"
    saturation_current: float = scene_key(1e-9, unit="A", doc="diode I_s")
    emission_coefficient: float = scene_key(1.8, unit="-", doc="diode n")
    series_resistance: float = scene_key(0.05, unit="ohm")

    def __post_init__(self) -> None:
        name = self.SECTION
        check_range(name, "saturation_current", self.saturation_current, "A", 1e-20, 1e-3, low_open=True)
        check_range(name, "emission_coefficient", self.emission_coefficient, "", 0.5, 5.0)
        check_range(name, "series_resistance", self.series_resistance, "ohm", 0.0, 100.0)
