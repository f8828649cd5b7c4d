"""A make-before-break changeover on a 5 V supply at RELTOL 1e-6: the record of why it aborted
("timestep too small ... trouble with node common") and of the fix. Prints one line per variant.

    .venv/bin/python benchmarks/bench_mbb_low_voltage.py

The scene: examples/bridge_contactor.toml's motion wired as template "changeover" (contacts NO
and NC, NC's load 24 ohm), 5 V, the arc model on, RELTOL 1e-6. It aborted at ngspice time
0.404308 ms: not while both throws were open, as first read, but at NC's second make. There
the mechanics' normal force returns from its clip at zero (a "force_clip_end" event, the
rivet never left: no contact_start, so the coupling passes no breakpoint) and G(t) rises from
0 as ~(t - t_make)^0.27 (0.018 S 1e-18 s after, 0.1 S at 1e-15 s, 4.4 S at 1 ns). ngspice
finds such a make only by rejected steps and resolves the 100 pF discharge through G(t) with
steps of ~1e-14 s (1.2e-14 to 2e-14 s in every passing variant; delmin is 1.2e-15 s).

The cause, measured: the solve at those steps was wrong. ngspice factors the matrix in the
pivot order it chose at the first time point and keeps it (sparse/spfactor.c reorders only
on an exactly zero pivot). The template had its load probe Vload between the wiring
inductor and the common (src -R- wire -Lwire- common -Vload- contact_a): node common carried
no conductance, only the two branch currents, while Lwire's L/h reached 1e9 ohm at 1e-15 s
steps. The factored matrix (ngspice's mdump just before the make) held an entry of 3.8e15
(8.3e4 with the probe at the source, same time; which pivot grew was not traced); the
solution broke the probe's own 0 V,
V(common) - V(contact_a), by 5.3 mV (32 mV with a breakpoint at the make), against 0 in the
arc-off run; Newton's test (niconv.c) failed at node common at every retry and each cut
the step 8x, down to delmin. Which decks hit it depended on the pivot order, hence the
puzzling list of earlier sessions: arc off, 24 V, RELTOL 1e-5, leakage 1e-6 S passed; ABSTOL,
CHGTOL, method, capacitance, wiring, U_min, the arc's off-conductance did not help; so did
ngspice's `.options pivrel=1` (0.5 did not), and moving the probe.

The fix (circuit/templates/changeover.py, ChangeoverCircuit.build): the probe at the source (src -Vload-
supply -R- wire -Lwire- contact_a), the wiring ending on the common as in the one-contact
template; the same circuit in series order, the 0 V probes now exact. Part 2 below runs the
old arrangement (the deck rewritten by text) and the new on the small make of
tests/circuit/test_circuit_changeover_make.py. Output (2026-11-28)::

    Part 1: every variant ok, 2 bounce(s)
    before: FAILED (TimestepTooSmallError), smallest step near the make 1.29e-17 s, largest 0 V probe violation 203 V (Vload)
    now:    ok, smallest step near the make 2.38e-14 s, largest 0 V probe violation 0 V (Vload_nc)
"""

from __future__ import annotations

import copy
import math
import re
import sys
import tomllib
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import circuit.deck as deck  # noqa: E402
from circuit import (ArcModel, ChangeoverCircuit, DCSource, ResistiveLoad, SimulationOptions,  # noqa: E402
                     Stepper, Wiring, get_session)
from coupling import CoupledRunError, run, scene_from_dict  # noqa: E402

VARIANTS = {
    "5 V, RELTOL 1e-6 (aborted before the fix)": {},
    "arc off": {"arc": False},
    "24 V": {"voltage": 24.0},
    "RELTOL 1e-5": {"reltol": 1e-5},
    "leakage 1e-6 S": {"leakage_conductance": 1e-6},
    "ABSTOL 1e-15": {"abstol": 1e-15},
    "method trap": {"method": "trap"},
}


