"""Benchmark: `switchsim sweep` throughput, per-run overhead and client memory.

Targets (issue 12), all measured in this one run:
- throughput with 2 workers >= 1.8 x that with 1 worker (this machine has 2 cores);
- per-run overhead of the sweep machinery (Dask task, scene build, row, Parquet batch)
  <= 10 % against the same runs made one after the other by a bare in-process run();
- peak client memory flat in the number of runs (waveforms kept: they stay on the workers' side).

Timed sweeps run on an already started cluster whose workers have each made one run
(imports and the numba cache loaded), as a worker is after its first run of a long sweep.
Not a test: run by hand,

    .venv/bin/python benchmarks/bench_sweep.py [--runs 16] [--no-write]

It rewrites the block between the bench_sweep markers in docs/sweeps.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
DOC = ROOT / "docs" / "sweeps.md"
BEGIN, END = "<!-- bench_sweep:begin -->", "<!-- bench_sweep:end -->"

TINY = """
[bar]
length = 0.1
diameter = 0.006
tip_radius = 0.003
modes = 2
[initial]
height = 0.0001
angle_deg = 30.0
velocity = [0.0, 0.0, -1.0]
[solver]
t_end = 0.0005
[tribology]
source = "illustrative"
[circuit]
template = "resistive"
voltage = 24.0
load_resistance = 12.0
"""


def coupled_sweep(runs: int):
    """The force-driven relay (relay_force), 3 ms, load resistance varied over `runs` values."""
    from coupling.core.scene import builtin_scene
    from coupling.app.sweep import Sweep

    base = builtin_scene("relay_force").set("solver.t_end", 0.003)
    return Sweep.grid(base, {"circuit.load_resistance": [6.0 + 0.5 * k for k in range(runs)]})


def bare(sweep, repeat: int) -> float:
    """s: the sweep's runs one after the other in this process, through coupling.run (warm;
    the best of `repeat`: on a shared machine the load only ever adds time)."""
    from coupling import run

    run(sweep.scene(sweep.runs[0]))  # warm-up
    best = float("inf")
    for _ in range(repeat):
        tick = time.perf_counter()
        for r in sweep.runs:
            run(sweep.scene(r))
        best = min(best, time.perf_counter() - tick)
    return best


def on_cluster(sweep, workers: int, tmp: Path, repeat: int) -> float:
    """s from the first submission to the last row, on a warm cluster of `workers` processes
    (the best of `repeat` sweeps)."""
    from distributed import Client

    from coupling.app.sweep import local_cluster, run_sweep

    env = {"PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    with local_cluster(workers, env=env) as cluster, Client(cluster) as client:
        warm = dataclasses.replace(sweep, runs=sweep.runs[:workers])
        run_sweep(warm, tmp / f"warm{workers}", client=client, progress=False, window=1)
        best = float("inf")
        for k in range(repeat):
            report = run_sweep(sweep, tmp / f"sweep{workers}-{k}", client=client, progress=False)
            assert report.complete and report.failed == 0, report
            best = min(best, report.run_seconds)
        return best


def _timed_runs(n: int = 4) -> dict:
    """n runs of the 3 ms relay_force scene in the calling process, after a warm-up,
    each timed (s), and the process's resident memory after them (bytes)."""
    import psutil

    from coupling import run
    from coupling.core.scene import builtin_scene

    scene = builtin_scene("relay_force").set("solver.t_end", 0.003)
    run(scene)
    times = []
    for k in range(n):
        tick = time.perf_counter()
        run(scene.set("circuit.load_resistance", 6.0 + 0.5 * k))
        times.append(time.perf_counter() - tick)
    return dict(times=times, rss=psutil.Process().memory_info().rss)


def worker_settings_cost(n: int) -> dict:
    """The same runs timed inside one Dask worker task under Dask's default worker settings,
    with only the profiler off, and under local_cluster's WORKER_SETTINGS; and in this process."""
    import dask
    from distributed import Client, LocalCluster

    from coupling.app.sweep import WORKER_SETTINGS

    env = {"PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    routes = (("worker, Dask's defaults (profiler on, MALLOC_TRIM_THRESHOLD_ 64 KiB)", {}),
              ("worker, profiler off", {"distributed.worker.profile.enabled": False}),
              ("worker, local_cluster's settings (profiler off, no malloc trim)", WORKER_SETTINGS))
    out = {}
    for label, settings in routes:
        with dask.config.set(settings):
            with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                              silence_logs=40, env=env) as cluster, Client(cluster) as client:
                out[label] = client.submit(_timed_runs, n, pure=False).result()
    out["this process"] = _timed_runs(n)
    return out


CLIENT = textwrap.dedent("""
    import json, resource, sys, tomllib, tracemalloc
    sys.path.insert(0, sys.argv[4])
    from coupling.core.scene import scene_from_dict
    from coupling.app.sweep import Sweep, run_sweep
    base = scene_from_dict(tomllib.loads(open(sys.argv[1]).read()), name="tiny")
    n = int(sys.argv[2])
    sweep = Sweep.grid(base, {"initial.angle_deg": [20.0 + 50.0 * k / n for k in range(n)]}, waveforms=True)
    tracemalloc.start()
    report = run_sweep(sweep, sys.argv[3], workers=2, progress=False)
    peak = tracemalloc.get_traced_memory()[1]
    print(json.dumps(dict(done=report.done, failed=report.failed, traced=peak,
                          rss=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)))
""")


