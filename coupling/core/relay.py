"""What a relay's coil and armature did in a run: summary.json ``relay`` (docs/coupling.md).

A pure function of the run's waveforms (the circuit's coil columns and the coil link's
armature_position, working_gap and magnetic_force), its operations and the coil's drive:

- ``operate_time`` (s): the coil switched on (the driver's ``on_time``) to the first make;
  ``release_time`` (s): the coil switched off (``off_time``) to the first break after it
  (the break of the contact's last operation); None where the run does not reach them;
- ``pull_in_current`` (A): the coil current when the armature first leaves its rest stop;
  ``drop_out_current`` (A): the coil current when it leaves the pole after the coil is
  switched off; ``armature_arrival`` (s): its first arrival at the pole; all three at the
  mechanics' located stop events (the current interpolated between the circuit's points
  there), not at samples of the travel, which a coarse step can miss;
- ``energy``: the coil's energy balance, J: ``into_coil`` (integral of v i dt) =
  ``copper`` (integral of R i^2 dt) + ``magnetic_change`` (W(psi, g) at the end less at the
  start, the magnet's stored energy) + ``armature_work`` (integral of F d(g) along the
  pole face's travel: F from the magnet at the circuit's flux and the mechanics' gap) +
  ``residual``; ``relative_residual`` is |residual| / into_coil. The circuit integrates
  the coil in flux form, and the audit's quadrature is its: each step's mean current times
  its mean voltage (into_coil, copper), the trapezoid of i in psi and of F in the gap (the
  magnet's exact differential), so what is left is the flux's integration error, second
  order in the points' spacing (docs/coupling.md, "The relay"); the run's soundness judges
  it against solver.energy_tolerance (the mechanics' own audit holds the armature's side).
  With the work the mechanics received from the drive (``received``, J: the integral of
  F_drive dq along the mechanics' own solution, coupling.core.exchange.CoilLink.receive):
  ``armature_received``, ``interface_residual`` = armature_work - armature_received (J,
  energy made or lost at the coil-armature interface: the extrapolated psi^2 against the
  circuit's, the gap the circuit read against the mechanics' path) and
  ``interface_relative_residual`` = |interface_residual| / into_coil; so into_coil = copper
  + magnetic_change + armature_received + interface_residual + residual.
"""

from __future__ import annotations

import numpy as np

def stop_times(events: list[dict], stop: str, kind: str) -> list[float]:
    """s: the times of the mechanics' armature stop events on ``stop`` ("rest" or "pole")
    of ``kind`` ("start": it reached the stop, "end": it left it)."""
    return [float(e["time"]) for e in events if e.get("stop") == stop and e["kind"] == f"armature_stop_{kind}"]


def relay_metrics(waves: dict, operations: list[dict], drive, magnet, events: list[dict], resistance: float,
                  received: float | None = None) -> dict:
    """The ``relay`` block (module docstring). waves: the run's columns (SI); operations:
    the contact's (coupling.core.metrics.operations; [] without a contact); drive: the
    circuit's CoilDrive (its on_time and off_time), or None for a netlist's coil; magnet:
    the coupling.laws.magnet magnet; events: the mechanics' events (its armature's stop
    events); resistance: ohm, the coil's winding; received: J, the work the mechanics
    received from the armature's drive (coupling.core.exchange.CoilLink.receive), or None
    (no interface keys)."""
    t = np.asarray(waves["time"], float)
    i = np.asarray(waves["coil_current"], float)
    v = np.asarray(waves["coil_voltage"], float)
    psi = np.asarray(waves["coil_flux_linkage"], float)
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
        lifted = stop_times(events, "rest", "end")
        if lifted:
            out["pull_in_current"] = float(np.interp(lifted[0], t, i))
        arrived = stop_times(events, "pole", "start")
        if arrived:
            out["armature_arrival"] = arrived[0]
        if off is not None:
            left = [s for s in stop_times(events, "pole", "end") if s >= off]
            if left:
                out["drop_out_current"] = float(np.interp(left[0], t, i))
        # The product of the step's mean current and mean voltage, not the mean of their
        # product: into_coil - copper is then exactly sum(i_mean h (v - R i)_mean), the
        # current's trapezoid against the trapezoid of d(psi)/dt, which the circuit's flux
        # increments and the magnet's trapezoid of i d(psi) meet term by term; the trapezoid
        # of v i would add sum(h di d(v - R i)) / 4, an O(h^2) error of the audit alone
        # (half the default relay's residual at ngspice's 240 us steps; docs/coupling.md).
        h = np.diff(t)
        i_mean = 0.5 * (i[1:] + i[:-1])
        into = float(np.sum(h * i_mean * 0.5 * (v[1:] + v[:-1])))
        copper = float(np.sum(h * resistance * i_mean * i_mean))
        stored = float(magnet.energy(psi[-1], gap[-1]) - magnet.energy(psi[0], gap[0]))
        work = float(np.sum(0.5 * (force[1:] + force[:-1]) * -np.diff(gap)))  # trapezoid in the gap
        residual = into - copper - stored - work
        out["energy"] = dict(into_coil=into, copper=copper, magnetic_change=stored, armature_work=work,
                             residual=residual, relative_residual=abs(residual) / abs(into) if into else None)
        if received is not None:
            interface = work - received
            out["energy"].update(armature_received=received, interface_residual=interface,
                                 interface_relative_residual=abs(interface) / abs(into) if into else None)
    return out
