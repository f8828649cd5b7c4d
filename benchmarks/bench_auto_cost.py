"""Benchmark: cost of modes = "auto" against the former default of 3 modes per family.

Run: .venv/bin/python benchmarks/bench_auto_cost.py [--repeat N]

The default coupled scene (coupling.default_scene(): mechanics, ngspice circuit, arc)
and the default mechanics scene alone (mech.default_scene(), 50 ms), each with
bar.modes = "auto" and bar.modes = 3, in one process; best of N warm runs (the machine is
shared: other load only adds time). Prints the wall times and the ratio auto / 3
(issue 9 target: <= 1.5x on the default coupled scene).
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import coupling  # noqa: E402
import mech  # noqa: E402


def best(fn, repeat: int) -> float:
    fn()  # warm-up (numba cache, ngspice start)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    base = coupling.builtin_scene("free_drop")  # the former default coupled scene
    rows = []
    for label, value in (("auto", "auto"), ("3", 3)):
        sc = base.set("bar.modes", value)
        res = coupling.run(sc)
        rule = res.mechanics.solver.get("modes_rule")
        t = best(lambda: coupling.run(sc), args.repeat)
        rows.append(("coupled default", label, t, res.mechanics.solver["modes"], rule))
        print(rows[-1], flush=True)
    ms = mech.default_scene()
    for label, value in (("auto", "auto"), ("3", 3)):
        sc = dataclasses.replace(ms, bar=dataclasses.replace(ms.bar, axial_modes=value, bending_modes=value))
        res = mech.simulate(sc)
        t = best(lambda: mech.simulate(sc), args.repeat)
        rows.append(("mechanics default", label, t, res.solver["modes"], res.solver["modes_rule"]))
        print(rows[-1], flush=True)
    print("\n| scene | modes | n | wall time (best of %d) |\n|---|---|---|---|" % args.repeat)
    for scene, label, t, n, _rule in rows:
        print(f"| {scene} | {label} | {n} | {t:.3f} s |")
    for scene in ("coupled default", "mechanics default"):
        a = next(r for r in rows if r[0] == scene and r[1] == "auto")
        b = next(r for r in rows if r[0] == scene and r[1] == "3")
        print(f"{scene}: auto / 3 = {a[2] / b[2]:.2f}x ({a[4]})")
    print(f"load average {os.getloadavg()[0]:.1f} (2 cores)")


if __name__ == "__main__":
    main()
