"""A switch read by a microcontroller input (``McuInput``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from PySpice.Spice.Netlist import Circuit

from ..blocks import CoilBlock, ContactBlock
from ..contact import DEFAULT_LEAKAGE, add_contact, check_current_factor
from ..probes import Probes
from ..validation import check_range, internal, scene_key
from .switch import LOAD_PROBE


PULLS = ("up", "down")
MCU_PIN = "pin"  # the input pin's node
MCU_SWITCH_NODE = "sw"  # the switch node, between the pull resistor and the contact
MCU_SUPPLY_NODE = "vcc"


@dataclass(frozen=True)
class McuInput:
    """A pushbutton or switch read by a microcontroller input pin, with its RC filter. SI units.

    voltage: the logic supply Vcc, V (an ideal rail: its impedance is far below any pull
        resistor).
    pull: "up": a pull resistor from Vcc to the switch node and the contact from the switch
        node to ground (active low, the usual wiring); "down": the contact from Vcc to the
        switch node and the pull resistor to ground (active high).
    pull_resistance: ohm, the pull-up (or pull-down) resistor, > 0.
    series_resistance: ohm, from the switch node to the pin (0: none); it sets how fast the
        closing contact discharges the input capacitor and limits that current.
    input_capacitance: F, from the pin to ground: the filter capacitor plus the pin's own.
    logic_low, logic_high: V, the input's Schmitt thresholds (0 < low < high < Vcc): the
        input reads low once the pin falls below logic_low and high once it rises above
        logic_high (defaults 0.3 and 0.7 of 3.3 V, the CMOS V_IL / V_IH); the scene's logic
        metric reads them (coupling.core.logic).
    contact_capacitance: F, across the contact (stray capacitance of the switch and leads).
    leakage_conductance: S, the open contact's conductance.
    contact_current_factor: optional ngspice expression g(I) of the contact current (A).

    The netlist (pull = "up"; "down" swaps the contact and the pull resistor's places)::

        Vsource vcc 0 Vcc
        Vload   vcc pull 0                 (0 V probe: the pull resistor's current, the loop current)
        Rpull   pull sw R_pull
        contact sw 0                       (circuit.contact; Ccontact sw 0 across it)
        Rseries sw pin R_series            (Vseries sw pin 0 when R_series = 0)
        Cinput  pin 0 C_in

    With the contact's closed resistance R_c, the pin relaxes exponentially after each make
    and break (contact capacitance neglected, C_contact << C_in): after a break towards the
    open level (Vcc pulled up, 0 pulled down) with tau = (R_pull + R_series) C_in; after a
    make towards the divider R_pull : R_c (Vcc R_c / (R_pull + R_c) pulled up) with
    tau = (R_series + R_pull R_c / (R_pull + R_c)) C_in (``break_time_constant``,
    ``make_time_constant``).
    """

    SECTION: ClassVar[str] = "circuit"
    voltage: float = scene_key(3.3, unit="V")
    pull: str = scene_key(
        "up", unit="-", doc='mcu_input: "up" (pull resistor to Vcc, the contact to ground: active low) or "down" '
        "(pull resistor to ground, the contact to Vcc)")
    pull_resistance: float = scene_key(10e3, unit="ohm", doc="mcu_input: the pull-up (pull-down) resistor, > 0")
    series_resistance: float = scene_key(1e3, unit="ohm", doc="mcu_input: from the switch node to the pin (0: none)")
    input_capacitance: float = scene_key(
        100e-9, unit="F", doc="mcu_input: from the pin to ground (the filter C plus the pin's own)")
    logic_low: float = scene_key(
        0.99, unit="V", doc="mcu_input: the input reads low below it (Schmitt threshold; the default of "
        "`[metrics] logic`)")
    logic_high: float = scene_key(
        2.31, unit="V", doc="mcu_input: the input reads high above it (> `logic_low`, < `voltage`)")
    contact_capacitance: float = scene_key(5e-12, unit="F")
    leakage_conductance: float = scene_key(DEFAULT_LEAKAGE, unit="S")
    contact_current_factor: str | None = internal(None)
    title: str = internal("switchsim mcu input")

    def __post_init__(self) -> None:
        name = self.SECTION
        check_range(name, "voltage", self.voltage, "V", 0.0, 1e3, low_open=True)
        if isinstance(self.pull, (list, dict)) or self.pull not in PULLS:
            raise ValueError(f"{name}.pull = {self.pull!r}: allowed values are 'up' (pull-up to Vcc, contact "
                             "to ground) and 'down' (pull-down to ground, contact to Vcc)")
        check_range(name, "pull_resistance", self.pull_resistance, "ohm", 0.0, 1e9, low_open=True)
        check_range(name, "series_resistance", self.series_resistance, "ohm", 0.0, 1e9)
        check_range(name, "input_capacitance", self.input_capacitance, "F", 0.0, 1e-2)
        check_range(name, "logic_low", self.logic_low, "V", 0.0, 1e3, low_open=True)
        check_range(name, "logic_high", self.logic_high, "V", 0.0, 1e3, low_open=True)
        if self.logic_low >= self.logic_high:
            raise ValueError(f"{name}.logic_low = {self.logic_low:g} V must be below {name}.logic_high = "
                             f"{self.logic_high:g} V (the Schmitt thresholds: low < high)")
        if self.logic_high >= self.voltage:
            raise ValueError(f"{name}.logic_high = {self.logic_high:g} V must be below {name}.voltage = "
                             f"{self.voltage:g} V: the pin never rises above the supply")
        check_range(name, "contact_capacitance", self.contact_capacitance, "F", 0.0, 1e-6)
        check_range(name, "leakage_conductance", self.leakage_conductance, "S", 0.0, 1e-3)
        check_current_factor(type(self).__name__, self.contact_current_factor)
        if not isinstance(self.title, str) or "\n" in self.title:
            raise ValueError(f"McuInput.title = {self.title!r}: must be a one-line string")

    @property
    def nodes(self) -> tuple[str, str]:
        """(node_a, node_b) of the contact: (sw, 0) pulled up, (vcc, sw) pulled down."""
        return (MCU_SWITCH_NODE, "0") if self.pull == "up" else (MCU_SUPPLY_NODE, MCU_SWITCH_NODE)

    @property
    def contacts(self) -> tuple[ContactBlock, ...]:
        """The switch, as the circuit's one (unnamed) contact."""
        return (ContactBlock("", *self.nodes, self.leakage_conductance, self.contact_current_factor),)

    @property
    def coils(self) -> tuple[CoilBlock, ...]:
        return ()

    @property
    def probes(self) -> Probes:
        return Probes(self.contacts, load_current=f"{LOAD_PROBE}#branch")

    @property
    def break_time_constant(self) -> float:
        """s: the pin's time constant while the contact is open, (R_pull + R_series) C_in."""
        return (self.pull_resistance + self.series_resistance) * self.input_capacitance

    def make_time_constant(self, closed_resistance: float) -> float:
        """s: the pin's time constant while the contact is closed with ``closed_resistance``
        (ohm): (R_series + R_pull || R_c) C_in."""
        parallel = self.pull_resistance * closed_resistance / (self.pull_resistance + closed_resistance)
        return (self.series_resistance + parallel) * self.input_capacitance

    def build(self) -> Circuit:
        """The PySpice circuit (``print`` it for the netlist)."""
        c = Circuit(self.title)
        gnd = c.gnd
        c.V("source", MCU_SUPPLY_NODE, gnd, float(self.voltage))
        node_a, node_b = self.nodes
        if self.pull == "up":
            c.V(LOAD_PROBE[1:], MCU_SUPPLY_NODE, "pull", 0)
            c.R("pull", "pull", MCU_SWITCH_NODE, float(self.pull_resistance))
        else:
            c.R("pull", MCU_SWITCH_NODE, "pull", float(self.pull_resistance))
            c.V(LOAD_PROBE[1:], "pull", gnd, 0)
        add_contact(c, node_a, node_b, self.leakage_conductance, self.contact_current_factor)
        if self.contact_capacitance > 0:
            c.C("contact", node_a, node_b, float(self.contact_capacitance))
        if self.series_resistance > 0:
            c.R("series", MCU_SWITCH_NODE, MCU_PIN, float(self.series_resistance))
        else:  # ngspice rejects a 0 ohm resistor
            c.V("series", MCU_SWITCH_NODE, MCU_PIN, 0)
        if self.input_capacitance > 0:
            c.C("input", MCU_PIN, gnd, float(self.input_capacitance))
        return c
