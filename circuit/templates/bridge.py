"""A double-break bridge: two contacts in series in one loop (``BridgeCircuit``)."""

from __future__ import annotations

from dataclasses import dataclass, replace

from PySpice.Spice.Netlist import Circuit

from ..arc import add_arc
from ..blocks import ContactBlock
from ..contact import add_contact
from ..names import check_block_name
from ..validation import check_range, internal, scene_key
from .loads import InductiveLoad, ResistiveLoad
from .switch import NODE_A, NODE_B, SwitchCircuit


BRIDGE_NODE = "bridge"  # the moving bridge itself, between its two contacts


@dataclass(frozen=True)
class BridgeCircuit(SwitchCircuit):
    """A ``SwitchCircuit`` whose switch is a double-break bridge: two contacts in series in
    the one loop, the moving bridge between them (SI units)::

        ... Lwire -- contact_a =CONTACT_<n0>= bridge =CONTACT_<n1>= contact_b --Vload-- load ...
                   |--Ccontact_<n0>--|      |--Ccontact_<n1>--|    (each contact's stray capacitance)
                   |--arc path <n0>--|      |--arc path <n1>--|    (each its own arc, optional)
                   |--Rsnubber--snubber--Csnubber-------------|    (optional, across the whole bridge)

    contact_names: the two contacts' names, in the loop's order from the supply (each a
        block name, circuit.names: the coupled scene gives its two electrical [[fixed]]
        contacts' names); each is its own ``ContactBlock`` with its own conductance and gap
        inputs, arc and result columns (``contact_voltage_<name>``, ...).
    contact_capacitance: F, across each contact (not across the bridge: in series two
        such give half of it across the whole).
    load_inductance: H, the load's inductance in series with its resistance (0: resistive; a
        contactor's motor or coil, AC-3/DC-3 duty): Lload below Rload (node ``load_l``), as
        an ``InductiveLoad``'s; ``flyback`` is then a diode from ground to ``contact_b``,
        across the load and its probe (as the one-contact template's: below the probe, the
        probe's nA open current would come out of a node where the diode carries amperes).
    Every other field is SwitchCircuit's; the arc model (``arc``) is each contact's, so at
    a break the two arcs in series hold twice its burning voltage and share the inductor's
    energy.
    """

    contact_names: tuple = internal(("a", "b"))  # the scene's two electrical [[fixed]] contacts
    load_inductance: float = scene_key(
        0.0, unit="H", doc="bridge: the load's inductance, in series with `load_resistance` (0: resistive)")

    def __post_init__(self) -> None:
        super().__post_init__()
        names = self.contact_names
        if not isinstance(names, (tuple, list)) or len(names) != 2:
            raise ValueError(f"BridgeCircuit.contact_names = {names!r}: the bridge's two contacts, two names")
        for name in names:
            check_block_name("BridgeCircuit.contact_names", name)
            if not name:
                raise ValueError("BridgeCircuit.contact_names: each of the bridge's contacts is named")
        if names[0].lower() == names[1].lower():
            raise ValueError(f"BridgeCircuit.contact_names = {tuple(names)!r}: two distinct names (SPICE ignores case)")
        object.__setattr__(self, "contact_names", tuple(names))

    def _check_own_keys(self) -> None:
        # (before SwitchCircuit's checks read the load's inductance)
        check_range(self.SECTION, "load_inductance", self.load_inductance, "H", 0.0, 100.0)
        if self.load_inductance > 0.0 and not isinstance(self.load, ResistiveLoad):
            raise ValueError(f"{self.SECTION}.load_inductance = {self.load_inductance!r} with a "
                             f"{type(self.load).__name__}: the bridge's load_inductance goes in series with a "
                             "ResistiveLoad (or give the InductiveLoad alone)")

    @property
    def _inductive_load(self) -> bool:
        return self.load_inductance > 0.0 or isinstance(self.load, InductiveLoad)

    @property
    def _flyback_refusal(self) -> str:
        return (f"{self.SECTION}.flyback is set but the bridge's load is resistive (load_inductance = "
                f"{self.load_inductance!r}): a flyback diode belongs across an inductive load")

    @property
    def _load_inductance(self) -> float:
        return float(self.load_inductance) if self.load_inductance > 0.0 else super()._load_inductance

    def build(self) -> Circuit:
        if self.load_inductance > 0.0:  # the one-contact template's R-L load, the same netlist
            load = InductiveLoad(self.load.load_resistance, self.load_inductance)
            return replace(self, load=load, load_inductance=0.0).build()
        return super().build()

    #: how the contacts are arranged in the loop: the current flows only while both are closed
    arrangement = "series"

    @property
    def contacts(self) -> tuple[ContactBlock, ...]:
        """The bridge's two contacts, in the loop's order."""
        (n0, n1), args = self.contact_names, (self.leakage_conductance, self.contact_current_factor, self.arc)
        return (ContactBlock(n0, NODE_A, BRIDGE_NODE, *args), ContactBlock(n1, BRIDGE_NODE, NODE_B, *args))

    def _place_switch(self, c: Circuit) -> None:
        for block in self.contacts:
            add_contact(c, block.node_a, block.node_b, self.leakage_conductance, self.contact_current_factor,
                        block.name)
            if self.contact_capacitance > 0:
                c.C(block.element("Ccontact")[1:], block.node_a, block.node_b, float(self.contact_capacitance))
            if self.arc is not None:
                add_arc(c, self.arc, block.node_a, block.node_b, block.name)
        if self.snubber is not None:
            c.R("snubber", NODE_A, "snubber", float(self.snubber.resistance))
            c.C("snubber", "snubber", NODE_B, float(self.snubber.capacitance))
