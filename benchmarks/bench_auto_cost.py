"""Benchmark: cost of modes = "auto" against the counts the scenes had before it.

Run: .venv/bin/python benchmarks/bench_auto_cost.py [--repeat N] [--no-write]

Three scenes, each with bar.modes = "auto" and with its former count, in one process; best
of N warm runs (the machine is shared: other load only adds time):
- the free drop, coupled (builtin_scene("free_drop"), the default scene when auto was
  introduced; issue 9's target: auto <= 1.5x its former 3 modes per family);
- the relay, coupled (builtin_scene("relay_force"), the default scene until the coil relay; formerly 1 axial +
  6 bending modes, which run --check showed unconverged);
- the mechanics default alone (mech.default_scene(), 50 ms), formerly 3 per family.
Writes the block between the auto-cost markers of docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import time
from pathlib import Path

from doc_block import write_block

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import coupling  # noqa: E402
import mech  # noqa: E402
import mech.model  # noqa: E402


def best(fn, repeat: int) -> float:
    fn()  # warm-up (numba cache, ngspice start)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def check_cost(repeat: int) -> list[str]:
    """What checking the count on the run's own impacts costs (issue 23: the converged auto
    count <= 25 % of the run it protects, on the default relay and the free drop): the check
    (mech.model.refined_mode_count on the run's impact speeds) timed alone, against the run;
    a rerun where the check asks for one counts whole."""
    out = ["The check of the auto count on the run's own impacts (issue 23's target: <= 25 % of the run "
           "it protects):", "", "| scene | run | check | rerun | cost / run |", "|---|---|---|---|---|"]
    for name, sc in (("default relay (coil-driven, 12 ms)", coupling.builtin_scene("default")),
                     ("free drop, coupled (10 ms)", coupling.builtin_scene("free_drop"))):
        res = coupling.run(sc)
        run_t = best(lambda: coupling.run(sc), repeat)
        m = res.mechanics
        speeds = m.contact_columns["normal_speed_in"]

        def one_check():
            return mech.model.refined_mode_count(sc.mech, m.model.mode_count, speeds)

        check_t = best(one_check, max(repeat, 20))
        refined = one_check()
        rerun = run_t if refined is not None else 0.0
        cost = (check_t + rerun) / run_t
        out.append(f"| {name} | {run_t:.3f} s | {check_t * 1e6:.0f} us | {'yes' if refined is not None else 'no'} | "
                   f"**{100 * cost:.2g} %** ({'met' if cost <= 0.25 else 'not met'}) |")
        print(out[-1], flush=True)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--no-write", action="store_true")
    args = ap.parse_args()
    rows = []
    coupled = (("free drop, coupled (10 ms)", coupling.builtin_scene("free_drop"), 3),
               ("relay_force, coupled (5 ms)", coupling.builtin_scene("relay_force"), {"axial": 1, "bending": 6}))
    for name, base, former in coupled:
        for label, value in (("auto", "auto"), ("former", former)):
            sc = base.set("bar.modes", value)
            res = coupling.run(sc)
            t = best(lambda: coupling.run(sc), args.repeat)
            rows.append((name, label, value, t, res.mechanics.solver["modes"], res.mechanics.solver.get("modes_rule")))
            print(rows[-1], flush=True)
    ms = mech.default_scene()
    for label, value in (("auto", "auto"), ("former", 3)):
        sc = dataclasses.replace(ms, bar=dataclasses.replace(ms.bar, axial_modes=value, bending_modes=value))
        res = mech.simulate(sc)
        t = best(lambda: mech.simulate(sc), args.repeat)
        rows.append(("mechanics default (50 ms)", label, value, t, res.solver["modes"], res.solver["modes_rule"]))
        print(rows[-1], flush=True)
    lines = [f"`.venv/bin/python benchmarks/bench_auto_cost.py --repeat {args.repeat}` (best of {args.repeat} warm "
             f"runs, load average {os.getloadavg()[0]:.1f} at the end, 2 cores):", "",
             "| scene | modes | n (total) | wall time |", "|---|---|---|---|"]
    for scene, label, value, t, n, rule in rows:
        former = f"{value['axial']} axial, {value['bending']} bending modes" if isinstance(value, dict) else f"{value} per family"
        shown = rule.split(" below")[0] if label == "auto" else f"former: {former}"
        lines.append(f"| {scene} | {shown} | {n} | {t:.3f} s |")
    lines.append("")
    for scene in dict.fromkeys(r[0] for r in rows):
        a = next(r for r in rows if r[0] == scene and r[1] == "auto")
        b = next(r for r in rows if r[0] == scene and r[1] == "former")
        target = " (issue 9's target <= 1.5x: " + ("met" if a[3] / b[3] <= 1.5 else "**not met**") + ")" \
            if scene.startswith("free drop") else ""
        lines.append(f"- {scene}: auto / former = **{a[3] / b[3]:.2f}x**{target}")
    lines += ["", *check_cost(args.repeat)]
    text = "\n".join(lines)
    print(text)
    if not args.no_write:
        write_block(ROOT / "docs" / "benchmarks.md", "<!-- auto-cost:begin -->", "<!-- auto-cost:end -->", text)
        print("written to docs/benchmarks.md")


if __name__ == "__main__":
    main()
