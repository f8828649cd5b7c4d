"""Coil suppression and the release: none, a diode, a diode + zener, an RC across the coil.

The built-in default relay (`coupling.default_scene()`: 12 V coil switched on at 1 ms and
off at 9 ms, the contact making a 24 V / 10 ohm load) is released with each suppression
of its coil (`coil.suppression`). What a relay designer trades:

- none: the driver transistor takes the coil's inductive kick up to its avalanche
  voltage (the coil sees supply - breakdown); the flux collapses fastest, the armature
  drops out soonest, the contact opens fast and the break arc is shortest;
- a diode: the coil voltage is held at one forward drop, the driver is safe, but the
  coil current freewheels and decays with the coil's own L/R: the release is several
  times slower, the contact opens slowly and the break arc burns longest;
- a diode + zener: the coil is clamped at -(V_z + V_d), the driver sees supply + V_z:
  most of the speed of "none" at a voltage the driver is rated for;
- an RC (here 360 ohm, 1 uF: R about the coil's, C holding the spike to a few tens of
  volts): in between.

Printed per suppression: release time (coil off -> contact break), drop-out current,
the coil's most negative voltage, the break's arc duration and energy.
Written to --out: suppression.png (coil current, coil voltage and contact voltage around
the release, one colour per suppression), one run folder per suppression, example.json.

    .venv/bin/python examples/relay_suppression.py [--fast] [--out DIR]
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from coupling import default_scene, run  # noqa: E402

import example_cli  # noqa: E402  (examples/example_cli.py, next to this script)

NAME = "relay_suppression"
T_END = 0.02  # s: the diode's release (about 6.5 ms after the coil is switched off) and its arc
SUPPRESSIONS = {
    "none": {"coil.suppression": "none"},
    "diode": {"coil.suppression": "diode"},
    "zener": {"coil.suppression": "zener"},
    "rc": {"coil.suppression": "rc", "coil.rc_resistance": 360.0, "coil.rc_capacitance": 1e-6},
}
COLORS = {"none": "#d62728", "diode": "#1f77b4", "zener": "#2ca02c", "rc": "#ff7f0e"}


def main(fast: bool = False, out=None) -> dict:
    """Run the four releases (fast: the same runs, about a second each) and return the
    numbers the summary prints."""
    out = Path(out) if out else Path("runs/examples") / NAME
    out.mkdir(parents=True, exist_ok=True)
    # the released coil rings (with the RC: through zero, ~6 ms period) over the default relay's
    # macro steps of up to 1 ms, and the coil-armature interface's residual reaches 1.4e-3 of
    # the energy into the coil (> solver.energy_tolerance: warned, docs/coupling.md)
    base = default_scene().set("solver.t_end", T_END).set("coupling.max_macro_step", 1e-4)
    off = float(base.raw["coil"]["off_time"])
    rows, waves = {}, {}
    for kind, keys in SUPPRESSIONS.items():
        res = run(base.update(keys))
        res.save(out / kind, overwrite=True)
        brk = res.operations[-1].get("break", {}) if res.operations else {}
        rows[kind] = dict(status=res.status.value, release_time=res.relay["release_time"],
                          drop_out_current=res.relay["drop_out_current"],
                          coil_voltage_min=float(res.waveforms.coil_voltage.min()),
                          arc_duration=brk.get("arc_duration"), arc_energy=brk.get("arc_energy"),
                          break_complete=brk.get("complete"), operate_time=res.relay["operate_time"])
        waves[kind] = res.waveforms
    _plot(waves, off, out / "suppression.png")
    numbers = dict(off_time=off, t_end=T_END, suppressions=rows,
                   rc=dict(resistance=SUPPRESSIONS["rc"]["coil.rc_resistance"],
                           capacitance=SUPPRESSIONS["rc"]["coil.rc_capacitance"]))
    (out / "example.json").write_text(json.dumps(numbers, indent=2))
    return numbers


def _plot(waves: dict, off: float, path: Path) -> None:
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(8, 7.5), constrained_layout=True)
    for kind, w in waves.items():
        sel = w.time >= off - 0.5e-3
        t = (w.time[sel] - off) * 1e3
        axes[0].plot(t, w.coil_current[sel] * 1e3, color=COLORS[kind], lw=1.1, label=kind)
        axes[1].plot(t, w.coil_voltage[sel], color=COLORS[kind], lw=1.1)
        axes[2].plot(t, w.contact_voltage[sel], color=COLORS[kind], lw=1.1)
    for ax, label in zip(axes, ("coil current (mA)", "coil voltage (V)", "contact voltage (V)")):
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    axes[0].legend(title="suppression", fontsize=9)
    axes[0].set_title("the default relay released: coil switched off at 0 ms")
    axes[-1].set_xlabel("time after the coil is switched off (ms)")
    fig.savefig(path, dpi=120)
    plt.close(fig)


def summary(n: dict) -> str:
    lines = ["suppression  release (ms)  drop-out (mA)  coil min (V)  arc (ms)  arc energy (mJ)"]
    for kind, r in n["suppressions"].items():
        def ms(v):
            return f"{v * 1e3:9.3f}" if v is not None else "        -"
        lines.append(f"{kind:11s}  {ms(r['release_time'])}     {ms(r['drop_out_current'])}      "
                     f"{r['coil_voltage_min']:8.1f}  {ms(r['arc_duration'])}  {ms(r['arc_energy'])}"
                     + ("" if r["status"] == "ok" else f"  ({r['status']})"))
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(example_cli.run(__doc__, NAME, main, summary, fast_help="the same runs (about a second each)"))
