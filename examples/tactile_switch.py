"""A tactile switch: a snap dome pressed and released by a finger, and the RC that gives one edge each way.

The key of examples/tactile_switch.toml (a plunger on a snap dome, docs/mechanics.md
section 12) is pressed by a finger force rising to 3 N in 10 ms, held, and released
over 10 ms; its contact pulls a microcontroller pin low behind the mcu_input template's
pull-up R to 3.3 V, a 100 ohm series resistor and the filter C. The script reports the make
and break patterns the model gives (make when the dome snaps past its 1.6 N peak, break
when the finger has fallen to the dome's return force at the pad), sweeps R and C (one
coupled run each, Scene.update and coupling.run in a plain loop), counts the edges the
pin's Schmitt input sees (summary.json "logic") and names the smallest R C that gives one
edge per press and one per release (two edges in all).

What the model gives against a measured tactile switch (issue 20: 32 presses, 10 k pull-up,
a clean make and up to 1.2 ms of chatter at release): a short make bounce (the plunger's
impact after the snap, one rebound at the contact's restitution) and a clean break (the
contact force falls smoothly to zero and the dome's return pushes the plunger off the pad;
nothing brings it back). The model's moving part is one rigid plunger on one contact point:
the dome shell's own modes, its centre rolling off the pad over several points and the
films of a contact at vanishing force, which are the likely causes of the measured release
chatter, are not in it. So the script also gives the RC that covers the measured chatter by
the closed form: the pin must not reach V_high within any opening of the chatter, which
holds for every pattern when (R + R_series) C ln(Vcc / (Vcc - V_high)) exceeds its
1.2 ms.

    .venv/bin/python examples/tactile_switch.py [--fast] [--out DIR]
"""

from __future__ import annotations

import json
import math
import sys
import tomllib
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from coupling import load_scene, run  # noqa: E402

import example_cli  # noqa: E402  (examples/example_cli.py, next to this script)

NAME = "tactile_switch"
SCENE = Path(__file__).with_name(f"{NAME}.toml")
PULLUPS = (1e3, 10e3, 47e3)  # ohm
CAPACITANCES = (1e-9, 10e-9, 100e-9)  # F
FAST_PULLUPS = (1e3, 10e3)
FAST_CAPACITANCES = (1e-9, 10e-9)
MEASURED_RELEASE_CHATTER = 1.2e-3  # s: the measurement (32 presses, 10 k pull-up)


def release_start() -> float:
    """s: when the finger starts to let go (the third point of its time table)."""
    return float(tomllib.loads(SCENE.read_text())["force"][0]["time"][2])


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
            logic = result.logic
            rows.append(dict(
                pull_resistance=r, input_capacitance=c, rc=r * c, edges=logic["edges"],
                edge_times=[e["time"] for e in logic["edge_table"]], final_level=logic["final_level"],
                closed_intervals=[list(iv) for iv in result.closed_intervals], status=result.status,
                result=result))
    return rows


def patterns(intervals: list, release: float) -> dict:
    """The make pattern (first make, bounce openings, s) among the contacts that begin
    before the finger starts to let go at ``release`` (s), and the break: the first break
    after that, the last break and the chatter between them (s)."""
    pressed = [iv for iv in intervals if iv[0] < release]
    openings = [b[0] - a[1] for a, b in zip(pressed[:-1], pressed[1:])]
    first_break = min(b for _, b in intervals if b > release)
    return dict(first_make=pressed[0][0], make_bounces=len(pressed) - 1, bounce_openings=openings,
                settled_make=pressed[-1][0], make_chatter=pressed[-1][0] - pressed[0][0],
                first_break=first_break, last_break=intervals[-1][1], release_chatter=intervals[-1][1] - first_break)