def client_memory(n: int, tmp: Path) -> dict:
    scene = tmp / "tiny.toml"
    scene.write_text(TINY)
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    done = subprocess.run([sys.executable, "-c", CLIENT, str(scene), str(n), str(tmp / f"mem{n}"), str(ROOT)],
                          env=env, capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=16, help="runs of the throughput sweep")
    parser.add_argument("--repeat", type=int, default=2, help="timed repetitions per route (the best is kept)")
    parser.add_argument("--settings-runs", type=int, default=12, help="runs timed per worker setting")
    parser.add_argument("--memory-runs", default="10,40,160", help="sweep sizes for the client memory")
    parser.add_argument("--no-write", action="store_true")
    args = parser.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="bench_sweep_"))
    sweep = coupled_sweep(args.runs)
    t_bare = bare(sweep, args.repeat)
    print(f"bare in-process run(), {args.runs} runs: {t_bare:.2f} s (load {os.getloadavg()[0]:.1f})", flush=True)
    t1 = on_cluster(sweep, 1, tmp, args.repeat)
    print(f"sweep, 1 worker: {t1:.2f} s", flush=True)
    t2 = on_cluster(sweep, 2, tmp, args.repeat)
    print(f"sweep, 2 workers: {t2:.2f} s", flush=True)
    prof = worker_settings_cost(args.settings_runs)
    for label, m in prof.items():
        print(f"{label}: {', '.join(f'{t * 1e3:.0f}' for t in m['times'])} ms; RSS {m['rss'] / 2**20:.0f} MiB",
              flush=True)
    memory = []
    for n in [int(x) for x in args.memory_runs.split(",")]:
        m = client_memory(n, tmp)
        memory.append((n, m))
        print(f"client, {n} runs (waveforms kept): traced peak {m['traced'] / 2**20:.1f} MiB, "
              f"ru_maxrss {m['rss'] / 1024:.0f} MiB, {m['failed']} failed", flush=True)
    try:
        load = os.getloadavg()[0]
    except OSError:
        load = float("nan")
    speedup = t1 / t2
    overhead = t1 / t_bare - 1.0
    lines = [f"`.venv/bin/python benchmarks/bench_sweep.py --runs {args.runs} --repeat {args.repeat}` "
             f"(load average {load:.1f} at the end; {os.cpu_count()} CPUs; best of {args.repeat} per route)", "",
             f"Throughput: the relay_force scene at 3 ms, circuit.load_resistance over {args.runs} values, "
             "on a started cluster whose workers have made one run each.", "",
             "| route | wall | runs/s |", "|---|---|---|",
             f"| bare `coupling.run`, one process, one after the other | {t_bare:.2f} s | {args.runs / t_bare:.2f} |",
             f"| sweep, 1 worker | {t1:.2f} s | {args.runs / t1:.2f} |",
             f"| sweep, 2 workers | {t2:.2f} s | {args.runs / t2:.2f} |", "",
             f"- 2 workers / 1 worker: **{speedup:.2f}x** (target >= 1.8x: {'met' if speedup >= 1.8 else 'not met'}).",
             f"- Overhead of the sweep machinery per run (1 worker against bare): **{100 * overhead:+.1f} %** "
             f"(target <= 10 %: {'met' if overhead <= 0.10 else 'not met'}).", "",
             f"Worker settings (the same 3 ms relay_force run, {args.settings_runs} runs inside one Dask task "
             "after a warm-up run; the worker's resident memory after them):", "",
             "| where | per run (median, range) | RSS after |", "|---|---|---|",
             *[f"| {label} | {1e3 * sorted(m['times'])[len(m['times']) // 2]:.0f} ms ({min(m['times']) * 1e3:.0f}-"
               f"{max(m['times']) * 1e3:.0f}) | {m['rss'] / 2**20:.0f} MiB |" for label, m in prof.items()], "",
             "Client memory (a tiny coupled scene, waveforms kept, 2 workers; tracemalloc peak of the client's "
             "Python allocations during run_sweep, and its whole-process ru_maxrss):", "",
             "| runs | traced peak | ru_maxrss |", "|---|---|---|"]
    for n, m in memory:
        lines.append(f"| {n} | {m['traced'] / 2**20:.1f} MiB | {m['rss'] / 1024:.0f} MiB |")
    block = "\n".join(lines)
    print("\n" + block)
    if not args.no_write:
        text = DOC.read_text()
        head, rest = text.split(BEGIN, 1)
        DOC.write_text(head + BEGIN + "\n" + block + "\n" + END + rest.split(END, 1)[1])
        print(f"\nwrote {DOC}")


if __name__ == "__main__":
    main()
