"""Benchmark: the energy scale of each drive kind, against what its run did.

Run: .venv/bin/python benchmarks/bench_energy_scale.py [--no-write]

One scene per drive kind (a steel blade clamped at one end, a rigid arm on a pivot; the
scenes of tests/coupling/test_drive_soundness.py): the energy scale E, its parts from the
scene (W_rest, W_all; mech.model.load_work_bound) and from the run (W_run), the largest
kinetic energy, the relative residual and the verdict of coupling.core.soundness.
Writes the block between the energy-scale markers of docs/mechanics.md.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

from doc_block import command_line, publish

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from coupling import run, scene_from_dict  # noqa: E402
from coupling.core.soundness import assess  # noqa: E402

BEGIN = "<!-- bench_energy_scale begin -->"
END = "<!-- bench_energy_scale end -->"
STEEL = dict(youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)


def blade(**over) -> dict:
    doc = {"bar": dict(length=0.02, width=0.003, thickness=0.0003, tip_radius=0.0016, **STEEL,
                       modes={"axial": 1, "bending": 6}, modal_damping=0.02),
           "mount": dict(kind="clamp", position=0.02), "rivet": [dict(position=0.0015, radius=0.0015)],
           "initial": dict(height=1e-4), "contact": dict(law="hunt_crossley", restitution=0.5),
           "solver": dict(t_end=0.01), "environment": dict(gravity=0.0)}
    doc.update(over)
    return doc


def arm(**over) -> dict:
    doc = {"bar": dict(length=0.1, diameter=0.01, tip_radius=0.005, **STEEL, modes=0),
           "mount": dict(kind="pivot", position=0.1), "initial": dict(height=1e-3),
           "contact": dict(law="hunt_crossley", restitution=0.3, reference_speed=0.1),
           "solver": dict(t_end=0.02), "environment": dict(gravity=0.0)}
    doc.update(over)
    return doc


DRIVES = {
    "constant force 1 N on the blade": blade(force=[dict(position=0.01, magnitude=1.0)]),
    "force ramped 0-2 N over 3 ms": blade(force=[dict(position=0.01, time=[0.0, 0.003], value=[0.0, 2.0])]),
    "pivot preload torque 0.05 N m": arm(mount=dict(kind="pivot", position=0.1, preload_torque=0.05)),
    "spring preload 2 N on the arm": arm(spring=[dict(anchor=[-0.045, 0.0, 0.05], position=0.05, stiffness=100.0,
                                                      preload=-2.0)]),
    "clamp lowered 0.3 mm in 2 ms": blade(mount=dict(kind="clamp", position=0.02, base_motion=dict(
        time=[0.0, 0.002], displacement=[[0.0, 0.0, 0.0], [0.0, 0.0, -3e-4]]))),
    "gravity on the blade (sag)": blade(environment=dict(gravity=9.81), initial=dict(height=1e-3)),
    "gravity on the arm (pendulum, 5 cm)": arm(environment=dict(gravity=9.81), initial=dict(height=0.05),
                                               solver=dict(t_end=0.15)),
}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-write", action="store_true")
    args = ap.parse_args()
    from mech.model import load_work_bound

    lines = [f"`{command_line()}`", "",
             "| drive | E (J) | W_rest (J) | W_all (J) | W_run (J) | largest kinetic (J) | relative residual | verdict |",
             "|---|---|---|---|---|---|---|---|"]
    for name, doc in DRIVES.items():
        result = run(scene_from_dict(doc))
        m = result.mechanics
        en = m.energy_columns
        s0 = float(en["spring_stored"][0])
        e_in = float(en["kinetic"][0] + en["elastic"][0] + en["contact_stored"][0]) + s0
        w_run = float(np.max(en["work_in"] - en["potential"] - (en["spring_stored"] - s0)))
        w_rest = load_work_bound(m.model, e_in, forces=False)
        w_all = math.inf if m.model.scene.mount.base_motion is not None else load_work_bound(m.model, e_in)
        verdict = assess(result)
        lines.append(f"| {name} | {m.energy_scale:.3g} | {w_rest:.3g} | {w_all:.3g} | {w_run:.3g} | "
                     f"{m.max_kinetic:.3g} | {m.energy['relative_residual']:.2g} | "
                     f"{'ok' if not verdict['problems'] else 'unsound'} |")
    lines += ["", "W_all: inf where the scene has no bound (a moving clamp); W_run is capped at W_all plus the "
              "springs' initial energy (0.02 J on the spring's arm)."]
    publish(ROOT / "docs" / "mechanics.md", BEGIN, END, lines, write=not args.no_write)


if __name__ == "__main__":
    main()
