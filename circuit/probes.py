"""Which ngspice vectors hold the contact and load quantities, and how they become result columns."""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .blocks import CoilBlock, ContactBlock
from .names import GROUND

#: Result columns of a circuit with one unnamed contact, in order (SI: s, V, A, A, ohm, S, A).
COLUMNS = (
    "time",
    "contact_voltage",
    "contact_current",
    "load_current",
    "contact_resistance",
    "contact_conductance",
    "arc_current",
)
#: Per contact, its columns (each with the contact's suffix: "" or "_<name>").
CONTACT_COLUMNS = ("contact_voltage", "contact_current", "contact_resistance", "contact_conductance", "arc_current")
#: Per coil, its columns (SI: A, V, Wb; each with the coil's suffix).
COIL_COLUMNS = ("coil_current", "coil_voltage", "coil_flux_linkage")

CLOSED_CONDUCTANCE = 1e-6  # S: above it the contact voltage is I/G (see Probes._contact_voltage)
# the per-block result columns that are one ngspice vector as it stands: base name -> the
# block's attribute naming it (Probes.vector_of; an arc's is None without an arc model)
RAW_CONTACT_COLUMNS = {"contact_current": "current_vector", "contact_conductance": "conductance_node",
                       "arc_current": "arc_current_vector", "load_current": "load_vector"}
RAW_COIL_COLUMNS = {"coil_current": "current_vector", "coil_flux_linkage": "flux_node"}


@dataclass(frozen=True)
class Probes:
    """Which ngspice vectors hold each result column of a circuit.

    contacts: the circuit's contact blocks (circuit.blocks.ContactBlock); each gives the
        columns CONTACT_COLUMNS with its suffix ("" for the unnamed contact, "_<name>"):
        contact_voltage, V: I/G while the contact conducts, V(node_a) - V(node_b)
        otherwise (see _contact_voltage); contact_current: the metallic conduction only
        (A, positive from a to b; the arc and the parasitic capacitance are not in it);
        contact_conductance / contact_resistance: S / ohm the element conducts with
        (inf open); arc_current: the arc path's current, A (0 without an arc).
    load_current: branch vector of the load probe, A, or None (column of NaN).
    coils: the circuit's coil blocks (circuit.blocks.CoilBlock); each gives COIL_COLUMNS
        with its suffix: coil_current (A, into its first terminal), coil_voltage (V, across
        it), coil_flux_linkage (Wb).
    """

    contacts: tuple[ContactBlock, ...]
    load_current: str | None = None
    coils: tuple[CoilBlock, ...] = ()

    def __post_init__(self) -> None:
        names = [c.name for c in self.contacts]
        if len(set(names)) != len(names) or not (names or self.coils):
            raise ValueError(f"Probes.contacts: contacts with distinct names (or none, beside a coil), got {names!r}")

    @staticmethod
    def contact_columns(c: ContactBlock) -> tuple[str, ...]:
        """A contact's column base names: CONTACT_COLUMNS, and load_current where it has its
        own load probe (a changeover's throw)."""
        return CONTACT_COLUMNS + (("load_current",) if c.load_probe is not None else ())

    @property
    def column_names(self) -> tuple[str, ...]:
        """Every result column, in order: COLUMNS for one unnamed contact; else time,
        load_current, then each contact's columns with its suffix (``contact_columns``)."""
        coils = tuple(f"{name}{c.suffix}" for c in self.coils for name in COIL_COLUMNS)
        if not self.contacts:  # a coil's drive alone (an actuator)
            return ("time",) + coils
        if len(self.contacts) == 1 and not self.contacts[0].name:
            return COLUMNS + coils
        return ("time", "load_current") + tuple(
            f"{name}{c.suffix}" for c in self.contacts for name in self.contact_columns(c)) + coils

    def contact(self, column: str) -> tuple[ContactBlock, str]:
        """(the contact, the column's base name) of a per-contact column such as contact_voltage_no."""
        for c in self.contacts:
            for base in self.contact_columns(c):
                if column == base + c.suffix:
                    return c, base
        raise KeyError(f"unknown result column {column!r}; known: {', '.join(self.column_names)}")

    def columns(self, read: Callable[[str], np.ndarray], names: tuple[str, ...] | None = None) -> dict[str, np.ndarray]:
        """The requested columns (default: all), each read through ``read(vector_name) -> array``."""
        cache: dict[str, np.ndarray] = {}

        def vec(name: str) -> np.ndarray:
            key = name.lower()
            if key not in cache:
                cache[key] = read(key)
            return cache[key]

        time = vec("time")
        out: dict[str, np.ndarray] = {}
        for name in (self.column_names if names is None else names):
            vector = self.vector_of(name)
            if vector is not None:
                out[name] = vec(vector)
            elif name == "load_current":
                out[name] = vec(self.load_current) if self.load_current else np.full_like(time, np.nan)
            elif name.startswith("coil_"):
                out[name] = self._coil_column(name, vec, time)
            else:
                c, base = self.contact(name)
                out[name] = self._contact_column(c, base, vec, time)
        return out

    def vector_of(self, column: str) -> str | None:
        """The ngspice vector that is the result column ``column`` as it stands (time, a
        current, a conductance, a flux linkage); None for a column computed from vectors or
        constant (a voltage, a resistance, a missing load probe or arc)."""
        if column == "time":
            return "time"
        if column == "load_current":
            return self.load_current or None
        for blocks, raw in ((self.contacts, RAW_CONTACT_COLUMNS), (self.coils, RAW_COIL_COLUMNS)):
            for c in blocks:
                for base, attribute in raw.items():
                    if column == base + c.suffix:
                        return getattr(c, attribute) or None
        return None

    def _contact_column(self, c: ContactBlock, base: str, vec, time: np.ndarray) -> np.ndarray:
        """A per-contact column that is not one vector as it stands (``vector_of``)."""
        if base == "contact_voltage":
            return self._contact_voltage(c, vec, time)
        if base == "contact_resistance":
            g = vec(c.conductance_node)
            with np.errstate(divide="ignore"):
                return np.where(g > 0.0, 1.0 / np.where(g > 0.0, g, 1.0), np.inf)
        return np.zeros_like(time)  # arc_current without an arc model

    def _coil_column(self, name: str, vec, time: np.ndarray) -> np.ndarray:
        """A coil column that is not one vector as it stands: its terminal voltage."""
        for c in self.coils:
            if name == "coil_voltage" + c.suffix:
                return self._node(vec, c.node_p, time) - self._node(vec, c.node_n, time)
        raise KeyError(f"unknown result column {name!r}; known: {', '.join(self.column_names)}")

    def frame(self, read: Callable[[str], np.ndarray], extra: tuple[str, ...] = ()):
        """All columns plus ``extra`` raw ngspice vectors (e.g. 'load', 'vsource#branch'), a
        pandas DataFrame."""
        import pandas as pd

        data = self.columns(read)
        for name in extra:
            data[name] = read(name.lower())
        return pd.DataFrame(data)

    def _contact_voltage(self, c: ContactBlock, vec, time: np.ndarray) -> np.ndarray:
        """V: while the contact conducts, the element's law I/G with the branch current;
        otherwise the difference of the two node potentials.

        ngspice converges each node potential to RELTOL of its own size: with the contact on
        the supply side both nodes sit near the supply voltage, and their difference while
        closed (mV) carried 4 % errors at RELTOL 1e-4 (measured against RELTOL 1e-8), while
        the branch current, converged to RELTOL of itself, gave I/G within 1.1e-4. Below
        CLOSED_CONDUCTANCE (S) the leakage term of the element matters and the voltage is
        large, so the node difference is the accurate one there.
        """
        nodes = self._node(vec, c.node_a, time) - self._node(vec, c.node_b, time)
        g = vec(c.conductance_node)
        closed = g > CLOSED_CONDUCTANCE
        with np.errstate(divide="ignore", invalid="ignore"):
            law = vec(c.current_vector) / np.where(closed, g, 1.0)
        return np.where(closed, law, nodes)

    @staticmethod
    def _node(vec: Callable[[str], np.ndarray], node: str, time: np.ndarray) -> np.ndarray:
        if node.lower() in GROUND:
            return np.zeros_like(time)
        return vec(node)


