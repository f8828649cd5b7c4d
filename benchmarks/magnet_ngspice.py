"""The magnet's coil-current expression in real ngspice against the magnet's i(psi, g) in Python.

    python benchmarks/magnet_ngspice.py [--no-write]

Loads one behavioural source V = i(V(psi), V(gap)) (the magnet's ``current_expression``)
into ngspice, sweeps psi and the gap with ``dc`` (Newton converged tight: reltol 1e-12) and
compares the swept values with ``current`` evaluated in Python at the same points: for the
built-in plunger solenoid (flux tubes) and for a table magnet made from it. Also measures
how exactly ngspice reads a B-source's numeric constants. Writes its block between the
magnet-ngspice markers of docs/magnet.md. The tests check the expression with an evaluator
of their own, without ngspice (tests/coupling/test_magnet_expression.py).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from doc_block import command_line, load_line, publish

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from circuit.ngspice import get_session  # noqa: E402
from coupling.laws.magnet import (  # noqa: E402
    FluxTubeMagnet, IronPath, LinearMaterial, PoleLeakage, TableMagnet, WorkingGap, plunger_solenoid,
)

DOC = REPO / "docs" / "magnet.md"
BEGIN, END = "<!-- magnet-ngspice:begin -->", "<!-- magnet-ngspice:end -->"
OPTIONS = ".options reltol=1e-12 vntol=1e-15 abstol=1e-18"
MM = 1e-3


def sweep(session, magnet, wrap="{}"):
    """(psi, gap, ngspice's i, Python's i) over psi in +-1.5 psi(4 A, smallest gap) and the
    gap from 0.2x the smallest to 1.2x the largest the magnet describes."""
    low, high = magnet.gap_range
    high = min(high, 5 * MM)
    low = max(low, 0.25 * MM)
    psi_max = 1.5 * magnet.flux_linkage(4.0, low)
    lines = ["* magnet expression", "Vpsi psi 0 dc 0", "Vgap gap 0 dc 1e-3",
             "Bi out 0 V = " + wrap.format(magnet.current_expression("V(psi)", "V(gap)")), "Rload out 0 1k", OPTIONS,
             ".end"]
    session.load(lines)
    g_lo, g_hi = 0.2 * low, 1.2 * high
    session.command(f"dc vpsi {-psi_max!r} {psi_max!r} {psi_max / 400!r} vgap {g_lo!r} {g_hi!r} {(g_hi - g_lo) / 100!r}")
    psi, gap, out = (session.vector(name) for name in ("psi", "gap", "out"))
    return psi, gap, out, np.asarray(magnet.current(psi, gap)), (low, high)


def constant_precision(session, count=200):
    rng = np.random.default_rng(3)
    values = rng.uniform(1.0, 10.0, count) * 10.0 ** rng.integers(-9, 4, count)
    lines = (["* constants"] + [f"B{k} n{k} 0 V = {float(v)!r}" for k, v in enumerate(values)]
             + [f"R{k} n{k} 0 1k" for k in range(count)] + [OPTIONS, ".end"])
    session.load(lines)
    session.command("op")
    got = np.array([session.vector(f"n{k}")[0] for k in range(count)])
    return np.max(np.abs(got / values - 1.0))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print the block only")
    args = parser.parse_args()
    session = get_session()
    solenoid = plunger_solenoid().magnet
    table = TableMagnet.from_magnet(solenoid, np.linspace(0, 3, 16), np.geomspace(0.25 * MM, 5 * MM, 12))
    lines = [f"`{command_line()}`: one B-source with the magnet's expression, swept by ngspice's `dc` "
             f"(`{OPTIONS}`), against `current` in Python at the swept points (psi to 1.5x psi(4 A), gaps "
             "0.2x to 1.2x the magnet's range):", "",
             "| magnet | characters | points | max abs difference / max abs i | inside the range (gaps and table psi) |",
             "|---|---:|---:|---:|---:|"]
    linear = FluxTubeMagnet(300, WorkingGap(1e-4), iron=(IronPath(0.05, 1e-4, LinearMaterial(1000.0)),),
                            pole_leakage=PoleLeakage(0.04, 3e-3))
    cases = (("plunger solenoid (flux tubes)", solenoid, "{}"), ("its 16 x 12 table", table, "{}"),
             ("a linear magnet with leakage", linear, "{}"),
             ("the solenoid, its expression wrapped as `1*(...)`", solenoid, "1*({})"))
    for label, magnet, wrap in cases:
        psi, gap, out, want, (low, high) = sweep(session, magnet, wrap)
        scale = np.max(np.abs(want))
        inside = (gap >= low) & (gap <= high)
        if isinstance(magnet, TableMagnet):
            inside &= np.abs(psi) <= magnet.flux_linkages[-1][-1]
        diff = np.abs(out - want)
        lines.append(f"| {label} | {len(wrap.format(magnet.current_expression('V(psi)', 'V(gap)')))} | {psi.size} | "
                     f"{diff.max() / scale:.1e} | {diff[inside].max() / np.max(np.abs(want[inside])):.1e} |")
    lines += ["", f"- ngspice reads a B-source's plain numeric constants (`V = 0.0950463696...`, 17 digits) to "
              f"{constant_precision(session):.1e} relative (largest of 200): about 11 significant digits; the "
              "numbers of a pwl's point list, and every number of a line whose expression begins with `pwl(`, "
              "it reads in full. Every magnet expression begins with `pwl(`.", load_line()]
    publish(DOC, BEGIN, END, lines, write=not args.no_write)


if __name__ == "__main__":
    main()
