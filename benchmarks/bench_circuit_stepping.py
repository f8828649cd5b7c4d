"""Benchmark: the stepping API against the one-shot PWL run, same 2 ms five-bounce schedule.

Run: .venv/bin/python benchmarks/bench_circuit_stepping.py [--repeat N] [--no-write]

For each circuit, interleaved and repeated (best of N, the machine is shared):
- the reference: the schedule written as a PWL conductance source (no Python in ngspice's loop);
- the one-shot run with G(t) from Python through the EXTERNAL source;
- the stepping API at macro steps of 2 us and 10 us (G(t) and the breakpoints per step).
Prints absolute times and the ratio to the PWL run (target <= 1.5x). With an arc model
the PWL run has Python in its loop too: the arc state, decided at each accepted point.
Also derived from the same times: the cost of one macro step, (t(2 us) - t(10 us)) over the
extra macro steps. Writes its table between the bench-circuit-stepping markers of
docs/circuit.md (section 9).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from doc_block import command_line, load_line, publish  # noqa: E402

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

DOC = Path(__file__).resolve().parents[1] / "docs" / "circuit.md"
BEGIN, END = "<!-- bench-circuit-stepping:begin -->", "<!-- bench-circuit-stepping:end -->"
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
    parser.add_argument("--no-write", action="store_true", help="print only; leave docs/circuit.md alone")
    args = parser.parse_args()
    print(f"2 ms, 5 bounces, max_step {OPTIONS.max_step:g} s, method {OPTIONS.method}, reltol {OPTIONS.reltol:g}; best of {args.repeat}")
    lines = [f"`{command_line()}`: 2 ms, 5 bounces, max step {OPTIONS.max_step * 1e6:g} us, {OPTIONS.method}, "
             f"RELTOL {OPTIONS.reltol:g}; best of {args.repeat}, the routes interleaved.", "",
             "| circuit | route | best | / PWL | points |", "|---|---|---|---|---|"]
    ratios = {}
    per_step = []
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
            lines.append(f"| {name if label.startswith('PWL') else ''} | {label} | {best[label] * 1e3:.1f} ms | {best[label] / reference:.2f}x | "
                         f"{points[label]} |")
            ratios.setdefault(label, []).append(best[label] / reference)
        extra_steps = round(T_END / 2e-6) - round(T_END / 10e-6)
        per_step.append((best["stepping, H = 2 us"] - best["stepping, H = 10 us"]) / extra_steps)

    def spread(values, fmt):
        return fmt.format(min(values)) if len(values) == 1 else f"{fmt.format(min(values))}-{fmt.format(max(values))}"

    lines.append("")
    for h in ("10", "2"):
        r = ratios[f"stepping, H = {h} us"]
        met = sum(x <= 1.5 for x in r)
        lines.append(f"- Target stepping <= 1.5x the PWL run, H = {h} us: **{'met' if met == len(r) else 'not met'}** "
                     f"({met} of {len(r)} circuits; {spread(r, '{:.2f}')}x).")
    lines += [
        f"- G(t) from Python by itself (callback one-shot / PWL): {spread(ratios['callback one-shot'], '{:.2f}')}x.",
        f"- One macro step, (t(H = 2 us) - t(H = 10 us)) / {extra_steps} extra steps: "
        f"{spread([1e6 * x for x in per_step], '{:.0f}')} us.",
        load_line(),
    ]
    publish(DOC, BEGIN, END, lines, write=not args.no_write)
    return 0


if __name__ == "__main__":
    sys.exit(main())
