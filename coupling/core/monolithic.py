"""Monolithic reference: mechanics and a series-loop circuit in one stiff solve (no coupling error).

For circuits that are one series loop (DC source with internal resistance, wiring R and
L, the contact with its parallel capacitance C_p, a resistive, inductive or capacitive
load; no arc, snubber or flyback diode) the circuit is the ODE

    L dI/dt    = V - I R - v_c - v_C                 (I algebraic when L = 0)
    C_p dv_c/dt = I - i_c - G_leak v_c,   i_c g(|i_c|) = G_F(F_n(t)) v_c
    C dv_C/dt   = I - v_C / R_bleed                  (capacitive load only)

with R = R_source + R_wire + R_load, L = L_wire + L_load. These states are integrated
together with the mechanics by scipy's Radau (L-stable: the closed contact makes
C_p/G ~ 1e-12 s) through mech's CoupledStates hook; mu follows the loop current I, as
in the co-simulation. The difference between a co-simulation and this run is the
coupling error plus both routes' integration errors, so compare at tight tolerances.
"""

from __future__ import annotations

import time

import numpy as np
from scipy.optimize import brentq

from mech import CoupledStates, ImpactSolver
from mech.frozen import frozen

from coupling.core.exchange import conduction_onset
from coupling.core.results import CoupledResult
from coupling.core.scene import Scene


@frozen
class SeriesLoop:
    """The loop's constants (SI): V, R, L, C_p, G_leak, and C, R_bleed of a capacitive load (else 0)."""

    voltage: float
    resistance: float
    inductance: float
    contact_capacitance: float
    leakage_conductance: float
    load_capacitance: float = 0.0
    bleed_resistance: float = 0.0

    @property
    def has_inductance(self) -> bool:
        return self.inductance > 0.0

    @property
    def capacitive(self) -> bool:
        return self.load_capacitance > 0.0


def series_loop(circuit) -> SeriesLoop:
    """The SeriesLoop of a SwitchCircuit, or a ValueError saying why it is not one."""
    import circuit as ck

    if not isinstance(circuit, ck.SwitchCircuit):
        raise ValueError("monolithic reference: only template circuits (SwitchCircuit) can be written as an ODE")
    if len(circuit.contacts) != 1:
        # (a bridge's or a changeover's contacts would be read as one, and their load_inductance missed)
        raise ValueError(f"monolithic reference: the circuit holds {len(circuit.contacts)} contacts "
                         f"({type(circuit).__name__}); the reference covers a loop with one contact")
    for part in ("arc", "snubber", "flyback"):
        if getattr(circuit, part) is not None:
            raise ValueError(f"monolithic reference: circuit.{part} is set; the reference covers series "
                             "R/L/C loops only (no arc, snubber or flyback diode)")
    if not isinstance(circuit.source, ck.DCSource):
        raise ValueError("monolithic reference: the source is a CurrentSource; the reference covers a "
                         "voltage source only")
    if circuit.source.frequency > 0.0:
        raise ValueError(f"monolithic reference: the source is AC (circuit.frequency = {circuit.source.frequency:g} "
                         "Hz); the reference covers a DC source only")
    if circuit.contact_capacitance <= 0.0:
        raise ValueError("monolithic reference: contact_capacitance must be > 0 (it carries the loop "
                         "current while the contact is open)")
    load = circuit.load
    r = circuit.source.source_resistance + circuit.wiring.wiring_resistance + load.load_resistance
    inductance = circuit.wiring.wiring_inductance + (load.load_inductance if isinstance(load, ck.InductiveLoad) else 0.0)
    cap = load.load_capacitance if isinstance(load, ck.CapacitiveLoad) else 0.0
    bleed = load.bleed_resistance if isinstance(load, ck.CapacitiveLoad) else 0.0
    return SeriesLoop(circuit.source.voltage, r, inductance, circuit.contact_capacitance,
                      circuit.leakage_conductance, cap, bleed)


