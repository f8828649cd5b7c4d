"""Benchmark: cost of one right-hand-side evaluation against the number of modes per family.

Run: .venv/bin/python benchmarks/bench_rhs_cost.py [--repeat N] [--no-write]

Scene (issue 9): 3D, a steel bar 6 mm round, 0.3 m long, 3 mm tips, released at 30 deg
at 1 m/s, damped Hertz contact with friction, run for 0.9 ms (first impact included).
The recorded states of that run are replayed through, in one process:
- ``dynamics``: the whole compiled right-hand side (it calls the Gram-product route);
- the inertia block alone by the Gram-product route (``mech.inertia.inertia_terms``);
- the same block by the sparse-tensor route the kernel used before
  (``mech.inertia.inertia_terms_sparse``: every non-zero J2 and S entry).
The old right-hand side's cost is then dynamics - new block + old block (the rest of
dynamics is the same code). Each figure is the best of --repeat passes of the
per-evaluation time over all recorded states (cycled to >= 20000 calls). The exponent
is the least-squares slope of log(cost) on log(modes per family) from 12 to 40.
Writes the table between the rhs-cost markers of docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from doc_block import write_block

import numpy as np
from numba import njit

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mech import Bar, Contact, Friction, ImpactSolver, Initial, MechScene, SolverOptions  # noqa: E402
from mech.inertia import inertia_terms, inertia_terms_sparse  # noqa: E402
from mech.compiled import jit_dispatcher, make_work  # noqa: E402
from mech.kernel_layout import NAUX  # noqa: E402

dynamics = jit_dispatcher("dynamics")  # called from the njit timing loop below

MODES = (3, 7, 12, 20, 30, 40)
DOC = ROOT / "docs" / "benchmarks.md"
BEGIN, END = "<!-- rhs-cost:begin -->", "<!-- rhs-cost:end -->"


def scene(modes: int) -> MechScene:
    return MechScene(
        bar=Bar(diameter=0.006, length=0.3, tip_radius=0.003, axial_modes=modes, bending_modes=modes),
        contact=Contact(), friction=Friction(),
        initial=Initial(height=1e-4, angle_deg=30.0, velocity=(0.0, 0.0, -1.0)),
        solver=SolverOptions(t_end=0.9e-3, model="3d"),
    )


@njit(cache=False)
def _time_dynamics(states, calls, mdl, work):
    dy = np.empty(states.shape[1])
    aux = np.empty((2, NAUX))
    regime = np.zeros(2, np.int64)
    eref = np.array([[1.0, 0.0], [0.0, 1.0]])
    acc = 0.0
    for c in range(calls):
        dynamics(0.0, states[c % states.shape[0]], mdl, regime, eref, dy, aux, work)
        acc += dy[0]
    return acc


@njit(cache=False)
def _time_block(route, qs, etas, ws, calls, m, J0, ptr, idx, val):
    n = qs.shape[1]
    Jm = np.zeros((3, 3))
    B = np.zeros((3, n))
    f_e = np.zeros(n)
    sv = np.zeros(3)
    f_r = np.zeros(3)
    A = np.zeros((3, 3))
    Ainv = np.zeros((3, 3))
    acc = 0.0
    for c in range(calls):
        k = c % qs.shape[0]
        if route == 0:
            acc += inertia_terms(n, m, qs[k], etas[k], ws[k], J0, ptr, idx, val, Jm, B, f_e, sv, f_r, A, Ainv)
        else:
            acc += inertia_terms_sparse(n, m, qs[k], etas[k], ws[k], J0, ptr, idx, val, Jm, B, f_e, sv, f_r, A, Ainv)
        acc += Ainv[0, 0]
    return acc


def per_call(fn, calls: int, repeat: int) -> float:
    """Best (least disturbed) seconds per call over ``repeat`` passes, after a warm-up pass:
    the machine is shared, and other load only ever adds time."""
    fn(min(calls, 100))
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn(calls)
        times.append((time.perf_counter() - t0) / calls)
    return min(times)


def measure(modes: int, repeat: int) -> dict:
    solver = ImpactSolver(scene(modes))
    res = solver.run()
    model = solver.model
    states = np.ascontiguousarray(res.states)
    sl = model.slices()
    qs = np.ascontiguousarray(states[:, sl["q"]])
    etas = np.ascontiguousarray(states[:, sl["eta"]])
    ws = np.ascontiguousarray(states[:, sl["omega"]])
    arrays = model.arrays
    J0, ptr, idx, val = arrays[2:6]
    work = make_work(model.n)
    calls = max(20000, 4 * len(states))
    m = model.basis.mass
    full = per_call(lambda c: _time_dynamics(states, c, arrays, work), calls, repeat)
    new = per_call(lambda c: _time_block(0, qs, etas, ws, c, m, J0, ptr, idx, val), calls, repeat)
    old = per_call(lambda c: _time_block(1, qs, etas, ws, c, m, J0, ptr, idx, val), calls, repeat)
    return {"modes": modes, "n": model.n, "states": len(states), "full_new": full,
            "block_new": new, "block_old": old, "full_old": full - new + old}


def slope(xs, ys) -> float:
    return float(np.polyfit(np.log(xs), np.log(ys), 1)[0])


def table(rows) -> str:
    us = 1e6
    lines = [
        "| modes per family | n | rhs old (us) | rhs new (us) | speed-up | inertia block old (us) | inertia block new (us) |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(f"| {r['modes']} | {r['n']} | {r['full_old'] * us:.2f} | {r['full_new'] * us:.2f} | "
                     f"{r['full_old'] / r['full_new']:.1f}x | {r['block_old'] * us:.2f} | {r['block_new'] * us:.2f} |")
    big = [r for r in rows if r["modes"] >= 12]
    xs = [r["modes"] for r in big]
    lines.append("")
    lines.append(
        f"Fitted exponent (cost ~ modes^p, 12 to 40 per family): rhs old p = {slope(xs, [r['full_old'] for r in big]):.2f}, "
        f"rhs new p = {slope(xs, [r['full_new'] for r in big]):.2f}; inertia block old "
        f"p = {slope(xs, [r['block_old'] for r in big]):.2f}, new p = {slope(xs, [r['block_new'] for r in big]):.2f}.")
    at20 = next((r for r in rows if r["modes"] == 20), None)
    if at20 is not None:
        ok = "met" if at20["full_new"] <= 8e-6 else "NOT met"
        lines.append(f"At 20 modes per family: {at20['full_new'] * us:.2f} us per evaluation "
                     f"(target <= 8 us: {ok}).")
    return "\n".join(lines)


def write_doc(text: str) -> None:
    write_block(DOC, BEGIN, END, text)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--modes", type=int, nargs="*", default=list(MODES))
    ap.add_argument("--no-write", action="store_true", help="print only; leave docs/benchmarks.md alone")
    args = ap.parse_args()
    rows = []
    for k in args.modes:
        r = measure(k, args.repeat)
        rows.append(r)
        print(f"modes {k:2d}: rhs new {r['full_new'] * 1e6:6.2f} us, old {r['full_old'] * 1e6:6.2f} us "
              f"(block new {r['block_new'] * 1e6:.2f}, old {r['block_old'] * 1e6:.2f}; {r['states']} states)",
              flush=True)
    load = os.getloadavg()[0]
    text = table(rows) + f"\nLoad average at the end of the run: {load:.1f} (2 cores)."
    print(text)
    if not args.no_write and len(rows) >= 3:
        write_doc(text)
        print(f"written to {DOC.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
