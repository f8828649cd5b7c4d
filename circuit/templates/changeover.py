"""A changeover (form C): the moving contact between a normally-open and a normally-closed
(``ChangeoverCircuit``)."""

from __future__ import annotations

from dataclasses import dataclass

from PySpice.Spice.Netlist import Circuit

from ..arc import add_arc
from ..blocks import ContactBlock
from ..contact import add_contact
from ..names import check_block_name
from ..validation import check_range, internal, scene_key
from .loads import ResistiveLoad
from .sources import CurrentSource
from .switch import LOAD_PROBE, NODE_A, SwitchCircuit


@dataclass(frozen=True)
class ChangeoverCircuit(SwitchCircuit):
    """A ``SwitchCircuit`` whose switch is a changeover (form C): the supply feeds the moving
    contact (the common), which connects it to the normally-open (NO) or the normally-closed
    (NC) fixed contact, each throw with its own resistive load to ground, as a relay's form C
    contact is wired and tested (SI units)::

        Vsource src 0; src --Vload-- supply --Rsource-- ... Lwire -- contact_a =CONTACT_<no>= throw_<no> --Vload_<no>-- load_<no> --Rload_<no>-- [load_<no>_l --Lload_<no>--] 0
                                                                   |       =CONTACT_<nc>= throw_<nc> --Vload_<nc>-- load_<nc> --Rload_<nc>-- [load_<nc>_l --Lload_<nc>--] 0
        (an inductive throw: Lload_<n> below its resistor, the flyback Dflyback_<n> from 0 to throw_<n>)
        across each contact: Ccontact_<n>, its arc path, the snubber (Rsnubber_<n>, Csnubber_<n>) when given

    contact_names: (NO's name, NC's name): each contact a block name (circuit.names; the
        coupled scene gives its two electrical [[fixed]] contacts named NO and NC, as
        written), each its own ``ContactBlock`` with its own conductance and gap inputs, arc
        and result columns (``contact_voltage_<name>``, ...). NO is the first contact.
    load: NO's load, a ResistiveLoad (ohm).
    nc_load_resistance: ohm, NC's load; None: the same as NO's.
    load_inductance: H, NO's load inductance in series with its resistance (0: resistive;
        a valve or motor winding, a contactor's coil).
    nc_load_inductance: H, NC's; None: the same as NO's.
    flyback: a diode across each inductive throw's load (``FlybackDiode``), or None; only
        with an inductive throw.
    contact_capacitance: F, across each contact; the snubber, when given, across each too.
    The load probe ``Vload`` sits at the source (in series with the supply, the wiring
    ending on the common, contact_a): ``load_current`` is the supply's current through the
    moving contact, NO's and NC's together; each throw's own load current
    is ``i(Vload_<name>)`` (a probe). Every other field is SwitchCircuit's; the arc model is
    each contact's. Both throws open: the supply sees only the contacts' leakage and stray
    capacitance.
    """

    contact_names: tuple = internal(("NO", "NC"))  # the scene's electrical [[fixed]] contacts NO and NC
    nc_load_resistance: float | None = scene_key(
        None, unit="ohm", doc="changeover: NC's load (> 0); omitted: the same as `load_resistance`")
    load_inductance: float = scene_key(
        0.0, unit="H", doc="changeover: NO's load inductance, in series with `load_resistance` (0: resistive)")
    nc_load_inductance: float | None = scene_key(
        None, unit="H", doc="changeover: NC's load inductance (0: resistive); omitted: the same as `load_inductance`")

    #: how the contacts are arranged: each in its own branch, each closed while it touches
    arrangement = "changeover"

    def __post_init__(self) -> None:
        super().__post_init__()
        name = "ChangeoverCircuit"
        names = self.contact_names
        if not isinstance(names, (tuple, list)) or len(names) != 2:
            raise ValueError(f"{name}.contact_names = {names!r}: the changeover's two contacts, (NO, NC)")
        for n in names:
            check_block_name(f"{name}.contact_names", n)
            if not n:
                raise ValueError(f"{name}.contact_names: each of the changeover's contacts is named")
        if names[0].lower() == names[1].lower():
            raise ValueError(f"{name}.contact_names = {tuple(names)!r}: two distinct names (SPICE ignores case)")
        object.__setattr__(self, "contact_names", tuple(names))
        if not isinstance(self.load, ResistiveLoad):
            raise ValueError(f"{name}.load is {type(self.load).__name__}: a changeover's throws each drive a "
                             "ResistiveLoad")
        if isinstance(self.source, CurrentSource):
            raise ValueError(f"{name}.source is a CurrentSource: a changeover is fed by a voltage source (DCSource)")
        if self.nc_load_resistance is not None:
            check_range(self.SECTION, "nc_load_resistance", self.nc_load_resistance, "ohm", 0.0, 1e9, low_open=True)

    def _check_own_keys(self) -> None:
        # (the load inductances are checked before SwitchCircuit's checks read them)
        check_range(self.SECTION, "load_inductance", self.load_inductance, "H", 0.0, 100.0)
        if self.nc_load_inductance is not None:
            check_range(self.SECTION, "nc_load_inductance", self.nc_load_inductance, "H", 0.0, 100.0)

    @property
    def load_inductances(self) -> tuple[float, float]:
        """H: (NO's load inductance, NC's)."""
        nc = self.load_inductance if self.nc_load_inductance is None else self.nc_load_inductance
        return float(self.load_inductance), float(nc)

    @property
    def _inductive_load(self) -> bool:
        return any(x > 0.0 for x in self.load_inductances)

    @property
    def _flyback_refusal(self) -> str:
        return (f"{self.SECTION}.flyback is set but both throws are resistive (load_inductance = "
                f"{self.load_inductance!r}, nc_load_inductance = {self.nc_load_inductance!r}): a flyback diode belongs "
                "across an inductive load")

    @property
    def _load_inductance(self) -> float:
        return max(self.load_inductances)

    @property
    def load_resistances(self) -> tuple[float, float]:
        """ohm: (NO's load, NC's load)."""
        nc = self.load.load_resistance if self.nc_load_resistance is None else self.nc_load_resistance
        return float(self.load.load_resistance), float(nc)

    @property
    def contacts(self) -> tuple[ContactBlock, ...]:
        """(NO, NC): each from the common to its throw."""
        args = (self.leakage_conductance, self.contact_current_factor, self.arc)
        # each throw's own load current (its probe Vload_<name>, build): its mu(I), its columns
        return tuple(ContactBlock(n, NODE_A, f"throw_{n.lower()}", *args, load_probe=f"Vload_{n.lower()}")
                     for n in self.contact_names)

    def build(self) -> Circuit:
        c = Circuit(self.title)
        gnd = c.gnd
        # The load probe sits at the source, not between the wiring and the common: there the
        # node between it and Lwire carried no conductance, only the two branch currents, and
        # in the pivot order ngspice fixes at the first time point (it reorders only at an
        # exactly zero pivot) the factors grew at the femtosecond steps of a make (Lwire's L/h
        # 1e9 ohm): an entry of 3.8e15, the probe's 0 V violated by up to 32 mV, Newton's test
        # failed at node "common" and a 5 V make at RELTOL 1e-6 aborted (docs/circuit.md,
        # section 7). The wiring now ends on the common, as in the one-contact template.
        self._place_supply(c, NODE_A, probe=LOAD_PROBE)
        for block, resistance, inductance in zip(self.contacts, self.load_resistances, self.load_inductances):
            add_contact(c, block.node_a, block.node_b, self.leakage_conductance, self.contact_current_factor,
                        block.name)
            n = block.name.lower()
            if self.contact_capacitance > 0:
                c.C(block.element("Ccontact")[1:], block.node_a, block.node_b, float(self.contact_capacitance))
            if self.snubber is not None:
                c.R(f"snubber_{n}", block.node_a, f"snubber_{n}", float(self.snubber.resistance))
                c.C(f"snubber_{n}", f"snubber_{n}", block.node_b, float(self.snubber.capacitance))
            if self.arc is not None:
                add_arc(c, self.arc, block.node_a, block.node_b, block.name)
            c.V(f"load_{n}", block.node_b, f"load_{n}", 0)
            if inductance > 0.0:
                c.R(f"load_{n}", f"load_{n}", f"load_{n}_l", resistance)
                c.L(f"load_{n}", f"load_{n}_l", gnd, inductance)
                if self.flyback is not None:
                    # across the load and its probe (as the one-contact template's): below the
                    # probe, the probe's branch current, a few nA, came out of the KCL of a node
                    # where the diode carries amperes, and its Newton noise (~1e-7 A) never met
                    # ABSTOL: "timestep too small" at the freewheeling throw's break
                    self._place_flyback(c, block.node_b, f"flyback_{n}")
            else:
                c.R(f"load_{n}", f"load_{n}", gnd, resistance)
        if self.coil is not None:
            self.coil.add_to(c)
        return c
