"""Circuit blocks: a contact (with its arc) and a coil, each placed in a circuit any number of times.

A block knows its name, its nodes and its constants, places its elements on a PySpice
circuit, and names its input channels (the EXTERNAL sources Python drives) and its
probes (the ngspice vectors its result columns come from). Templates and netlists list
their blocks; the deck, the stepper and the probes work from that list.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import ClassVar

from PySpice.Spice.Netlist import Circuit

from .arc import GAP_NODE, GAP_SOURCE, SENSE_SOURCE as ARC_SENSE, STATE_NODE, STATE_SOURCE, ArcModel, add_arc
from .contact import (
    CONDUCTANCE_NODE, CONDUCTANCE_SOURCE, DEFAULT_LEAKAGE, EFFECTIVE_NODE, SENSE_SOURCE, add_contact,
    check_current_factor,
)
from .names import check_block_name, named
from .validation import check_range


@dataclass(frozen=True)
class ContactBlock:
    """One electrical contact of a circuit, as a block: its name, where it sits, its element's
    constants and its arc. A circuit holds any number of them, each with its own
    conductance and gap inputs, arc state and probes (SI units).

    name: "" for a circuit's one contact (elements and nodes named as they always were:
        Vcontact, contact_g, Varc, ...), else letters and digits ("no", "nc", "a"): the
        elements and nodes then carry it (Vcontact_no, contact_no_g, Varc_no, ...), the
        result columns a suffix (contact_voltage_no, ...).
    node_a, node_b: the contact's nodes; its voltage is V(node_a) - V(node_b).
    leakage_conductance: S, the open contact's conductance.
    current_factor: optional ngspice expression g(I) of the contact current I (A).
    arc: optional ArcModel of the opening gap (circuit.arc).
    load_probe: optional name of a 0 V voltage source in series with this contact's own load
        (a changeover's throw: ``Vload_no``); its branch current is the contact's load current,
        result column ``load_current_<name>`` (A). Only a named contact has one: the circuit's
        ``load_current`` is the supply's, through every contact.
    """

    name: str
    node_a: str
    node_b: str
    leakage_conductance: float = DEFAULT_LEAKAGE
    current_factor: str | None = None
    arc: ArcModel | None = None
    load_probe: str | None = None

    def __post_init__(self) -> None:
        check_block_name("ContactBlock.name", self.name)
        for node in ("node_a", "node_b"):
            value = getattr(self, node)
            if not (isinstance(value, str) and value and value.split() == [value]):
                raise ValueError(f"ContactBlock.{node} = {value!r}: a node name (one word)")
        check_range("ContactBlock", "leakage_conductance", self.leakage_conductance, "S", 0.0, 1e-3)
        check_current_factor("ContactBlock", self.current_factor)
        if self.arc is not None and not isinstance(self.arc, ArcModel):
            raise ValueError(f"ContactBlock.arc = {self.arc!r}: must be an ArcModel or None")
        if self.load_probe is not None and not (
                self.name and isinstance(self.load_probe, str) and self.load_probe[:1] in "vV"
                and self.load_probe.split() == [self.load_probe] and len(self.load_probe) > 1):
            raise ValueError(f"ContactBlock.load_probe = {self.load_probe!r}: the name of a voltage source "
                             "(V..., one word), on a named contact only")

    @property
    def suffix(self) -> str:
        """What this contact's result columns carry after their name ("" or "_<name>")."""
        return f"_{self.name}" if self.name else ""

    @property
    def label(self) -> str:
        """The contact as its input and output channels name it: "contact" or "contact_<name>"."""
        return "contact" + self.suffix

    def element(self, base: str) -> str:
        """The name in the netlist of this contact's element or node ``base`` (e.g. Vcontact_g)."""
        return named(base, self.name)

    @property
    def conductance_node(self) -> str:
        """Node whose voltage is the conductance the element conducts with (G(t), or G(t)/g(I))."""
        return self.element(CONDUCTANCE_NODE if self.current_factor is None else EFFECTIVE_NODE)

    @property
    def current_vector(self) -> str:
        """ngspice vector of the metallic contact current (A, a to b)."""
        return f"{self.element(SENSE_SOURCE)}#branch"

    @property
    def arc_current_vector(self) -> str | None:
        """ngspice vector of the arc path's current (A, a to b), None without an arc."""
        return None if self.arc is None else f"{self.element(ARC_SENSE)}#branch"

    @property
    def load_vector(self) -> str | None:
        """ngspice vector of this contact's own load current (A), None without ``load_probe``."""
        return None if self.load_probe is None else f"{self.load_probe.lower()}#branch"

    @property
    def conductance_source(self) -> str:
        """The EXTERNAL source that gives G(t) (S, as its voltage)."""
        return self.element(CONDUCTANCE_SOURCE)

    @property
    def gap_source(self) -> str | None:
        """The EXTERNAL source that gives the gap d(t) (m, as its voltage), if the arc needs it."""
        return self.element(GAP_SOURCE) if self.arc is not None and self.arc.uses_gap else None

    @property
    def state_source(self) -> str | None:
        """The EXTERNAL current source that carries the arc's state, None without an arc."""
        return None if self.arc is None else self.element(STATE_SOURCE)

    @property
    def inputs(self) -> dict[str, str]:
        """Input channel name -> the EXTERNAL source behind it: "<label>.conductance" (S) and,
        when the arc depends on it, "<label>.gap" (m)."""
        out = {f"{self.label}.conductance": self.conductance_source}
        if self.gap_source is not None:
            out[f"{self.label}.gap"] = self.gap_source
        return out

    def add_to(self, circuit: Circuit) -> None:
        """Place the contact (and its arc path) on a PySpice circuit."""
        add_contact(circuit, self.node_a, self.node_b, self.leakage_conductance, self.current_factor, self.name)
        if self.arc is not None:
            add_arc(circuit, self.arc, self.node_a, self.node_b, self.name)




#: The coil's elements and nodes (the unnamed coil's; a named one carries its name).
# (an "x" in every name, as in the netlist's XCOIL line: a user's own Rcoil or Lcoil keeps its name)
COIL_SENSE = "Vxcoil"
COIL_PSI_NODE = "xcoil_psi"
COIL_GAP_SOURCE = "Vxcoil_gap"
COIL_GAP_NODE = "xcoil_gap"
COILS_PLACED = "_switchsim_coils"  # where CoilBlock.add_to records itself on a PySpice Circuit
COIL_PSI_LEAK = 1e12  # ohm across the flux node: a DC path for the operating point (decay time 1e12 s)
_PSI_TOKEN = re.compile(r"\bPSI\b")
_GAP_TOKEN = re.compile(r"\bGAP\b")


def check_coil_current(where: str, expression) -> str:
    """A coil's current law: a one-line ngspice expression of PSI (Wb) and GAP (m)."""
    if not isinstance(expression, str) or not expression.strip() or "\n" in expression:
        raise ValueError(f"{where} = {expression!r}: must be a one-line ngspice expression of the flux linkage PSI "
                         "(Wb) and the working air gap GAP (m), e.g. 'PSI*GAP/(4e-7*pi*1000^2*1e-4)'")
    if expression.count("(") != expression.count(")"):
        raise ValueError(f"{where} = {expression!r}: unbalanced parentheses")
    if not _PSI_TOKEN.search(expression):
        raise ValueError(f"{where} = {expression!r}: the coil current must depend on the flux linkage PSI")
    return expression


@dataclass(frozen=True)
class CoilBlock:
    """The coil of an electromagnet, in flux form (SI units).

    The flux linkage psi (Wb) is a circuit state: node ``xcoil_psi`` carries it as a
    voltage across 1 F, charged by the coil's inductive voltage v_L = d(psi)/dt; the
    coil current is an explicit function i(psi, g) of the flux linkage and the magnet's
    working air gap g (m), which Python gives as the input channel "<label>.gap"::

        Vxcoil     p xcoil_s 0                        (0 V: coil current probe, A from p to n)
        Rxcoil     xcoil_s xcoil_e R                  (copper)
        Bxcoil     xcoil_e n  I=i(V(xcoil_psi), V(xcoil_gap))
        Bxcoil_psi 0 xcoil_psi I=V(xcoil_e,n)         (d psi/dt = v_L)
        Cxcoil_psi xcoil_psi 0 1
        Rxcoil_psi xcoil_psi 0 1e12                   (a DC path: the operating point)
        Vxcoil_gap xcoil_gap 0 external               (g(t) in volts = metres)

    So the coil voltage is R i + d(psi)/dt, the back-EMF of a moving armature included
    (d(psi)/dt = (d psi/d i) di/dt + (d psi/d g) dg/dt), and the magnet's energy balance
    is the circuit's own. The magnet (coupling.laws.magnet) gives the expression.

    name: "" for a circuit's one coil, else letters and digits (elements Vxcoil_<name>, ...).
    node_p, node_n: the coil's terminals; its voltage is V(node_p) - V(node_n).
    resistance: ohm, the winding's copper resistance.
    current: the current law, an ngspice expression of PSI (Wb) and GAP (m), in A.
    """

    SECTION: ClassVar[str] = "coil"  # resistance is [coil] resistance: errors name coil.resistance, coil.current
    name: str
    node_p: str
    node_n: str
    resistance: float
    current: str

    def __post_init__(self) -> None:
        check_block_name(f"{self.SECTION}.name", self.name)
        for node in ("node_p", "node_n"):
            value = getattr(self, node)
            if not (isinstance(value, str) and value and value.split() == [value]):
                raise ValueError(f"{self.SECTION}.{node} = {value!r}: a node name (one word)")
        check_range(self.SECTION, "resistance", self.resistance, "ohm", 0.0, 1e7, low_open=True)
        check_coil_current(f"{self.SECTION}.current", self.current)

    @property
    def suffix(self) -> str:
        """What this coil's result columns carry after their name ("" or "_<name>")."""
        return f"_{self.name}" if self.name else ""

    @property
    def label(self) -> str:
        """The coil as its channels name it: "coil" or "coil_<name>"."""
        return "coil" + self.suffix

    def element(self, base: str) -> str:
        return named(base, self.name)

    @property
    def current_vector(self) -> str:
        return f"{self.element(COIL_SENSE)}#branch"

    @property
    def flux_node(self) -> str:
        return self.element(COIL_PSI_NODE)

    @property
    def gap_source(self) -> str:
        return self.element(COIL_GAP_SOURCE)

    @property
    def inputs(self) -> dict[str, str]:
        """Input channel -> source: "<label>.gap" (m), the magnet's working air gap."""
        return {f"{self.label}.gap": self.gap_source}

    def add_to(self, circuit: Circuit) -> None:
        """Place the coil on a PySpice circuit."""
        e = self.element
        sense_node, inner, psi, gap = e("xcoil_s"), e("xcoil_e"), e(COIL_PSI_NODE), e(COIL_GAP_NODE)
        law = _GAP_TOKEN.sub(f"V({gap})", _PSI_TOKEN.sub(f"V({psi})", self.current))
        circuit.V(e(COIL_SENSE)[1:], self.node_p, sense_node, 0)
        circuit.R(e("Rxcoil")[1:], sense_node, inner, float(self.resistance))
        circuit.B(e("Bxcoil")[1:], inner, self.node_n, current_expression=law)
        circuit.B(e("Bxcoil_psi")[1:], circuit.gnd, psi, current_expression=f"V({inner},{self.node_n})")
        circuit.C(e("Cxcoil_psi")[1:], psi, circuit.gnd, 1)
        circuit.R(e("Rxcoil_psi")[1:], psi, circuit.gnd, COIL_PSI_LEAK)
        # No value after 'external' (a value segfaults ngspice 38-40 on V sources).
        circuit.V(e(COIL_GAP_SOURCE)[1:], gap, circuit.gnd, "external")
        setattr(circuit, COILS_PLACED, getattr(circuit, COILS_PLACED, ()) + (self,))
