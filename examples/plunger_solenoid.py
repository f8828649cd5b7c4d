"""A plunger solenoid pulling in: coil current, magnetic force and armature travel.

examples/plunger_solenoid.toml switches 12 V onto the solenoid's coil at t = 0; the
armature travels from its rest stop (5 mm working gap) to the stop at the pole (0.25 mm)
and stays there. The script runs it and reports

- the current before the armature has moved much, against the coil's L/R rise with the
  magnet's open-gap inductance: i(t) = V/R (1 - exp(-t R / L(5 mm)));
- the characteristic dip: while the armature flies the gap closes, the inductance rises
  and the back-EMF i dL/dt pulls the current down; its minimum marks the arrival;
- the arrival time at the pole, the force at the current's peak and at the pole, and the current
  rising afterwards towards V/R with the closed magnet's (saturating) inductance; the stop
  at the pole (1e11 N/m, 400 N s/m: a restitution of 0.99 for this armature) throws the
  armature back, and each time the gap opens again the flux the coil holds drives its
  current above V/R;
- the coil's energy balance (energy into the coil = copper loss + stored magnetic
  energy + work on the armature + residual).

Written to --out: the run's files (summary.json, waveforms.csv, ...), solenoid.png and
example.json.

    .venv/bin/python examples/plunger_solenoid.py [--fast] [--out DIR]
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from coupling import load_scene, run  # noqa: E402
from coupling.core.device import device  # noqa: E402

import example_cli  # noqa: E402  (examples/example_cli.py, next to this script)

NAME = "plunger_solenoid"
SCENE = Path(__file__).with_name(f"{NAME}.toml")
EARLY = 0.5e-3  # s: a time before the armature has moved a thousandth of its travel


def main(fast: bool = False, out=None) -> dict:
    """Run the scene (fast: the same run, it takes a fraction of a second) and return the
    numbers the summary prints."""
    out = Path(out) if out else Path("runs/examples") / NAME
    scene = load_scene(SCENE)
    res = run(scene)
    res.save(out, overwrite=True)
    w = res.waveforms
    t, i, x, f = (w[c].to_numpy() for c in ("time", "coil_current", "armature_position", "magnetic_force"))
    coil = scene.raw["coil"]
    spec = device(scene.raw)
    travel = scene.mech.armature.travel
    rest_gap = float(w.working_gap.iloc[0])
    volts, ohm = float(coil["voltage"]), spec.resistance
    tau_open = float(spec.magnet.inductance(rest_gap)) / ohm
    k = int(np.searchsorted(t, EARLY))
    arrival = res.relay["armature_arrival"]
    before = t < arrival
    numbers = dict(
        status=res.status.value,
        voltage=volts, resistance=ohm, tau_open=tau_open,
        early=dict(time=float(t[k]), current=float(i[k]), travel=float(x[k]),
                   closed_form=volts / ohm * (1.0 - np.exp(-t[k] / tau_open))),
        arrival=arrival,
        peak_current_before_arrival=float(i[before].max()),
        current_at_arrival=float(np.interp(arrival, t, i)),
        force_at_peak_current=float(f[np.argmax(np.where(before, i, -np.inf))]),
        force_at_pole=float(np.interp(arrival, t, f)),
        final_current=float(i[-1]), steady_current=volts / ohm,
        travel=travel, energy=res.relay["energy"],
        macro_steps=res.stats["macro_steps"], wall_time=res.stats["wall_time"])
    _plot(t, i, x, f, arrival, out / "solenoid.png")
    (out / "example.json").write_text(json.dumps(numbers, indent=2))
    return numbers


def _plot(t, i, x, f, arrival, path: Path) -> None:
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(7, 7), constrained_layout=True)
    for ax, y, label in zip(axes, (i, f, x * 1e3), ("coil current (A)", "magnetic force (N)", "armature travel (mm)")):
        ax.plot(t * 1e3, y, lw=1.2)
        ax.axvline(arrival * 1e3, color="0.6", lw=0.8, ls="--")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].set_title("plunger solenoid, 12 V step (dashed: arrival at the pole)")
    axes[-1].set_xlabel("time (ms)")
    fig.savefig(path, dpi=120)
    plt.close(fig)


def summary(n: dict) -> str:
    e = n["energy"]
    return "\n".join([
        f"status {n['status']}; {n['macro_steps']} macro steps, {n['wall_time']:.2f} s",
        f"at {n['early']['time'] * 1e3:.2f} ms: {n['early']['current']:.4f} A (L/R rise with L(5 mm): "
        f"{n['early']['closed_form']:.4f} A, tau = {n['tau_open'] * 1e3:.2f} ms)",
        f"arrival at the pole {n['arrival'] * 1e3:.3f} ms; the current dips from {n['peak_current_before_arrival']:.3f} A "
        f"to {n['current_at_arrival']:.3f} A on the way",
        f"force {n['force_at_peak_current']:.2f} N at the current's peak, {n['force_at_pole']:.1f} N at the pole",
        f"current at the end {n['final_current']:.3f} A (V/R = {n['steady_current']:.2f} A)",
        f"energy into the coil {e['into_coil'] * 1e3:.2f} mJ = copper {e['copper'] * 1e3:.2f} + magnetic "
        f"{e['magnetic_change'] * 1e3:.2f} + armature {e['armature_work'] * 1e3:.2f} mJ, residual "
        f"{e['relative_residual']:.1e} of it",
    ])


if __name__ == "__main__":
    sys.exit(example_cli.run(__doc__, NAME, main, summary, fast_help="the same run (it takes well under a second)"))
