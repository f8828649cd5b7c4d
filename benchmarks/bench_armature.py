"""Benchmark: the relay's armature in the mechanics (issue 19, item 3) -- solver time.

Two measurements, each against `python -c "import numpy"` (whole process, median of 5)
measured in the same run (no timed tests):

(a) The plunger solenoid's armature alone (issue 19: a steel armature of radius 5 mm,
    length 26 mm, 7853 kg/m^3, with a 10 g load; 5 mm to 0.25 mm of working gap; stops
    1e11 N/m and 400 N s/m) for 50 ms under a force profile as the coupling would pass it:
    the drive psi(t)^2 with psi rising as a coil's flux, (1 - exp(-t / 5 ms))^2 x 0.5, times
    the gain table of an ideal working gap, (g_rest / g(q))^2 (201 points, denser towards
    the pole), given in 1000 macro steps of 50 us, each linear in time, with the dense
    output on and the armature's position asked at every step's middle (as the coupling
    asks for the gap). Solver time = the solver's integration wall time; loop = the whole
    stepping loop in Python.
(b) The default relay's make (coupling.builtin_scene("relay_force") mechanics, 5 ms) with its
    armature force table against the same blade closed by an armature: a plunger of 2 g,
    0.5 mm of travel (stops 1e9 N/m, 600 N s/m), return spring 0.3 N + 400 N/m, its card
    at the force's position (lever 1, 0.1 mm free travel, 1e5 N/m, 0.5 N s/m), driven by
    the force table's ramp (0 to 5.4 N in 3 ms) given in 100 steps of 50 us. The force
    table's scene is stepped the same way, and once in one advance.

    .venv/bin/python benchmarks/bench_armature.py [--repeat 5] [--no-write]

It rewrites the block between the bench_armature markers in docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import statistics
import sys
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # before numpy: no BLAS threads on a shared box

import numpy as np  # noqa: E402

from doc_block import command_line, load_line, write_block  # noqa: E402
from bench_mechanisms import baseline_import_numpy  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
DOC = ROOT / "docs" / "benchmarks.md"
BEGIN, END = "<!-- bench_armature:begin -->", "<!-- bench_armature:end -->"

G_REST, G_POLE = 0.005, 0.00025  # m, the solenoid's working gap at rest and at the pole
T_END_A, H_A, TAU, F0 = 0.05, 50e-6, 5e-3, 0.5  # s, s, s, N
T_END_B, H_B, RAMP, F_RELAY = 0.005, 50e-6, 3e-3, 5.4  # s, s, s, N


def solenoid_scene():
    from mech.scene import scene_from_dict

    mass = 7853.0 * math.pi * 0.005**2 * 0.026 + 0.010
    travel = G_REST - G_POLE
    q = travel * (1.0 - (1.0 - np.linspace(0.0, 1.0, 201)) ** 2)  # denser towards the pole
    gain = (G_REST / (G_REST - q)) ** 2
    return scene_from_dict({"armature": dict(kind="plunger", mass=mass, travel=travel, stop_stiffness=1e11,
                                             stop_damping=400.0, force_gain=dict(position=q.tolist(),
                                                                                 gain=gain.tolist())),
                            "solver": dict(t_end=T_END_A)})


def part_a(repeat: int) -> dict:
    import time

    from mech import ImpactSolver

    scene = solenoid_scene()
    walls, loops, res = [], [], None
    for _ in range(repeat):
        solver = ImpactSolver(scene, keep_dense=True)
        tick = time.perf_counter()
        before = 0.0
        for k in range(1, int(round(T_END_A / H_A)) + 1):
            t = k * H_A
            value = F0 * (1.0 - math.exp(-t / TAU)) ** 2
            segment = solver.advance(t, {"armature.force": (before, value)})
            segment.armature(t - 0.5 * H_A)
            before = value
        loops.append(time.perf_counter() - tick)
        res = solver.result()
        walls.append(res.stats["wall_time"])
    kinds = [e["kind"] for e in res.events]
    out = dict(solver=statistics.median(walls), loop=statistics.median(loops), steps=res.stats["steps"],
               rejected=res.stats["rejected_steps"], events=res.stats["events"],
               stop_events=sum(k.startswith("armature_stop") for k in kinds),
               seats=sum(k == "armature_seat" for k in kinds), residual=res.energy["relative_residual"],
               **res.armature)
    print(f"(a) solenoid alone, 50 ms: solver {out['solver']:.4f} s, loop {out['loop']:.4f} s, {out['steps']} steps")
    return out


def relay_scenes():
    from coupling import builtin_scene

    from mech.parameters import Armature

    table = builtin_scene("relay_force").set("solver.t_end", T_END_B).mech
    force = table.forces[0]
    arm = Armature(kind="plunger", mass=2e-3, travel=5e-4, stop_stiffness=1e9, stop_damping=600.0,
                   spring_rate=400.0, spring_preload=0.3, card_position=force.position, card_lever=1.0,
                   card_free_travel=1e-4, card_stiffness=1e5, card_damping=0.5)
    return table, dataclasses.replace(table, forces=(), armature=arm)


def part_b(repeat: int) -> dict:
    import time

    from mech import ImpactSolver

    table, armature = relay_scenes()
    mu = table.friction.mu_at(0.0)
    out = {}
    for label, scene, stepped in (("table, one advance", table, False), ("table, 50 us steps", table, True),
                                  ("armature, 50 us steps", armature, True)):
        walls, loops, res = [], [], None
        for _ in range(repeat):
            solver = ImpactSolver(scene, keep_dense=True)
            tick = time.perf_counter()
            if not stepped:
                solver.advance(T_END_B)
            for k in range(1, int(round(T_END_B / H_B)) + 1 if stepped else 0):
                t = k * H_B
                drives = None
                if scene.armature.present:
                    drives = {"armature.force": (F_RELAY * min((t - H_B) / RAMP, 1.0), F_RELAY * min(t / RAMP, 1.0))}
                solver.advance(t, drives, mu=mu)
            loops.append(time.perf_counter() - tick)
            res = solver.result()
            walls.append(res.stats["wall_time"])
        contacts = res.contact_columns
        out[label] = dict(solver=statistics.median(walls), loop=statistics.median(loops), steps=res.stats["steps"],
                          events=res.stats["events"], contacts=len(contacts["tip"]),
                          first_make=float(contacts["t_start"][0]) if len(contacts["tip"]) else None,
                          force=float(res.history_columns["normal_force_0"][-1]),
                          residual=res.energy["relative_residual"], armature=res.armature)
        print(f"(b) relay make, {label}: solver {out[label]['solver']:.4f} s, {out[label]['steps']} steps")
    return out


def render(a: dict, b: dict, base: float, repeat: int) -> list[str]:
    L = [f"`{command_line()}`: solver times warm, median of {repeat}; baseline `python -c \"import numpy\"` "
         f"{base:.3f} s in the same run.", ""]
    L += [f"**(a) The plunger solenoid's armature alone, {T_END_A * 1e3:g} ms** (drive (1 - exp(-t / "
          f"{TAU * 1e3:g} ms))^2 x {F0:g} N times the ideal gap's (g_rest / g)^2, in "
          f"{int(round(T_END_A / H_A))} steps of {H_A * 1e6:g} us):", "",
          "| solver | / baseline | stepping loop | steps | rejected | events | stop events | seated | first arrival "
          "| speed there | bounces on the pole | energy residual |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|",
          f"| {a['solver'] * 1e3:.1f} ms | {a['solver'] / base:.2f}x | {a['loop'] * 1e3:.1f} ms | {a['steps']} | "
          f"{a['rejected']} | {a['events']} | {a['stop_events']} | {a['seats']} | "
          f"{a['first_arrival'] * 1e3:.3f} ms | {a['arrival_speed']:.3f} m/s | {a['pole_bounces']} | "
          f"{a['residual']:.2g} |", ""]
    L += [f"**(b) The default relay's make, {T_END_B * 1e3:g} ms of mechanics**: the force table against an "
          f"armature whose card closes the blade (drive 0 to {F_RELAY:g} N in {RAMP * 1e3:g} ms):", "",
          "| scene | solver | / baseline | stepping loop | steps | events | contacts | first make | final contact "
          "force | energy residual |", "|---|---|---|---|---|---|---|---|---|---|"]
    for label, r in b.items():
        make = f"{r['first_make'] * 1e3:.3f} ms" if r["first_make"] is not None else "none"
        L.append(f"| {label} | {r['solver'] * 1e3:.1f} ms | {r['solver'] / base:.2f}x | {r['loop'] * 1e3:.1f} ms | "
                 f"{r['steps']} | {r['events']} | {r['contacts']} | {make} | {r['force']:.3f} N | "
                 f"{r['residual']:.2g} |")
    arm = b["armature, 50 us steps"]["armature"]
    L += ["", f"The relay's armature reached its pole stop at {arm['first_arrival'] * 1e3:.3f} ms "
          f"({arm['arrival_speed']:.3f} m/s) and bounced {arm['pole_bounces']} times on it.", "", load_line()]
    return L


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--no-write", action="store_true", help="print only; leave docs/benchmarks.md alone")
    args = ap.parse_args()
    from mech import ImpactSolver  # warm-up: load the compiled mechanics outside the timings

    ImpactSolver(solenoid_scene()).advance(1e-3, {"armature.force": 1.0})
    base0 = baseline_import_numpy()
    a = part_a(args.repeat)
    b = part_b(args.repeat)
    base = 0.5 * (base0 + baseline_import_numpy())
    lines = render(a, b, base, args.repeat)
    print("\n".join(lines))
    if not args.no_write:
        write_block(DOC, BEGIN, END, "\n".join(lines),
                    heading="## The relay's armature in the mechanics (issue 19)\n"
                            "Written by benchmarks/bench_armature.py (what each part measures: its docstring).\n\n")
        print(f"wrote {DOC}")


if __name__ == "__main__":
    main()
