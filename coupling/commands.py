"""What `switchsim run` does: load a scene (or the default), run it, write the results."""

from __future__ import annotations

import sys
from pathlib import Path


def run_command(scene_path: str | None, out_dir: str, *, quiet: bool = False, check: bool = False) -> int:
    from .master import CoupledRunError, run
    from .scene import default_scene, load_scene

    scene = default_scene() if scene_path is None else load_scene(scene_path)  # validates before running
    out = Path(out_dir)
    if not quiet:
        print(f"switchsim: running {scene.name} ({scene.kind}, t_end = {scene.t_end * 1e3:g} ms)", file=sys.stderr)
    try:
        result = run(scene, progress=not quiet, check=check)
    except CoupledRunError as err:
        if err.partial is not None:
            err.partial.save(out)
            print(f"switchsim: {err}; what was computed is in {out}", file=sys.stderr)
        else:
            print(f"switchsim: {err}", file=sys.stderr)
        return 1
    result.save(out)
    if not quiet:
        summary = result.summary
        if "bounce" in summary:
            b = summary["bounce"]
            print(f"switchsim: first make {_ms(b['first_make'])}, last make {_ms(b['last_make'])}, "
                  f"{b['bounces']} bounce(s), final state {b['final_state']}, "
                  f"peak contact voltage {b['peak_contact_voltage'] or 0:.3g} V, arc energy {b['arc_energy']:.3g} J")
        if "contacts" in summary:
            print(f"switchsim: {len(summary['contacts'])} tip contact(s), first restitution "
                  f"{summary['restitution']}, energy residual {summary['energy']['relative_residual']:.2g}")
        for flag in summary.get("flags", []):
            print(f"switchsim: flag: {flag}")
    if check:
        print(f"switchsim: accuracy: {result.accuracy['verdict']}")
        print(f"switchsim: wrote {out}", file=sys.stderr)
    return 0


def _ms(value) -> str:
    return "none" if value is None else f"{value * 1e3:.4f} ms"
