"""The deck ngspice reads: circuit netlist + how each input channel is driven + analysis lines."""

from __future__ import annotations

from typing import TYPE_CHECKING, Mapping, Union

import numpy as np
from PySpice.Spice.Netlist import Circuit

from .arc import ArcState, recorded_arc
from .blocks import COILS_PLACED, ContactBlock
from .coil_drive import CoilDrive
from .contact import placed_contacts
from .options import SimulationOptions
from .probes import Probes
from .validation import check_range

if TYPE_CHECKING:
    from .netlist import NetlistCircuit
    from .templates import McuInput, SwitchCircuit

# (named, not imported: a run whose circuit is a coil drive never loads them, circuit/__init__.py)
CircuitLike = Union["SwitchCircuit", CoilDrive, "McuInput", "NetlistCircuit", Circuit]

#: Drive of an input channel's source: "external" (a Python function of time, through
#: ngspice's callback) or PWL vertices (times s, values in the channel's unit, >= 0).
Drive = Union[str, tuple[np.ndarray, np.ndarray]]


def circuit_netlist(circuit: CircuitLike) -> tuple[str, Probes]:
    """Netlist text (title line first, no analysis, no .end) and its probes."""
    if isinstance(circuit, CoilDrive):
        return str(circuit.build()), circuit.probes
    # (imported here, not at the top: a coil drive's run never loads them, circuit/__init__.py;
    # a circuit of theirs has imported its module already, and a template's run does not
    # load the netlist reader, nor the template families it does not use: loaded)
    from .templates import loaded

    if isinstance(circuit, loaded("SwitchCircuit", "McuInput")):
        return str(circuit.build()), circuit.probes
    from .netlist import NetlistCircuit

    if isinstance(circuit, NetlistCircuit):
        return circuit.netlist(), circuit.probes
    if isinstance(circuit, Circuit):
        from .templates import LOAD_PROBE

        return str(circuit), Probes(_pyspice_contacts(circuit), load_current=(
            f"{LOAD_PROBE}#branch" if LOAD_PROBE.lower() in {n.lower() for n in circuit.element_names} else None),
            coils=tuple(getattr(circuit, COILS_PLACED, ())))
    raise TypeError(
        f"expected a SwitchCircuit, an McuInput, a CoilDrive, a NetlistCircuit or a PySpice Circuit with a contact, "
        f"got {type(circuit).__name__}"
    )


def _pyspice_contacts(circuit: Circuit) -> tuple[ContactBlock, ...]:
    """The contacts ``add_contact`` placed on a PySpice circuit (with the arcs ``add_arc`` gave them)."""
    placed = placed_contacts(circuit)
    if not placed:
        raise ValueError(
            "the PySpice circuit has no contact: add it with circuit.add_contact(circuit, node_a, node_b)"
        )
    names = {n.lower() for n in circuit.element_names}
    blocks = []
    for name, (node_a, node_b, leakage, factor) in placed.items():
        block = ContactBlock(name, node_a, node_b, leakage, factor, recorded_arc(circuit, name))
        if block.arc is None and block.element("Varc").lower() in names:
            raise ValueError(f"the PySpice circuit has an element {block.element('Varc')} but no arc model: "
                             "add the arc with add_arc")
        blocks.append(block)
    return tuple(blocks)


def arc_states(probes: Probes) -> dict[str, ArcState]:
    """The state machine of each contact's arc (decided at accepted points), keyed by the
    EXTERNAL current source that carries it."""
    return {c.state_source.lower(): ArcState(c.arc, c.arc_current_vector, c.node_a, c.node_b,
                                             c.element("contact_g"), c.element("arc_gap"),
                                             conductance_source=c.conductance_source, gap_source=c.gap_source)
            for c in probes.contacts if c.arc is not None}


def input_sources(probes: Probes) -> dict[str, str]:
    """Every input channel of the circuit -> the EXTERNAL source behind it."""
    out: dict[str, str] = {}
    for block in probes.contacts + probes.coils:
        out.update(block.inputs)
    return out


def build_deck(
    circuit: CircuitLike, t_end: float, options: SimulationOptions, drives: Mapping[str, Drive] | None = None,
) -> tuple[list[str], Probes]:
    """Deck lines for a transient 0..t_end (s), each input channel's source driven as
    ``drives`` says (channel name -> "external" or PWL vertices; default "external")."""
    check_range("transient", "t_end", t_end, "s", 0.0, 1e3, low_open=True)
    text, probes = circuit_netlist(circuit)
    sources = input_sources(probes)
    drives = dict(drives or {})
    unknown = sorted(set(drives) - set(sources))
    if unknown:
        raise ValueError(f"drives for {', '.join(unknown)}: the circuit's input channels are {', '.join(sources)}")
    by_source = {source.lower(): (channel, source) for channel, source in sources.items()}
    states = {c.state_source.lower() for c in probes.contacts if c.state_source}
    lines = [line for line in text.splitlines() if line.strip()]
    replaced = set()
    for i, line in enumerate(lines):
        tokens = line.split()
        if not tokens or i == 0:
            continue
        head = tokens[0].lower()
        if head in by_source:
            channel, source = by_source[head]
            # (the one unnamed contact's inputs keep their plain words in messages)
            what = channel.split(".", 1)[1] if channel.startswith("contact.") else channel
            lines[i] = "\n".join(_source_lines(drives.get(channel, "external"), f"{source} {tokens[1]} {tokens[2]}",
                                               what))
            replaced.add(head)
        elif head[0] in "vi" and head not in states and "external" in (t.lower() for t in tokens[3:]):
            raise ValueError(
                f"netlist line {line!r}: only a contact's conductance source (and the arc state and gap) and a coil's "
                "gap may be EXTERNAL"
            )
        elif head == ".end":
            lines[i] = ""
    missing = sorted(channel for source, (channel, _) in by_source.items() if source not in replaced)
    if missing:
        raise ValueError(f"the netlist has no source for the input channel(s) {', '.join(missing)}")
    lines = [part for line in lines if line for part in line.split("\n")]
    lines += options.deck_lines(t_end)
    lines.append(".end")
    return lines, probes


def _source_lines(drive: Drive, head: str, what: str) -> list[str]:
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
