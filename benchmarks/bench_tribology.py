"""Benchmark: the shipped tribometer fit, against the fit of its chosen models alone.

The default scene fits the shipped dataset once per process (`coupling.laws.tribology.default_fit`),
so the whole model selection (every mu(I) candidate, every R_c load law x current factor,
with profile-likelihood intervals) is start-up cost of every default run. Target: well under
1 s on this 2-core machine. The baseline, measured in the same run, is the fit restricted to
the models the selection chooses: the ratio is what ranking the candidates costs.

Not a test: run by hand,
    .venv/bin/python benchmarks/bench_tribology.py [--repeat N] [--no-write]
It writes its table between the bench-tribology markers of docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

from doc_block import command_line, load_line, publish

from coupling.laws.tribology import fit_tribometer, illustrative_data_path, read_tribometer_csv

DOC = Path(__file__).resolve().parents[1] / "docs" / "benchmarks.md"
BEGIN, END = "<!-- bench-tribology:begin -->", "<!-- bench-tribology:end -->"


def timed(fn, repeat: int):
    times, out = [], None
    for _ in range(repeat):
        tick = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - tick)
    return statistics.median(times), min(times), out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7, help="timed repetitions (median and min reported)")
    ap.add_argument("--no-write", action="store_true", help="print only; leave docs/benchmarks.md alone")
    args = ap.parse_args()
    if args.repeat < 1:
        raise SystemExit(f"--repeat = {args.repeat}: must be >= 1")

    path = illustrative_data_path()
    full_med, full_min, fit = timed(lambda: fit_tribometer(read_tribometer_csv(path)), args.repeat)
    mu_model = fit.friction.mu_selection.chosen.name
    r_load, r_current = fit.resistance.selection.chosen.name.split("+")
    base_med, base_min, base = timed(
        lambda: fit_tribometer(read_tribometer_csv(path), mu_models=[mu_model],
                               resistance_candidates=[(r_load, r_current)]), args.repeat)
    # the restricted fit must land on the same estimate, or the baseline is not the same work
    if abs(base.gamma - fit.gamma) > 1e-9 * max(1.0, abs(fit.gamma)):
        raise SystemExit(f"restricted fit gamma {base.gamma!r} differs from the full fit's {fit.gamma!r}")

    chosen = f"chosen models only ({mu_model}; {r_load}+{r_current})"
    lines = [
        f"`{command_line()}` (median and min of {args.repeat} repetitions):", "",
        "| route | median | min |", "| --- | --- | --- |",
        f"| full fit: every mu(I) candidate and every R_c load law x current factor ranked | "
        f"{1e3 * full_med:.1f} ms | {1e3 * full_min:.1f} ms |",
        f"| {chosen} | {1e3 * base_med:.1f} ms | {1e3 * base_min:.1f} ms |", "",
        f"- Ranking the candidates costs **{full_med / base_med:.2f}x** the fit of the chosen models alone.",
        f"- Target: the full fit, which every default run does once per process at start-up, well under 1 s: "
        f"**{'met' if full_med < 1.0 else 'NOT met'}** ({full_med:.3f} s).",
        load_line(),
    ]
    publish(DOC, BEGIN, END, lines, write=not args.no_write)


if __name__ == "__main__":
    main()
