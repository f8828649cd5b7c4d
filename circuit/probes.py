"""Which ngspice vectors hold the contact and load quantities, and how they become result columns."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import pandas as pd

#: Result columns, in order (SI: s, V, A, A, ohm, S, A).
COLUMNS = (
    "time",
    "contact_voltage",
    "contact_current",
    "load_current",
    "contact_resistance",
    "contact_conductance",
    "arc_current",
)

_GROUND = ("0", "gnd")
CLOSED_CONDUCTANCE = 1e-6  # S: above it the contact voltage is I/G (see Probes._contact_voltage)


@dataclass(frozen=True)
class Probes:
    """Vector names (as ngspice knows them) behind each result column.

    node_a, node_b: contact nodes; contact_voltage, V: I/G while the contact conducts,
        V(node_a) - V(node_b) otherwise (see _contact_voltage).
    contact_current: branch vector of the contact's 0 V probe (metallic conduction
        only, A, positive from a to b); the arc and the parasitic capacitance are not in it.
    conductance_node: node whose voltage is the prescribed conductance G(t), S.
    load_current: branch vector of the load probe, A, or None (column of NaN).
    arc_current: branch vector of the arc path, A, or None (no arc model: column of 0).
    """

    node_a: str
    node_b: str
    contact_current: str
    conductance_node: str
    load_current: str | None = None
    arc_current: str | None = None

    def columns(self, read: Callable[[str], np.ndarray], names: tuple[str, ...] = COLUMNS) -> dict[str, np.ndarray]:
        """The requested columns, each read through ``read(vector_name) -> array``."""
        cache: dict[str, np.ndarray] = {}

        def vec(name: str) -> np.ndarray:
            key = name.lower()
            if key not in cache:
                cache[key] = read(key)
            return cache[key]

        time = vec("time")
        out: dict[str, np.ndarray] = {}
        for name in names:
            if name == "time":
                out[name] = time
            elif name == "contact_voltage":
                out[name] = self._contact_voltage(vec, time)
            elif name == "contact_current":
                out[name] = vec(self.contact_current)
            elif name == "load_current":
                out[name] = vec(self.load_current) if self.load_current else np.full_like(time, np.nan)
            elif name in ("contact_resistance", "contact_conductance"):
                g = vec(self.conductance_node)
                if name == "contact_conductance":
                    out[name] = g
                else:
                    with np.errstate(divide="ignore"):
                        out[name] = np.where(g > 0.0, 1.0 / np.where(g > 0.0, g, 1.0), np.inf)
            elif name == "arc_current":
                out[name] = vec(self.arc_current) if self.arc_current else np.zeros_like(time)
            else:
                raise KeyError(f"unknown result column {name!r}; known: {', '.join(COLUMNS)}")
        return out

    def frame(self, read: Callable[[str], np.ndarray], extra: tuple[str, ...] = ()) -> pd.DataFrame:
        """All columns plus ``extra`` raw ngspice vectors (e.g. 'load', 'vsource#branch')."""
        data = self.columns(read)
        for name in extra:
            data[name] = read(name.lower())
        return pd.DataFrame(data)

    def _contact_voltage(self, vec, time: np.ndarray) -> np.ndarray:
        """V: while the contact conducts, the element's law I/G with the branch current;
        otherwise the difference of the two node potentials.

        ngspice converges each node potential to RELTOL of its own size: with the contact on
        the supply side both nodes sit near the supply voltage, and their difference while
        closed (mV) carried 4 % errors at RELTOL 1e-4 (measured against RELTOL 1e-8), while
        the branch current, converged to RELTOL of itself, gave I/G within 1.1e-4. Below
        CLOSED_CONDUCTANCE (S) the leakage term of the element matters and the voltage is
        large, so the node difference is the accurate one there.
        """
        nodes = self._node(vec, self.node_a, time) - self._node(vec, self.node_b, time)
        g = vec(self.conductance_node)
        closed = g > CLOSED_CONDUCTANCE
        with np.errstate(divide="ignore", invalid="ignore"):
            law = vec(self.contact_current) / np.where(closed, g, 1.0)
        return np.where(closed, law, nodes)

    @staticmethod
    def _node(vec: Callable[[str], np.ndarray], node: str, time: np.ndarray) -> np.ndarray:
        if node.lower() in _GROUND:
            return np.zeros_like(time)
        return vec(node)
