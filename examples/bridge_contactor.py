"""A double-break bridge switching a DC load: two arcs in series against one contact of the same gap.

examples/bridge_contactor.toml: a free steel bridge on two rivets pressed onto two fixed
contacts "a" and "b" (make, with bounces), then pulled off (break). The circuit's two
contacts are in series in one loop (circuit.template = "bridge"): the load current flows
only while both rivets touch, and at the break each contact draws its own arc. The same
motion switching the same circuit through one contact (template "resistive": one arc
across the nearer rivet's gap) is run beside it.

While the arcs burn the loop is V_s = (R_s + R_L + n R_arc) I + n U_min + E_col d_sum
(n arcs, d_sum their summed gap), so they go out where I = I_min:

    d_sum* = (V_s - n U_min - I_min (R_s + R_L + n R_arc)) / E_col,

1.43 mm summed (0.71 mm per contact) for the bridge, 3.83 mm for one contact: the bridge
opens its load in less than half the arc time. Written to --out: bridge/ and one_contact/
(the result folders), break.png (the load current and the switch's voltage at the break,
both) and example.json.

    .venv/bin/python examples/bridge_contactor.py [--fast] [--out DIR]
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

import example_cli  # noqa: E402  (examples/example_cli.py, next to this script)

NAME = "bridge_contactor"
SCENE = Path(__file__).with_name(f"{NAME}.toml")


def extinction_gap(result, arcs: int) -> dict:
    """The break's arc: where it went out (the last sample with an arc burning), the summed gap
    of its contacts there (m) and the closed form d_sum* for ``arcs`` arcs in series."""
    w = result.waveform_columns
    c = result.scene.circuit.circuit
    arc = c.arc
    names = [b.suffix for b in c.contacts] if arcs > 1 else [""]
    brk = result.operations[-1]["break"]
    after = w["time"] > brk["time"]
    on = np.any([np.abs(w[f"arc_current{n}"]) > 1e-3 for n in names], axis=0) & after
    k = int(np.flatnonzero(on)[-1])
    gap = float(sum(w[f"gap{n}"][k] for n in names))
    loop = c.source.source_resistance + c.wiring.wiring_resistance + c.load.load_resistance + arcs * arc.resistance
    closed_form = (c.source.voltage - arcs * arc.min_voltage - arc.min_current * loop) / arc.column_gradient
    return dict(time=float(w["time"][k]), gap=gap, gap_closed_form=float(closed_form),
                break_time=brk["time"], arc_duration=brk["arc_duration"], arc_energy=brk["arc_energy"],
                complete=brk["complete"])


def plot(results: dict, path: Path) -> None:
    fig, (ax_i, ax_v) = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
    t0 = results["bridge"].operations[-1]["break"]["time"]
    for label, res in results.items():
        w = res.waveform_columns
        sel = (w["time"] > t0 - 2e-4) & (w["time"] < t0 + 2e-3)
        t = (w["time"][sel] - t0) * 1e3
        ax_i.plot(t, w["load_current"][sel], label=label.replace("_", " "))
        ax_v.plot(t, w["contact_voltage"][sel], label=label.replace("_", " "))
    ax_i.set_ylabel("load current (A)")
    ax_v.set_ylabel("voltage across the switch (V)")
    ax_v.set_xlabel("time from the break (ms)")
    ax_i.legend()
    ax_i.set_title("two arcs in series (bridge) against one contact of the same gap")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(fast: bool = False, out: str | Path | None = None) -> dict:
    out = Path(out) if out else Path("runs/examples") / NAME
    out.mkdir(parents=True, exist_ok=True)
    bridge = load_scene(SCENE)
    if fast:
        bridge = bridge.set("solver.t_end", 5e-3)
    scenes = {"bridge": bridge, "one_contact": bridge.set("circuit.template", "resistive")}
    results = {name: run(scene) for name, scene in scenes.items()}
    for name, res in results.items():
        res.save(out / name, overwrite=True)
    plot(results, out / "break.png")
    numbers = {"bridge": extinction_gap(results["bridge"], 2), "one_contact": extinction_gap(results["one_contact"], 1)}
    numbers["bridge"]["closed_intervals"] = [list(iv) for iv in results["bridge"].closed_intervals]
    numbers["arc_duration_ratio"] = numbers["bridge"]["arc_duration"] / numbers["one_contact"]["arc_duration"]
    numbers["status"] = {name: str(res.status) for name, res in results.items()}
    (out / "example.json").write_text(json.dumps(numbers, indent=2))
    return numbers


def _summary(n: dict) -> str:
    b, o = n["bridge"], n["one_contact"]
    return "\n".join([
        f"bridge (two arcs in series): out after {b['arc_duration'] * 1e3:.3f} ms at a summed gap of "
        f"{b['gap'] * 1e3:.3f} mm (closed form {b['gap_closed_form'] * 1e3:.3f} mm), {b['arc_energy'] * 1e3:.2f} mJ",
        f"one contact of the same gap: out after {o['arc_duration'] * 1e3:.3f} ms at {o['gap'] * 1e3:.3f} mm "
        f"(closed form {o['gap_closed_form'] * 1e3:.3f} mm), {o['arc_energy'] * 1e3:.2f} mJ",
        f"arc time ratio {n['arc_duration_ratio']:.2f}",
    ])


def cli(argv=None) -> int:
    return example_cli.run(__doc__, NAME, main, _summary, argv)


if __name__ == "__main__":
    sys.exit(cli())
