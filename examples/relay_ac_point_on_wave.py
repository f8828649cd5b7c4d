"""Point on wave: the default relay breaking 230 V AC at six phases of the mains.

The built-in default relay (`coupling.default_scene()`: its coil switched off at 9 ms, the
contact parting at 9.32 ms) switches a 230 V, 50 Hz, 100 ohm load (`[circuit] frequency`,
`voltage` as the RMS value). The contact parts at the same instant in every run; what moves
is where on the mains' wave it parts (`circuit.phase_deg`, the source's phase at t = 0).
The arc then burns from the parting to the next current zero, where it goes out at its
minimum current: from nearly nothing (parting just before a zero) to nearly a half period
(parting just after one), and its energy with it. This is why AC relays are rated far above
their DC rating at the same gap, and why synchronous switching (parting just before a zero)
saves the contacts.

Printed per phase: the current at the parting, the arc's duration and energy, and the
break's peak voltage. Written to --out: point_on_wave.png (arc duration and energy against
the phase at the parting), one run folder per phase, example.json.

    .venv/bin/python examples/relay_ac_point_on_wave.py [--fast] [--out DIR]
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from coupling import default_scene, run  # noqa: E402

import example_cli  # noqa: E402  (examples/example_cli.py, next to this script)

NAME = "relay_ac_point_on_wave"
MAINS = {"circuit.voltage": 230.0, "circuit.frequency": 50.0, "circuit.load_resistance": 100.0}
T_END = 0.02  # s: the break at 9.3 ms and its arc, at most a half period (10 ms)
PHASES = (0.0, 30.0, 60.0, 90.0, 120.0, 150.0)  # deg, the mains' phase at t = 0


def main(fast: bool = False, out=None) -> dict:
    """Run the six breaks (fast: the same runs, about a second each) and return the numbers
    the summary prints."""
    out = Path(out) if out else Path("runs/examples") / NAME
    out.mkdir(parents=True, exist_ok=True)
    base = default_scene().update(MAINS).set("solver.t_end", T_END)
    rows = []
    for phase in PHASES:
        res = run(base.set("circuit.phase_deg", phase))
        res.save(out / f"phase_{phase:03.0f}", overwrite=True)
        brk = res.operations[-1].get("break", {}) if res.operations else {}
        rows.append(dict(phase_deg=phase, status=res.status.value, break_time=brk.get("time"),
                         current_at_break=brk.get("current_at_break"), arc_duration=brk.get("arc_duration"),
                         arc_energy=brk.get("arc_energy"), peak_voltage=brk.get("peak_voltage"),
                         complete=brk.get("complete")))
    circuit = base.circuit.circuit
    numbers = dict(frequency=MAINS["circuit.frequency"], voltage_rms=MAINS["circuit.voltage"],
                   loop_resistance=circuit.source.source_resistance + circuit.wiring.wiring_resistance
                   + MAINS["circuit.load_resistance"], min_current=circuit.arc.min_current, t_end=T_END, runs=rows)
    _plot(rows, MAINS["circuit.frequency"], out / "point_on_wave.png")
    (out / "example.json").write_text(json.dumps(numbers, indent=2))
    return numbers


def parting_phase(row: dict, frequency: float) -> float:
    """deg in [0, 360): the mains' phase at the contact's parting."""
    return (row["phase_deg"] + 360.0 * frequency * row["break_time"]) % 360.0


def _plot(rows: list[dict], frequency: float, path: Path) -> None:
    ok = [r for r in rows if r["status"] == "ok" and r["arc_duration"] is not None]
    phase = [parting_phase(r, frequency) for r in ok]
    fig, axes = plt.subplots(2, 1, sharex=True, figsize=(7, 6), constrained_layout=True)
    axes[0].plot(phase, [r["arc_duration"] * 1e3 for r in ok], "o")
    axes[1].plot(phase, [r["arc_energy"] * 1e3 for r in ok], "o")
    axes[0].set_ylabel("break arc duration (ms)")
    axes[1].set_ylabel("break arc energy (mJ)")
    axes[1].set_xlabel("mains phase at the parting (deg)")
    for ax in axes:
        ax.grid(alpha=0.3)
    axes[0].set_title("the default relay breaking 230 V AC, 100 ohm, at six points on the wave")
    fig.savefig(path, dpi=120)
    plt.close(fig)


def summary(n: dict) -> str:
    lines = ["phase at t=0 (deg)  at parting (deg)  current (A)  arc (ms)  arc energy (mJ)  peak (V)"]
    for r in n["runs"]:
        if r["status"] != "ok" or r["arc_duration"] is None:
            lines.append(f"{r['phase_deg']:18.0f}  ({r['status']})")
            continue
        lines.append(f"{r['phase_deg']:18.0f}  {parting_phase(r, n['frequency']):16.1f}  "
                     f"{r['current_at_break']:11.3f}  {r['arc_duration'] * 1e3:8.3f}  {r['arc_energy'] * 1e3:15.2f}  "
                     f"{r['peak_voltage']:8.1f}")
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(example_cli.run(__doc__, NAME, main, summary, fast_help="the same runs (about a second each)"))
