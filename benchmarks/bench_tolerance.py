"""Benchmark: a tolerance study of the default relay's make, `switchsim sweep` as a user runs it.

Target (issue 22): 1000 samples of the default relay's make on this 2-core machine in
<= 15 minutes with 2 workers, the client's memory flat (the rows go to Parquet batches, the
waveforms stay on the workers). The study: the coil-driven default scene to 8 ms (the coil
on at 1 ms, the contact makes at ~5.5 ms and settles), no files per run; tolerances on the
return spring's preload (5 %), the contact gap (5 %), the magnet's rest gap (5 %, normal,
3 sigma) and the coil's resistance (7 %, uniform); limit: operate time 4.6 ms.

Measured: the whole command from spawn to exit, the client's resident memory sampled every
second from /proc (its peak in each quarter of the runs, the end of the runs read from the
progress lines: flat means the last quarter within 25 MiB of the second, the first holding
the first results' imports; and its peak at the statistics stage after the runs, which reads the
rows' batch files), and the study's own statistics of the operate time. Not a
test: run by hand,

    .venv/bin/python benchmarks/bench_tolerance.py [--samples 1000] [--no-write]

It rewrites the block between the bench_tolerance markers in docs/sweeps.md.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from doc_block import write_block

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "sweeps.md"
BEGIN, END = "<!-- bench_tolerance:begin -->", "<!-- bench_tolerance:end -->"
LIMIT = 4.6e-3  # s, operate time

SWEEP = """
[sweep]
design = "tolerance"
samples = {samples}
seed = 1
limits = {{ "relay.operate_time" = {limit!r} }}
set = {{ "solver.t_end" = 0.008, "output.csv" = false, "output.parquet" = false, "output.html" = false, "output.plots" = false }}

[sweep.tolerances]
"armature.spring_preload" = {{ tolerance = 0.05, distribution = "normal", relative = true }}
"initial.height" = {{ tolerance = 0.05, distribution = "normal", relative = true }}
"magnet.rest_gap" = {{ tolerance = 0.05, distribution = "normal", relative = true }}
"coil.resistance" = {{ tolerance = 0.07, distribution = "uniform", relative = true }}
"""


def rss_mib(pid: int) -> float | None:
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    except OSError:
        return None
    return None


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=1000)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--no-write", action="store_true")
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="bench_tolerance_"))
    sweep = tmp / "study.toml"
    sweep.write_text(SWEEP.format(samples=args.samples, limit=LIMIT))
    out = tmp / "out"
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    cmd = [sys.executable, "-m", "coupling", "sweep", str(sweep), "--out", str(out), "--workers", str(args.workers)]
    start = time.perf_counter()
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    # the progress lines on stderr say when the last run is done: the statistics stage follows
    first_done_at: list[float] = []
    runs_done_at: list[float] = []
    errors: list[str] = []

    def follow() -> None:
        for line in proc.stderr:
            errors.append(line)
            if " runs done" in line and not first_done_at:
                first_done_at.append(time.perf_counter() - start)
            if f"{args.samples}/{args.samples} runs done" in line and not runs_done_at:
                runs_done_at.append(time.perf_counter() - start)

    reader = threading.Thread(target=follow, daemon=True)
    reader.start()
    samples: list[tuple[float, float]] = []
    while proc.poll() is None:
        r = rss_mib(proc.pid)
        if r is not None:
            samples.append((time.perf_counter() - start, r))
        time.sleep(1.0)
    wall = time.perf_counter() - start
    reader.join(timeout=10)
    if proc.returncode != 0:
        raise SystemExit(f"sweep failed ({proc.returncode}): {''.join(errors).strip()[-2000:]}")
    stats = json.loads((out / "statistics.json").read_text())
    op = stats["relay.operate_time"]
    files = len(list((out / "results").glob("part-*.parquet")))
    # the runs: from the first finished (the cluster has started) to the last; quarters of it
    first = first_done_at[0] if first_done_at else 0.0
    end = runs_done_at[0] if runs_done_at else wall
    quarters = []
    for k in range(4):
        lo, hi = first + k * (end - first) / 4, first + (k + 1) * (end - first) / 4
        part = [r for t, r in samples if lo <= t < hi]
        quarters.append(max(part) if part else float("nan"))
    after = max((r for t, r in samples if t >= end), default=float("nan"))
    try:
        load = os.getloadavg()[0]
    except OSError:
        load = float("nan")
    study = stats.get("_study", {})
    lines = [
        f"`.venv/bin/python benchmarks/bench_tolerance.py --samples {args.samples}` (load average {load:.1f} at "
        f"the end; {args.workers} workers on this 2-core machine):",
        "",
        f"- {args.samples} samples of the default relay's make (8 ms each), "
        f"{study.get('rows', args.samples)} rows, {study.get('failed', 0)} failed: **{wall / 60:.1f} min** whole "
        f"command (target <= 15 min: {'met' if wall <= 900 else 'not met'}), {wall / args.samples:.2f} s per sample.",
        f"- client resident memory, peak per quarter of the runs: "
        + ", ".join(f"{q:.0f}" for q in quarters) + " MiB: "
        + (f"flat (the last within {quarters[-1] - quarters[1]:+.0f} MiB of the second)" if abs(quarters[-1] - quarters[1]) <= 25 else
           f"not flat (the last {quarters[-1] - quarters[1]:+.0f} MiB above the second)")
        + f"; then {after:.0f} MiB at the statistics and plots stage (it reads the rows, {files} batch files, "
        "and imports SciPy and matplotlib).",
        f"- operate time: mean {op['mean']['value'] * 1e3:.4f} ms (95 % interval "
        f"{op['mean']['interval'][0] * 1e3:.4f}-{op['mean']['interval'][1] * 1e3:.4f}), std "
        f"{op['std']['value'] * 1e6:.1f} us, p99 {op['p99']['value'] * 1e3:.4f} ms; beyond {LIMIT * 1e3:g} ms: "
        f"{op['limit']['fraction']['value']:.3f} of the samples (95 % interval "
        f"{op['limit']['fraction']['interval'][0]:.3f}-{op['limit']['fraction']['interval'][1]:.3f})"
        + ("; the spread is driven by " + ", ".join(
            f"{k} (Spearman {v['spearman']:+.2f})" for k, v in sorted(
                op.get("sensitivity", {}).items(), key=lambda kv: -abs(kv[1]["spearman"]))) if op.get("sensitivity")
           else "") + ".",
    ]
    block = "\n".join(lines)
    print(block)
    if not args.no_write:
        write_block(DOC, BEGIN, END, block, heading="## Speed of a tolerance study\nWritten by "
                                                    "benchmarks/bench_tolerance.py.\n\n")
        print(f"wrote {DOC}")


if __name__ == "__main__":
    main()
