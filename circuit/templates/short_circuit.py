"""A fault: the load shorted at a time (``ShortCircuit``)."""

from __future__ import annotations

from dataclasses import dataclass

from PySpice.Spice.Netlist import Circuit

from ..validation import check_range, scene_key
from .sources import CurrentSource
from .switch import SwitchCircuit


FAULT_NODE = "fault_g"
FAULT_OFF = 1e-9  # S: the fault path before the fault (an insulation's leakage)


@dataclass(frozen=True)
class ShortCircuit(SwitchCircuit):
    """A ``SwitchCircuit`` whose load terminals are shorted at a time: the fault current that
    flows through a closed contact when the load side fails (SI units).

    fault_time: s, when the short starts; fault_resistance: ohm, the short's resistance (the
    fault loop is then source, wiring, contact and this, the load in parallel); fault_rise: s,
    over which the short's conductance ramps from 1e-9 S to 1/fault_resistance (a bolted
    fault: a short rise; the wiring's L/R shapes the current as well). The steady fault
    current through a closed contact of resistance R_c is E / (R_source + R_wire + R_c +
    R_fault || R_load) (``fault_current``). Every other field is SwitchCircuit's.

    The netlist adds, across the load (node ``load`` to ground, after the load probe, so the
    load current is the loop current with the fault's share)::

        Vfault_g fault_g 0 PWL(0 1e-9 t_f 1e-9 t_f+rise 1/R_f)   (the short's conductance, S, as a voltage)
        Bfault   load 0 I=V(load)*V(fault_g)
    """

    fault_time: float = scene_key(1e-3, unit="s", doc="short_circuit: when the load is shorted")
    fault_resistance: float = scene_key(
        0.01, unit="ohm", doc="short_circuit: the short's resistance (the fault current E / (R_source + R_wire + "
        "R_c + R_fault || R_load))")
    fault_rise: float = scene_key(
        1e-6, unit="s", doc="short_circuit: over which the short's conductance ramps in (> 0)")

    def __post_init__(self) -> None:
        super().__post_init__()
        name = self.SECTION
        check_range(name, "fault_time", self.fault_time, "s", 0.0, 1e3)
        check_range(name, "fault_resistance", self.fault_resistance, "ohm", 1e-6, 1e6)
        check_range(name, "fault_rise", self.fault_rise, "s", 0.0, 10.0, low_open=True)
        if isinstance(self.source, CurrentSource):
            raise ValueError(f"ShortCircuit.source is a CurrentSource: a fault is a short behind a voltage source "
                             "(DCSource), whose current only the loop's impedance limits")

    def fault_current(self, contact_resistance: float = 0.0) -> float:
        """A: the steady current through the closed contact (``contact_resistance``, ohm) with
        the short in place (inductances carry no voltage then; an inductive load's L is a short);
        with an AC source the amplitude its peak voltage drives, the inductances neglected."""
        load = self.load.load_resistance
        parallel = load * self.fault_resistance / (load + self.fault_resistance)
        loop = self.source.source_resistance + self.wiring.wiring_resistance + contact_resistance + parallel
        return self.source.amplitude / loop

    def fault_vertices(self) -> list[tuple[float, float]]:
        """(time s, conductance S) of the short's PWL."""
        on = 1.0 / self.fault_resistance
        if self.fault_time <= 0.0:
            return [(0.0, FAULT_OFF), (self.fault_rise, on)]
        return [(0.0, FAULT_OFF), (self.fault_time, FAULT_OFF), (self.fault_time + self.fault_rise, on)]

    def build(self) -> Circuit:
        c = super().build()
        pwl = " ".join(f"{t!r} {g!r}" for t, g in self.fault_vertices())
        c.V(FAULT_NODE, FAULT_NODE, c.gnd, f"PWL({pwl})")
        c.B("fault", "load", c.gnd, current_expression=f"V(load)*V({FAULT_NODE})")
        return c
