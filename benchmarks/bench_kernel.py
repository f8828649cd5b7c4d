"""Benchmark: the compiled mechanics' cost per step on the default scene, this tree against another.

    .venv/bin/python benchmarks/bench_kernel.py --baseline DIR [--repeat 5] [--replays 3]

The default scene (the coil-driven relay) is run once, coupled, in a child process of this
tree, recording every call the co-simulation makes on its mechanics (``advance`` with its
drives, ``checkpoint``, ``restore``). Each tree then replays that recording in fresh child
processes (its own ahead-of-time module, as `switchsim run` loads it; built first if
missing), alternating tree by tree --repeat times, so both see the same machine load;
each figure is the CPU time of the process's thread (time.thread_time: a shared machine's
other processes add less to it than to the wall time), the best of --replays:
- the mechanics phase: the replay (the solver's Python side and the compiled
  ``integrate``), and per accepted step;
- the right-hand side alone: ``contact_series`` at 20000 points of the run (the compiled
  ``dense_contact`` loop: one ``dynamics`` per point), per call;
- the energy table of the run's history (the compiled ``energy_table`` loop: one
  ``energies`` per record), per record.
Printed: medians over the repetitions and the ratios this tree / baseline. Not a test,
and nothing is written to docs: timings are only compared within one run.
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import statistics
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

RECORD = textwrap.dedent("""
    import pickle, sys
    import coupling.core.master as master
    from coupling.core.scene import default_scene
    calls = []
    class Recording(master.ImpactSolver):
        def advance(self, t_target, drives=None, **kw):
            calls.append(("advance", t_target, dict(drives or {}), kw))
            return super().advance(t_target, drives, **kw)
        def checkpoint(self):
            calls.append(("checkpoint",))
            return super().checkpoint()
        def restore(self, cp):
            calls.append(("restore",))
            return super().restore(cp)
    master.ImpactSolver = Recording
    scene = default_scene()
    result = master.run(scene)
    pickle.dump(dict(calls=calls, input_work=scene.duty is not None and scene.duty.repulsion),
                open(sys.argv[1], "wb"))
""")

REPLAY = textwrap.dedent("""
    import json, math, pickle, sys, time
    import numpy as np
    from coupling.core.scene import default_scene
    from mech import ImpactSolver
    doc = pickle.load(open(sys.argv[1], "rb"))
    replays = int(sys.argv[2])
    scene = default_scene()
    def replay():
        solver = ImpactSolver(scene.mech, keep_dense=True, input_work=doc["input_work"])
        cp = None
        tick = time.thread_time()
        for call in doc["calls"]:
            if call[0] == "advance":
                solver.advance(call[1], call[2], **call[3])
            elif call[0] == "checkpoint":
                cp = solver.checkpoint()
            else:
                solver.restore(cp)
        return time.thread_time() - tick, solver
    replay()  # warm-up: the module's load, the model build's caches
    walls = []
    for _ in range(replays):
        wall, solver = replay()
        walls.append(wall)
    steps = int(solver.stats[0])
    rhs = int(solver.stats[2])
    times = np.linspace(0.0, solver.t, 20000)
    solver.contact_series(times)
    rhs_wall = math.inf
    for _ in range(replays):
        tick = time.thread_time()
        solver.contact_series(times)
        rhs_wall = min(rhs_wall, time.thread_time() - tick)
    from mech.compiled import energy_table
    result = solver.result()
    m = result.model
    energy_table(result.states[:2], m.arrays, m.armature_arrays)
    energy_wall = math.inf
    for _ in range(replays):
        tick = time.thread_time()
        table = energy_table(result.states, m.arrays, m.armature_arrays)
        energy_wall = min(energy_wall, time.thread_time() - tick)
    print(json.dumps(dict(mech=min(walls), steps=steps, rhs=rhs, per_step=min(walls) / steps,
                          per_rhs_call=rhs_wall / len(times), per_energy_row=energy_wall / len(table),
                          rows=len(table))))
""")


def _env(root: Path) -> dict:
    return dict(os.environ, PYTHONPATH=str(root) + os.pathsep + os.environ.get("PYTHONPATH", ""),
                MPLBACKEND="Agg", OPENBLAS_NUM_THREADS="1")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", type=Path, required=True, help="another tree of the project")
    parser.add_argument("--repeat", type=int, default=5, help="child processes per tree (alternating)")
    parser.add_argument("--replays", type=int, default=3, help="replays per child process (best taken)")
    args = parser.parse_args()
    py = sys.executable
    trees = {"baseline": args.baseline.resolve(), "this tree": ROOT}
    tmp = Path(tempfile.mkdtemp(prefix="bench_kernel_"))
    calls = tmp / "calls.pickle"
    # (each child runs in its tree's folder: `python -c` puts the working folder first on
    # sys.path, before PYTHONPATH)
    for root in trees.values():  # each tree's ahead-of-time module, built if missing
        subprocess.run([py, "-c", "import coupling.core.master"], env=_env(root), cwd=root, check=True)
    subprocess.run([py, "-c", RECORD, str(calls)], env=_env(ROOT), cwd=ROOT, check=True)
    n_calls = len(pickle.loads(calls.read_bytes())["calls"])
    rows: dict = {name: [] for name in trees}
    for _ in range(args.repeat):
        for name, root in trees.items():
            done = subprocess.run([py, "-c", REPLAY, str(calls), str(args.replays)], env=_env(root), cwd=root,
                                  capture_output=True, text=True, check=True)
            rows[name].append(json.loads(done.stdout.strip().splitlines()[-1]))
    try:
        load = os.getloadavg()[0]
    except OSError:
        load = float("nan")
    first = rows["this tree"][0]
    print(f"default scene's mechanics replayed ({n_calls} calls of the co-simulation; {first['steps']} steps, "
          f"{first['rhs']} right-hand sides, {first['rows']} records); median of {args.repeat} processes "
          f"per tree, alternating; load average {load:.1f}")
    print(f"{'':32s} {'baseline':>12s} {'this tree':>12s} {'ratio':>7s}")
    for key, label, scale, unit in (("mech", "mechanics phase (replay)", 1e3, "ms"),
                                    ("per_step", "  per accepted step", 1e6, "us"),
                                    ("per_rhs_call", "dynamics (contact_series)", 1e6, "us"),
                                    ("per_energy_row", "energies (energy_table)", 1e6, "us")):
        a, b = (statistics.median(r[key] for r in rows[name]) for name in ("baseline", "this tree"))
        print(f"{label:32s} {a * scale:9.2f} {unit} {b * scale:9.2f} {unit} {b / a:7.3f}")
    steps = {name: rows[name][0]["steps"] for name in trees}
    if len(set(steps.values())) > 1:
        print(f"note: the trees took different step counts on the same calls: {steps}")


if __name__ == "__main__":
    main()
