"""The source paper's free drop, kept as an example: a steel bar dropped on a block.

examples/free_drop.toml is the scene of coupling.builtin_scene("free_drop") (the default
scene of `switchsim run` before the switch mechanisms): the paper's steel link released
1 mm above the block at 30 deg, moving down at 1 m/s, closing a 24 V / 12 ohm circuit.
The script reports each contact (time, peak force, normal speeds, restitution), and that
the bar then flies off: the run ends open, gravity the only force on the bar. Checks:
the first touchdown at t = (sqrt(v0^2 + 2 g h) - v0)/g with speed sqrt(v0^2 + 2 g h);
after the last contact the centre of mass falls at g.

    .venv/bin/python examples/free_drop.py [--fast] [--out DIR]
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

from coupling import load_scene, run

import example_cli  # noqa: E402  (examples/example_cli.py, next to this script)

NAME = "free_drop"
SCENE = Path(__file__).with_name(f"{NAME}.toml")


def scene(fast: bool = False):
    """The scene; fast: the contacts only (3 ms) and a looser mechanics tolerance."""
    sc = load_scene(SCENE)
    if fast:
        sc = sc.set("solver.t_end", 3e-3).set("solver.rtol", 1e-5).set("output.plots", False)
    return sc


def touchdown(sc) -> tuple[float, float]:
    """(s, m/s): free-fall time to the first contact and the speed there, from the scene."""
    m = sc.mech
    v0 = -m.initial.velocity[2]
    h, g = m.initial.height, m.gravity
    v = math.sqrt(v0 * v0 + 2.0 * g * h)
    return (v - v0) / g, v


def analyse(result) -> dict:
    c = result.mechanics.contacts
    h = result.mechanics.history
    b = result.bounce
    t_cf, v_cf = touchdown(result.scene)
    out = dict(contacts=c[["tip", "t_start", "t_end", "peak_force", "normal_speed_in", "normal_speed_out",
                           "kinematic_restitution"]].to_dict("records"),
               bounces=b["bounces"], final_state=b["final_state"], arc_energy=b["arc_energy"],
               touchdown_closed_form=t_cf, touchdown_speed_closed_form=v_cf,
               wall_time_s=result.stats.get("wall_time"))
    after = h.time.to_numpy() > float(c.t_end.max()) + 1e-4
    if after.sum() > 10:
        t, vz = h.time.to_numpy()[after], h.vz.to_numpy()[after]
        out["flight_acceleration"] = float(np.polyfit(t, vz, 1)[0])
        out["final_vz"] = float(vz[-1])
        out["final_gap"] = float(min(h.tip_height_0.iloc[-1], h.tip_height_1.iloc[-1]))
    return out


def main(fast: bool = False, out: str | Path | None = None) -> dict:
    out = Path(out) if out is not None else Path("runs/examples") / NAME
    out.mkdir(parents=True, exist_ok=True)
    result = run(scene(fast))
    result.save(out)
    numbers = analyse(result)
    (out / "example.json").write_text(json.dumps(numbers, indent=2))
    return numbers


def _summary(n: dict) -> str:
    lines = [f"touchdown closed form {n['touchdown_closed_form'] * 1e3:.4f} ms at {n['touchdown_speed_closed_form']:.4f} m/s"]
    for k in n["contacts"]:
        lines.append(f"tip {k['tip']}: {k['t_start'] * 1e3:.4f}-{k['t_end'] * 1e3:.4f} ms, peak {k['peak_force']:.0f} N, "
                     f"in {k['normal_speed_in']:.4f} m/s, out {k['normal_speed_out']:.4f} m/s, "
                     f"restitution {k['kinematic_restitution']:.3f}")
    line = f"{n['bounces']} bounce(s), ends {n['final_state']}, arc energy {n['arc_energy'] * 1e3:.1f} mJ"
    if "flight_acceleration" in n:
        line += (f"; then flies: centre of mass at {n['final_vz']:.3f} m/s, accelerating at "
                 f"{n['flight_acceleration']:.3f} m/s^2, {n['final_gap'] * 1e3:.3f} mm above the block at the end")
    lines.append(line)
    return "\n".join(lines)


def cli(argv=None) -> int:
    return example_cli.run(__doc__, NAME, main, _summary, argv)


if __name__ == "__main__":
    sys.exit(cli())
