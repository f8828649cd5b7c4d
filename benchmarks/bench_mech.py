"""Benchmark: the compiled DOPRI5 against scipy solve_ivp (Radau, DOP853) on the default scene.

Run: .venv/bin/python benchmarks/bench_mech.py [--repeat N] [--no-radau] [--compile] [--no-write]

The default mechanics scene (mech.default_scene(): 3D, modes = "auto", friction gamma = 0.7,
50 ms after release including every re-contact) at rtol 1e-6, in one process:
- cold: the first call in a fresh process (with the compiled mechanics already in the
  cache, or, with --compile, a subprocess with an empty cache that builds them), measured
  separately;
- DOPRI5 warm: median (and best) of N >= 5 runs after a warm-up;
- scipy Radau (the stiff baseline the issue names) and DOP853, same right-hand side,
  events and regime logic, one run each (they are slow).
Prints a markdown table: wall time, steps, rhs evaluations, contacts, first restitution,
the Radau/DOPRI5 ratio (target >= 20x), whether DOPRI5 warm <= 0.1 s, and the peak memory
of a DOPRI5 run (tracemalloc peak of Python/NumPy allocations in a separate, untimed run;
process ru_maxrss after the DOPRI5 runs, before the scipy ones). It writes them between the
bench-mech markers of docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

from doc_block import command_line, load_line, publish

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
DOC = ROOT / "docs" / "benchmarks.md"
BEGIN, END = "<!-- bench-mech:begin -->", "<!-- bench-mech:end -->"

COLD_SNIPPET = """
import time
t0 = time.perf_counter()
import mech
t1 = time.perf_counter()
res = mech.simulate(mech.default_scene())
t2 = time.perf_counter()
print(t1 - t0, t2 - t1)
"""


def cold_start(empty_cache: bool) -> tuple[float, float]:
    """(import mech, first simulate) in a fresh interpreter; empty_cache compiles from scratch."""
    env = dict(os.environ)
    with tempfile.TemporaryDirectory() as cache:
        if empty_cache:
            env["NUMBA_CACHE_DIR"] = cache
        out = subprocess.run([sys.executable, "-c", COLD_SNIPPET], cwd=ROOT, env=env, check=True,
                             capture_output=True, text=True).stdout.split()
    return float(out[0]), float(out[1])


def summary(res) -> dict:
    c = res.contacts
    return dict(steps=res.stats["steps"], rhs=res.stats["rhs_evals"], contacts=len(c),
                restitution=float(c.kinematic_restitution.iloc[0]) if len(c) else float("nan"),
                solver_wall=res.stats["wall_time"])


def timed(run) -> tuple[float, object]:
    start = time.perf_counter()
    res = run()
    return time.perf_counter() - start, res


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7, help="warm DOPRI5 runs (>= 5)")
    parser.add_argument("--no-radau", action="store_true", help="skip the (slow) Radau baseline")
    parser.add_argument("--compile", action="store_true",
                        help="also time a full numba compile in a subprocess with an empty cache")
    parser.add_argument("--no-write", action="store_true", help="print only; leave docs/benchmarks.md alone")
    args = parser.parse_args()
    repeat = max(args.repeat, 5)

    cold_import, cold_first = cold_start(empty_cache=False)
    compile_times = cold_start(empty_cache=True) if args.compile else None

    import mech  # noqa: E402  (after the cold subprocess, so this process is the warm one)
    from mech import ImpactSolver

    scene = mech.default_scene()
    assert scene.solver.rtol == 1e-6 and scene.solver.t_end == 0.05

    first, _ = timed(lambda: mech.simulate(scene))  # this process's first call (cache load)
    warm = []
    for _ in range(repeat):
        warm.append(timed(lambda: mech.simulate(scene)))
    dopri = summary(warm[-1][1])
    warm_times = [w for w, _ in warm]
    rss_kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss

    tracemalloc.start()
    mech.simulate(scene)
    _, traced_peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()

    rows = [("DOPRI5 compiled, warm (median of %d)" % repeat, statistics.median(warm_times), dopri)]
    baselines = {}
    methods = ["DOP853"] + ([] if args.no_radau else ["Radau"])
    for method in methods:
        wall, res = timed(lambda: ImpactSolver(scene, backend=f"scipy:{method}").run())
        baselines[method] = wall
        rows.append((f"scipy solve_ivp {method}", wall, summary(res)))

    median = statistics.median(warm_times)
    last = warm[-1][1]
    t_last = float(last.contacts.t_end.max()) if len(last.contacts) else 0.0
    after = float((last.history.time > t_last).mean())
    lines = [f"`{command_line()}`: `mech.default_scene()`, {last.solver['model']}, {last.solver.get('modes_rule') or last.solver['modes']} "
             f"({last.solver['modes']} modal coordinates), friction mu = {scene.friction.mu}, gamma = {scene.friction.gamma}, "
             f"t_end = {scene.solver.t_end} s, rtol = {scene.solver.rtol:g}", "",
             "| route | wall time | steps | rhs evals | contacts | first restitution |",
             "|---|---|---|---|---|---|"]
    for name, wall, s in rows:
        lines.append(f"| {name} | {wall * 1e3:.1f} ms | {s['steps']} | {s['rhs']} | {s['contacts']} | {s['restitution']:.5f} |")
    lines.append("")
    for method, wall in baselines.items():
        ratio = wall / median
        target = " (target >= 20x: **" + ("met" if ratio >= 20 else "NOT met") + "**)" if method == "Radau" else ""
        lines.append(f"- {method} / DOPRI5 warm: **{ratio:.0f}x**{target}")
    lines += [
        f"- DOPRI5 warm: median **{median * 1e3:.1f} ms**, best {min(warm_times) * 1e3:.1f} ms, integration only "
        f"{dopri['solver_wall'] * 1e3:.1f} ms; target <= 0.1 s: **{'met' if median <= 0.1 else 'NOT met'}**",
        f"- Steps after the last contact (free flight from {t_last * 1e3:.2f} ms on): {100 * after:.0f} % of the "
        f"{dopri['steps']}",
        f"- Cold, fresh process with the compiled mechanics in the cache: import mech {cold_import:.2f} s, first "
        f"simulate {cold_first:.2f} s; first call in this process {first * 1e3:.0f} ms",
    ]
    if compile_times:
        lines.append(f"- Cold, empty cache (the compiled mechanics built first): import mech {compile_times[0]:.2f} s, "
                     f"first simulate {compile_times[1]:.2f} s")
    lines += [
        f"- Peak memory of a DOPRI5 run: tracemalloc peak {traced_peak / 2**20:.1f} MiB; process ru_maxrss "
        f"{rss_kib / 1024:.0f} MiB (the interpreter and every library this process loaded)",
        load_line(),
    ]
    publish(DOC, BEGIN, END, lines, write=not args.no_write)
    return 0


if __name__ == "__main__":
    sys.exit(main())
