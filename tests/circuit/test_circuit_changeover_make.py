"""A make-before-break changeover on a 5 V supply at RELTOL 1e-6 (circuit.ChangeoverCircuit with
both arcs and a current factor), checked against closed forms. SI units.

NC carries the load, NO makes (both closed), NC breaks, NO breaks (both throws open: the
wiring carries only the open gaps' nA), then NC makes again with no breakpoint and a
conductance that rises from 0 as (t - t_make)^(1/3) (a Hertz contact's radius grows as
F^(1/3), and F from 0 linearly where the mechanics' force returns from its clip at zero,
which is not a make event, so the coupling passes no breakpoint there). ngspice steps down
to ~1e-14 s at that make. With the load probe between the wiring inductor and the common
the LU lost the solution's digits at those steps and the run aborted ("timestep too small
... trouble with node common"; docs/circuit.md, "A changeover").
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from circuit import ArcModel, ChangeoverCircuit, DCSource, ResistiveLoad, SimulationOptions, Stepper, Wiring
from circuit.arc import OFF_CONDUCTANCE
from circuit.contact import DEFAULT_LEAKAGE
from circuit.probes import check_probes

V_S, R_S, L_W, C_C = 5.0, 0.05, 1e-6, 1e-10
R_NO, R_NC = 12.0, 24.0
G0 = 50.0  # S: a closed contact's G(t) (its resistance g(I) / G0 with the current factor)
FACTOR = "0.6+0.4*exp(-abs(I)/1.7)"
T_NO_MAKE, T_NC_BREAK, T_NO_BREAK, T_NC_MAKE, T_END = 10e-6, 20e-6, 30e-6, 41e-6, 60e-6
RISE = 1e-6  # s: NC's conductance reaches G0 this long after its make


def g(i: float) -> float:
    """The current factor (FACTOR) at contact current i (A)."""
    return 0.6 + 0.4 * math.exp(-abs(i) / 1.7)


def closed_currents(no: bool, nc: bool) -> tuple[float, float]:
    """(NO's, NC's) contact current, A, in the steady state: the supply through R_S into the
    common, each closed throw g(I) / G0 + its load (a fixed point, converged to round-off)."""
    i_no = i_nc = 0.0
    for _ in range(200):
        v_common = V_S - R_S * (i_no + i_nc)
        i_no = v_common / (g(i_no) / G0 + R_NO) if no else 0.0
        i_nc = v_common / (g(i_nc) / G0 + R_NC) if nc else 0.0
    return i_no, i_nc


def g_no(t: float) -> float:
    return G0 if T_NO_MAKE <= t < T_NO_BREAK else 0.0


def g_nc(t: float) -> float:
    if t < T_NC_BREAK:
        return G0
    if t < T_NC_MAKE:
        return 0.0
    return G0 * min(1.0, ((t - T_NC_MAKE) / RISE) ** (1.0 / 3.0))


def test_a_low_voltage_make_before_break_at_tight_reltol_runs_and_keeps_its_closed_forms():
    circuit = ChangeoverCircuit(DCSource(V_S, R_S), ResistiveLoad(R_NO), Wiring(0.0, L_W), contact_capacitance=C_C,
                                arc=ArcModel(), contact_current_factor=FACTOR, contact_names=("NO", "NC"),
                                nc_load_resistance=R_NC)
    inputs = {"contact_NO.conductance": g_no, "contact_NC.conductance": g_nc}
    events = (T_NO_MAKE, T_NC_BREAK, T_NO_BREAK)  # NC's second make is not among them
    with Stepper(circuit, T_END, SimulationOptions(reltol=1e-6)) as stepper:
        t = 0.0
        while t < T_END:
            t_next = min(t + 5e-6, T_END)  # the coupling's macro step
            stepper.advance(t_next, inputs=inputs, breakpoints=[b for b in events if t < b <= t_next])
            t = t_next
        w = stepper.results(probes=check_probes(["i(Vload_nc)"], stepper.deck))
    time = w["time"].to_numpy()

    def at(column: str, s: float) -> float:
        return float(np.interp(s, time, w[column].to_numpy()))

    # Steady states (each 9 us after its event; the wiring's LC rings down in ~0.3 us):
    # RELTOL 1e-6 of the currents (measured 7e-11).
    nc_alone = closed_currents(False, True)[1]
    assert at("contact_current_NC", T_NO_MAKE - 1e-6) == pytest.approx(nc_alone, rel=1e-6)
    both_no, both_nc = closed_currents(True, True)
    assert at("contact_current_NO", T_NC_BREAK - 1e-6) == pytest.approx(both_no, rel=1e-6)
    assert at("contact_current_NC", T_NC_BREAK - 1e-6) == pytest.approx(both_nc, rel=1e-6)
    assert at("load_current", T_NC_BREAK - 1e-6) == pytest.approx(both_no + both_nc, rel=1e-6)
    assert at("contact_current_NC", T_END - 1e-6) == pytest.approx(nc_alone, rel=1e-6)
    assert at("contact_current_NO", T_END - 1e-6) == pytest.approx(0.0, abs=1e-9)

    # Both throws open: the supply feeds each gap's leakage and arc off-conductance, 10 nA in
    # all; to 1 % (measured 1.5e-3: the 1.5e-11 A spread is ABSTOL-sized, 1e-12 A per unknown).
    open_ = (time > T_NO_BREAK + 5e-6) & (time < T_NC_MAKE)
    expected = 2.0 * V_S * (DEFAULT_LEAKAGE + OFF_CONDUCTANCE)
    assert np.all(np.abs(w["load_current"].to_numpy()[open_] / expected - 1.0) < 1e-2)

    # NC's make dumps its capacitance's charge through the contact: the contact's and the arc
    # path's current less the throw's load current, integrated over the make, is C times the
    # fall of NC's contact voltage (~5 V to its closed value); to 1e-3 (trapezoidal sums over
    # ngspice's points, measured 2.4e-5).
    make = (time >= T_NC_MAKE - 1e-7) & (time <= T_NC_MAKE + 3e-6)
    s = time[make]
    through = (w["contact_current_NC"].to_numpy()[make] + w["arc_current_NC"].to_numpy()[make]
               - w["i(Vload_nc)"].to_numpy()[make])
    charge = float(np.sum(0.5 * (through[1:] + through[:-1]) * np.diff(s)))
    v_nc = w["contact_voltage_NC"].to_numpy()[make]
    assert v_nc[0] == pytest.approx(V_S, rel=1e-6)  # open: the whole supply across the gap
    assert charge == pytest.approx(C_C * (v_nc[0] - v_nc[-1]), rel=1e-3)
