"""Benchmark: `switchsim life` on the built-in relay_cycle scene.

Targets (issue 21), measured in this one run:
- <= 0.5 s of solver time per simulated operation, against the cost of a single run of the
  scene (what one sample costs beyond its run is the study's overhead: scene rebuild,
  bookkeeping, the table and checkpoint written after each sample);
- 1000 operations sampled every 50 (20 runs) in well under a minute.
With ``--convergence`` it also measures the wear interpolation's error: 1000 operations at
an erosion coefficient 2000 times the library's (so that the wear changes the contact
within them), no end criterion, sampled every 100, 50 and 25 operations; the explicit rule
is first order in K.

Not a test: run by hand,

    .venv/bin/python benchmarks/bench_life.py [--operations 1000] [--every 50] [--convergence] [--no-write]

It rewrites the block between the bench_life markers in docs/contact_duty.md.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))
DOC = ROOT / "docs" / "contact_duty.md"
BEGIN, END = "<!-- bench_life:begin -->", "<!-- bench_life:end -->"


def single_runs(scene, repeats: int = 3) -> list[float]:
    """Wall time (s) of ``repeats`` plain runs of the scene, in this process."""
    from coupling import run

    out = []
    for _ in range(repeats):
        tick = time.perf_counter()
        run(scene)
        out.append(time.perf_counter() - tick)
    return out


def study(scene, operations: int, every: int):
    from coupling.app.life import LifeStudy, life_study

    with tempfile.TemporaryDirectory(prefix="bench_life_") as folder:
        tick = time.perf_counter()
        report = life_study(scene, LifeStudy(operations, every), Path(folder) / "life")
        return report, time.perf_counter() - tick


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--operations", type=int, default=1000)
    parser.add_argument("--every", type=int, default=50)
    parser.add_argument("--convergence", action="store_true")
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args()
    from doc_block import command_line, load_line, publish

    from coupling import builtin_scene
    from coupling.app.life import prepare

    scene = prepare(builtin_scene("relay_cycle"))[0]
    single_runs(scene, 1)  # imports, the compiled mechanics, ngspice: loaded once
    single = statistics.median(single_runs(scene))
    report, wall = study(scene, args.operations, args.every)
    runs = [r["wall_time"] for r in report.rows]
    per_sample = wall / len(report.rows)
    grown = (report.rows[-1]["gap"] - report.rows[0]["gap"]) * 1e9
    lines = [f"`{command_line()}`", "",
             f"- a single run of relay_cycle (median of 3): {single:.3f} s;",
             f"- {args.operations} operations sampled every {args.every}: {len(report.rows)} runs in {wall:.1f} s "
             f"(end: {report.end_note}); the runs' own time {sum(runs):.1f} s "
             f"(median {statistics.median(runs):.3f} s);",
             f"- per sample {per_sample:.3f} s = {per_sample / single:.2f} x the single run; per simulated operation "
             f"{wall / report.operations_done * 1e3:.1f} ms (target <= 500 ms);",
             f"- worn after {report.operations_done} operations: {report.worn[0]:.3g} m^3 (moving), "
             f"{report.worn[1]:.3g} m^3 (fixed); the gap grew by {grown:.3g} nm by the last sample."]
    if args.convergence:
        # no end criterion: the studies must reach the same operation count to compare
        fast = scene.update({"duty.erosion_coefficient": 2e-10, "duty.life": {
            "gap_range": [0.0, 0.01], "min_force": 0.0, "max_resistance": 1.0, "stop_on_weld": "never"}})
        results = {}
        for k in (100, 50, 25):
            rep, seconds = study(fast, args.operations, k)
            results[k] = (rep, seconds)
        ref = results[25][0].worn[0]
        lines += ["", f"Wear interpolation, {args.operations} operations at erosion_coefficient = 2e-10 m^3/J "
                      "(2000 x the library's):", "",
                  "| every K | runs | moving worn volume (m^3) | gap after (mm) | change from K = 25 | s |",
                  "|---|---|---|---|---|---|"]
        for k, (rep, seconds) in results.items():
            from coupling.app.life import ContactGeometry

            gap = ContactGeometry.of(fast).worn(*rep.worn)["gap"]
            lines.append(f"| {k} | {len(rep.rows)} | {rep.worn[0]:.5g} | {gap * 1e3:.5g} | "
                         f"{(rep.worn[0] - ref) / ref:+.2e} | {seconds:.1f} |")
    lines += ["", load_line()]
    publish(DOC, BEGIN, END, lines, write=not args.no_write)


if __name__ == "__main__":
    main()
