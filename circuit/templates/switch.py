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

Sources: ``DCSource`` (a voltage source E behind its internal resistance; AC, E the RMS
value, with ``frequency`` > 0) or
``CurrentSource`` (a supply in constant-current mode: I_set with its output resistance
and capacitance and a compliance clamp; see its docstring for the netlist)::

    Isource 0 src I_set ; Rsource_out src 0 ; Csource_out src 0
    Dclamp src clamp (switchsim_clamp) ; Vclamp clamp 0 V_comp - (diode drop at I_set)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

from PySpice.Spice.Netlist import Circuit

from ..arc import ArcModel, add_arc
from ..blocks import CoilBlock, ContactBlock
from ..coil_drive import CoilDrive
from ..contact import DEFAULT_LEAKAGE, add_contact, check_current_factor
from ..probes import Probes
from ..validation import check_range, internal, scene_key
from . import loaded
from .loads import CapacitiveLoad, InductiveLoad, Load, ResistiveLoad
from .sources import CLAMP_MODEL, CLAMP_SATURATION_CURRENT, CLAMP_TEMPERATURE, CurrentSource, DCSource, Source

if TYPE_CHECKING:
    from .suppression import FlybackDiode, Snubber

NODE_A = "contact_a"
NODE_B = "contact_b"
LOAD_PROBE = "Vload"
SUPPLY_NODE = "supply"  # between a probe at the source and the series elements (_place_supply)


