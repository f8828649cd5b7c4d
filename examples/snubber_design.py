"""Snubber design: choose R and C for a 24 V / 10 ohm / 5 mH load, and map the bounce time.

Two sweeps of examples/snubber_design.toml on Dask (coupling.app.sweep, one local cluster):

1. The opening of the coil's circuit (the bar lifted off the block at 2 m/s, 2.4 A
   flowing) for every snubber resistance R and capacitance C of a grid. The current goes
   into an arc across the widening gap; once the arc goes out (below I_min) what is left
   rings into the snubber and the contact capacitance: the peak opening voltage is about
   E + I_min sqrt(L / C). Kept: the (R, C) under both limits, PEAK_LIMIT on the peak
   contact voltage and ARC_LIMIT on the arc energy; the choice is the smallest C that
   meets them (the smaller capacitor, and the smaller inrush at the next make), with the
   lowest peak among its R.
2. A drop of the same bar (1 m/s down, restitution 0.8) over a grid of release angles and
   heights: the bounce time (last make - first make) as a map.

Written to --out: rc/ and map/ (the sweeps: results/ Parquet datasets, rc/waveforms/),
peak_voltage.png, arc_energy.png, opening_overlay.png (the contact voltage of each R, C),
bounce_map.png, example.json.

    .venv/bin/python examples/snubber_design.py [--fast] [--out DIR]
"""

from __future__ import annotations

import json
import math
import shutil
import sys
from pathlib import Path

from coupling import load_scene
from coupling.app.sweep import Sweep, local_cluster, read_results, run_sweep
from coupling.app.sweep_plots import plot_map, plot_metric, plot_overlay, save

import example_cli  # noqa: E402  (examples/example_cli.py, next to this script)

NAME = "snubber_design"
SCENE = Path(__file__).with_name(f"{NAME}.toml")
PEAK_LIMIT = 100.0  # V: peak contact voltage at the opening
ARC_LIMIT = 0.05    # J: arc energy of the opening
R_VALUES = (10.0, 22.0, 47.0, 100.0, 220.0)  # ohm
C_VALUES = (10e-9, 22e-9, 47e-9, 100e-9, 220e-9, 470e-9, 1e-6)  # F
R_FAST, C_FAST = (47.0,), (10e-9, 100e-9, 1e-6)
ANGLES, HEIGHTS = tuple(float(a) for a in range(10, 81, 10)), (0.25e-3, 0.5e-3, 1e-3, 2e-3)  # deg, m
ANGLES_FAST, HEIGHTS_FAST = (20.0, 60.0), (0.5e-3, 1e-3)
DROP = {"initial.resting": False, "initial.velocity": [0.0, 0.0, -1.0], "contact.restitution": 0.8}
WAVES = ["contact_voltage", "arc_current", "load_current"]
R_KEY, C_KEY = "circuit.snubber.resistance", "circuit.snubber.capacitance"
ANGLE_KEY, HEIGHT_KEY = "initial.angle_deg", "initial.height"


def choose(rows: list[dict]) -> dict | None:
    """The smallest C meeting both limits, with the lowest peak among its R; None if none does."""
    ok = [r for r in rows if r["status"] == "ok" and r["peak_voltage"] <= PEAK_LIMIT and r["arc_energy"] <= ARC_LIMIT]
    if not ok:
        return None
    c_min = min(r["C"] for r in ok)
    return min((r for r in ok if r["C"] == c_min), key=lambda r: r["peak_voltage"])