class LoopODE:
    """The circuit part of the monolithic system; state z = [I (if L > 0), v_c, v_C (if capacitive)]."""

    def __init__(self, loop: SeriesLoop, resistance_law, mu, rtol: float, onset: float = 0.0):
        self.loop = loop
        self.law = resistance_law
        self.onset = onset
        self.mu = mu
        self.i_I = 0 if loop.has_inductance else None
        self.i_vc = 1 if loop.has_inductance else 0
        self.i_vC = self.i_vc + 1 if loop.capacitive else None
        n = 1 + int(loop.has_inductance) + int(loop.capacitive)
        i_scale = loop.voltage / loop.resistance
        atol = np.full(n, rtol * loop.voltage)
        if self.i_I is not None:
            atol[self.i_I] = rtol * i_scale
        self.atol = atol
        # DC operating point with the contact open (leakage only), as ngspice starts
        r_open = loop.resistance + 1.0 / loop.leakage_conductance + (loop.bleed_resistance if loop.capacitive else 0.0)
        i0 = loop.voltage / r_open
        z0 = np.zeros(n)
        if self.i_I is not None:
            z0[self.i_I] = i0
        z0[self.i_vc] = i0 / loop.leakage_conductance
        if self.i_vC is not None:
            z0[self.i_vC] = i0 * loop.bleed_resistance
        self.initial = z0

    def conductance(self, contact) -> float:
        """S: G_F of both tips with the conduction onset, as the co-simulation gives ngspice."""
        return sum(self.law.scalar_force_conductance(contact[i, 2]) * conduction_onset(contact[i, 0], self.onset)
                   for i in range(2))

    def loop_current(self, z) -> float:
        lp = self.loop
        if self.i_I is not None:
            return float(z[self.i_I])
        v_cap = z[self.i_vC] if self.i_vC is not None else 0.0
        return float((lp.voltage - z[self.i_vc] - v_cap) / lp.resistance)

    def contact_current(self, g_force: float, v: float) -> float:
        """Metallic current i with i g(|i|) = G_F v (A); g is in (0, 1], so |i| <= G_F |v| / min g."""
        if g_force <= 0.0 or v == 0.0:
            return 0.0
        target = g_force * abs(v)
        f = lambda i: i * float(self.law.current_factor(i)) - target
        hi = target
        while f(hi) < 0.0:
            hi *= 2.0
        return float(np.sign(v) * brentq(f, 0.0, hi, xtol=1e-15, rtol=1e-13))

    def rhs(self, t, z, contact) -> np.ndarray:
        lp = self.loop
        g_force = self.conductance(contact)
        v = z[self.i_vc]
        i_c = self.contact_current(g_force, v)
        i_loop = self.loop_current(z)
        dz = np.empty_like(z)
        v_cap = z[self.i_vC] if self.i_vC is not None else 0.0
        if self.i_I is not None:
            dz[self.i_I] = (lp.voltage - i_loop * lp.resistance - v - v_cap) / lp.inductance
        dz[self.i_vc] = (i_loop - i_c - lp.leakage_conductance * v) / lp.contact_capacitance
        if self.i_vC is not None:
            dz[self.i_vC] = (i_loop - v_cap / lp.bleed_resistance) / lp.load_capacitance
        return dz

    def friction_coefficient(self, t, z) -> float:
        return float(self.mu(self.loop_current(z)))


def run_monolithic(scene: Scene, *, method: str = "Radau", rtol: float | None = None) -> CoupledResult:
    """The scene's mechanics and circuit in one solve; returns a CoupledResult whose
    waveforms have the co-simulation's columns (arc_current is 0: no arc here)."""
    if scene.kind != "coupled":
        raise ValueError(f"monolithic reference: needs a coupled scene, got {scene.kind!r}")
    loop = series_loop(scene.circuit.circuit)
    laws = scene.tribology.laws
    feedback = scene.tribology.feedback
    mu = (lambda i: float(laws.mu(i))) if feedback else (lambda i, m0=float(laws.mu(0.0)): m0)
    tol = rtol if rtol is not None else scene.mech.solver.rtol
    ode = LoopODE(loop, laws.resistance_law, mu, tol, scene.coupling.onset_penetration)
    coupled = CoupledStates(initial=ode.initial, atol=ode.atol, rhs=ode.rhs,
                            friction_coefficient=ode.friction_coefficient)
    mech_scene = scene.mech
    if rtol is not None:
        from dataclasses import replace

        mech_scene = replace(mech_scene, solver=replace(mech_scene.solver, rtol=rtol))
    tick = time.perf_counter()
    solver = ImpactSolver(mech_scene, backend=f"scipy:{method}", coupled=coupled)
    mech_result = solver.run()
    wall = time.perf_counter() - tick
    z = mech_result.extra_states
    aux = mech_result.aux
    times = mech_result.t
    forces = aux[:, :, 2]
    g_force = np.array([ode.conductance(np.column_stack([aux[k, :, 0], aux[k, :, 1], forces[k]]))
                        for k in range(len(times))])
    v = z[:, ode.i_vc]
    i_c = np.array([ode.contact_current(g, vv) for g, vv in zip(g_force, v)])
    i_loop = np.array([ode.loop_current(row) for row in z])
    g_eff = np.where(g_force > 0, g_force / np.asarray(laws.resistance_law.current_factor(i_c), dtype=float), 0.0)
    with np.errstate(divide="ignore"):
        r_eff = np.where(g_eff > 0, 1.0 / np.where(g_eff > 0, g_eff, 1.0), np.inf)
    waves = {
        "time": times, "contact_voltage": v, "contact_current": i_c, "load_current": i_loop,
        "contact_resistance": r_eff, "contact_conductance": g_eff, "arc_current": np.zeros(len(times)),
        "normal_force_0": forces[:, 0], "normal_force_1": forces[:, 1],
        "penetration_0": np.maximum(aux[:, 0, 0], 0.0), "penetration_1": np.maximum(aux[:, 1, 0], 0.0),
        "normal_force": forces.sum(axis=1), "mu": np.array([mu(i) for i in i_loop], dtype=float),
    }
    return CoupledResult(scene=scene, mechanics=mech_result, waveform_columns=waves,
                         stats=dict(wall_time=wall, method=method, rtol=tol))
