"""Benchmark: the cost of a circuit's contact arrangement (issue 20) -- one contact, a bridge, a changeover.

Each arrangement on its own motion against one contact on the same motion, all measured in
the same run (no timed tests):

- bridge: examples/bridge_contactor.toml (a free bar pressed onto two fixed contacts by an
  actuator, then pulled off; 36 V, 12 ohm, each contact's arc), template "bridge" (the two
  contacts in series: two blocks) against template "resistive" (one circuit contact fed by
  both contact pairs in parallel: one block, one arc);
- changeover: examples/changeover_relay.toml (the coil-driven relay, its blade between NC
  and NO), template "changeover" (two blocks, each throw its own load) against template
  "resistive" (one circuit contact fed by NO's and NC's pairs in parallel, NO's load).

The one motion cannot serve all three: a changeover's throws wired to a bridge's motion are
both closed at once and open together (a make-before-break changeover, not the example's
form C), and a bridge wired to a changeover's motion never conducts. Per run: the wall time (``result.stats`` wall_time),
the mechanics and circuit seconds, macro steps and the circuit's points, median of
--repeat runs. The issue's target: the co-simulation's cost grows at most linearly with
the contacts, so a two-contact run costs at most twice its one-contact run (ratio <= 2). Baseline for the machine's speed:
`python -c "import numpy"` whole-process wall (median of 5), as bench_startup.py; the load
average from os.getloadavg(). Not a test: run by hand,

    .venv/bin/python benchmarks/bench_arrangements.py [--repeat 3] [--no-write]

It rewrites the block between the bench_arrangements markers in docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

from doc_block import command_line, load_line, publish

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # before numpy: no BLAS threads on a shared box

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
DOC = ROOT / "docs" / "benchmarks.md"
BEGIN, END = "<!-- bench_arrangements:begin -->", "<!-- bench_arrangements:end -->"


def scenes() -> dict:
    """(motion, arrangement) -> scene (module docstring)."""
    import copy
    import tomllib

    from coupling import load_scene, scene_from_dict

    bridge = load_scene(ROOT / "examples" / "bridge_contactor.toml")
    path = ROOT / "examples" / "changeover_relay.toml"
    doc = tomllib.loads(path.read_text())
    one = copy.deepcopy(doc)
    del one["circuit"]["nc_load_resistance"]
    one["circuit"]["template"] = "resistive"
    return {("bridge contactor", "one contact"): bridge.set("circuit.template", "resistive"),
            ("bridge contactor", "bridge"): bridge,
            ("changeover relay", "one contact"): scene_from_dict(one, base_dir=path.parent),
            ("changeover relay", "changeover"): scene_from_dict(doc, base_dir=path.parent)}


def numpy_baseline() -> float:
    """s: a whole `python -c "import numpy"` process (median of 5)."""
    walls = []
    for _ in range(5):
        tick = time.perf_counter()
        subprocess.run([sys.executable, "-c", "import numpy"], check=True)
        walls.append(time.perf_counter() - tick)
    return statistics.median(walls)


def measure(scene, repeat: int) -> dict:
    """Median wall, mechanics and circuit seconds of ``repeat`` runs; macro steps, points."""
    from coupling import run

    rows = []
    for _ in range(repeat):
        res = run(scene)
        if res.status != "ok":
            raise SystemExit(f"{scene.circuit.template}: the run is {res.status}: {res.message}")
        rows.append(res)
    med = {k: statistics.median(r.stats[k] for r in rows) for k in ("wall_time", "mech_seconds", "circuit_seconds")}
    return dict(med, macro_steps=rows[0].stats["macro_steps"], points=len(rows[0].waveform_columns["time"]),
                blocks=len(rows[0].scene.circuit.circuit.contacts))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="runs per arrangement (median)")
    parser.add_argument("--no-write", action="store_true", help="print the block, leave docs/benchmarks.md")
    args = parser.parse_args(argv)
    baseline = numpy_baseline()
    built = scenes()
    for scene in built.values():  # a first run of each: compiled code, ngspice loaded
        from coupling import run

        run(scene)
    results = {key: measure(scene, args.repeat) for key, scene in built.items()}
    lines = [f"Measured with `{command_line()}` (median of {args.repeat} runs each, after one warm-up run; "
             f"`python -c \"import numpy\"` takes {baseline:.3f} s on this machine). Each arrangement against "
             "one contact on the same motion (examples/bridge_contactor.toml, 6 ms; examples/changeover_relay.toml, "
             "19 ms):", "",
             "| motion | arrangement | circuit contacts | wall (s) | mechanics (s) | circuit (s) | macro steps | "
             "circuit points | wall / one contact | circuit / one contact |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    wall, circuit = [], []  # per circuit contact, against one contact: linear growth keeps both <= 1
    for (motion, name), r in results.items():
        one = results[(motion, "one contact")]
        if r["blocks"] > 1:
            wall.append(r["wall_time"] / one["wall_time"] / r["blocks"])
            circuit.append(r["circuit_seconds"] / one["circuit_seconds"] / r["blocks"])
        lines.append(f"| {motion} | {name} | {r['blocks']} | {r['wall_time']:.3f} | {r['mech_seconds']:.3f} | "
                     f"{r['circuit_seconds']:.3f} | {r['macro_steps']} | {r['points']} | "
                     f"{r['wall_time'] / one['wall_time']:.2f} | {r['circuit_seconds'] / one['circuit_seconds']:.2f} |")
    lines += ["", f"- Per circuit contact, against the one-contact run on the same motion: the whole run's wall "
              f"time at most {max(wall):.2f}, the circuit's seconds at most {max(circuit):.2f} (linear growth: at "
              "most 1).", load_line()]
    publish(DOC, BEGIN, END, lines, write=not args.no_write)
    return 0


if __name__ == "__main__":
    sys.exit(main())
