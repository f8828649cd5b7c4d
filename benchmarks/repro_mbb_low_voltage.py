"""Reproducer (not fixed): a make-before-break changeover on a 5 V supply with the arc
model on aborts with ngspice "timestep too small ... trouble with node common" at
RELTOL 1e-6, 0.404 ms into the run (examples/bridge_contactor.toml's motion wired as
template "changeover", contacts NO and NC, NC's load 24 ohm).

What it is not (each a variant below, measured): the arc's own step control (both
ArcStates return no step limit and no landing at the failing points, and neither
switches: both contacts are open, NC parted ~5 us before), ABSTOL (1e-9 and 1e-15 fail
alike), CHGTOL, the integration method (gear and trap), the contact capacitance (1 pF
fails), the wiring (0.1-10 uH fail), the arc's U_min (4 V fails). What it needs: the arc
model on (arc = false passes), a low supply (24 V and 36 V pass; 4-6 V fail), a tight
RELTOL (1e-5 and the default 1e-4 pass) and the open contacts' nA currents: raising
leakage_conductance from 1e-9 to 1e-6 S makes it pass. With both throws open the common
node hangs on the two contact capacitances and ~4e-9 S of leakage and arc off-conductance,
its lead current (the 0-V probe Vload) ~1e-8 A.

Not the arc's off-conductance either (measured by setting circuit.arc.OFF_CONDUCTANCE
before the run, the failing variant otherwise): 0, 1e-12 and 1e-9 S fail at 0.40379 ms
alike, 1e-6 S passes. The arc never burns here (|V| < U_min at 5 V, so the uramp terms
and their Jacobian are zero), and arc = false passes with the same 1e-9 S leakage, so
the arc's part that matters is what it adds besides its off path: the 0-V sense source
Varc (a branch-current unknown carrying nA) and the node arc_p between it and Barc, or
the EXTERNAL Iarc_on into its 1-ohm node. Nor is it Barc's nonlinearity: with its
expression replaced by the linear 1e-9*V(arc_p,b) alone (PySpice's Circuit.B wrapped
in a probe script) the run still fails, at 0.40334 ms. Next to test: drop Varc (sense the current
another way) and see whether the failure goes; then ngspice's NIconvTest on branch
currents at RELTOL 1e-6.

    .venv/bin/python benchmarks/repro_mbb_low_voltage.py    (prints one line per variant)
"""

from __future__ import annotations

import copy
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from coupling import CoupledRunError, run, scene_from_dict  # noqa: E402

VARIANTS = {
    "5 V, RELTOL 1e-6 (fails)": {},
    "arc off": {"arc": False},
    "24 V": {"voltage": 24.0},
    "RELTOL 1e-5": {"reltol": 1e-5},
    "leakage 1e-6 S": {"leakage_conductance": 1e-6},
    "ABSTOL 1e-15": {"abstol": 1e-15},
    "method trap": {"method": "trap"},
}


def main() -> None:
    doc = tomllib.loads((ROOT / "examples" / "bridge_contactor.toml").read_text())
    doc["output"] = {"plots": False, "csv": False, "parquet": False}
    doc["circuit"].update(template="changeover", nc_load_resistance=24.0, voltage=5.0, reltol=1e-6)
    doc["fixed"][0]["name"], doc["fixed"][1]["name"] = "NO", "NC"
    for label, change in VARIANTS.items():
        d = copy.deepcopy(doc)
        d["circuit"].update(change)
        try:
            result = run(scene_from_dict(d, name="repro"))
            print(f"{label}: ok, {result.bounce.get('bounces')} bounce(s)")
        except CoupledRunError as err:
            print(f"{label}: FAILED {str(err).splitlines()[0]}")


if __name__ == "__main__":
    main()
