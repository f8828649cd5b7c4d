"""Co-simulation error against run time: both schemes and a range of macro steps,
against the monolithic reference (mechanics + circuit in one stiff solve).

    .venv/bin/python benchmarks/bench_coupling_order.py [--no-write]

Scene: tests/coupling/scenes/impact_inrush.toml (an impact whose make starts a capacitive
inrush while the tip slides with Coulomb friction whose mu doubles with the current).
Errors: largest difference over the run of the centre-of-mass tangential speed (m/s),
and the RMS difference of the load current over the run (A; a maximum would only measure
how far a make or break instant moved). Writes its table between the bench-coupling-order
markers of docs/coupling.md (section 3).
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from coupling import load_scene, run
from coupling.core.monolithic import run_monolithic
from doc_block import command_line, write_block

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "tests" / "coupling" / "scenes" / "impact_inrush.toml"
DOC = ROOT / "docs" / "coupling.md"
BEGIN, END = "<!-- bench-coupling-order:begin -->", "<!-- bench-coupling-order:end -->"


STEPS = (8e-5, 4e-5, 2e-5, 1e-5, 5e-6, 2.5e-6, 1.25e-6, 6.25e-7)
SCHEMES = ("mechanics_first", "jacobi")


def reference(base):
    """(monolithic CoupledResult, wall s)."""
    tick = time.perf_counter()
    ref = run_monolithic(base)
    return ref, time.perf_counter() - tick


def study(base, ref, schemes=SCHEMES, steps=STEPS):
    """One co-simulation per scheme and macro step against the monolithic ``ref``: yields
    dicts with scheme, h (s), the CoupledResult, wall (s), speed error (m/s), RMS current error (A)."""
    href, wref = ref.mechanics.history, ref.waveforms
    grid = np.linspace(0.01, 1.0, 600) * base.t_end
    run(base)  # warm-up
    for scheme in schemes:
        for h in steps:
            sc = base.set("coupling.scheme", scheme).set("coupling.macro_step", h)
            tick = time.perf_counter()
            r = run(sc)
            wall = time.perf_counter() - tick
            hh, w = r.mechanics.history, r.waveforms
            dv = np.max(np.abs(np.interp(grid, hh.time, hh.vx) - np.interp(grid, href.time, href.vx)))
            di = np.sqrt(np.mean((np.interp(grid, w.time, w.load_current)
                                  - np.interp(grid, wref.time, wref.load_current)) ** 2))
            yield dict(scheme=scheme, h=h, result=r, wall=wall, speed_error=float(dv), current_error=float(di))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-write", action="store_true", help="print only; leave docs/coupling.md alone")
    args = ap.parse_args()
    base = load_scene(SCENE)
    ref, t_ref = reference(base)
    lines = [f"`{command_line()}`: scene `{SCENE.relative_to(ROOT)}`; monolithic reference (Radau, rtol "
             f"{base.mech.solver.rtol:g}): {t_ref:.2f} s, {ref.mechanics.stats['steps']} steps.", "",
             "| scheme | macro step | speed error (m/s) | RMS current error (A) | wall time | macro steps |",
             "|---|---|---|---|---|---|"]
    print(lines[0], flush=True)
    errors: dict = {}
    for row in study(base, ref):
        scheme, h, r = row["scheme"], row["h"], row["result"]
        lines.append(f"| {scheme} | {h * 1e6:g} us | {row['speed_error']:.2e} | {row['current_error']:.2e} | "
                     f"{row['wall'] * 1e3:.0f} ms | {r.stats['macro_steps']} |")
        print(lines[-1], flush=True)
        errors.setdefault(scheme, []).append((h, row["speed_error"]))
    lines.append("")
    for scheme, pairs in errors.items():
        hs, es = np.array(pairs).T
        lines.append(f"- Observed order ({scheme}, speed error, least squares over {hs.max() * 1e6:g} .. "
                     f"{hs.min() * 1e6:g} us): **{np.polyfit(np.log(hs), np.log(es), 1)[0]:.2f}**")
    lines.append(f"- Load average at the end of the run: {os.getloadavg()[0]:.1f} (2 cores).")
    print("\n".join(lines[-len(errors) - 1:]))
    if not args.no_write:
        write_block(DOC, BEGIN, END, "\n".join(lines))
        print(f"written to {DOC}")


if __name__ == "__main__":
    main()
