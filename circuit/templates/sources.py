"""The templates' sources: ``DCSource`` (a voltage source, DC or AC) and ``CurrentSource``
(a supply in constant-current mode with its compliance clamp); the netlist in switch.py."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Union

from ..validation import check_range, scene_key


BOLTZMANN_OVER_CHARGE = 8.617333262e-5  # V/K
CLAMP_TEMPERATURE = 27.0  # degC: the clamp diode's instance temperature (fixed, whatever TEMP)
CLAMP_SATURATION_CURRENT = 1e-12  # A
CLAMP_MODEL = "switchsim_clamp"


@dataclass(frozen=True)
class DCSource:
    """A voltage source behind its internal resistance ``source_resistance`` (ohm): DC, or AC
    with ``frequency`` > 0.

    voltage: V (positive): the DC open-circuit voltage, or with ``frequency`` > 0 the RMS
        value of the sine (a relay's load is rated in V AC): amplitude sqrt(2) * voltage.
    frequency: Hz; 0 (default): DC. > 0: v(t) = sqrt(2) voltage sin(2 pi frequency t + phase).
    phase_deg: the sine's phase at t = 0, degrees (only with ``frequency`` > 0; 0: the source
        starts at its rising zero, 90: at its positive peak).
    """

    SECTION: ClassVar[str] = "circuit"  # the scene section of its keys: [circuit] voltage, ...
    voltage: float = scene_key(
        24.0, unit="V", doc="source: DC, or RMS with `frequency` > 0; mcu_input: the logic supply Vcc")
    source_resistance: float = scene_key(0.01, unit="ohm")
    frequency: float = scene_key(0.0, unit="Hz", doc="source: 0 DC; > 0 a sine of RMS `voltage`")
    phase_deg: float = scene_key(0.0, unit="deg", doc="source: the sine's phase at t = 0 (`frequency` > 0)")

    def __post_init__(self) -> None:
        check_range(self.SECTION, "voltage", self.voltage, "V", 0.0, 1e5, low_open=True)
        check_range(self.SECTION, "source_resistance", self.source_resistance, "ohm", 0.0, 1e6)
        # mains and aircraft supplies (50-400 Hz) up to ultrasound; a slip of units (rad/s, kHz) shows
        check_range(self.SECTION, "frequency", self.frequency, "Hz", 0.0, 1e6)
        check_range(self.SECTION, "phase_deg", self.phase_deg, "deg", -360.0, 360.0)
        if self.frequency == 0.0 and self.phase_deg != 0.0:
            raise ValueError(f"{self.SECTION}.phase_deg = {self.phase_deg:g} deg applies to an AC source: set "
                             f"{self.SECTION}.frequency (Hz, > 0), or leave phase_deg out for DC")

    @property
    def amplitude(self) -> float:
        """V: the largest voltage the source puts out (sqrt(2) voltage for AC, voltage for DC)."""
        return math.sqrt(2.0) * self.voltage if self.frequency > 0.0 else self.voltage

    def spice_value(self) -> float | str:
        """The source's SPICE value: the DC volts, or ``SIN(0 amplitude frequency 0 0 phase)``."""
        if self.frequency == 0.0:
            return float(self.voltage)
        return f"SIN(0 {self.amplitude!r} {float(self.frequency)!r} 0 0 {float(self.phase_deg)!r})"


@dataclass(frozen=True)
class CurrentSource:
    """DC supply in constant-current mode (SI units).

    current: the set current I_set, A (> 0).
    compliance_voltage: V_comp, the most the supply puts out, V: with the load open it
        leaves constant-current mode and holds V_comp (constant-voltage mode).
    output_capacitance: C_out across the output terminals, F (> 0: output filter
        capacitor, lead capacitance). It sets how fast the voltage rises when the load
        opens (I_set / C_out at first) and discharges into the contact at each make.
    output_resistance: R_out across the output, ohm: the finite output impedance of the
        current regulator; a closed loop of resistance R gets I_set R_out / (R_out + R).

    The netlist (``SwitchCircuit.build``)::

        Isource     0 src I_set                 (the regulated current, into src)
        Rsource_out src 0 R_out
        Csource_out src 0 C_out
        Dclamp      src clamp switchsim_clamp temp=27   (IS = 1e-12 A, N = 1, RS = 0)
        Vclamp      clamp 0 V_comp - V_T ln(1 + I_set/IS)

    The compliance limit is a diode clamp onto a voltage source, not a behavioural
    min(I_set, ...) law: ngspice limits a junction's voltage between Newton iterations
    (pnjlim), so the clamp's exponential knee converges from any operating point, while
    a piecewise-linear clamp has a kink that Newton and the truncation-error control must
    find by step rejection at every break. Vclamp is offset by the diode's drop at I_set,
    so with the load open the output sits at V_comp when the clamp takes the whole set
    current, and at V_comp + V_T ln(I_clamp / I_set) when it takes less (V_T = k T / q =
    25.9 mV at the clamp's fixed 27 degC: -60 mV per decade). Below V_comp - 0.3 V the
    clamp carries less than 1e-5 I_set: constant-current mode.
    """

    SECTION: ClassVar[str] = "circuit"
    current: float = scene_key(1.0, unit="A", doc="current_source: set current")
    compliance_voltage: float = scene_key(20.0, unit="V", doc="current_source: the most the supply puts out")
    output_capacitance: float = scene_key(1e-6, unit="F", doc="current_source")
    output_resistance: float = scene_key(1e4, unit="ohm", doc="current_source")

    def __post_init__(self) -> None:
        name = self.SECTION
        check_range(name, "current", self.current, "A", 0.0, 1e3, low_open=True)
        check_range(name, "compliance_voltage", self.compliance_voltage, "V", 0.0, 1e5, low_open=True)
        check_range(name, "output_capacitance", self.output_capacitance, "F", 0.0, 1.0, low_open=True)
        check_range(name, "output_resistance", self.output_resistance, "ohm", 1e-3, 1e12)

    @property
    def thermal_voltage(self) -> float:
        """V: k T / q of the clamp diode at its fixed temperature."""
        return BOLTZMANN_OVER_CHARGE * (CLAMP_TEMPERATURE + 273.15)

    @property
    def clamp_source_voltage(self) -> float:
        """V: the clamp's voltage source, V_comp less the diode's drop at I_set."""
        return self.compliance_voltage - self.thermal_voltage * math.log1p(self.current / CLAMP_SATURATION_CURRENT)

    def open_voltage(self, load_conductance: float = 0.0) -> float:
        """V: the steady output voltage with the contact open (CV mode if the clamp conducts).

        load_conductance: S, whatever else draws current from the output (leakage).
        Solves I_set = V (1/R_out + G) + IS (exp((V - V_clamp)/V_T) - 1) by bisection.
        """
        g = 1.0 / self.output_resistance + load_conductance
        vt, vc, i_s = self.thermal_voltage, self.clamp_source_voltage, CLAMP_SATURATION_CURRENT
        lo, hi = 0.0, min(self.current / g, self.compliance_voltage + 1.0)
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            excess = mid * g + i_s * math.expm1(min((mid - vc) / vt, 700.0)) - self.current
            lo, hi = (mid, hi) if excess < 0 else (lo, mid)
        return 0.5 * (lo + hi)


Source = Union[DCSource, CurrentSource]