@dataclass(frozen=True)
class Wiring:
    """Loop wiring between source and contact: wiring_resistance (ohm) and wiring_inductance
    (H, ~1 uH per metre of loop)."""

    SECTION: ClassVar[str] = "circuit"
    wiring_resistance: float = scene_key(0.01, unit="ohm")
    wiring_inductance: float = scene_key(1e-6, unit="H")

    def __post_init__(self) -> None:
        check_range(self.SECTION, "wiring_resistance", self.wiring_resistance, "ohm", 0.0, 1e3)
        check_range(self.SECTION, "wiring_inductance", self.wiring_inductance, "H", 0.0, 1.0)


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
    coil: the relay's own coil with its drive and suppression (``CoilDrive``), in the same
        ngspice circuit as the contact's loop, or None.

    Example::

        circuit = SwitchCircuit(DCSource(24.0), InductiveLoad(24.0, 10e-3), arc=ArcModel())
        print(circuit.build())        # the netlist
    """

    SECTION: ClassVar[str] = "circuit"
    source: Source = internal(default_factory=DCSource)  # its keys are the source's fields
    load: Load = internal(default_factory=ResistiveLoad)
    wiring: Wiring = internal(default_factory=Wiring)
    contact_capacitance: float = scene_key(
        100e-12, unit="F", doc="across the contact (bridge, changeover: across each of its two)")
    snubber: Snubber | None = scene_key(
        None, unit="-", doc="RC across the contact (changeover: one across each contact), `{resistance = 100.0, capacitance = 100e-9}` (ohm, F; give "
        "both): [circuit.snubber]; omitted or false: none")
    flyback: FlybackDiode | None = scene_key(
        None, unit="-", doc="a diode across an inductive load: true (its defaults) or a table: [circuit.flyback]; "
        "omitted or false: none (bridge: across its inductive load; changeover: one across each inductive throw's load)")
    arc: ArcModel | None = scene_key(
        None, unit="-", doc="the arc model: true (its defaults) or a table: [circuit.arc]; omitted or false: none")
    leakage_conductance: float = scene_key(DEFAULT_LEAKAGE, unit="S", doc="open-contact insulation")
    contact_current_factor: str | None = internal(None)  # from [tribology]'s resistance law
    title: str = internal("switchsim contact circuit")
    coil: CoilDrive | None = internal(None)  # from [coil]

    def __post_init__(self) -> None:
        name = self.SECTION
        if not isinstance(self.source, (DCSource, CurrentSource)):
            raise ValueError(f"SwitchCircuit.source = {self.source!r}: must be a DCSource or CurrentSource")
        if not isinstance(self.wiring, Wiring):
            raise ValueError(f"SwitchCircuit.wiring = {self.wiring!r}: must be a Wiring")
        if not isinstance(self.load, (ResistiveLoad, InductiveLoad, CapacitiveLoad)):
            raise ValueError(
                f"SwitchCircuit.load = {self.load!r}: must be a ResistiveLoad, InductiveLoad or CapacitiveLoad"
            )
        # (the snubber's and the flyback's classes as loaded: a circuit without them imports neither)
        for attr, kind, classes in (("snubber", "Snubber", loaded("Snubber")),
                                    ("flyback", "FlybackDiode", loaded("FlybackDiode")),
                                    ("arc", "ArcModel", (ArcModel,)), ("coil", "CoilDrive", (CoilDrive,))):
            value = getattr(self, attr)
            if value is not None and not isinstance(value, classes):
                raise ValueError(f"SwitchCircuit.{attr} = {value!r}: must be a {kind} or None")
        self._check_own_keys()
        if self.flyback is not None and not self._inductive_load:
            raise ValueError(self._flyback_refusal)
        if isinstance(self.source, CurrentSource):
            if not isinstance(self.load, ResistiveLoad):
                raise ValueError(f"SwitchCircuit.load is {type(self.load).__name__}: a CurrentSource drives a "
                                 "ResistiveLoad (the rest of the loop: leads, specimen)")
            closed = self.wiring.wiring_resistance + self.load.load_resistance
            if self.source.compliance_voltage < self.source.current * closed:
                raise ValueError(
                    f"{name}.compliance_voltage = {self.source.compliance_voltage:g} V is below "
                    f"{name}.current x ({name}.wiring_resistance + {name}.load_resistance) = "
                    f"{self.source.current:g} A x {closed:g} ohm = {self.source.current * closed:g} V: the "
                    "supply could not drive the set current even through the closed contact"
                )
        check_range(name, "contact_capacitance", self.contact_capacitance, "F", 0.0, 1e-6)
        series_l = self.wiring.wiring_inductance + (self._load_inductance if self.flyback is None else 0.0)
        if self.contact_capacitance == 0.0 and series_l > 0.0 and self.snubber is None:
            raise ValueError(
                f"{name}.contact_capacitance = 0 F with {series_l!r} H in series with the contact and no snubber: "
                "opening the contact would stop an inductor current in zero time (ngspice aborts, 'timestep too "
                "small'); give the contact's stray capacitance (> 0 F, default 1e-10 F) or a snubber"
            )
        check_range(name, "leakage_conductance", self.leakage_conductance, "S", 0.0, 1e-3)
        check_current_factor(type(self).__name__, self.contact_current_factor)
        if not isinstance(self.title, str) or "\n" in self.title:
            raise ValueError(f"SwitchCircuit.title = {self.title!r}: must be a one-line string")

    def _check_own_keys(self) -> None:
        """A subclass's own keys, checked before the checks here read them."""

    @property
    def _inductive_load(self) -> bool:
        """Whether a flyback diode has an inductive load to go across."""
        return isinstance(self.load, InductiveLoad)

    @property
    def _flyback_refusal(self) -> str:
        return (f"{self.SECTION}.flyback is set but load is {type(self.load).__name__}: "
                "a flyback diode belongs across an InductiveLoad")

    @property
    def _load_inductance(self) -> float:
        """H: the largest load inductance in series with a contact."""
        return float(self.load.load_inductance) if isinstance(self.load, InductiveLoad) else 0.0

    def _place_flyback(self, c: Circuit, node: str, name: str = "flyback") -> None:
        """The flyback diode from ground to ``node`` (the load's top), its model once."""
        d = self.flyback
        c.D(name, c.gnd, node, model="switchsim_flyback")
        if "switchsim_flyback" not in c.model_names:
            c.model("switchsim_flyback", "D", IS=float(d.saturation_current), N=float(d.emission_coefficient),
                    RS=float(d.series_resistance))

    @property
    def contacts(self) -> tuple[ContactBlock, ...]:
        """The circuit's one contact, as a block (unnamed: its elements keep their names)."""
        return (ContactBlock("", NODE_A, NODE_B, self.leakage_conductance, self.contact_current_factor, self.arc),)

    @property
    def coils(self) -> tuple[CoilBlock, ...]:
        """The relay's own coil, when the circuit drives it (``coil``)."""
        return () if self.coil is None else (self.coil.coil,)

    @property
    def probes(self) -> Probes:
        return Probes(self.contacts, load_current=f"{LOAD_PROBE}#branch", coils=self.coils)

    def build(self) -> Circuit:
        """The PySpice circuit (``print`` it for the netlist)."""
        c = Circuit(self.title)
        gnd = c.gnd
        self._place_supply(c, NODE_A)
        self._place_switch(c)
        c.V(LOAD_PROBE[1:], NODE_B, "load", 0)
        load = self.load
        if isinstance(load, ResistiveLoad):
            c.R("load", "load", gnd, float(load.load_resistance))
        elif isinstance(load, InductiveLoad):
            c.R("load", "load", "load_l", float(load.load_resistance))
            c.L("load", "load_l", gnd, float(load.load_inductance))
        else:
            c.R("load", "load", "load_c", float(load.load_resistance))
            c.C("load", "load_c", gnd, float(load.load_capacitance))
            c.R("bleed", "load_c", gnd, float(load.bleed_resistance))
        if self.flyback is not None:
            self._place_flyback(c, NODE_B)
        if self.coil is not None:
            self.coil.add_to(c)
        return c

    def _place_supply(self, c: Circuit, end: str, probe: str | None = None) -> None:
        """The source and the wiring in series, from the supply to node ``end``; with ``probe``
        (a voltage source's name), a 0 V probe of the supply's current right at the source."""
        gnd = c.gnd
        source = self.source
        if isinstance(source, CurrentSource):
            c.I("source", gnd, "src", float(source.current))
            c.R("source_out", "src", gnd, float(source.output_resistance))
            c.C("source_out", "src", gnd, float(source.output_capacitance))
            c.D("clamp", "src", "clamp", model=CLAMP_MODEL, temperature=CLAMP_TEMPERATURE)
            c.model(CLAMP_MODEL, "D", IS=CLAMP_SATURATION_CURRENT, N=1.0, RS=0.0)
            c.V("clamp", "clamp", gnd, float(source.clamp_source_voltage))
            r_source = 0.0
        else:
            c.V("source", "src", gnd, source.spice_value())
            r_source = source.source_resistance
        series = [
            (kind, name, value)
            for kind, name, value in (
                ("R", "source", r_source),
                ("R", "wire", self.wiring.wiring_resistance),
                ("L", "wire", self.wiring.wiring_inductance),
            )
            if value > 0
        ]
        if not series:
            # ngspice rejects a 0 ohm resistor; a 0 V source keeps the node names.
            series = [("V", "wire_short", 0.0)]
        inner_nodes = iter(("wire", "wire_l"))
        node = "src"
        if probe is not None:
            c.V(probe[1:], node, SUPPLY_NODE, 0)
            node = SUPPLY_NODE
        for i, (kind, name, value) in enumerate(series):
            next_node = end if i == len(series) - 1 else next(inner_nodes)
            getattr(c, kind)(name, node, next_node, float(value))
            node = next_node

    def _place_switch(self, c: Circuit) -> None:
        """What sits between NODE_A and NODE_B: the contact, its capacitance, the snubber, the arc."""
        add_contact(c, NODE_A, NODE_B, self.leakage_conductance, self.contact_current_factor)
        if self.contact_capacitance > 0:
            c.C("contact", NODE_A, NODE_B, float(self.contact_capacitance))
        if self.snubber is not None:
            c.R("snubber", NODE_A, "snubber", float(self.snubber.resistance))
            c.C("snubber", "snubber", NODE_B, float(self.snubber.capacitance))
        if self.arc is not None:
            add_arc(c, self.arc, NODE_A, NODE_B)