def coupled_variants() -> None:
    doc = tomllib.loads((ROOT / "examples" / "bridge_contactor.toml").read_text())
    doc["output"] = {"plots": False, "csv": False, "parquet": False}
    doc["circuit"].update(template="changeover", nc_load_resistance=24.0, voltage=5.0, reltol=1e-6)
    doc["fixed"][0]["name"], doc["fixed"][1]["name"] = "NO", "NC"
    for label, change in VARIANTS.items():
        d = copy.deepcopy(doc)
        d["circuit"].update(change)
        try:
            result = run(scene_from_dict(d, name="mbb"))
            print(f"{label}: ok, {result.bounce.get('bounces')} bounce(s)")
        except CoupledRunError as err:
            print(f"{label}: FAILED {str(err).splitlines()[0]}")


def old_arrangement(text: str) -> str:
    """The deck as the template wrote it before the fix: Vload between Lwire and the common."""
    text = text.replace("Vload src supply 0\n", "")
    text = re.sub(r"^Rsource supply (\S+)", r"Rsource src \1", text, flags=re.M)
    return re.sub(r"^(Lwire \S+) contact_a (\S+)$", r"\1 common \2\nVload common contact_a 0", text, flags=re.M)


def small_make(old: bool) -> str:
    """The test's make-before-break (5 V, RELTOL 1e-6, NC's breakpoint-less make at 41 us as
    G0 ((t - t_make) / 1 us)^(1/3)): status, smallest step, largest 0 V probe violation."""
    g0, t4, t_end = 50.0, 41e-6, 60e-6
    circuit = ChangeoverCircuit(DCSource(5.0, 0.05), ResistiveLoad(12.0), Wiring(0.0, 1e-6), contact_capacitance=1e-10,
                                arc=ArcModel(), contact_current_factor="0.6+0.4*exp(-abs(I)/1.7)",
                                contact_names=("NO", "NC"), nc_load_resistance=24.0)
    inputs = {"contact_NO.conductance": lambda t: g0 if 10e-6 <= t < 30e-6 else 0.0,
              "contact_NC.conductance": lambda t: g0 if t < 20e-6 else 0.0 if t < t4 else
              g0 * min(1.0, ((t - t4) / 1e-6) ** (1.0 / 3.0))}
    original = deck.circuit_netlist
    text = {}

    def netlist(c):
        lines, probes = original(c)
        text["deck"] = old_arrangement(lines) if old else lines
        return text["deck"], probes

    deck.circuit_netlist = netlist
    status = "ok"
    try:
        with Stepper(circuit, t_end, SimulationOptions(reltol=1e-6)) as stepper:
            t = 0.0
            try:
                while t < t_end:
                    t_next = min(t + 5e-6, t_end)
                    stepper.advance(t_next, inputs=inputs,
                                    breakpoints=[b for b in (10e-6, 20e-6, 30e-6) if t < b <= t_next])
                    t = t_next
            except Exception as err:  # the old arrangement's abort, reported as a line
                status = f"FAILED ({type(err).__name__})"
            session = get_session()
            time = np.asarray(session.vector("time"))
            worst, name = 0.0, ""
            for line in text["deck"].splitlines():
                p = line.split()
                if len(p) == 4 and p[0][0] in "vV" and p[3] == "0":
                    v = [np.asarray(session.vector(n)) if n != "0" else 0.0 for n in p[1:3]]
                    gap = float(np.max(np.abs(v[0] - v[1])))
                    if gap >= worst:
                        worst, name = gap, p[0]
    finally:
        deck.circuit_netlist = original
    near = (time > t4 - 1e-6) & (time < t4 + 1e-6)
    step = float(np.min(np.diff(time[near]))) if near.sum() > 1 else math.nan
    return (f"{status}, smallest step near the make {step:.3g} s, largest 0 V probe violation "
            f"{worst:.3g} V ({name})")


def main() -> None:
    print("Part 1: the coupled scene (examples/bridge_contactor.toml as a changeover)")
    coupled_variants()
    print("Part 2: the test's small make, the load probe between the wiring and the common (before) and at the source")
    print(f"  before: {small_make(True)}")
    print(f"  now:    {small_make(False)}")


if __name__ == "__main__":
    main()
