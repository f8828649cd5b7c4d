"""The coil-armature interface's energy audit on the shipped relays: its relative residual at
the scene's own steps and under halvings of every step rule, and what the audit costs.

    .venv/bin/python benchmarks/bench_relay_interface.py [--repeat 5] [--no-write]

Per scene (the default relay, examples/plunger_solenoid.toml, examples/changeover_relay.toml)
and the plunger's pull-in alone (to 12 ms), per level of refinement (every step rule halved,
as `run --check` does it: coupling.app.accuracy.refined_steps): the macro steps, the work the mechanics received from
the drive (relay.energy.armature_received), the interface residual (relay.energy.
interface_residual, the magnet's work as the circuit sees it less that) relative to the energy
into the coil, and beside it the coil's own audit (relay.energy.relative_residual). The default
relay with its coil's time-scale fraction 3, 5 and 10 times its own: the interface residual
beside the operate time's error against a run at a quarter of every step rule. The cost:
the co-simulation's own wall_time of the default relay and of the plunger with the audit
(coupling.core.exchange.CoilLink.receive) and without it (replaced by nothing), the two
interleaved in one process, medians of --repeat runs each. Writes the block
"bench-relay-interface" of docs/coupling.md.
"""

from __future__ import annotations

import argparse
import statistics
from pathlib import Path

from doc_block import command_line, load_line, publish

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "coupling.md"
BEGIN, END = "<!-- bench-relay-interface:begin -->", "<!-- bench-relay-interface:end -->"
LEVELS = 3  # the scene's own steps, halved once, twice
COARSE = (1.0, 3.0, 5.0, 10.0)  # the default relay's coil time-scale fraction times these


def scenes():
    from coupling import builtin_scene, load_scene

    plunger = load_scene(ROOT / "examples" / "plunger_solenoid.toml")
    return [("default relay", builtin_scene("default")),
            ("examples/plunger_solenoid.toml", plunger),
            ("examples/changeover_relay.toml", load_scene(ROOT / "examples" / "changeover_relay.toml")),
            ("the plunger's pull-in (t_end 12 ms)", plunger.set("solver.t_end", 0.012))]


def refinement_rows() -> list[str]:
    from coupling import run
    from coupling.app.accuracy import refined_steps

    rows = ["| scene | steps | macro steps | armature_received | interface residual | interface / into_coil "
            "| coil audit's relative residual |", "|---|---|---|---|---|---|---|"]
    for name, scene in scenes():
        for level in range(LEVELS):
            res = run(scene)
            e = res.relay["energy"]
            label = "own" if level == 0 else f"halved x{level}"
            rows.append(f"| {name} | {label} | {res.stats['macro_steps']} | {e['armature_received']:.6e} J "
                        f"| {e['interface_residual']:.2e} J | {e['interface_relative_residual']:.1e} "
                        f"| {e['relative_residual']:.1e} |")
            scene = refined_steps(scene)[1]
    return rows


def coarse_rows() -> list[str]:
    """The default relay with its coil's time-scale fraction raised, against a reference at a
    quarter of every step rule: the interface residual, the coil's audit and the operate time's
    error."""
    from coupling import builtin_scene, run

    scene = builtin_scene("default")
    c = scene.coupling
    reference = run(scene.update({f"coupling.{key}": getattr(c, key) / 4.0 for key in (
        "macro_step", "max_macro_step", "coil_time_scale_fraction", "gap_change_fraction")}))
    rows = ["| coil_time_scale_fraction | macro steps | interface / into_coil | coil audit's relative residual "
            "| operate time - reference's |", "|---|---|---|---|---|"]
    for factor in COARSE:
        res = run(scene.set("coupling.coil_time_scale_fraction", factor * c.coil_time_scale_fraction))
        e = res.relay["energy"]
        late = res.relay["operate_time"] - reference.relay["operate_time"]
        rows.append(f"| {factor * c.coil_time_scale_fraction:g} | {res.stats['macro_steps']} "
                    f"| {e['interface_relative_residual']:.1e} | {e['relative_residual']:.1e} | {late * 1e6:+.1f} us |")
    return rows


def cost_lines(repeat: int) -> list[str]:
    from coupling import run
    from coupling.core import exchange

    receive = exchange.CoilLink.receive
    lines = []
    for name, scene in scenes()[:2]:
        times = {"with": [], "without": []}
        run(scene)  # (a first run: imports and ngspice's start-up out of the timing)
        for _ in range(repeat):
            for mode in ("without", "with"):
                exchange.CoilLink.receive = receive if mode == "with" else (lambda self, seg, mech: None)
                try:
                    times[mode].append(run(scene).stats["wall_time"])
                finally:
                    exchange.CoilLink.receive = receive
        with_, without = statistics.median(times["with"]), statistics.median(times["without"])
        lines.append(f"- {name}: {1e3 * with_:.0f} ms with the audit, {1e3 * without:.0f} ms without "
                     f"(median of {repeat} each, interleaved): {100 * (with_ / without - 1):+.1f} %.")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="timed runs of each variant (default 5)")
    parser.add_argument("--no-write", action="store_true", help="print the block, do not write the docs")
    args = parser.parse_args()
    lines = [f"`{command_line()}`: the interface residual at the scene's own steps and with every step rule "
             "halved once and twice (`run --check`'s refinement):", "", *refinement_rows(), "",
             "The default relay with a coarser coupling of its coil (operate time against a run at a quarter of "
             "every step rule):", "", *coarse_rows(), "",
             "The audit's cost, the co-simulation's wall_time:", *cost_lines(args.repeat), load_line()]
    publish(DOC, BEGIN, END, lines, write=not args.no_write)


if __name__ == "__main__":
    main()