# --- user probes: any node voltage or branch current of the deck ------------------------------

_PROBE = re.compile(r"^\s*([vViI])\s*\(\s*([^(),\s]+)\s*(?:,\s*([^(),\s]+)\s*)?\)\s*$")
_SUFFIX = {"t": 1e12, "g": 1e9, "meg": 1e6, "k": 1e3, "m": 1e-3, "u": 1e-6, "n": 1e-9, "p": 1e-12, "f": 1e-15}
_TWO_NODES = set("rclvidbsw")  # element letters whose first two tokens after the name are nodes


@dataclass(frozen=True)
class UserProbe:
    """A recorded quantity named as in SPICE: ``v(node)``, ``v(node1,node2)`` (V) or
    ``i(element)`` (A, positive into the element's first node): the column name is ``text``.

    Currents: a voltage source's or inductor's branch vector; a resistor's (V(n1) - V(n2)) / R;
    a capacitor's C d(V(n1) - V(n2))/dt by finite differences over the accepted points.
    """

    text: str
    kind: str  # "v" | "i"
    names: tuple[str, ...]  # nodes (v) or the element (i), lower case


def parse_probe(text, where: str = "probes") -> UserProbe:
    """One probe from its text; ValueError (one line) for anything else."""
    m = _PROBE.match(text) if isinstance(text, str) else None
    if m is None or (m.group(1).lower() == "i" and m.group(3)):
        raise ValueError(f"{where}: probe {text!r}: expected 'v(node)', 'v(node1,node2)' or 'i(element)'")
    names = tuple(n.lower() for n in m.groups()[1:] if n)
    return UserProbe(text.strip(), m.group(1).lower(), names)


