"""What a relay's coil and armature did in a run: summary.json ``relay`` (docs/coupling.md).

A pure function of the run's waveforms (the circuit's coil columns and the coil link's
armature_position, working_gap and magnetic_force), its operations and the coil's drive:

- ``operate_time`` (s): the coil switched on (the driver's ``on_time``) to the first make;
  ``release_time`` (s): the coil switched off (``off_time``) to the first break after it
  (the break of the contact's last operation); None where the run does not reach them;
- ``pull_in_current`` (A): the coil current when the armature first leaves its rest stop;
  ``drop_out_current`` (A): the coil current when it leaves the pole after the coil is
  switched off; ``armature_arrival`` (s): its first arrival at the pole;
- ``energy``: the coil's energy balance, J: ``into_coil`` (integral of v i dt) =
  ``copper`` (integral of R i^2 dt) + ``magnetic_change`` (W(psi, g) at the end less at the
  start, the magnet's stored energy) + ``armature_work`` (integral of F d(g) along the
  pole face's travel: F from the magnet at the circuit's flux and the mechanics' gap) +
  ``residual``; ``relative_residual`` is |residual| / into_coil. The circuit integrates
  the coil in flux form, so what is left is ngspice's integration error and the trapezoid
  rule on its points (the mechanics' own audit, `energy`, holds the armature's side).
"""

from __future__ import annotations

import numpy as np

from coupling.core.metrics import trapezoid

MOVED = 1e-3  # of the pole face's full travel: the armature has left a stop


def relay_metrics(waves: dict, operations: list[dict], drive, magnet, travel: float, resistance: float) -> dict:
    """The ``relay`` block (module docstring). waves: the run's columns (SI); operations:
    the contact's (coupling.core.metrics.operations; [] without a contact); drive: the
    circuit's CoilDrive (its on_time and off_time), or None for a netlist's coil; magnet:
    the coupling.laws.magnet magnet; travel: m, the pole face's full travel; resistance:
    ohm, the coil's winding."""
    t = np.asarray(waves["time"], float)
    i = np.asarray(waves["coil_current"], float)
    v = np.asarray(waves["coil_voltage"], float)
    psi = np.asarray(waves["coil_flux_linkage"], float)
    x = np.asarray(waves["armature_position"], float)
    gap = np.asarray(waves["working_gap"], float)
    force = np.asarray(waves["magnetic_force"], float)
    on = drive.on_time if drive is not None else None
    off = drive.off_time if drive is not None else None
    out: dict = dict(operate_time=None, release_time=None, pull_in_current=None, drop_out_current=None,
                     armature_arrival=None)
    makes = [op["make"]["time"] for op in operations if "make" in op]
    breaks = [op["break"]["time"] for op in operations if "break" in op]
    if on is not None and makes and makes[0] >= on:
        out["operate_time"] = makes[0] - on
    if off is not None:
        after = [b for b in breaks if b >= off]
        if after:
            out["release_time"] = after[0] - off
    if len(t):
        moved = np.flatnonzero(x > MOVED * travel)
        if len(moved):
            out["pull_in_current"] = float(i[moved[0]])
        closed = np.flatnonzero(x >= (1.0 - MOVED) * travel)
        if len(closed):
            out["armature_arrival"] = float(t[closed[0]])
        if off is not None and len(closed):
            left = np.flatnonzero((t >= off) & (x < (1.0 - MOVED) * travel))
            if len(left):
                out["drop_out_current"] = float(i[left[0]])
        into = trapezoid(t, v * i)
        copper = trapezoid(t, resistance * i * i)
        stored = float(magnet.energy(psi[-1], gap[-1]) - magnet.energy(psi[0], gap[0]))
        work = float(np.sum(0.5 * (force[1:] + force[:-1]) * -np.diff(gap)))  # trapezoid in the gap
        residual = into - copper - stored - work
        out["energy"] = dict(into_coil=into, copper=copper, magnetic_change=stored, armature_work=work,
                             residual=residual, relative_residual=abs(residual) / abs(into) if into else None)
    return out
