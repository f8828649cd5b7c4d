"""Circuit blocks: a contact (with its arc), placed in a circuit any number of times.

A block knows its name, its nodes and its constants, places its elements on a PySpice
circuit, and names its input channels (the EXTERNAL sources Python drives) and its
probes (the ngspice vectors its result columns come from). Templates and netlists list
their blocks; the deck, the stepper and the probes work from that list.
"""

from __future__ import annotations

from dataclasses import dataclass

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
    """

    name: str
    node_a: str
    node_b: str
    leakage_conductance: float = DEFAULT_LEAKAGE
    current_factor: str | None = None
    arc: ArcModel | None = None

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


