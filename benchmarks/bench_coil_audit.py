"""What the default relay's coil energy audit is made of, at the coil's circuit step rules and
without them: its relative residual split into the circuit's part and the magnet's, beside
the operate time's distance from a converged run.

    .venv/bin/python benchmarks/bench_coil_audit.py [--no-write]

The audit (coupling/core/relay.py): into_coil - copper - magnetic_change - armature_work,
relative to into_coil. Split at the run's points (SI, signed, relative to into_coil):
- the circuit's part, sum(i_m (h u_m - d psi)), u = v - R i: ngspice's increments of the
  coil's flux against the trapezoid of d(psi)/dt = u, its integration error;
- the magnet's part, sum(i_m d psi) - dW - sum(F_m d(-g)): the magnet's exact differential
  dW = i d(psi) - F d(-g) against its trapezoids at the points (the current the circuit
  drew against the magnet's at the recorded gap).
Rows: `coupling.coil_step_points` (ngspice's least points per macro step) and
`coupling.coil_point_fraction` (its steps, while the coil's flux changes, at most that
fraction of the coil's L/R at the rest gap), the current values and others. The reference:
every step rule halved three times (`run --check`'s refinement, coupling.app.accuracy
refined_steps), whose operate time the next halving moves by well under 0.1 us. Writes the
block "bench-coil-audit" of docs/coupling.md.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from doc_block import command_line, load_line, publish

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "coupling.md"
BEGIN, END = "<!-- bench-coil-audit:begin -->", "<!-- bench-coil-audit:end -->"
# (label, coupling.coil_step_points, coupling.coil_point_fraction)
ROWS = (
    ("before the rules: 1 point a step, no bound from L/R", 1, 1.0),
    ("2 points a step, no bound from L/R", 2, 1.0),
    ("1 point a step, 1/80 of L/R", 1, 0.0125),
    ("the current rules: 2 points a step, 1/80 of L/R", 2, 0.0125),
    ("4 points a step, 1/80 of L/R", 4, 0.0125),
    ("2 points a step, 1/160 of L/R", 2, 0.00625),
)


def split(result) -> dict:
    """The audit's parts at the run's points (module docstring), relative to into_coil."""
    from coupling.core.device import device

    spec = device(result.scene.raw)
    w = result.waveform_columns
    t, i, v = w["time"], w["coil_current"], w["coil_voltage"]
    psi, gap, force = w["coil_flux_linkage"], w["working_gap"], w["magnetic_force"]
    h, i_m = np.diff(t), 0.5 * (i[1:] + i[:-1])
    u_m = 0.5 * (v[1:] + v[:-1]) - spec.resistance * i_m
    energy = result.relay["energy"]
    into = energy["into_coil"]
    circuit = float(np.sum(i_m * (h * u_m - np.diff(psi)))) / into
    magnet = float(np.sum(i_m * np.diff(psi)) - np.sum(np.diff(spec.magnet.energy(psi, gap)))
                   - np.sum(0.5 * (force[1:] + force[:-1]) * -np.diff(gap))) / into
    return dict(residual=energy["residual"] / into, circuit=circuit, magnet=magnet, points=len(t),
                steps=result.stats["macro_steps"], operate=result.relay["operate_time"],
                wall=result.stats["wall_time"])


def main() -> None:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print the block only")
    args = parser.parse_args()

    from coupling import default_scene, run
    from coupling.app.accuracy import refined_steps

    base = default_scene()
    run(base)  # (warm: ngspice loaded, the compiled mechanics imported)
    reference = base
    for _ in range(3):
        reference = refined_steps(reference)[1]
    ref = split(run(reference))
    lines = [f"`{command_line()}`: the default relay (12 ms), its coil's energy audit split at the run's points "
             f"(relative to the energy into the coil, signed); the operate time against the run with every step "
             f"rule halved three times ({ref['operate'] * 1e3:.5f} ms, {ref['steps']} macro steps, "
             f"{ref['points']} ngspice points, audit {ref['residual']:.1e}).", "",
             "| coil's circuit steps | macro steps | ngspice points | relative residual | circuit's part | magnet's part "
             "| operate time - reference's | run time |", "|---|---|---|---|---|---|---|---|"]
    for label, points, fraction in ROWS:
        m = split(run(base.update({"coupling.coil_step_points": points, "coupling.coil_point_fraction": fraction})))
        lines.append(f"| {label} | {m['steps']} | {m['points']} | {m['residual']:.1e} | {m['circuit']:.1e} | "
                     f"{m['magnet']:.1e} | {(m['operate'] - ref['operate']) * 1e6:+.2f} us | {m['wall'] * 1e3:.0f} ms |")
    lines += ["", load_line()]
    publish(DOC, BEGIN, END, lines, write=not args.no_write)


if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    main()
