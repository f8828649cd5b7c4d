"""What `switchsim run` does: load a scene (or the default), run it, write the results."""

from __future__ import annotations

import sys
from pathlib import Path


def run_command(scene_path: str | None, out_dir: str, *, quiet: bool = False) -> int:
    from mech import ImpactSolver, default_scene, load_scene
    from mech.solver import MechSolverError

    scene = default_scene() if scene_path is None else load_scene(scene_path)
    out = Path(out_dir)
    try:
        result = ImpactSolver(scene).run()
    except MechSolverError as err:
        if err.partial_result is not None:
            err.partial_result.save(out)
        print(f"switchsim: run failed: {err}; partial results in {out}", file=sys.stderr)
        return 1
    result.save(out)
    if not quiet:
        summary = result.to_summary()
        print(f"switchsim: {len(summary['contacts'])} contacts, restitution {summary['restitution']}, "
              f"energy residual {summary['energy']['relative_residual']:.2g}; wrote {out}")
        for flag in summary["flags"]:
            print(f"switchsim: flag: {flag}")
    return 0
