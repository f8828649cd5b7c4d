"""Which mechanics rtol gives a physically sound run? (sets the allowed range of [solver] rtol)

Runs the built-in default coupled scene (10 ms) and the mechanics default scene (50 ms)
at several rtol, including values above the allowed maximum (on purpose: the options
object is validated at 1e-6, then its rtol is replaced), and prints the soundness
measures of coupling.soundness: the largest |energy residual| against the scene's energy
scale, the deepest penetration and the fastest centre speed against their energy bounds,
the loop current against the circuit's bound.

    PYTHONPATH=. .venv/bin/python benchmarks/bench_rtol_soundness.py
"""

from __future__ import annotations

import dataclasses
import sys
import time

import mech
from coupling import builtin_scene, run
from coupling.master import CoupledRunError
from coupling.results import CoupledResult
from coupling.soundness import assess

RTOLS = (1e-3, 1e-4, 5e-5, 2e-5, 1e-5, 1e-6)


def with_rtol(mscene, rtol):
    solver = dataclasses.replace(mscene.solver)
    object.__setattr__(solver, "rtol", rtol)  # measuring outside the validated range on purpose
    return dataclasses.replace(mscene, solver=solver)


def report(label, rtol, result, wall):
    s = assess(result)
    extra = ""
    if "max_load_current" in s:
        extra = f", I_load {s['max_load_current']:.3g} A (bound {s['load_current_bound']:.3g})"
        extra += f", bounces {result.bounce['bounces']}"
    print(f"{label:10s} rtol {rtol:7.0e}: residual/E {s['relative_residual']:.2e} (E = {s['energy_scale']:.4g} J), "
          f"max penetration {s['max_penetration']:.3g} m (bound {s['penetration_bound']:.3g}), "
          f"max speed {s['max_speed']:.3g} m/s (bound {s['speed_bound']:.3g}), "
          f"max kinetic {s['max_kinetic']:.3g} J{extra}, "
          f"{'SOUND' if not s['problems'] else 'UNSOUND'}, {wall:.1f} s", flush=True)


def main(rtols=RTOLS) -> None:
    # the free drop, what these figures were measured on, at the 3 modes per family it had then
    # (the scene is modes = "auto" now: 3 axial, 10 bending); pinned so the docs' figures stay true
    coupled = builtin_scene("free_drop").set("bar.modes", 3)
    for rtol in rtols:
        scene = dataclasses.replace(coupled, mech=with_rtol(coupled.mech, rtol))
        tick = time.perf_counter()
        try:
            res = run(scene)
        except CoupledRunError as err:
            print(f"coupled    rtol {rtol:7.0e}: failed: {err}", flush=True)
            continue
        report("coupled", rtol, res, time.perf_counter() - tick)
    mscene = mech.default_scene()
    wrapper = coupled.without("circuit", "coupling", "tribology")
    for rtol in rtols:
        tick = time.perf_counter()
        m = mech.simulate(with_rtol(mscene, rtol))
        res = CoupledResult(scene=wrapper, mechanics=m, waveform_columns=None, stats={})
        report("mechanics", rtol, res, time.perf_counter() - tick)


if __name__ == "__main__":
    main([float(x) for x in sys.argv[1:]] or RTOLS)