def plot(rows: list[dict], out: Path) -> None:
    """pin_voltage.png: the pin through the press and the release for each (R, C)."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), sharey=True)
    iv = rows[0]["closed_intervals"]
    windows = ((iv[0][0] - 1e-4, iv[-1][0] + 4e-4), (iv[-1][1] - 2e-4, iv[-1][1] + 1.2e-3))
    for ax, (a, b), title in zip(axes, windows, ("press (make)", "release (break)")):
        for row in rows:
            w = row["result"].waveform_columns
            keep = (w["time"] >= a) & (w["time"] <= b)
            ax.plot(w["time"][keep] * 1e3, w["v(pin)"][keep], lw=1,
                    label=f"{row['pull_resistance'] / 1e3:g} k, {row['input_capacitance'] * 1e9:g} nF: "
                          f"{row['edges']} edges")
        for lo, hi in iv:
            ax.axvspan(max(lo, a) * 1e3, min(hi, b) * 1e3, color="0.9", zorder=0)
        logic = rows[0]["result"].scene.metrics.logic
        for level in (logic.low, logic.high):
            ax.axhline(level, color="k", ls="--", lw=0.8)
        ax.set(xlabel="time (ms)", title=title)
    axes[0].set_ylabel("v(pin) (V)")
    axes[1].legend(fontsize=7)
    fig.suptitle("tactile switch: the pin (grey: contact closed)")
    fig.tight_layout()
    fig.savefig(out / "pin_voltage.png", dpi=120)
    plt.close(fig)


def main(fast: bool = False, out: str | Path | None = None) -> dict:
    out = Path(out) if out is not None else Path("runs/examples") / NAME
    out.mkdir(parents=True, exist_ok=True)
    scene = base_scene(fast)
    rows = sweep(scene, FAST_PULLUPS if fast else PULLUPS, FAST_CAPACITANCES if fast else CAPACITANCES)
    single = [r for r in rows if r["edges"] == 2]  # one edge per press, one per release
    chosen = min(single, key=lambda r: r["rc"]) if single else None
    (chosen or rows[-1])["result"].save(out)
    plot(rows, out)
    circ = scene.circuit.circuit
    crossing = math.log(circ.voltage / (circ.voltage - circ.logic_high))  # time constants from 0 to V_high
    numbers = dict(
        voltage=circ.voltage, series_resistance=circ.series_resistance, logic_low=circ.logic_low,
        logic_high=circ.logic_high, patterns=patterns(rows[0]["closed_intervals"], release_start()),
        grid=[{k: v for k, v in r.items() if k != "result"} for r in rows],
        chosen=None if chosen is None else {k: v for k, v in chosen.items() if k != "result"},
        measured_release_chatter=MEASURED_RELEASE_CHATTER,
        rc_for_measured_chatter=MEASURED_RELEASE_CHATTER / crossing,  # (R + R_series) C, s
    )
    (out / "example.json").write_text(json.dumps(numbers, indent=2))
    return numbers


def _summary(n: dict) -> str:
    p = n["patterns"]
    caps = sorted({r["input_capacitance"] for r in n["grid"]})
    pullups = sorted({r["pull_resistance"] for r in n["grid"]})
    edges = {(r["pull_resistance"], r["input_capacitance"]): r["edges"] for r in n["grid"]}
    lines = [f"make: first at {p['first_make'] * 1e3:.3f} ms, {p['make_bounces']} bounce(s) "
             f"(openings {', '.join(f'{g * 1e6:.1f}' for g in p['bounce_openings'])} us), closed for good at "
             f"{p['settled_make'] * 1e3:.3f} ms",
             f"break: first at {p['first_break'] * 1e3:.3f} ms, last at {p['last_break'] * 1e3:.3f} ms: "
             f"{p['release_chatter'] * 1e6:.0f} us of chatter (the measured switch: up to "
             f"{n['measured_release_chatter'] * 1e3:g} ms)",
             "edges the input sees per press and release (rows: pull-up R, columns: C; 2 is one each way)",
             "R \\ C      " + "".join(f"{c * 1e9:>9g} nF" for c in caps)]
    for r in pullups:
        lines.append(f"{r / 1e3:>6g} kohm" + "".join(f"{edges[(r, c)]:>12d}" for c in caps))
    c = n["chosen"]
    lines.append("no (R, C) of the grid gives one edge each way" if c is None else
                 f"smallest R C with one edge each way (the model's bounces): {c['pull_resistance'] / 1e3:g} kohm x "
                 f"{c['input_capacitance'] * 1e9:g} nF = {c['rc'] * 1e6:.3g} us")
    lines.append(f"to cover the measured release chatter as well: (R + {n['series_resistance']:g} ohm) C >= "
                 f"{n['rc_for_measured_chatter'] * 1e3:.3g} ms, e.g. 10 kohm x 100 nF")
    return "\n".join(lines)


def cli(argv=None) -> int:
    return example_cli.run(__doc__, NAME, main, _summary, argv,
                           fast_help="a 2 x 2 grid at rtol 1e-5 (some seconds)")


if __name__ == "__main__":
    sys.exit(cli())
