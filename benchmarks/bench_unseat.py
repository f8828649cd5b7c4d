"""The relay's pull-in at the coil's step rules, with and without the two rules for where the
drive is hard to extrapolate: psi^2's curvature in the change rule (a stationary psi^2, at the
coil's switch-on and in a ringing coil) and the approach to the armature's unseat.

    .venv/bin/python benchmarks/bench_unseat.py [--no-write]

For the default relay (to 5.6 ms: its pull-in, the card's touch and the first make) and
examples/changeover_relay.toml (to 13 ms: its operate transfer): the instant the armature
leaves its rest stop (the unseat), the instant its card meets the blade, and the operate time
(coil on -> first make), each against the run with every step rule halved twice (`run
--check`'s refinement twice, coupling.app.accuracy.refined_steps), beside the macro steps of
the whole default relay (12 ms) and its RC-released variant's coil-armature interface
residual. The rows switch a rule off in this process only (the previous rules: the change
rule on psi^2's slope alone, `StepPolicy.plan` without ``curvature``; no redo at the unseat,
`CoSimulation._approach_unseat` returning the step as it was). Writes the block
"bench-unseat" of docs/coupling.md.
"""

from __future__ import annotations

import contextlib
import os
from pathlib import Path

from doc_block import command_line, load_line, publish

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "coupling.md"
BEGIN, END = "<!-- bench-unseat:begin -->", "<!-- bench-unseat:end -->"
ROWS = (("the current rules", True, True), ("without the approach to the unseat", True, False),
        ("without psi^2's curvature in the change rule", False, True), ("neither (the rules before)", False, False))


@contextlib.contextmanager
def rules(curvature: bool, approach: bool):
    """The step rules with either rule switched off in this process (module docstring)."""
    from coupling.core.master import CoSimulation
    from coupling.core.policy import StepPolicy

    plan, unseat = StepPolicy.plan, CoSimulation._approach_unseat
    if not curvature:
        StepPolicy.plan = lambda self, *a, curvature=0.0, **k: plan(self, *a, **k)
    if not approach:
        CoSimulation._approach_unseat = lambda self, mech, start, t, t_next, seg, drives, in_flight: (t_next, seg)
    try:
        yield
    finally:
        StepPolicy.plan, CoSimulation._approach_unseat = plan, unseat


def pull_in(result, t_on: float) -> dict:
    """s after the coil's switch-on: the unseat, the card's touch; the operate time."""
    events = result.mechanics.events
    unseat = next(e["time"] for e in events if e["kind"] == "armature_stop_end" and e["time"] > t_on)
    card = next(e["time"] for e in events if e["kind"] == "card_start" and e["time"] > t_on)
    return dict(unseat=unseat - t_on, card=card - t_on, operate=result.relay["operate_time"],
                steps=result.stats["macro_steps"])


def main() -> None:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print the block only")
    args = parser.parse_args()

    from coupling import builtin_scene, load_scene, run
    from coupling.app.accuracy import refined_steps

    relay = builtin_scene("default")
    changeover = load_scene(ROOT / "examples" / "changeover_relay.toml")
    scenes = {"default relay": (relay.set("solver.t_end", 0.0056), relay.raw["coil"]["on_time"]),
              "changeover": (changeover.set("solver.t_end", 0.013), changeover.raw["coil"]["on_time"])}
    run(relay.set("solver.t_end", 1e-3))  # (warm: ngspice loaded, the compiled mechanics imported)
    refs, previous = {}, {}
    for name, (scene, t_on) in scenes.items():
        quarter = refined_steps(refined_steps(scene)[1])[1]
        refs[name] = pull_in(run(quarter), t_on)
        with rules(False, False):
            previous[name] = pull_in(run(quarter), t_on)
    lines = [f"`{command_line()}`: the pull-in of the default relay (to 5.6 ms) and of examples/changeover_relay.toml "
             "(to 13 ms) against the run with every step rule halved twice: "
             + "; ".join(f"{name}: unseat {r['unseat'] * 1e6:.2f} us, card {r['card'] * 1e6:.2f} us, operate time "
                         f"{r['operate'] * 1e6:.2f} us after the coil's switch-on, {r['steps']} macro steps "
                         f"(the rules before: {abs(previous[name]['unseat'] - r['unseat']) * 1e6:.2f}, "
                         f"{abs(previous[name]['card'] - r['card']) * 1e6:.2f}, "
                         f"{abs(previous[name]['operate'] - r['operate']) * 1e6:.2f} us from it)"
                         for name, r in refs.items()) + ".", "",
             "| rules | scene | macro steps | unseat - reference's | card - reference's | operate time - reference's "
             "| whole default relay: macro steps | its RC release: interface / into_coil |",
             "|---|---|---|---|---|---|---|---|"]
    for label, curvature, approach in ROWS:
        with rules(curvature, approach):
            whole = run(relay)
            rc = run(relay.set("coil.suppression", "rc")).relay["energy"]["interface_relative_residual"]
            for k, (name, (scene, t_on)) in enumerate(scenes.items()):
                m, r = pull_in(run(scene), t_on), refs[name]
                whole_cells = (whole.stats["macro_steps"], f"{rc:.1e}") if k == 0 else ("", "")
                lines.append(f"| {label if k == 0 else ''} | {name} | {m['steps']} | "
                             f"{(m['unseat'] - r['unseat']) * 1e6:+.2f} us | {(m['card'] - r['card']) * 1e6:+.2f} us | "
                             f"{(m['operate'] - r['operate']) * 1e6:+.2f} us | {whole_cells[0]} | {whole_cells[1]} |")
    lines += ["", load_line()]
    publish(DOC, BEGIN, END, lines, write=not args.no_write)


if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    main()
