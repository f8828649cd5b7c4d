"""Switch-circuit templates: validated parameter dataclasses that build a PySpice ``Circuit``.

Topology of ``SwitchCircuit`` (the contact on the supply side, the load to ground)::

    src --Rsource-- wire --Rwire-- wire_l --Lwire-- contact_a =CONTACT= contact_b --Vload-- load --LOAD-- 0
                                                    |--Ccontact--|    (parasitic, across the contact)
                                                    |--Rsnubber--snubber--Csnubber--|  (optional)
                                                    |--arc path--|    (optional ArcModel)
    flyback diode (optional): anode 0, cathode contact_b (across Vload + load)

Loads: ``ResistiveLoad`` (R), ``InductiveLoad`` (R + L in series: relay coil, motor),
``CapacitiveLoad`` (series R, then C with a bleed resistor across it: lamp or
supply-input inrush). ``Vload`` is a 0 V probe: its current is the load current, which
keeps flowing through it when the flyback diode freewheels.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Union

from PySpice.Spice.Netlist import Circuit

from .arc import ArcModel, add_arc
from .contact import (
    CONDUCTANCE_NODE, DEFAULT_LEAKAGE, EFFECTIVE_NODE, SENSE_SOURCE, add_contact, check_current_factor,
)
from .probes import Probes
from .validation import check_range

NODE_A = "contact_a"
NODE_B = "contact_b"
LOAD_PROBE = "Vload"


@dataclass(frozen=True)
class DCSource:
    """DC supply: open-circuit voltage (V, positive) and internal resistance (ohm)."""

    voltage: float = 24.0
    internal_resistance: float = 0.01

    def __post_init__(self) -> None:
        check_range("DCSource", "voltage", self.voltage, "V", 0.0, 1e5, low_open=True)
        check_range("DCSource", "internal_resistance", self.internal_resistance, "ohm", 0.0, 1e6)


@dataclass(frozen=True)
class Wiring:
    """Loop wiring between source and contact: resistance (ohm) and inductance (H, ~1 uH per metre of loop)."""

    resistance: float = 0.01
    inductance: float = 1e-6

    def __post_init__(self) -> None:
        check_range("Wiring", "resistance", self.resistance, "ohm", 0.0, 1e3)
        check_range("Wiring", "inductance", self.inductance, "H", 0.0, 1.0)


@dataclass(frozen=True)
class ResistiveLoad:
    """Resistive load, ohm."""

    resistance: float = 12.0

    def __post_init__(self) -> None:
        check_range("ResistiveLoad", "resistance", self.resistance, "ohm", 1e-6, 1e9)


@dataclass(frozen=True)
class InductiveLoad:
    """Series R-L load (relay coil, motor winding): resistance (ohm), inductance (H)."""

    resistance: float = 24.0
    inductance: float = 10e-3

    def __post_init__(self) -> None:
        check_range("InductiveLoad", "resistance", self.resistance, "ohm", 1e-6, 1e9)
        check_range("InductiveLoad", "inductance", self.inductance, "H", 0.0, 100.0, low_open=True)


@dataclass(frozen=True)
class CapacitiveLoad:
    """Inrush load: series resistance (ohm), then a capacitance (F) with a bleed resistance (ohm) across it.

    The bleed resistor is the load's steady consumption and gives the capacitor a DC
    path, so the operating point is defined with the contact open.
    """

    resistance: float = 0.5
    capacitance: float = 100e-6
    bleed_resistance: float = 1e3

    def __post_init__(self) -> None:
        check_range("CapacitiveLoad", "resistance", self.resistance, "ohm", 1e-6, 1e9)
        check_range("CapacitiveLoad", "capacitance", self.capacitance, "F", 0.0, 1.0, low_open=True)
        check_range("CapacitiveLoad", "bleed_resistance", self.bleed_resistance, "ohm", 1e-3, 1e12)


Load = Union[ResistiveLoad, InductiveLoad, CapacitiveLoad]


@dataclass(frozen=True)
class Snubber:
    """RC snubber across the contact: resistance (ohm) in series with capacitance (F)."""

    resistance: float = 100.0
    capacitance: float = 100e-9

    def __post_init__(self) -> None:
        check_range("Snubber", "resistance", self.resistance, "ohm", 0.0, 1e6, low_open=True)
        check_range("Snubber", "capacitance", self.capacitance, "F", 0.0, 1e-3, low_open=True)


@dataclass(frozen=True)
class FlybackDiode:
    """Freewheeling diode across an inductive load (ngspice D model: IS in A, N, RS in ohm)."""

    saturation_current: float = 1e-9
    emission_coefficient: float = 1.8
    series_resistance: float = 0.05

    def __post_init__(self) -> None:
        check_range("FlybackDiode", "saturation_current", self.saturation_current, "A", 1e-20, 1e-3, low_open=True)
        check_range("FlybackDiode", "emission_coefficient", self.emission_coefficient, "", 0.5, 5.0)
        check_range("FlybackDiode", "series_resistance", self.series_resistance, "ohm", 0.0, 100.0)


@dataclass(frozen=True)
class SwitchCircuit:
    """A DC switch circuit around one contact. SI units throughout.

    contact_capacitance: parasitic capacitance across the contact, F (contact plus
        wiring stray capacitance). It bounds the opening dv/dt; 0 is refused when an
        inductance is in series with the contact (wiring, or an inductive load without
        a flyback diode) and there is no snubber: the opening would then abort.
    leakage_conductance: conductance of the open contact, S (insulation).
    contact_current_factor: optional ngspice expression g(I) of the contact current I
        (A): the contact conductance is then G(t)/g(I), solved by ngspice (see contact.py).

    Example::

        circuit = SwitchCircuit(DCSource(24.0), InductiveLoad(24.0, 10e-3), arc=ArcModel())
        print(circuit.build())        # the netlist
    """

    source: DCSource = field(default_factory=DCSource)
    load: Load = field(default_factory=ResistiveLoad)
    wiring: Wiring = field(default_factory=Wiring)
    contact_capacitance: float = 100e-12
    snubber: Snubber | None = None
    flyback: FlybackDiode | None = None
    arc: ArcModel | None = None
    leakage_conductance: float = DEFAULT_LEAKAGE
    contact_current_factor: str | None = None
    title: str = "switchsim contact circuit"

    def __post_init__(self) -> None:
        name = "SwitchCircuit"
        for attr, kind in (("source", DCSource), ("wiring", Wiring)):
            if not isinstance(getattr(self, attr), kind):
                raise ValueError(f"{name}.{attr} = {getattr(self, attr)!r}: must be a {kind.__name__}")
        if not isinstance(self.load, (ResistiveLoad, InductiveLoad, CapacitiveLoad)):
            raise ValueError(
                f"{name}.load = {self.load!r}: must be a ResistiveLoad, InductiveLoad or CapacitiveLoad"
            )
        for attr, kind in (("snubber", Snubber), ("flyback", FlybackDiode), ("arc", ArcModel)):
            value = getattr(self, attr)
            if value is not None and not isinstance(value, kind):
                raise ValueError(f"{name}.{attr} = {value!r}: must be a {kind.__name__} or None")
        if self.flyback is not None and not isinstance(self.load, InductiveLoad):
            raise ValueError(
                f"{name}.flyback is set but load is {type(self.load).__name__}: "
                "a flyback diode belongs across an InductiveLoad"
            )
        check_range(name, "contact_capacitance", self.contact_capacitance, "F", 0.0, 1e-6)
        series_l = self.wiring.inductance + (self.load.inductance if isinstance(self.load, InductiveLoad)
                                             and self.flyback is None else 0.0)
        if self.contact_capacitance == 0.0 and series_l > 0.0 and self.snubber is None:
            raise ValueError(
                f"{name}.contact_capacitance = 0 F with {series_l!r} H in series with the contact and no snubber: "
                "opening the contact would stop an inductor current in zero time (ngspice aborts, 'timestep too "
                "small'); give the contact's stray capacitance (> 0 F, default 1e-10 F) or a snubber"
            )
        check_range(name, "leakage_conductance", self.leakage_conductance, "S", 0.0, 1e-3)
        check_current_factor(name, self.contact_current_factor)
        if not isinstance(self.title, str) or "\n" in self.title:
            raise ValueError(f"{name}.title = {self.title!r}: must be a one-line string")

    @property
    def probes(self) -> Probes:
        return Probes(
            node_a=NODE_A,
            node_b=NODE_B,
            contact_current=f"{SENSE_SOURCE}#branch",
            conductance_node=CONDUCTANCE_NODE if self.contact_current_factor is None else EFFECTIVE_NODE,
            load_current=f"{LOAD_PROBE}#branch",
            arc_current=None if self.arc is None else "Varc#branch",
        )

    def build(self) -> Circuit:
        """The PySpice circuit (``print`` it for the netlist)."""
        c = Circuit(self.title)
        gnd = c.gnd
        c.V("source", "src", gnd, float(self.source.voltage))
        series = [
            (kind, name, value)
            for kind, name, value in (
                ("R", "source", self.source.internal_resistance),
                ("R", "wire", self.wiring.resistance),
                ("L", "wire", self.wiring.inductance),
            )
            if value > 0
        ]
        if not series:
            # ngspice rejects a 0 ohm resistor; a 0 V source keeps the node names.
            series = [("V", "wire_short", 0.0)]
        inner_nodes = iter(("wire", "wire_l"))
        node = "src"
        for i, (kind, name, value) in enumerate(series):
            next_node = NODE_A if i == len(series) - 1 else next(inner_nodes)
            getattr(c, kind)(name, node, next_node, float(value))
            node = next_node
        add_contact(c, NODE_A, NODE_B, self.leakage_conductance, self.contact_current_factor)
        if self.contact_capacitance > 0:
            c.C("contact", NODE_A, NODE_B, float(self.contact_capacitance))
        if self.snubber is not None:
            c.R("snubber", NODE_A, "snubber", float(self.snubber.resistance))
            c.C("snubber", "snubber", NODE_B, float(self.snubber.capacitance))
        if self.arc is not None:
            add_arc(c, self.arc, NODE_A, NODE_B)
        c.V(LOAD_PROBE[1:], NODE_B, "load", 0)
        load = self.load
        if isinstance(load, ResistiveLoad):
            c.R("load", "load", gnd, float(load.resistance))
        elif isinstance(load, InductiveLoad):
            c.R("load", "load", "load_l", float(load.resistance))
            c.L("load", "load_l", gnd, float(load.inductance))
        else:
            c.R("load", "load", "load_c", float(load.resistance))
            c.C("load", "load_c", gnd, float(load.capacitance))
            c.R("bleed", "load_c", gnd, float(load.bleed_resistance))
        if self.flyback is not None:
            d = self.flyback
            c.D("flyback", gnd, NODE_B, model="switchsim_flyback")
            c.model(
                "switchsim_flyback",
                "D",
                IS=float(d.saturation_current),
                N=float(d.emission_coefficient),
                RS=float(d.series_resistance),
            )
        return c

