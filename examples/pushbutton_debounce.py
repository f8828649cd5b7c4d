"""A pushbutton read by a microcontroller input: which pull-up R and filter C give one edge per press?

The lever of examples/pushbutton_debounce.toml (the pushbutton example's, pressed and held)
closes a contact to ground; the input pin sits behind the mcu_input template's pull-up R
to 3.3 V, a 100 ohm series resistor and the filter C to ground, and reads it through
Schmitt thresholds 0.99 / 2.31 V. The script runs the coupled scene for every (R, C) of a
grid (Scene.update and coupling.run in a plain loop), counts the edges the input sees
(summary.json "logic"), prints them as a table, and names the smallest R C that gives one
edge. The physics: each bounce opening lets the pin charge towards Vcc with
tau = (R + R_series) C, from the level the previous contact left; it reads high again only
if the opening lasts longer than tau ln((Vcc - v0) / (Vcc - V_high)). One edge per press
needs that time to exceed the longest bounce opening (the contacts, discharging C through
R_series in tens of ns to us, pull it low each time).

    .venv/bin/python examples/pushbutton_debounce.py [--fast] [--out DIR]
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from coupling import load_scene, run  # noqa: E402

import example_cli  # noqa: E402  (examples/example_cli.py, next to this script)

NAME = "pushbutton_debounce"
SCENE = Path(__file__).with_name(f"{NAME}.toml")
PULLUPS = (1e3, 4.7e3, 10e3, 22e3, 47e3)  # ohm
CAPACITANCES = (1e-9, 10e-9, 33e-9, 100e-9)  # F
FAST_PULLUPS = (1e3, 10e3, 47e3)
FAST_CAPACITANCES = (10e-9, 100e-9)


def base_scene(fast: bool = False):
    """The scene with nothing written but summary.json and the tables (fast: rtol 1e-5)."""
    scene = load_scene(SCENE).set("output.plots", False)
    return scene.set("solver.rtol", 1e-5) if fast else scene


def sweep(scene, pullups, capacitances) -> list[dict]:
    """One coupled run per (R, C): the logic summary and the contact's closed intervals."""
    rows = []
    for r in pullups:
        for c in capacitances:
            result = run(scene.update({"circuit.pull_resistance": r, "circuit.input_capacitance": c}))
            logic, bounce = result.logic, result.bounce
            circ = result.scene.circuit.circuit
            rows.append(dict(
                pull_resistance=r, input_capacitance=c, rc=r * c, break_time_constant=circ.break_time_constant,
                edges=logic["edges"], first_edge=logic["first_edge"], last_edge=logic["last_edge"],
                edge_burst=logic["edge_burst"], final_level=logic["final_level"],
                latency=None if logic["first_edge"] is None else logic["first_edge"] - bounce["first_make"],
                closed_intervals=[list(iv) for iv in result.closed_intervals], status=result.status,
                result=result))
    return rows


def smallest_single_edge(rows: list[dict]) -> dict | None:
    """The row of the smallest R C whose input sees exactly one edge."""
    single = [r for r in rows if r["edges"] == 1]
    return min(single, key=lambda r: r["rc"]) if single else None


def plot(rows: list[dict], chosen: dict | None, out: Path) -> None:
    """pin_voltage.png: the pin through the press at the chosen R for each C, with the thresholds."""
    r_shown = chosen["pull_resistance"] if chosen else rows[-1]["pull_resistance"]
    fig, ax = plt.subplots(figsize=(9, 4.5))
    for row in rows:
        if row["pull_resistance"] != r_shown:
            continue
        w = row["result"].waveform_columns
        ax.plot(w["time"] * 1e3, w["v(pin)"], lw=1,
                label=f"C = {row['input_capacitance'] * 1e9:g} nF: {row['edges']} edge(s)")
    logic = rows[0]["result"].scene.metrics.logic
    for level in (logic.low, logic.high):
        ax.axhline(level, color="k", ls="--", lw=0.8)
    for a, b in rows[0]["closed_intervals"]:
        ax.axvspan(a * 1e3, b * 1e3, color="0.9", zorder=0)
    ax.set(xlabel="time (ms)", ylabel="v(pin) (V)",
           title=f"pull-up {r_shown / 1e3:g} kohm: the pin through the press (grey: contact closed)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "pin_voltage.png", dpi=120)
    plt.close(fig)


def main(fast: bool = False, out: str | Path | None = None) -> dict:
    out = Path(out) if out is not None else Path("runs/examples") / NAME
    out.mkdir(parents=True, exist_ok=True)
    scene = base_scene(fast)
    rows = sweep(scene, FAST_PULLUPS if fast else PULLUPS, FAST_CAPACITANCES if fast else CAPACITANCES)
    chosen = smallest_single_edge(rows)
    if chosen is not None:
        chosen["result"].save(out)
    plot(rows, chosen, out)
    intervals = rows[0]["closed_intervals"]
    openings = [b2[0] - b1[1] for b1, b2 in zip(intervals[:-1], intervals[1:])]
    circ = scene.circuit.circuit
    numbers = dict(
        voltage=circ.voltage, series_resistance=circ.series_resistance, logic_low=circ.logic_low,
        logic_high=circ.logic_high, bounce_openings=openings,
        grid=[{k: v for k, v in r.items() if k != "result"} for r in rows],
        chosen=None if chosen is None else {k: v for k, v in chosen.items() if k not in ("result", "closed_intervals")},
    )
    (out / "example.json").write_text(json.dumps(numbers, indent=2))
    return numbers


def _summary(n: dict) -> str:
    caps = sorted({r["input_capacitance"] for r in n["grid"]})
    pullups = sorted({r["pull_resistance"] for r in n["grid"]})
    edges = {(r["pull_resistance"], r["input_capacitance"]): r["edges"] for r in n["grid"]}
    lines = [f"bounce openings (us): {', '.join(f'{g * 1e6:.1f}' for g in n['bounce_openings'])}",
             "edges the input sees per press (rows: pull-up R, columns: C)",
             "R \\ C      " + "".join(f"{c * 1e9:>9g} nF" for c in caps)]
    for r in pullups:
        lines.append(f"{r / 1e3:>6g} kohm" + "".join(f"{edges[(r, c)]:>12d}" for c in caps))
    c = n["chosen"]
    if c is None:
        lines.append("no (R, C) of the grid gives one edge: raise R or C")
    else:
        needed = max(n["bounce_openings"], default=0.0)
        crossing = c["break_time_constant"] * math.log(n["voltage"] / (n["voltage"] - n["logic_high"]))
        lines.append(f"smallest R C with one edge: {c['pull_resistance'] / 1e3:g} kohm x "
                     f"{c['input_capacitance'] * 1e9:g} nF = {c['rc'] * 1e3:.3g} ms; from low the pin needs "
                     f"{crossing * 1e6:.0f} us to reach {n['logic_high']:g} V, longer than the longest bounce "
                     f"opening ({needed * 1e6:.0f} us); the edge comes {c['latency'] * 1e6:.1f} us after the "
                     "first make")
    return "\n".join(lines)


def cli(argv=None) -> int:
    return example_cli.run(__doc__, NAME, main, _summary, argv,
                           fast_help="a 3 x 2 grid at rtol 1e-5 (a few seconds)")


if __name__ == "__main__":
    sys.exit(cli())