def spice_number(token: str) -> float:
    """A SPICE number with an optional scale suffix (1k, 100n, 2.2meg, 1e-6, 5uF)."""
    m = re.match(r"^([+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)([a-zA-Z]*)", token)
    if m is None:
        raise ValueError(f"not a number: {token!r}")
    value, suffix = float(m.group(1)), m.group(2).lower()
    for key in ("meg", "t", "g", "k", "m", "u", "n", "p", "f"):
        if suffix.startswith(key):
            return value * _SUFFIX[key]
    return value


def deck_topology(lines) -> tuple[set[str], dict[str, tuple[tuple[str, ...], str]]]:
    """(node names, element name -> (its two nodes, its value token)) of a deck, lower case."""
    nodes: set[str] = {"0"}
    elements: dict[str, tuple[tuple[str, ...], str]] = {}
    for line in list(lines)[1:]:
        tokens = line.split()
        if not tokens or tokens[0][0] in ".*+":
            continue
        name = tokens[0].lower()
        letter = name[0]
        if letter in _TWO_NODES and len(tokens) >= 3:
            pair = (tokens[1].lower(), tokens[2].lower())
            nodes.update(pair)
            elements[name] = (pair, tokens[3] if len(tokens) > 3 else "")
            if letter in "sw" and len(tokens) > 4:
                nodes.update(t.lower() for t in tokens[3:5])
        elif letter in "eg" and len(tokens) >= 5:
            nodes.update(t.lower() for t in tokens[1:5])
            elements[name] = ((tokens[1].lower(), tokens[2].lower()), "")
        elif letter == "x":
            nodes.update(t.lower() for t in tokens[1:-1] if "=" not in t)
        elif letter in "qmj":
            nodes.update(t.lower() for t in tokens[1:4])
    return nodes, elements


def check_probes(texts, lines, where: str = "probes") -> tuple[UserProbe, ...]:
    """Parse and validate probes against a deck's nodes and elements (one-line errors)."""
    if isinstance(texts, str) or not isinstance(texts, (list, tuple)):
        raise ValueError(f"{where} = {texts!r}: expected a list such as [\"v(snubber)\", \"i(Lload)\"]")
    nodes, elements = deck_topology(lines)
    out = []
    for text in texts:
        probe = parse_probe(text, where)
        if probe.kind == "v":
            for n in probe.names:
                if n not in nodes and n != "gnd":
                    raise ValueError(f"{where}: probe {text!r}: no node {n!r} in the circuit; nodes: "
                                     f"{', '.join(sorted(nodes))}")
        else:
            (name,) = probe.names
            if name not in elements or name[0] not in "vlrc":
                known = sorted(e for e in elements if e[0] in "vlrc")
                raise ValueError(f"{where}: probe {text!r}: no element {name!r} whose current can be recorded "
                                 f"(V, L, R or C elements: {', '.join(known)})")
            if name[0] in "rc":
                try:
                    spice_number(elements[name][1])
                except ValueError:
                    raise ValueError(f"{where}: probe {text!r}: the value {elements[name][1]!r} of {name} is "
                                     "not a number (a behavioural element): probe its nodes' voltages") from None
        if probe.text in COLUMNS or probe.text in (p.text for p in out):
            raise ValueError(f"{where}: probe {text!r} is given twice or names a built-in column")
        out.append(probe)
    return tuple(out)


def probe_columns(probes, read: Callable[[str], np.ndarray], lines) -> dict[str, np.ndarray]:
    """The probes' columns, each read through ``read(vector_name) -> array`` (SI: V, A)."""
    if not probes:
        return {}
    _, elements = deck_topology(lines)
    time = read("time")

    def node(n: str) -> np.ndarray:
        return np.zeros_like(time) if n in GROUND else read(n)

    out: dict[str, np.ndarray] = {}
    for p in probes:
        if p.kind == "v":
            out[p.text] = node(p.names[0]) - (node(p.names[1]) if len(p.names) > 1 else 0.0)
            continue
        name = p.names[0]
        (a, b), value = elements[name]
        if name[0] in "vl":
            out[p.text] = read(f"{name}#branch")
        elif name[0] == "r":
            out[p.text] = (node(a) - node(b)) / spice_number(value)
        else:
            dv = node(a) - node(b)
            out[p.text] = spice_number(value) * _derivative(dv, time)
    return out


def _derivative(y: np.ndarray, t: np.ndarray) -> np.ndarray:
    """dy/dt at the samples: the mean of the adjacent secant slopes (one-sided at the ends);
    repeated time points (a breakpoint's two sides) count as one."""
    if len(t) < 2:
        return np.zeros_like(t)
    dt = np.diff(t)
    slope = np.where(dt > 0, np.diff(y) / np.where(dt > 0, dt, 1.0), np.nan)
    left = np.concatenate([[np.nan], slope])
    right = np.concatenate([slope, [np.nan]])
    out = np.nanmean(np.vstack([left, right]), axis=0) if np.isfinite(slope).any() else np.zeros_like(t)
    return np.nan_to_num(out)
    return out
