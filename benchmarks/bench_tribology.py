"""Benchmark: the shipped tribometer fit, against the fit of its chosen models alone.

The default scene fits the shipped dataset once per process (`coupling.tribology.default_fit`),
so the whole model selection (every mu(I) candidate, every R_c load law x current factor,
with profile-likelihood intervals) is start-up cost of every default run. Target: well under
1 s on this 2-core machine. The baseline, measured in the same run, is the fit restricted to
the models the selection chooses: the ratio is what ranking the candidates costs.

Not a test: run by hand,
    .venv/bin/python benchmarks/bench_tribology.py [--repeat N]
and copy the table into docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

from coupling.tribology import fit_tribometer, illustrative_data_path, read_tribometer_csv


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

    print(f"load average {os.getloadavg()[0]:.2f}, {args.repeat} repetitions (median / min)")
    chosen = f"chosen models only ({mu_model}; {r_load}+{r_current})"
    width = max(len(chosen), 34) + 2
    print(f"{'route':<{width}}{'median ms':>11}{'min ms':>9}")
    print(f"{'full fit (all candidates ranked)':<{width}}{1e3 * full_med:>11.1f}{1e3 * full_min:>9.1f}")
    print(f"{chosen:<{width}}{1e3 * base_med:>11.1f}{1e3 * base_min:>9.1f}")
    print(f"ratio full / chosen-only: {full_med / base_med:.2f}x")
    print(f"target full fit < 1 s: {'met' if full_med < 1.0 else 'NOT met'} ({full_med:.3f} s)")


if __name__ == "__main__":
    main()
