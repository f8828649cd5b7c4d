"""Benchmark: whole-process `switchsim run`, against the interpreter's own start in the same run.

Targets, whole process (start to exit, as /usr/bin/time -v counts it):
- a mechanics-only scene (6 mm bar, 20 modes per family, 0.9 ms): <= 0.6 s (issue 12);
- the default scene (the coil-driven relay: coil on, make, settle, coil off, break) with its
  default outputs (summary.json, the mechanics tables, waveforms.csv/.parquet/.html,
  openings.csv; PNGs are on request): <= 6x `python -c "import numpy"` (issue 19; the
  force-driven relay it replaced, builtin relay_force, is measured beside it);
- the plunger solenoid example (examples/plunger_solenoid.toml): <= 3x `import numpy`.
Baselines measured in the same run: `python -c pass` and `python -c "import numpy"`;
on a loaded machine everything scales, so the ratios to them are printed too. The two
ratio targets are judged on interleaved rounds (``interleaved``: `import numpy`, the
default scene and the plunger back to back, round after round), not on the table's rows,
each of which repeats one command in a row: `import numpy` alone moved between 0.083 and
0.124 s from one minute to the next on this machine, and a row measured minutes before
another made their ratio swing by more than the targets' margins.

Then where the time goes: a fresh interpreter timing the steps of `switchsim run`
(imports, scene, run, soundness, writing), with its start and exit timed from outside,
and inside them the model build, ngspice's start, the mechanics and the circuit of the
co-simulation, and each output file; and what sets the default scene's mechanics step:
its step counts at rtol 1e-5, 1e-6 and 1e-7 against the explicit integrator's stability
bound on the bar's highest mode. The AOT module of this tree is built by the warm-up
if missing, and the held blade's eigenproblems are solved there and kept (mech.eigen_cache),
as a device's first run keeps them for its next: the default scene is timed once more with
them solved at every run (SWITCHSIM_EIGEN_CACHE=0, a device's first run). Not a test: run
by hand,

    .venv/bin/python benchmarks/bench_startup.py [--repeat 5] [--no-write] [--baseline DIR]

It rewrites the block between the bench_startup markers in docs/benchmarks.md.
--baseline DIR: also time the default scene and the plunger example from another tree of
the project (its own AOT module built by its warm-up), each repetition alternating the two
trees, and print both ratios to `import numpy` (a before/after in one run; not written to
the docs).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

from doc_block import write_block

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "benchmarks.md"
BEGIN, END = "<!-- bench_startup:begin -->", "<!-- bench_startup:end -->"

MECH_SCENE = """\
# mechanics only: a 6 mm steel bar, 20 modes per family, 0.9 ms (SI units)
[bar]
length = 0.3
diameter = 0.006
tip_radius = 0.003
modes = 20
[initial]
height = 0.0005
angle_deg = 30.0
velocity = [0.0, 0.0, -1.0]
[solver]
t_end = 0.0009
"""

NO_OUTPUT = "\n[output]\ncsv = false\nparquet = false\nplots = false\nhistory = false\nhtml = false\n"


def _env(root: Path = ROOT) -> dict:
    # PYTHONSAFEPATH: `python -m`/`-c` would put the working directory first on sys.path, so
    # run from inside a tree both "trees" of --baseline imported that one
    return dict(os.environ, PYTHONPATH=str(root) + os.pathsep + os.environ.get("PYTHONPATH", ""),
                MPLBACKEND="Agg", PYTHONSAFEPATH="1")


def whole_process(cmd: list[str], repeat: int, root: Path = ROOT, env: dict | None = None) -> tuple[float, float, float]:
    """(median wall s, min wall s, max peak RSS MiB) of a command started `repeat` times
    (``env``: variables set for it besides the tree's)."""
    walls, rss = [], []
    for _ in range(repeat):
        tick = time.perf_counter()
        proc = subprocess.Popen(cmd, env=dict(_env(root), **(env or {})), stdout=subprocess.DEVNULL,
                                stderr=subprocess.PIPE)
        _, status, usage = os.wait4(proc.pid, 0)
        walls.append(time.perf_counter() - tick)
        if os.waitstatus_to_exitcode(status) != 0:
            raise RuntimeError(f"{' '.join(cmd)} failed: {proc.stderr.read().decode()[-2000:]}")
        proc.stderr.close()
        rss.append(usage.ru_maxrss / 1024.0)
    return statistics.median(walls), min(walls), max(rss)


PHASES = textwrap.dedent("""
    import time
    wall0 = time.time()  # the parent's clock: interpreter start = wall0 - the parent's spawn time
    import gc, json, os, sys
    gc.disable()  # as coupling.app.commands.run_command does in the command line's own process
    marks = [("start", time.perf_counter())]
    def mark(name): marks.append((name, time.perf_counter()))
    collector = {}  # the cyclic collector's own time, from its callbacks
    def collecting(phase, info):
        if phase == "start":
            collector["since"] = time.perf_counter()
        else:
            collector["s"] = collector.get("s", 0.0) + time.perf_counter() - collector["since"]
            collector["n"] = collector.get("n", 0) + 1
    gc.callbacks.append(collecting)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # as coupling.app.cli.main sets it
    from coupling.core.master import run
    mark("import coupling.core.master (numpy, mech, the compiled module)")
    parts = {}  # seconds inside the phases: the callables below, timed where they are called
    def timed(owner, name, label=None):
        inner = getattr(owner, name)
        def wrapper(*args, **kw):
            tick = time.perf_counter()
            try:
                return inner(*args, **kw)
            finally:
                key = label or (args[0].name if name in ("write_csv", "write_parquet") else name)
                parts[key] = parts.get(key, 0.0) + time.perf_counter() - tick
        setattr(owner, name, wrapper)
    import mech.solver, circuit, coupling.app.output as output, coupling.app.waveview as waveview
    timed(mech.solver, "build_model", "model build (modes, FE eigenproblem)")
    timed(circuit.Stepper, "__init__", "ngspice start (netlist, operating point)")
    for name in ("write_csv", "write_parquet"):
        timed(output, name)
    timed(waveview, "write_waveform_html", "waveforms.html")
    from coupling.app.output import ResultFolder, scene_identity
    from coupling.core.scene import default_scene, load_scene
    from coupling.core.soundness import assess
    scene = default_scene() if sys.argv[1] == "default" else load_scene(sys.argv[1])
    mark("scene (read, validate; circuit: PySpice, laws)")
    folder = ResultFolder.check(sys.argv[2], scene_identity(scene, None), overwrite=True)
    gc.freeze()  # the scene built (run_command): frozen, the collector on for the run
    gc.enable()
    from coupling.app.table_writer import TableWriter, wanted
    writer = TableWriter.start() if wanted(scene) else None  # as run_command: the large tables' helper
    watch = None
    if writer is not None:
        timed(TableWriter, "submit", "large tables handed to the table writer")
        timed(TableWriter, "collect", "waiting for the table writer")
        if scene.output.history:  # as run_command: history.csv's rows sent while the run goes on
            from coupling.app.history_stream import HistoryStream
            timed(HistoryStream, "__call__", "history.csv's pieces (during the run: rows decided, computed, sent)")
            watch = writer.history = HistoryStream(writer, scene)
    result = run(scene, progress=False, watch=watch)
    mark("run (model build, ngspice start, co-simulation)")
    soundness = assess(result)
    mark("soundness")
    folder.write(result, {"soundness": soundness}, writer)
    if writer is not None:
        for path, seconds in writer.seconds.items():
            parts[os.path.basename(path) + " (by the table writer, meanwhile)"] = seconds
        writer.close(wait=False)
    mark("write the default outputs")
    stats = result.stats
    parts["Python's cyclic collector (gc.callbacks; imports to files written)"] = collector.get("s", 0.0)
    gc.freeze()  # as coupling.app.cli.main does when the process's own command line returns
    phases = [(b[0], b[1] - a[1]) for a, b in zip(marks, marks[1:])]
    steps = result.mechanics.stats["steps"] if result.mechanics is not None else 0
    print(json.dumps(dict(phases=phases, wall_time=stats.get("wall_time", 0.0),
                          mech=stats.get("mech_seconds"), circuit=stats.get("circuit_seconds"),
                          parts=parts, steps=steps, macro_steps=stats.get("macro_steps", 0), wall0=wall0,
                          wall1=time.time())), flush=True)
    sys.stderr.flush()
    os._exit(0)  # as coupling.app.cli.entry ends `switchsim run`: no interpreter teardown
""")


def phases(scene: str, out: str) -> dict:
    """One fresh interpreter timing the phases of `switchsim run` (coupling.app.commands.run_command's
    steps), with the interpreter's start and exit measured from here."""
    spawn = time.time()
    done = subprocess.run([sys.executable, "-c", PHASES, scene, out], env=_env(), capture_output=True, text=True,
                          check=True)
    end = time.time()
    doc = json.loads(done.stdout.strip().splitlines()[-1])
    doc["phases"] = ([("interpreter start (python, site)", doc["wall0"] - spawn)] + doc["phases"]
                     + [("exit (os._exit, as the command ends)", end - doc["wall1"])])
    doc["whole"] = end - spawn
    return doc


STEP_LIMIT = textwrap.dedent("""
    import json, sys
    import numpy as np
    from coupling.core.master import run
    from coupling.core.scene import default_scene
    from mech import ImpactSolver
    scene = default_scene()
    model = ImpactSolver(scene.mech).model
    rows = []
    for rtol in (1e-5, 1e-6, 1e-7):
        res = run(scene.set("solver.rtol", rtol))
        st = res.mechanics.stats
        dt = np.diff(res.mechanics.history["time"].to_numpy())
        rows.append(dict(rtol=rtol, steps=st["steps"], rejected=st["rejected_steps"], rhs=st["rhs_evals"],
                         median_step=float(np.median(dt[dt > 0]))))
    print(json.dumps(dict(rows=rows, f_max=float(np.max(model.basis.frequencies)),
                          zeta=float(scene.mech.bar.modal_damping))), flush=True)
""")


def dopri5_bound(zeta: float) -> float:
    """|h lambda| where DOPRI5's fifth-order solution stops being stable along the ray of a
    mode with damping ratio ``zeta`` (lambda = omega (-zeta + i sqrt(1 - zeta^2))): its
    stability function is R(z) = sum_{k<=5} z^k / k! + z^6 / 600 (the coefficients
    b' A^(k-1) 1 of the Dormand-Prince tableau in mech/integrator.py); the first r where
    |R(r e^{i phi})| exceeds 1, found by a scan and bisection."""
    import cmath
    import math

    def grows(r: float) -> bool:
        z = r * cmath.exp(1j * (math.pi - math.acos(zeta)))
        return abs(sum(z ** k / math.factorial(k) for k in range(6)) + z ** 6 / 600.0) > 1.0

    r = 0.5
    while not grows(r):
        r += 0.01
    lo, hi = r - 0.01, r
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if grows(mid) else (mid, hi)
    return lo


def budget(coupled: dict, plunger: dict, base: float) -> str:
    """What each target leaves for the co-simulation: the whole process of the phase
    measurement less the co-simulation itself (the run's wall_time less its model build
    and ngspice start), against the target times the interleaved rounds' `import numpy` (``base``, s)."""
    def split(doc: dict) -> tuple[float, float]:
        setup = sum(doc["parts"].get(k, 0.0) for k in ("model build (modes, FE eigenproblem)",
                                                        "ngspice start (netlist, operating point)"))
        cosim = doc["wall_time"] - setup
        return doc["whole"] - cosim, cosim

    (d_rest, d_sim), (p_rest, p_sim) = split(coupled), split(plunger)
    return (f"- In the phase measurement above, everything but the co-simulation (interpreter, imports, "
            f"scene, model build, ngspice start, soundness, writes, exit) takes {d_rest:.3f} s = "
            f"{d_rest / base:.1f}x `import numpy` for the default scene and {p_rest:.3f} s = "
            f"{p_rest / base:.1f}x for the plunger: the targets (6x, 3x) leave "
            f"{6 * base - d_rest:.3f} s for the default relay's 12 ms of co-simulation, which take "
            f"{d_sim:.3f} s here, and {3 * base - p_rest:.3f} s for the plunger's 50 ms, which take "
            f"{p_sim:.3f} s.")


def step_limit() -> list[str]:
    """What sets the default scene's mechanics step: the steps at three tolerances against the
    explicit integrator's stability bound on the bar's highest mode (a fresh interpreter)."""
    done = subprocess.run([sys.executable, "-c", STEP_LIMIT], env=_env(), capture_output=True, text=True, check=True)
    doc = json.loads(done.stdout.strip().splitlines()[-1])
    bound = dopri5_bound(doc["zeta"])
    h_stab = bound / (2.0 * math.pi * doc["f_max"])
    lines = ["", "What sets the mechanics step of the default scene (its co-simulation at three error "
             "tolerances; median of the history's step lengths; a fresh interpreter):", "",
             "| rtol | accepted steps | rejected | right-hand sides | median step |", "|---|---|---|---|---|"]
    for row in doc["rows"]:
        lines.append(f"| {row['rtol']:.0e} | {row['steps']} | {row['rejected']} | {row['rhs']} | "
                     f"{row['median_step'] * 1e6:.2f} us |")
    steps = [row["steps"] for row in doc["rows"]]
    lines += ["", f"- The bar's highest mode: {doc['f_max'] / 1e3:.1f} kHz (modal damping {doc['zeta']:g}); "
              f"DOPRI5 is stable on it up to |h lambda| = {bound:.2f}, h = {h_stab * 1e6:.2f} us.",
              f"- A 100-fold range of rtol moves the step count by {100 * (max(steps) / min(steps) - 1):.0f} %: "
              "the step is held near the stability bound of the highest mode, not by the error tolerance."]
    return lines


def interleaved(run: list[str], solenoid: Path, tmp: Path, rounds: int) -> dict:
    """The ratio targets measured as their ratios mean it, numerator and denominator at the
    same moment: ``rounds`` rounds of `import numpy`, the default scene and the plunger
    example (default outputs) back to back. Per command the median wall time (s); per scene
    the ratio of the medians, and the median, smallest and largest of the rounds' own
    ratios (each run over the round's `import numpy`)."""
    cmds = {
        "numpy": [sys.executable, "-c", "import numpy"],
        "default": run + ["--out", str(tmp / "i1"), "--quiet", "--overwrite"],
        "plunger": run + [str(solenoid), "--out", str(tmp / "i2"), "--quiet", "--overwrite"],
    }
    walls: dict[str, list[float]] = {name: [] for name in cmds}
    for _ in range(rounds):
        for name, cmd in cmds.items():
            walls[name].append(whole_process(cmd, 1)[0])
    out = {name: statistics.median(w) for name, w in walls.items()}
    for name in ("default", "plunger"):
        per_round = [a / b for a, b in zip(walls[name], walls["numpy"])]
        out[name + "_ratio"] = out[name] / out["numpy"]
        out[name + "_rounds"] = (statistics.median(per_round), min(per_round), max(per_round))
    out["rounds"] = rounds
    return out


def compare_trees(baseline: Path, solenoid: Path, tmp: Path, repeat: int) -> None:
    """The default scene and the plunger example whole process in this tree and in
    ``baseline``, alternating repetition by repetition, with `import numpy` between them:
    medians and ratios, printed."""
    py = sys.executable
    subprocess.run([py, "-c", "import coupling.core.master"], env=_env(baseline), check=True)  # its AOT build
    cmds = {
        "import numpy": ([py, "-c", "import numpy"], None),
        "default scene": ([py, "-m", "coupling.app.cli", "run", "--out", str(tmp / "cmp"), "--quiet",
                           "--overwrite"], "both"),
        "plunger solenoid": ([py, "-m", "coupling.app.cli", "run", str(solenoid), "--out", str(tmp / "cmp"),
                              "--quiet", "--overwrite"], "both"),
    }
    walls: dict = {}
    for _ in range(repeat):
        for label, (cmd, trees) in cmds.items():
            for tree, root in (("this tree", ROOT), ("baseline", baseline)) if trees else (("", ROOT),):
                walls.setdefault((label, tree), []).append(whole_process(cmd, 1, root)[0])
    numpy = statistics.median(walls[("import numpy", "")])
    print(f"\nthis tree against {baseline} (alternating, median of {repeat}; `import numpy` {numpy:.3f} s):")
    for label in ("default scene", "plunger solenoid"):
        a, b = (statistics.median(walls[(label, t)]) for t in ("baseline", "this tree"))
        print(f"  {label:17s} baseline {a:.3f} s ({a / numpy:.1f}x)  this tree {b:.3f} s ({b / numpy:.1f}x)")


def _bytecode_note() -> str:
    """Whether the children run switchsim from compiled bytecode: with PYTHONDONTWRITEBYTECODE
    set and no cache of this tree, every start compiles switchsim's ~50 modules from source
    (~0.05-0.09 s of the import and scene phases here)."""
    import importlib.util

    cached = os.path.exists(importlib.util.cache_from_source(str(ROOT / "coupling" / "app" / "cli.py")))
    if not sys.flags.dont_write_bytecode:
        return "bytecode caches on"
    return "PYTHONDONTWRITEBYTECODE set, " + ("bytecode caches present" if cached else
                                              "no bytecode cache: each start compiles switchsim's modules from source")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--no-write", action="store_true", help="print only; leave docs/benchmarks.md alone")
    parser.add_argument("--baseline", type=Path, help="another tree of the project to compare with (printed only)")
    args = parser.parse_args()
    py = sys.executable
    tmp = Path(tempfile.mkdtemp(prefix="bench_startup_"))
    mech = tmp / "mech.toml"
    mech.write_text(MECH_SCENE)
    mech_quiet = tmp / "mech_no_output.toml"
    mech_quiet.write_text(MECH_SCENE + NO_OUTPUT)
    # the default scene's text read as a file: this process imports nothing heavy, so a
    # child's peak RSS (counted from the fork) is its own
    default_text = (ROOT / "coupling" / "scenes" / "default.toml").read_text()
    coupled_quiet = tmp / "default_no_output.toml"
    coupled_quiet.write_text(default_text.split("[output]")[0] + NO_OUTPUT)
    force_scene = tmp / "relay_force.toml"
    force_scene.write_text((ROOT / "coupling" / "scenes" / "relay_force.toml").read_text())
    solenoid = ROOT / "examples" / "plunger_solenoid.toml"
    run = [py, "-m", "coupling.app.cli", "run"]
    # warm-up: the ahead-of-time module of this tree (built if missing), ngspice, the OS file
    # cache, the held blade's eigenproblems (mech.eigen_cache)
    for scene in (str(mech), None):
        whole_process(run + ([scene] if scene else []) + ["--out", str(tmp / "warm"), "--quiet", "--overwrite"], 1)

    rows = []
    for label, cmd in [
        ("`python -c pass`", [py, "-c", "pass"]),
        ("`python -c \"import numpy\"`", [py, "-c", "import numpy"]),
        ("`import coupling.core.master, coupling.core.scene`", [py, "-c", "import coupling.core.master, coupling.core.scene"]),
        ("mechanics-only scene, default outputs", run + [str(mech), "--out", str(tmp / "m1"), "--quiet"]),
        ("mechanics-only scene, outputs off", run + [str(mech_quiet), "--out", str(tmp / "m2"), "--quiet"]),
        ("default coupled scene, default outputs", run + ["--out", str(tmp / "c1"), "--quiet"]),
        ("default coupled scene, outputs off", run + [str(coupled_quiet), "--out", str(tmp / "c2"), "--quiet"]),
        ("relay_force (the former default), default outputs", run + [str(force_scene), "--out", str(tmp / "f1"),
                                                                     "--quiet"]),
        ("plunger solenoid example, default outputs", run + [str(solenoid), "--out", str(tmp / "s1"), "--quiet"]),
        # (every row above reads the held blade's eigenproblems back from mech.eigen_cache,
        # as a second run of a device does; this one solves them, as its first run does)
        ("default coupled scene, default outputs, eigenproblems solved (`SWITCHSIM_EIGEN_CACHE=0`)",
         run + ["--out", str(tmp / "c3"), "--quiet"]),
    ]:
        solved = {"SWITCHSIM_EIGEN_CACHE": "0"} if "EIGEN_CACHE=0" in label else None
        med, best, rss = whole_process(cmd, args.repeat, env=solved)
        rows.append((label, med, best, rss))
        print(f"{label:45s} {med:6.3f} s (best {best:.3f}), peak RSS {rss:.0f} MiB", flush=True)
    base = rows[1][1]
    rounds = max(21, args.repeat)
    targets = interleaved(run, solenoid, tmp, rounds)
    print(f"interleaved, {rounds} rounds: import numpy {targets['numpy']:.3f} s, default {targets['default']:.3f} s "
          f"({targets['default_ratio']:.2f}x), plunger {targets['plunger']:.3f} s ({targets['plunger_ratio']:.2f}x)",
          flush=True)
    if args.baseline:
        compare_trees(args.baseline.resolve(), solenoid, tmp, args.repeat)
    mech_phases = phases(str(mech), str(tmp / "pm"))
    coupled_phases = phases("default", str(tmp / "pc"))
    plunger_phases = phases(str(solenoid), str(tmp / "pp"))
    try:
        load = os.getloadavg()[0]
    except OSError:
        load = float("nan")

    lines = [f"`.venv/bin/python benchmarks/bench_startup.py --repeat {args.repeat}` "
             f"(load average {load:.1f} at the end; median of {args.repeat}, whole process, "
             f"peak RSS from wait4: the command's own process, not its table writer's); {_bytecode_note()}", "",
             "| command | wall | best | / `import numpy` | peak RSS |", "|---|---|---|---|---|"]
    for label, med, best, rss in rows:
        lines.append(f"| {label} | {med:.3f} s | {best:.3f} s | {med / base:.1f}x | {rss:.0f} MiB |")
    mech_run = rows[3][1]
    coupled_run = rows[5][1]

    def verdict(name: str, limit: float) -> str:
        ratio = targets[name + "_ratio"]
        middle, low, high = targets[name + "_rounds"]
        return (f"**{ratio:.2f}x** (target <= {limit:g}x: {'met' if ratio <= limit else 'not met'}; the rounds' own "
                f"ratios: median {middle:.2f}x, {low:.2f}-{high:.2f}x)")

    lines += ["",
              f"- Mechanics-only scene: **{mech_run:.2f} s** whole process (target <= 0.6 s: "
              f"{'met' if mech_run <= 0.6 else 'not met'}); {rows[4][1]:.2f} s with every output off.",
              f"- The ratio targets, on {targets['rounds']} interleaved rounds (`import numpy`, the default scene, "
              f"the plunger, back to back; medians: `import numpy` {targets['numpy']:.3f} s):",
              f"  - default scene (the coil-driven relay, 12 ms) with its default outputs: "
              f"{targets['default']:.3f} s, {verdict('default', 6)};",
              f"  - plunger solenoid example (50 ms): {targets['plunger']:.3f} s, {verdict('plunger', 3)}.",
              f"- The table's rows (each command {args.repeat} times in a row): the default scene "
              f"**{coupled_run:.2f} s**, {coupled_run / base:.1f}x its `import numpy`; {rows[6][1]:.2f} s with every "
              f"output off; relay_force (the former, force-driven default, 5 ms) {rows[7][1]:.2f} s, "
              f"{rows[7][1] / base:.1f}x; {rows[9][1]:.2f} s, {rows[9][1] / base:.1f}x, with its eigenproblems solved "
              f"rather than read back (a device's first run; docs/mechanics.md, \"Solved once per machine\"); the "
              f"plunger {rows[8][1]:.2f} s, {rows[8][1] / base:.1f}x.",
              f"- Scaled to this run's `import numpy` ({base:.3f} s): mechanics-only {mech_run / base:.1f}x, "
              f"default {coupled_run / base:.1f}x.",
              "", "Where the time goes (one fresh interpreter timing its own phases):", "",
              "| phase | mechanics-only | default (coil relay) | plunger solenoid |", "|---|---|---|---|"]
    runs = (mech_phases, coupled_phases, plunger_phases)

    def cells(values) -> str:
        return " | ".join("-" if v is None else (f"{v:.3f} s" if isinstance(v, float) else str(v)) for v in values)

    for name in [n for n, _ in coupled_phases["phases"]]:
        lines.append(f"| {name} | {cells(dict(r['phases']).get(name) for r in runs)} |")
    lines.append(f"| (of the run: its own wall_time) | {cells(r['wall_time'] for r in runs)} |")
    lines.append("| (of that: mechanics / circuit, coupled) | - | " + " | ".join(
        f"{r['mech'] or 0:.3f} s / {r['circuit'] or 0:.3f} s" for r in runs[1:]) + " |")
    for name in dict.fromkeys([*coupled_phases["parts"], *mech_phases["parts"], *plunger_phases["parts"]]):
        lines.append(f"| (inside: {name}) | {cells(r['parts'].get(name) for r in runs)} |")
    lines.append(f"| (mechanics steps) | {cells(r['steps'] for r in runs)} |")
    lines.append(f"| (macro steps of the co-simulation) | - | {cells(r['macro_steps'] for r in runs[1:])} |")
    lines.append(f"| whole process, this measurement | {cells(r['whole'] for r in runs)} |")
    lines += ["", budget(coupled_phases, plunger_phases, targets["numpy"])]
    lines += step_limit()
    block = "\n".join(lines)
    print("\n" + block)
    if not args.no_write:
        write_block(DOC, BEGIN, END, block, heading="## Start-up: whole-process `switchsim run` (issue 12)\n"
                                                     "Written by benchmarks/bench_startup.py.\n\n")
        print(f"\nwrote {DOC}")


if __name__ == "__main__":
    main()
