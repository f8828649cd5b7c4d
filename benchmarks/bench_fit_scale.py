"""`switchsim fit` on large tribometer CSVs: whole-process wall time and peak memory against rows.

    python benchmarks/bench_fit_scale.py [--rows 10000 100000 1000000] [--keep DIR] [--no-write]

Writes CSVs of the illustrative laws (coupling/laws/tribology/illustrative.py's generator: 11
loads x 4 currents, repeated; lognormal scatter) and runs `python -m coupling.app.cli fit`
on each in a fresh process, measuring that process alone (os.wait4: wall time and
peak resident memory). Also runs the imports alone, the fixed cost of any fit (IMPORTS:
what `switchsim fit` loads, the libraries it imports lazily included). Ratios are against
the smallest file, measured in the same run. Target (issue 10): 1,000,000 rows in <= 10 s
and <= 300 MB. Writes its table between the bench-fit-scale markers of docs/tribology.md
(section 5).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from doc_block import command_line, load_line, publish

REPO = Path(__file__).resolve().parents[1]
DOC = REPO / "docs" / "tribology.md"
BEGIN, END = "<!-- bench-fit-scale:begin -->", "<!-- bench-fit-scale:end -->"
# every module a fit loads: the command line and the fit, and what they import lazily (pandas
# with pyarrow, scipy.stats and scipy.optimize, matplotlib for the figures); `coupling` itself
# imports none of them, so importing the command alone no longer measures the fixed cost
IMPORTS = ("coupling.app.fit, coupling.app.cli, coupling.app.fit_plots, pandas, scipy.stats, "
           "scipy.optimize, matplotlib.backends.backend_agg")
TARGET_ROWS, TARGET_S, TARGET_MIB = 1_000_000, 10.0, 300e6 / 2**20


def write_csv(path: Path, rows: int, seed: int = 1) -> None:
    """Run in a child process (``--write``): the measuring process stays small, since a
    child's peak RSS counts the pages it shares with its parent until it execs."""
    import numpy as np

    sys.path.insert(0, str(REPO))
    from coupling.laws.tribology.illustrative import ILLUSTRATIVE_LAWS, SyntheticDesign, synthetic_tribometer_data

    loads = tuple(np.linspace(3.0, 8.0, 11))
    currents = (0.0, 1.0, 2.0, 5.0)
    repeats = -(-rows // (len(loads) * len(currents)))
    df = synthetic_tribometer_data(ILLUSTRATIVE_LAWS, SyntheticDesign(loads, currents, repeats),
                                   np.random.default_rng(seed)).iloc[:rows]
    with open(path, "w") as handle:
        handle.write("# synthetic (illustrative laws), benchmarks/bench_fit_scale.py\n")
        handle.write("load_N,current_A,friction_N,resistance_ohm,run\n")
        np.savetxt(handle, np.c_[df.load_N, df.current_A, df.friction_N, df.resistance_ohm, df.run],
                   fmt=["%.6g", "%g", "%.6g", "%.7g", "%d"], delimiter=",")


def measure(args: list[str]) -> tuple[float, float, int]:
    """Wall time (s), peak RSS (MB) and exit code of one child process."""
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    start = time.perf_counter()
    child = subprocess.Popen([sys.executable, *args], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - start
    child.returncode = os.waitstatus_to_exitcode(status)
    if child.returncode != 0:
        print(child.stderr.read().decode(errors="replace")[-2000:], file=sys.stderr)
    child.stderr.close()
    return wall, usage.ru_maxrss / 1024.0, child.returncode


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, nargs="+", default=[10_000, 100_000, 1_000_000])
    parser.add_argument("--keep", type=Path, default=None, help="folder for the CSVs and results (default: temporary)")
    parser.add_argument("--no-write", action="store_true", help="print only; leave docs/tribology.md alone")
    parser.add_argument("--write", nargs=2, metavar=("CSV", "ROWS"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.write:
        write_csv(Path(args.write[0]), int(args.write[1]))
        return
    folder = args.keep or Path(tempfile.mkdtemp(prefix="bench_fit_scale_"))
    folder.mkdir(parents=True, exist_ok=True)
    wall0, rss0, code0 = measure(["-c", f"import {IMPORTS}"])
    if code0 != 0:
        raise SystemExit(f"the imports alone exited with {code0}")
    print(f"imports only: {wall0:.2f} s, {rss0:.0f} MiB peak")
    lines = [f"`{command_line()}`: `python -m coupling.app.cli fit` on synthetic CSVs, each in a fresh process "
             "(wall time and peak RSS of that process alone, from wait4); ratios to the smallest file, same run.", "",
             f"The imports alone (`import {IMPORTS}`): {wall0:.2f} s, {rss0:.0f} MiB peak.", "",
             "| rows | MB file | wall s | peak MiB | t / t(first) | mem / mem(first) | over the imports |",
             "|---:|---:|---:|---:|---:|---:|---:|"]
    target = None
    print(f"{'rows':>9} {'MB file':>8} {'wall s':>8} {'peak MiB':>8} {'t/t0':>6} {'mem/mem0':>9} {'over imports':>13}")
    base = None
    for rows in args.rows:
        csv = folder / f"tribometer_{rows}.csv"
        subprocess.run([sys.executable, __file__, "--write", str(csv), str(rows)], check=True)
        out = folder / f"fit_{rows}"
        wall, rss, code = measure(["-m", "coupling.app.cli", "fit", str(csv), "--out", str(out)])
        if code != 0:
            raise SystemExit(f"switchsim fit exited with {code} on {csv}")
        base = base or (wall, rss)
        print(f"{rows:>9} {csv.stat().st_size / 1e6:>8.1f} {wall:>8.2f} {rss:>8.0f} {wall / base[0]:>6.2f} "
              f"{rss / base[1]:>9.2f} {wall - wall0:>7.2f} s {rss - rss0:>4.0f} MiB")
        lines.append(f"| {rows:,} | {csv.stat().st_size / 1e6:.1f} | {wall:.2f} | {rss:.0f} | {wall / base[0]:.2f} | "
                     f"{rss / base[1]:.2f} | {wall - wall0:.2f} s, {rss - rss0:.0f} MiB |")
        if rows == TARGET_ROWS:
            target = (wall, rss)
    print("target: 1,000,000 rows in <= 10 s and <= 300 MB = 286 MiB (whole process)")
    verdict = "not measured in this run" if target is None else (
        f"**{'met' if target[0] <= TARGET_S and target[1] <= TARGET_MIB else 'NOT met'}** "
        f"({target[0]:.2f} s, {target[1]:.0f} MiB = {target[1] * 2**20 / 1e6:.0f} MB)")
    lines += ["", f"- Target: {TARGET_ROWS:,} rows in <= {TARGET_S:g} s and <= 300 MB = {TARGET_MIB:.0f} MiB "
              f"(whole process): {verdict}.",
              load_line()]
    publish(DOC, BEGIN, END, lines, write=not args.no_write)


if __name__ == "__main__":
    main()