def main(fast: bool = False, out=None, workers: int | None = None) -> dict:
    out = Path(out) if out else Path("runs/examples") / NAME
    out.mkdir(parents=True, exist_ok=True)
    base = load_scene(SCENE)
    r_values, c_values = (R_FAST, C_FAST) if fast else (R_VALUES, C_VALUES)
    angles, heights = (ANGLES_FAST, HEIGHTS_FAST) if fast else (ANGLES, HEIGHTS)
    rc = Sweep.grid(base, {R_KEY: list(r_values), C_KEY: list(c_values)}, waveforms=WAVES)
    drop = Sweep.grid(base, {ANGLE_KEY: list(angles), HEIGHT_KEY: list(heights)}, common=DROP)
    for name in ("rc", "map"):  # a fresh study each time
        shutil.rmtree(out / name, ignore_errors=True)

    from distributed import Client

    n = workers or min(2, len(rc.runs))
    with local_cluster(n) as cluster, Client(cluster) as client:
        reports = [run_sweep(rc, out / "rc", client=client, progress=not fast),
                   run_sweep(drop, out / "map", client=client, progress=not fast)]

    df = read_results(out / "rc")
    rows = []
    for _, rec in df.sort_values([R_KEY, C_KEY]).iterrows():
        rows.append(dict(run_id=rec["run_id"], R=float(rec[R_KEY]), C=float(rec[C_KEY]), status=rec["status"],
                         peak_voltage=_f(rec.get("bounce.peak_contact_voltage")),
                         arc_energy=_f(rec.get("bounce.arc_energy")), error=rec["error"]))
    chosen = choose(rows)
    save(plot_metric(df, "bounce.peak_contact_voltage", C_KEY, by=R_KEY, limit=PEAK_LIMIT), out / "peak_voltage.png")
    save(plot_metric(df, "bounce.arc_energy", C_KEY, by=R_KEY, limit=ARC_LIMIT), out / "arc_energy.png")
    r_shown = chosen["R"] if chosen else r_values[len(r_values) // 2]
    shown = df[df[R_KEY] == r_shown].sort_values(C_KEY).run_id.tolist()
    save(plot_overlay(out / "rc", shown, "contact_voltage", label=[R_KEY, C_KEY], results=df), out / "opening_overlay.png")

    mp = read_results(out / "map")
    mp = mp.assign(bounce_time_ms=mp["bounce.total_bounce_time"] * 1e3)
    save(plot_map(mp, "bounce_time_ms", ANGLE_KEY, HEIGHT_KEY), out / "bounce_map.png")
    drops = [dict(angle_deg=float(r[ANGLE_KEY]), height=float(r[HEIGHT_KEY]), status=r["status"],
                  first_make=_f(r.get("bounce.first_make")), bounce_time=_f(r.get("bounce.total_bounce_time")),
                  bounces=_f(r.get("bounce.bounces")))
             for _, r in mp.sort_values([ANGLE_KEY, HEIGHT_KEY]).iterrows()]

    numbers = dict(limits=dict(peak_voltage=PEAK_LIMIT, arc_energy=ARC_LIMIT), rc=rows, chosen=chosen, drops=drops,
                   runs=dict(rc=len(rc.runs), map=len(drop.runs),
                             failed=sum(r.failed for r in reports), seconds=[round(r.seconds, 2) for r in reports]),
                   drop=dict(speed=1.0, gravity=base.mech.gravity))
    (out / "example.json").write_text(json.dumps(numbers, indent=2))
    return numbers


def _f(value):
    if value is None:
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def summary(n: dict) -> str:
    lines = [f"snubber grid: {n['runs']['rc']} runs, bounce map: {n['runs']['map']} runs, {n['runs']['failed']} failed"]
    for r in n["rc"]:
        ok = (r["peak_voltage"] is not None and r["peak_voltage"] <= PEAK_LIMIT
              and r["arc_energy"] is not None and r["arc_energy"] <= ARC_LIMIT)
        lines.append(f"  R = {r['R']:6.1f} ohm, C = {r['C'] * 1e9:7.1f} nF: peak {r['peak_voltage'] or float('nan'):7.1f} V, "
                     f"arc {1e3 * (r['arc_energy'] or float('nan')):6.1f} mJ {'ok' if ok else ''}")
    c = n["chosen"]
    lines.append(f"chosen (peak <= {PEAK_LIMIT:g} V, arc <= {1e3 * ARC_LIMIT:g} mJ): " + (
        f"R = {c['R']:g} ohm, C = {c['C'] * 1e9:g} nF (peak {c['peak_voltage']:.1f} V, arc {1e3 * c['arc_energy']:.1f} mJ)"
        if c else "none of the grid"))
    for d in n["drops"]:
        bt = d["bounce_time"]
        lines.append(f"  drop at {d['angle_deg']:4.0f} deg from {d['height'] * 1e3:4.2f} mm: first make "
                     f"{1e3 * (d['first_make'] or float('nan')):.3f} ms, bounce time "
                     f"{'-' if bt is None else f'{1e3 * bt:.3f} ms'}")
    return "\n".join(lines)


if __name__ == "__main__":
    sys.exit(example_cli.run(__doc__, NAME, main, summary))
