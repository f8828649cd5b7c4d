"""Which mechanics rtol gives a physically sound run? (sets the allowed range of [solver] rtol)

Runs the built-in default coupled scene (10 ms) and the mechanics default scene (50 ms)
at several rtol, including values above the allowed maximum (on purpose: the options
object is validated at 1e-6, then its rtol is replaced), and prints the soundness
measures of coupling.core.soundness: the largest |energy residual| against the scene's energy
scale, the deepest penetration and the fastest centre speed against their energy bounds,
the loop current against the circuit's bound.

    .venv/bin/python benchmarks/bench_rtol_soundness.py [RTOL ...] [--no-write]

It writes its table between the bench-rtol-soundness markers of docs/coupling.md ("The rtol
range").
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

from doc_block import command_line, load_line, publish

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import mech  # noqa: E402
from coupling import builtin_scene, run  # noqa: E402
from coupling.core.master import CoupledRunError  # noqa: E402
from coupling.core.results import CoupledResult  # noqa: E402
from coupling.core.soundness import assess  # noqa: E402

DOC = ROOT / "docs" / "coupling.md"
BEGIN, END = "<!-- bench-rtol-soundness:begin -->", "<!-- bench-rtol-soundness:end -->"

RTOLS = (1e-3, 1e-4, 5e-5, 2e-5, 1e-5, 1e-6)


def with_rtol(mscene, rtol):
    solver = dataclasses.replace(mscene.solver)
    object.__setattr__(solver, "rtol", rtol)  # measuring outside the validated range on purpose
    return dataclasses.replace(mscene, solver=solver)


def report(label, rtol, result, wall):
    """Print one run's soundness measures; return its row of the docs table."""
    s = assess(result)
    extra = ""
    current = "-"
    if "max_load_current" in s:
        extra = f", I_load {s['max_load_current']:.3g} A (bound {s['load_current_bound']:.3g})"
        extra += f", bounces {result.bounce['bounces']}"
        current = f"{s['max_load_current']:.3g} ({s['load_current_bound']:.3g})"
    verdict = "SOUND" if not s["problems"] else "UNSOUND"
    print(f"{label:10s} rtol {rtol:7.0e}: residual/E {s['relative_residual']:.2e} (E = {s['energy_scale']:.4g} J), "
          f"max penetration {s['max_penetration']:.3g} m (bound {s['penetration_bound']:.3g}), "
          f"max speed {s['max_speed']:.3g} m/s (bound {s['speed_bound']:.3g}), "
          f"max kinetic {s['max_kinetic']:.3g} J{extra}, "
          f"{verdict}, {wall:.1f} s", flush=True)
    return (f"| {label} | {rtol:.0e} | {s['relative_residual']:.2e} | {s['energy_scale']:.4g} | "
            f"{s['max_kinetic']:.3g} | {s['max_speed']:.3g} ({s['speed_bound']:.3g}) | "
            f"{s['max_penetration']:.3g} ({s['penetration_bound']:.3g}) | {current} | "
            f"{'**unsound**' if s['problems'] else 'sound'} | {wall:.2f} s |")


def main(rtols=RTOLS, write=True) -> None:
    # the free drop, what these figures were measured on, at the 3 modes per family it had then
    # (the scene is modes = "auto" now: 3 axial, 10 bending); pinned so the docs' figures stay true
    coupled = builtin_scene("free_drop").set("bar.modes", 3)
    rows = []
    for rtol in rtols:
        scene = dataclasses.replace(coupled, mech=with_rtol(coupled.mech, rtol))
        tick = time.perf_counter()
        try:
            res = run(scene)
        except CoupledRunError as err:
            print(f"coupled    rtol {rtol:7.0e}: failed: {err}", flush=True)
            rows.append(f"| coupled | {rtol:.0e} | failed: {str(err).splitlines()[0]} | | | | | | | |")
            continue
        rows.append(report("coupled", rtol, res, time.perf_counter() - tick))
    mscene = mech.default_scene()
    wrapper = coupled.without("circuit", "coupling", "tribology")
    rule = ""
    for rtol in rtols:
        tick = time.perf_counter()
        m = mech.simulate(with_rtol(mscene, rtol))
        res = CoupledResult(scene=wrapper, mechanics=m, waveform_columns=None, stats={})
        rows.append(report("mechanics", rtol, res, time.perf_counter() - tick))
        rule = m.solver.get("modes_rule") or f"{m.solver['modes']} modal coordinates"
    lines = [f"`{command_line()}`: coupled = `builtin_scene(\"free_drop\")` at 3 modes per family, "
             f"{coupled.t_end * 1e3:g} ms; mechanics = `mech.default_scene()` ({rule}), "
             f"{mscene.solver.t_end * 1e3:g} ms. Sound: every bound of coupling.core.soundness holds, the energy "
             f"residual within energy_tolerance = {mscene.solver.energy_tolerance:g} of E; bounds in parentheses.", "",
             "| run | rtol | residual / E | E (J) | max kinetic (J) | max speed (m/s) | max penetration (m) "
             "| max load current (A) | verdict | wall |", "|---|---|---|---|---|---|---|---|---|---|", *rows, "",
             load_line(bullet=False)]
    publish(DOC, BEGIN, END, lines, write=write)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("rtols", type=float, nargs="*", help=f"mechanics rtols (default {' '.join(map(str, RTOLS))})")
    ap.add_argument("--no-write", action="store_true", help="print only; leave docs/coupling.md alone")
    args = ap.parse_args()
    main(args.rtols or RTOLS, write=not args.no_write)
