"""Arc and breakdown model of an opening contact gap (minimum arc voltage, minimum arc current).

Physics kept (short arcs between contact metals, the bounce regime):

- A burning arc holds the gap voltage near the minimum arc voltage U_min (anode +
  cathode fall, ~10-15 V for Ag, Cu, Au), nearly independent of current; a small
  incremental resistance R_arc regularises the characteristic.
- An arc needs at least the minimum arc current I_min (~0.3-1 A) to sustain its
  cathode spot: it extinguishes as soon as its current falls below I_min.
- When a current-carrying contact parts, a molten bridge and then the arc form: the
  gap is "armed" while closed and for ``formation_time`` after parting; if in that
  window the gap voltage reaches U_min and the arc takes at least I_min, it burns.
  Otherwise (gap voltage stays below U_min, e.g. a supply below U_min with a resistive
  load, or the current goes into a snubber) no arc forms.
- Optionally, an extinguished gap re-ignites when its voltage reaches the breakdown
  voltage V_bd (repeated re-ignitions give the "showering arc" of inductive loads).

Not modelled: arc elongation with gap growth (U_min is constant, so a DC arc with
E > U_min and load current > I_min burns for as long as the contact stays open),
V_bd growing with gap distance, make arcs (pre-strike on closing), erosion, and the
glow discharge regime.

Netlist: the arc path across the gap is a hysteretic switch (ngspice SW) in series with
a dead-zone conductor. The switch is the arc's on/off state; its control voltage is

    max(K_I * (|i_arc| - I_min), K_c * (armed - 1/2), |v_gap| - V_bd)

so it stays on while either the arc current exceeds I_min, or the contact is (or has
just been) closed, or the gap voltage exceeds V_bd. ngspice's SW model limits the time
step as its control approaches the threshold, which locates extinction and breakdown
in time independently of the maximum step (K_I = 1000 / I_min V/A: the 0.05 V resolution
of that step control is 0.005 % of I_min; with 100 / I_min the extinction current
still varied by 0.08 % with the maximum step). "armed" is the closed indicator (G > 0)
low-pass filtered so that it stays above 1/2 for ``formation_time`` after parting.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from PySpice.Spice.Netlist import Circuit

from .contact import CONDUCTANCE_NODE
from .validation import check_range

SENSE_SOURCE = "Varc"
SWITCH_MODEL = "switchsim_arc"
_ARM_CAPACITANCE = 1e-9  # F; the arming RC filter's capacitor, its resistor sets the time
_SWITCH_HYSTERESIS = 0.01  # V of control voltage, i.e. 1e-5 * I_min of arc current
_CLOSED_GAIN = 10.0  # V per unit of the armed indicator


@dataclass(frozen=True)
class ArcModel:
    """Arc of an opening contact. SI units.

    min_voltage: minimum arc voltage U_min, V (Ag ~12 V, Cu ~13 V, Au ~15 V).
    min_current: minimum arc current I_min, A (Ag ~0.4 A, Cu ~0.43 A, Au ~0.38 A).
    resistance: incremental resistance of the burning arc, ohm (regularisation; the
        gap voltage is U_min + resistance * |i|).
    formation_time: how long after parting the gap stays armed for the arc to form, s
        (order of the molten-bridge lifetime at ampere currents).
    breakdown_voltage: gap voltage at which an extinguished gap re-ignites, V, or None
        for a gap that never re-ignites (the voltage is then limited only by the circuit).
    """

    min_voltage: float = 12.0
    min_current: float = 0.4
    resistance: float = 0.05
    formation_time: float = 1e-6
    breakdown_voltage: float | None = None

    def __post_init__(self) -> None:
        name = "ArcModel"
        check_range(name, "min_voltage", self.min_voltage, "V", 0.0, 1000.0, low_open=True)
        check_range(name, "min_current", self.min_current, "A", 0.0, 100.0, low_open=True)
        check_range(name, "resistance", self.resistance, "ohm", 1e-4, 100.0)
        check_range(name, "formation_time", self.formation_time, "s", 1e-10, 1e-3)
        if self.breakdown_voltage is not None:
            check_range(
                name, "breakdown_voltage", self.breakdown_voltage, "V", self.min_voltage, 1e6, low_open=True
            )


def add_arc(circuit: Circuit, arc: ArcModel, node_a: str, node_b: str) -> None:
    """Add the arc path across the contact (``node_a``, ``node_b``) of a PySpice circuit.

    The arc current (A, positive from a to b) is the branch current of ``Varc``. Needs
    the contact's conductance node (``add_contact`` first).
    """
    r_on = min(1e-3, arc.resistance / 10.0)
    slope = arc.resistance - r_on
    u = float(arc.min_voltage)
    circuit.V(SENSE_SOURCE[1:], node_a, "arc_p", 0)
    circuit.S("arc", "arc_p", "arc_q", "arc_ctl", circuit.gnd, model=SWITCH_MODEL)
    circuit.model(
        SWITCH_MODEL, "SW", vt=0.0, vh=_SWITCH_HYSTERESIS, ron=r_on, roff=r_on * 1e12
    )
    circuit.B(
        "arc",
        "arc_q",
        node_b,
        current_expression=f"(uramp(V(arc_q,{node_b})-{u!r})-uramp(-V(arc_q,{node_b})-{u!r}))/{slope!r}",
    )
    circuit.B("arc_closed", "arc_cl0", circuit.gnd, voltage_expression=f"V({CONDUCTANCE_NODE}) > 0 ? 1 : 0")
    # The filtered indicator falls from 1 to 1/2 in R C ln 2 = formation_time.
    circuit.R("arc_arm", "arc_cl0", "arc_cl", arc.formation_time / (math.log(2.0) * _ARM_CAPACITANCE))
    circuit.C("arc_arm", "arc_cl", circuit.gnd, _ARM_CAPACITANCE)
    k_i = 1000.0 / arc.min_current
    control = (
        f"max({k_i!r}*(abs(i({SENSE_SOURCE}))-{float(arc.min_current)!r}),"
        f"{_CLOSED_GAIN!r}*(V(arc_cl)-0.5))"
    )
    if arc.breakdown_voltage is not None:
        control = f"max({control},abs(V({node_a},{node_b}))-{float(arc.breakdown_voltage)!r})"
    circuit.B("arc_ctl", "arc_ctl", circuit.gnd, voltage_expression=control)
