"""The deck ngspice reads: circuit netlist + how the contact conductance is driven + analysis lines."""

from __future__ import annotations

from typing import Union

import numpy as np
from PySpice.Spice.Netlist import Circuit

from .arc import GAP_NODE, GAP_SOURCE, STATE_SOURCE, ArcModel, ArcState, recorded_arc
from .contact import CONDUCTANCE_NODE, CONDUCTANCE_SOURCE, SENSE_SOURCE
from .netlist import NetlistCircuit
from .options import SimulationOptions
from .probes import Probes
from .templates import LOAD_PROBE, NODE_A, NODE_B, SwitchCircuit
from .validation import check_range

CircuitLike = Union[SwitchCircuit, NetlistCircuit, Circuit]

#: Drive of the conductance source (or of the gap source): "external" (Python callback)
#: or PWL vertices (times s, values S or m).
Drive = Union[str, tuple[np.ndarray, np.ndarray]]


def circuit_netlist(circuit: CircuitLike) -> tuple[str, Probes]:
    """Netlist text (title line first, no analysis, no .end) and its probes."""
    if isinstance(circuit, SwitchCircuit):
        return str(circuit.build()), circuit.probes
    if isinstance(circuit, NetlistCircuit):
        return circuit.netlist(), circuit.probes
    if isinstance(circuit, Circuit):
        names = {name.lower() for name in circuit.element_names}
        if CONDUCTANCE_SOURCE.lower() not in names:
            raise ValueError(
                "the PySpice circuit has no contact: add it with circuit.add_contact(circuit, node_a, node_b)"
            )
        probes = Probes(
            node_a=_node_of(circuit, SENSE_SOURCE, 0),
            node_b=_node_of(circuit, "Bcontact", 1),
            contact_current=f"{SENSE_SOURCE}#branch",
            conductance_node=CONDUCTANCE_NODE,
            load_current=f"{LOAD_PROBE}#branch" if LOAD_PROBE.lower() in names else None,
            arc_current="Varc#branch" if "varc" in names else None,
        )
        return str(circuit), probes
    raise TypeError(
        f"expected a SwitchCircuit, a NetlistCircuit or a PySpice Circuit with a contact, got {type(circuit).__name__}"
    )


def circuit_arc(circuit: CircuitLike) -> ArcModel | None:
    """The circuit's ArcModel, or None without an arc path."""
    if isinstance(circuit, (SwitchCircuit, NetlistCircuit)):
        return circuit.arc
    arc = recorded_arc(circuit)
    if arc is None and "varc" in {name.lower() for name in circuit.element_names}:
        raise ValueError("the PySpice circuit has an element Varc but no arc model: add the arc with add_arc")
    return arc


def arc_state(circuit: CircuitLike, probes: Probes) -> ArcState | None:
    """The state machine of the circuit's arc (decided at accepted points), or None."""
    arc = circuit_arc(circuit)
    if arc is None:
        return None
    return ArcState(arc, probes.arc_current, probes.node_a, probes.node_b, CONDUCTANCE_NODE, GAP_NODE)


def _node_of(circuit: Circuit, element: str, index: int) -> str:
    for name in circuit.element_names:
        if name.lower() == element.lower():
            return str(circuit[name].nodes[index])
    return NODE_A if index == 0 else NODE_B


def build_deck(
    circuit: CircuitLike, t_end: float, options: SimulationOptions, drive: Drive = "external",
    gap_drive: Drive = "external",
) -> tuple[list[str], Probes]:
    """Deck lines for a transient 0..t_end (s), the conductance source driven by ``drive``
    and, with a gap-dependent arc model, the gap source by ``gap_drive``."""
    check_range("transient", "t_end", t_end, "s", 0.0, 1e3, low_open=True)
    text, probes = circuit_netlist(circuit)
    lines = [line for line in text.splitlines() if line.strip()]
    replaced = False
    for i, line in enumerate(lines):
        tokens = line.split()
        if not tokens or i == 0:
            continue
        head = tokens[0].lower()
        if head == CONDUCTANCE_SOURCE.lower():
            lines[i] = "\n".join(_source_lines(drive))
            replaced = True
        elif head == GAP_SOURCE.lower():
            lines[i] = "\n".join(_source_lines(gap_drive, f"{GAP_SOURCE} {GAP_NODE} 0", "gap"))
        elif head[0] in "vi" and head != STATE_SOURCE.lower() and "external" in (t.lower() for t in tokens[3:]):
            raise ValueError(
                f"netlist line {line!r}: only the contact's conductance source (and the arc state and gap) may be EXTERNAL"
            )
        elif head == ".end":
            lines[i] = ""
    if not replaced:
        raise ValueError(f"the netlist has no contact conductance source {CONDUCTANCE_SOURCE}")
    lines = [part for line in lines if line for part in line.split("\n")]
    lines += options.deck_lines(t_end)
    lines.append(".end")
    return lines, probes


def _source_lines(drive: Drive, head: str = f"{CONDUCTANCE_SOURCE} {CONDUCTANCE_NODE} 0",
                  what: str = "conductance") -> list[str]:
    if isinstance(drive, str):
        if drive != "external":
            raise ValueError(f"drive = {drive!r}: 'external' or PWL vertices")
        # No value after 'external': with one, ngspice 38-40 segfault.
        return [f"{head} external"]
    times, values = (np.asarray(a, dtype=float) for a in drive)
    if times.ndim != 1 or times.shape != values.shape or times.size < 2:
        raise ValueError(f"PWL {what}: times and values must be 1-D arrays of equal length >= 2")
    if not np.all(np.isfinite(times)) or np.any(np.diff(times) <= 0):
        raise ValueError(f"PWL {what}: times must be finite and increase strictly")
    if not np.all(np.isfinite(values)) or np.any(values < 0):
        bad = int(np.argmax(~np.isfinite(values) | (values < 0)))
        raise ValueError(f"PWL {what}: values must be finite and >= 0 (vertex {bad}: {values[bad]!r} at "
                         f"t = {times[bad]!r} s)")
    pairs = [f"{float(t)!r} {float(v)!r}" for t, v in zip(times, values)]
    # Continuation lines keep each physical line short for ngspice's reader.
    chunks = [" ".join(pairs[i : i + 8]) for i in range(0, len(pairs), 8)]
    return [f"{head} PWL({chunks[0]}"] + [f"+ {chunk}" for chunk in chunks[1:]] + ["+ )"]

