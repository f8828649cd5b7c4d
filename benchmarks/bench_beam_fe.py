"""Benchmark: build cost of the finite-element modal basis (mech.beam_fe) and its error constants.

Times, for a clamped blade and a free bar, the FE basis (axial + bend2 + bend3) with
60 elements and 20 modes per family and with the default mesh, and the invariants on it.
The baseline, measured in the same run, is the analytic free-free basis of
mech.modal_basis with the same mode counts (closed-form shapes, 400-point quadrature).
Target: the 60-element, 20-mode build well under 0.1 s.

It also prints the error constants behind the default mesh rule: the clamped-free
frequency error divided by (beta h)^4 (bending, Hermite cubic) and by (k h)^6 (axial, cubic).

Not a test: run by hand,
    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/bench_beam_fe.py [--repeat N] [--no-write]
(on a loaded 2-core machine OpenBLAS threads make these 200-400 dof eigenproblems tens of
times slower; the script prints the setting it ran with). It writes its tables between the
bench-beam-fe markers of docs/mechanics.md (section 8).
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

# this benchmark times the eigenproblems themselves: none read back from mech.eigen_cache
os.environ["SWITCHSIM_EIGEN_CACHE"] = "0"

from mech import Bar  # noqa: E402
from mech.beam_fe import FEBeam, beam_basis, beam_invariants, beam_modes, default_elements  # noqa: E402
from mech.modal_basis import build_modal_basis  # noqa: E402

from doc_block import command_line, load_line, publish  # noqa: E402

DOC = Path(__file__).resolve().parents[1] / "docs" / "mechanics.md"
BEGIN, END = "<!-- bench-beam-fe:begin -->", "<!-- bench-beam-fe:end -->"


def timed(fn, repeat: int):
    times, out = [], None
    for _ in range(repeat):
        tick = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - tick)
    return statistics.median(times), min(times), out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7, help="timed repetitions (median and min reported)")
    ap.add_argument("--no-write", action="store_true", help="print only; leave docs/mechanics.md alone")
    args = ap.parse_args()
    if args.repeat < 1:
        raise SystemExit(f"--repeat = {args.repeat}: must be >= 1")
    blas = os.environ.get("OPENBLAS_NUM_THREADS")
    print(f"OPENBLAS_NUM_THREADS={blas or 'unset'}")
    lines = [f"`{command_line(env=('OPENBLAS_NUM_THREADS',))}`"
             + ("" if blas else " (OPENBLAS_NUM_THREADS unset)") + f": median and min of {args.repeat} runs", ""]

    modes = 20
    bar = Bar(length=0.3, diameter=None, width=0.012, thickness=0.004, tip_radius=0.007,
              axial_modes=modes, bending_modes=modes)
    i22, i33 = bar.second_moments
    free = FEBeam(bar.length, bar.youngs_modulus, bar.density, bar.area, i22, i33)
    clamp = FEBeam(bar.length, bar.youngs_modulus, bar.density, bar.area, i22, i33,
                   support="clamp", support_position=bar.length, point_masses=[(0.0, 0.002, 1e-8)])

    base_med, base_min, _ = timed(lambda: build_modal_basis(bar, planar=False), args.repeat)
    print(f"\nanalytic free-free basis, {modes} modes/family: median {base_med * 1e3:.1f} ms, min {base_min * 1e3:.1f} ms")
    print(f"{'case':44s} {'median ms':>10s} {'min ms':>8s} {'/ analytic':>11s}")
    lines += [f"Axial + bend2 + bend3, {modes} modes each, bar {bar.length:g} m x {bar.width * 1e3:g} mm x "
              f"{bar.thickness * 1e3:g} mm. Baseline: the analytic "
              f"free-free basis (`mech.modal_basis`, same mode counts) {base_med * 1e3:.1f} ms median, "
              f"{base_min * 1e3:.1f} ms min.", "",
              "| case | median | min | / analytic |", "|---|---|---|---|"]
    build60 = {}
    for name, beam in (("free", free), ("clamped + tip rivet", clamp)):
        for elements in (60, None):
            label = f"{name}, {elements or default_elements(modes)} elements"
            med, mn, basis = timed(lambda: beam_basis(beam, modes, modes, elements=elements), args.repeat)
            print(f"{label + ': basis':44s} {med * 1e3:10.1f} {mn * 1e3:8.1f} {med / base_med:11.2f}")
            label += "" if elements else " (default mesh)"
            lines.append(f"| {label}: basis | {med * 1e3:.1f} ms | {mn * 1e3:.1f} ms | {med / base_med:.2f} |")
            basis_med = med
            med, mn, _ = timed(lambda: beam_invariants(beam, basis), args.repeat)
            print(f"{label + ': invariants':44s} {med * 1e3:10.1f} {mn * 1e3:8.1f} {med / base_med:11.2f}")
            lines.append(f"| {label}: invariants | {med * 1e3:.1f} ms | {mn * 1e3:.1f} ms | {med / base_med:.2f} |")
            if elements == 60:
                build60[name] = basis_med + med

    # Error constants (clamped-free, closed forms): relative frequency error / (beta h)^4.
    L, E, rho, A, I = 0.2, 2e11, 7800.0, 2.4e-5, 8e-12
    beam = FEBeam(L, E, rho, A, I, I, support="clamp", support_position=L)
    roots = []
    for n in range(1, 4):
        g = (n - 0.5) * math.pi
        roots.append(brentq(lambda b: math.cos(b) + 1.0 / math.cosh(b), g - 0.5, g + 0.5, xtol=1e-15))
    beta_l = np.array(roots)
    exact_b = beta_l**2 / L**2 * math.sqrt(E * I / (rho * A)) / (2 * math.pi)
    k_l = (2 * np.arange(1, 4) - 1) * math.pi / 2
    exact_a = k_l * math.sqrt(E / rho) / (2 * math.pi * L)
    print("\nclamped-free error constants, modes 1-3 (bending: err / (beta h)^4, axial: err / (k h)^6)")
    worst = max(build60.values())
    lines += ["", f"- Target: the {60}-element, {modes}-mode build (basis + invariants) well under 0.1 s: "
              f"**{'met' if worst < 0.1 else 'NOT met'}** (" + ", ".join(f"{k} {v * 1e3:.1f} ms" for k, v in build60.items())
              + ", medians).", "",
              "Error constants behind the default mesh rule: clamped-free relative frequency error of modes 1-3 over "
              f"(beta h)^4 (bending, Hermite cubic; 1/1440 = {1 / 1440:.6f}) and over (k h)^6 (axial, cubic):", "",
              "| elements | bending, modes 1-3 | axial, modes 1-3 |", "|---|---|---|"]
    for n in (8, 16, 32):
        eb = beam_modes(beam, "bend3", 3, elements=n).frequencies / exact_b - 1.0
        ea = beam_modes(beam, "axial", 3, elements=n).frequencies / exact_a - 1.0
        print(f"  {n:3d} elements: bending {np.array2string(eb / (beta_l / n) ** 4, precision=6)}"
              f"  (1/1440 = {1 / 1440:.6f}); axial {np.array2string(ea / (k_l / n) ** 6, precision=3)}")
        lines.append(f"| {n} | {', '.join(f'{x:.6f}' for x in eb / (beta_l / n) ** 4)} | "
                     f"{', '.join(f'{x:.3e}' for x in ea / (k_l / n) ** 6)} |")
    lines += ["", load_line(bullet=False)]
    publish(DOC, BEGIN, END, lines, write=not args.no_write)


if __name__ == "__main__":
    main()
