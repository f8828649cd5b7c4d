"""Benchmark: what the bounded history costs the default runs, and what it saves a long one.

Run: .venv/bin/python benchmarks/bench_memory.py [--repeat N] [--no-write]

1. Speed, in one process, runs alternating: each default scene run with the history's
   machinery as it is (the recorder's checks of every committed batch, a room counted in
   rows recorded, the contact sampled at the circuit's points every 4096 rows of dense
   output, which is then released) against the same code with that machinery off (no
   checks, the contact sampled from the whole run's dense output at the end, as before
   it). The median of the ratios of neighbouring runs: issue 24 allows 5 %.
2. Memory of a long mechanics run (the mechanics default over 0.5 s, ~10^5 steps), its
   history kept whole against thinned to solver.history_rows = 10 000: the peak of the
   allocations (tracemalloc) and the rows kept.
Writes the block between the memory markers of docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import sys
import time
import tracemalloc
from pathlib import Path

from doc_block import command_line, load_line, publish

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import coupling  # noqa: E402
import mech  # noqa: E402
from coupling.core import master  # noqa: E402
from mech.solver import ImpactSolver  # noqa: E402

BEGIN = "<!-- bench_memory begin -->"
END = "<!-- bench_memory end -->"


class MachineryOff:
    """The history's new machinery switched off, as the code ran before it: no check of the
    committed rows, and the co-simulation samples the contact at the end from the dense
    output of the whole run (nothing released)."""

    def __enter__(self):
        self.saved = (ImpactSolver._check_rows, master.CoSimulation._sample_contact)
        ImpactSolver._check_rows = lambda self, start, rows: None
        master.CoSimulation._sample_contact = lambda self, mech, step: None
        return self

    def __exit__(self, *exc):
        ImpactSolver._check_rows, master.CoSimulation._sample_contact = self.saved


def timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def speed_rows(repeat: int) -> list[str]:
    mech_default = coupling.scene_from_dict({"solver": {"t_end": 0.05}}, name="mechanics default")
    scenes = (("relay_force, coupled (5 ms)", coupling.builtin_scene("relay_force")),
              ("free drop, coupled (10 ms)", coupling.builtin_scene("free_drop")),
              ("mechanics default alone (50 ms)", mech_default))
    rows = ["| scene | with / without (median of neighbouring pairs) | with, s (median) | without, s (median) |",
            "|---|---|---|---|"]
    for name, scene in scenes:
        def go():
            coupling.run(scene).summary

        go()
        with MachineryOff():
            go()
        on, off = [], []
        for _ in range(repeat):
            on.append(timed(go))
            with MachineryOff():
                off.append(timed(go))
        ratio = statistics.median(a / b for a, b in zip(on, off))
        rows.append(f"| {name} | {ratio:.3f} | {statistics.median(on):.3f} | {statistics.median(off):.3f} |")
    return rows


def memory_rows() -> list[str]:
    base = mech.default_scene()
    rows = ["| history | steps | rows kept | peak allocations (MB) | wall (s) |", "|---|---|---|---|---|"]
    for label, keep in (("whole (history_rows = 1e6)", 1_000_000), ("thinned (history_rows = 10 000)", 10_000)):
        scene = dataclasses.replace(base, solver=dataclasses.replace(base.solver, t_end=0.5, history_rows=keep))
        tracemalloc.start()
        t0 = time.perf_counter()
        res = ImpactSolver(scene).run()
        wall = time.perf_counter() - t0
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        rows.append(f"| {label} | {res.stats['steps']} | {len(res.t)} | {peak / 1e6:.1f} | {wall:.2f} |")
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=9)
    ap.add_argument("--no-write", action="store_true")
    args = ap.parse_args()
    lines = [f"`{command_line()}`", ""]
    lines += speed_rows(args.repeat)
    lines += ["", "A long run's memory follows its rows, not its steps (tracemalloc's peak over the run):", ""]
    lines += memory_rows()
    lines += ["", load_line(bullet=False)]
    publish(ROOT / "docs" / "benchmarks.md", BEGIN, END, lines, write=not args.no_write)


if __name__ == "__main__":
    main()
