"""Benchmark: the stepping API against the one-shot PWL run, same 2 ms five-bounce schedule.

Run: .venv/bin/python benchmarks/bench_circuit_stepping.py [--repeat N]

For each circuit, interleaved and repeated (best of N, the machine is shared):
- the reference: the schedule written as a PWL conductance source (no Python in ngspice's loop);
- the one-shot run with G(t) from Python through the EXTERNAL source;
- the stepping API at macro steps of 2 us and 10 us (G(t) and the breakpoints per step).
Prints absolute times and the ratio to the PWL run (target <= 1.5x). With an arc model
the PWL run has Python in its loop too: the arc state, decided at each accepted point.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from circuit import (  # noqa: E402
    ArcModel,
    ContactSchedule,
    DCSource,
    InductiveLoad,
    ResistiveLoad,
    SimulationOptions,
    Stepper,
    SwitchCircuit,
    Wiring,
    run_pwl_reference,
    run_transient,
)

T_END = 2e-3
SCHEDULE = ContactSchedule.from_events(
    make=[0.10e-3, 0.30e-3, 0.55e-3, 0.73e-3, 0.87e-3, 0.96e-3],
    brk=[0.25e-3, 0.50e-3, 0.70e-3, 0.85e-3, 0.95e-3],
    closed_resistance=0.01,
    edge_time=10e-9,
)
OPTIONS = SimulationOptions(max_step=1e-6)
CIRCUITS = {
    "resistive 2 A, 1 uH wiring, 100 pF (rings at 16 MHz)": SwitchCircuit(
        DCSource(24.0, 0.05), ResistiveLoad(12.0), wiring=Wiring(0.0, 1e-6)
    ),
    "relay coil 24 ohm 10 mH + arc model": SwitchCircuit(
        DCSource(24.0, 0.05), InductiveLoad(24.0, 10e-3), wiring=Wiring(0.01, 1e-6), arc=ArcModel()
    ),
    # The coupled default scene's circuit: a 1 A DC arc burns through every opening.
    "resistive 2 A + arc model (DC arcs through the openings)": SwitchCircuit(
        DCSource(24.0, 0.05), ResistiveLoad(12.0), wiring=Wiring(0.0, 1e-6), arc=ArcModel()
    ),
}


def pwl(circuit):
    return len(run_pwl_reference(circuit, SCHEDULE, T_END, options=OPTIONS))


def one_shot(circuit):
    return len(run_transient(circuit, SCHEDULE, T_END, options=OPTIONS))


def stepped(circuit, macro_step):
    with Stepper(circuit, T_END, OPTIONS) as stepper:
        t = 0.0
        while not stepper.finished:
            t_next = min(t + macro_step, T_END)
            stepper.advance(t_next, SCHEDULE, SCHEDULE.breakpoints(t, t_next))
            t = t_next
        return stepper.stats["points"]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    print(f"2 ms, 5 bounces, max_step {OPTIONS.max_step:g} s, method {OPTIONS.method}, reltol {OPTIONS.reltol:g}; best of {args.repeat}")
    for name, circuit in CIRCUITS.items():
        runs = {
            "PWL one-shot (reference)": lambda: pwl(circuit),
            "callback one-shot": lambda: one_shot(circuit),
            "stepping, H = 10 us": lambda: stepped(circuit, 10e-6),
            "stepping, H = 2 us": lambda: stepped(circuit, 2e-6),
        }
        best = {label: float("inf") for label in runs}
        points = {}
        for _ in range(args.repeat):
            for label, run in runs.items():
                start = time.perf_counter()
                points[label] = run()
                best[label] = min(best[label], time.perf_counter() - start)
        reference = best["PWL one-shot (reference)"]
        print(f"\n{name}")
        for label in runs:
            print(f"  {label:26s} {best[label] * 1e3:8.1f} ms  {best[label] / reference:5.2f}x  {points[label]:6d} points")
    return 0


if __name__ == "__main__":
    sys.exit(main())
