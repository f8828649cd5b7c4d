"""The coil's step rules, error against run time: the plunger solenoid (and the default relay's
operate time, make bounces and openings) at the coil's time-scale fraction and gap rule of the
master against a refined reference, beside the results' sensitivity to 1 % changes of the
scene's inputs.

    .venv/bin/python benchmarks/bench_coil_steps.py [--repeat 5] [--no-write]

The coil's macro steps (coupling/core/policy.py, coupling/core/exchange.py CoilLink.observe)
are at most `coupling.coil_time_scale_fraction` of the time scale of psi^2 (from its
curvature, at most the time it takes to change by its own size) and of the time the working
gap takes to change by `coupling.gap_change_fraction` of itself while the armature moves,
and at most max_macro_step; ngspice takes at least `coupling.coil_step_points` points per
macro step, and while the coil's flux changes its steps are at most
`coupling.coil_point_fraction` of the coil's time constant L/R. Each row runs the scene with those keys changed and
compares with the reference: every step rule at a quarter (fraction, gap rule, macro_step,
max_macro_step, coil_point_fraction) and ngspice RELTOL / 10. Results (SI): the armature's first arrival at the
pole (s), the coil current at the end (A, relative), the times of the armature's later
arrivals at the pole (its bounces there; the largest difference, s) and the coil's energy
residual (relative to the energy into the coil). Run time: the co-simulation's own
wall_time (median of --repeat runs, one process, the rows interleaved). Writes the block "bench-coil-steps" of
docs/coupling.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
from pathlib import Path

from doc_block import command_line, load_line, publish

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "coupling.md"
BEGIN, END = "<!-- bench-coil-steps:begin -->", "<!-- bench-coil-steps:end -->"
PLUNGER = ROOT / "examples" / "plunger_solenoid.toml"
REFINE = 4.0  # the reference: every step rule at 1 / REFINE ...
RELTOL_REFINE = 10.0  # ... and ngspice RELTOL / RELTOL_REFINE
POINTS = 2  # coupling.coil_step_points of the current rules
POINT_FRACTION = 0.0125  # coupling.coil_point_fraction of the current rules (1: ngspice's own steps, about)
# (label, coupling.coil_time_scale_fraction, coupling.gap_change_fraction, max_macro_step factor, ngspice's
# largest step in s, None: its own choice, or "reltol": RELTOL / RELTOL_REFINE; coupling.coil_step_points)
VARIANTS = (
    ("current rules", 0.1, 1.0, 1.0, None, POINTS),
    ("fraction 0.05", 0.05, 1.0, 1.0, None, POINTS),
    ("fraction 0.15", 0.15, 1.0, 1.0, None, POINTS),
    ("fraction 0.2", 0.2, 1.0, 1.0, None, POINTS),
    ("fraction 0.3", 0.3, 1.0, 1.0, None, POINTS),
    ("fraction 0.5", 0.5, 1.0, 1.0, None, POINTS),
    ("gap rule x2", 0.1, 2.0, 1.0, None, POINTS),
    ("gap rule x4", 0.1, 4.0, 1.0, None, POINTS),
    ("max_macro_step x2", 0.1, 1.0, 2.0, None, POINTS),
    ("RELTOL / 10", 0.1, 1.0, 1.0, "reltol", POINTS),
    ("coil_step_points 1", 0.1, 1.0, 1.0, None, 1),
    ("coil_step_points 4", 0.1, 1.0, 1.0, None, 4),
    ("coil_step_points 1, coil_point_fraction 1 (before them)", 0.1, 1.0, 1.0, None, (1, 1.0)),
    ("ngspice max step 5 us", 0.1, 1.0, 1.0, 5e-6, POINTS),
    ("fraction 0.3, ngspice max step 5 us", 0.3, 1.0, 1.0, 5e-6, POINTS),
)
# the inputs changed by 1 % each way for the sensitivity rows (the plunger's own keys)
INPUTS = ("coil.voltage", "armature.mass", "armature.travel", "armature.stop_damping")


def with_options(scene, **options):
    """The scene with ngspice's options changed (``circuit.SimulationOptions`` fields: an
    actuator's coil drive takes no [circuit] table)."""
    spec = scene.circuit
    return dataclasses.replace(scene, circuit=dataclasses.replace(
        spec, options=dataclasses.replace(spec.options, **options)))


def run(scene, fraction: float, gap: float, points=POINTS, repeat: int = 1) -> dict:
    """The results of ``scene`` at the coil's step rules ``fraction``, ``gap`` and ``points``
    (coupling.coil_step_points, or that and coupling.coil_point_fraction as a pair; alone,
    the current rules' fraction), and its median wall time (s)."""
    from coupling.core import master

    count, point_fraction = points if isinstance(points, tuple) else (points, POINT_FRACTION)
    # (replaced, not set by key: a scene from with_options keeps its ngspice options)
    scene = dataclasses.replace(scene, coupling=dataclasses.replace(
        scene.coupling, coil_time_scale_fraction=fraction, gap_change_fraction=gap, coil_step_points=count,
        coil_point_fraction=point_fraction))
    walls = []
    for _ in range(repeat):
        result = master.run(scene)
        walls.append(result.stats["wall_time"])
    relay = result.relay
    arrivals = [e["time"] for e in result.mechanics.events
                if e["kind"] == "armature_stop_start" and relay["armature_arrival"] is not None
                and e["time"] > relay["armature_arrival"]]
    bounce = result.summary.get("bounce") or {}
    return dict(arrival=relay["armature_arrival"], operate=relay["operate_time"],
                make_bounces=bounce.get("bounces"),
                openings=[o["start"] for o in bounce.get("openings", [])],
                current=float(result.waveform_columns["coil_current"][-1]), bounces=arrivals,
                residual=relay["energy"]["relative_residual"], steps=result.stats["macro_steps"],
                points=result.stats["circuit"]["points"],
                wall=statistics.median(walls))


def binding_rules(scene) -> list[tuple[float, float, str]]:
    """(step start s, step length s, the rule that set the coil's time scale after it:
    "curvature", "size" or "gap", CoilLink.bound_by) of each macro step of a run of ``scene``."""
    from coupling.core import exchange, master

    log = []
    observe = exchange.CoilLink.observe

    def watched(self, step, seg, policy):
        observe(self, step, seg, policy)
        log.append((seg.t_start, seg.t_end - seg.t_start, self.bound_by))

    exchange.CoilLink.observe = watched
    try:
        master.run(scene)
    finally:
        exchange.CoilLink.observe = observe
    return log


def difference(m: dict, ref: dict) -> dict:
    """The differences of m's results from ref's: arrival (s), current (relative), bounces
    (the largest over the arrivals both have, s; and the two counts)."""
    n = min(len(m["bounces"]), len(ref["bounces"]))
    return dict(arrival=abs(m["arrival"] - ref["arrival"]), current=abs(m["current"] / ref["current"] - 1.0),
                bounce=max((abs(a - b) for a, b in zip(m["bounces"][:n], ref["bounces"][:n])), default=0.0),
                counts=(len(m["bounces"]), len(ref["bounces"])))


def bounce_text(d: dict) -> str:
    a, b = d["counts"]
    return f"{d['bounce'] * 1e6:.1f} us" + ("" if a == b else f" ({a} vs {b} arrivals)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs per row for the median wall time")
    parser.add_argument("--no-write", action="store_true", help="print the block only")
    args = parser.parse_args()

    import coupling

    base = coupling.load_scene(PLUNGER)
    opts = base.coupling
    run(base, 0.1, 1.0)  # (warm: ngspice loaded, the compiled mechanics imported)
    refined = with_options(base.update({"coupling.macro_step": opts.macro_step / REFINE,
                                       "coupling.max_macro_step": opts.max_macro_step / REFINE}),
                          reltol=base.circuit.options.reltol / RELTOL_REFINE)
    fine = (POINTS, POINT_FRACTION / REFINE)
    ref = run(refined, 0.1 / REFINE, 1.0 / REFINE, fine)
    check = run(refined.set("solver.rtol", base.mech.solver.rtol / 10.0), 0.1 / REFINE, 1.0 / REFINE, fine)
    d_check = difference(check, ref)

    lines = [f"`{command_line()}`: examples/plunger_solenoid.toml (50 ms; the armature arrives at the pole at "
             f"{ref['arrival'] * 1e3:.3f} ms and bounces there {len(ref['bounces'])} more times up to "
             f"{ref['bounces'][-1] * 1e3:.2f} ms). Reference: every step rule at 1/{REFINE:g} (fraction "
             f"{0.1 / REFINE:g}, gap rule {1.0 / REFINE:g}, macro_step {opts.macro_step / REFINE * 1e6:g} us, "
             f"max_macro_step {opts.max_macro_step / REFINE * 1e6:g} us, coil_point_fraction "
             f"{POINT_FRACTION / REFINE:g}) and RELTOL "
             f"{base.circuit.options.reltol / RELTOL_REFINE:g}: {ref['steps']} macro steps, "
             f"{ref['wall']:.2f} s; the reference with the mechanics' rtol / 10 differs from it by "
             f"{d_check['arrival'] * 1e6:.2f} us (arrival), {d_check['current']:.1e} (current), "
             f"{bounce_text(d_check)} (bounces): the reference's own uncertainty.",
             "",
             "| rules | macro steps | ngspice points | run time | arrival at the pole | coil current at 50 ms "
             "| bounces at the pole | energy residual |",
             "|---|---|---|---|---|---|---|---|"]
    log = binding_rules(base)
    early = [h for t, h, _ in log if t < ref["arrival"]]
    late = [(h, rule) for t, h, rule in log if t >= ref["arrival"]]
    share = {rule: sum(r == rule for _, r in late) / len(late) for rule in ("curvature", "gap", "size")}
    lines[1:1] = ["", f"The current rules' steps: {len(early)} before the arrival at the pole (median "
                      f"{statistics.median(early) * 1e6:.0f} us), {len(late)} after (median "
                      f"{statistics.median(h for h, _ in late) * 1e6:.0f} us, the coil's time scale set by "
                      f"the curvature rule after {share['curvature']:.0%} of them, the gap rule "
                      f"{share['gap']:.0%}, the change-by-its-size rule {share['size']:.0%})."]
    rows, scenes = {}, {}
    for label, fraction, gap, free, max_step, points in VARIANTS:
        scene = base if free == 1.0 else base.set("coupling.max_macro_step", opts.max_macro_step * free)
        if max_step == "reltol":
            scene = with_options(scene, reltol=base.circuit.options.reltol / RELTOL_REFINE)
        elif max_step is not None:
            scene = with_options(scene, max_step=max_step)
        scenes[label] = (scene, fraction, gap, points)
        rows[label] = run(*scenes[label])
    # the run times: the rows interleaved, repeat times, so that the shared machine's load
    # falls on every row alike
    walls = {label: [] for label in scenes}
    for _ in range(args.repeat):
        for label, config in scenes.items():
            walls[label].append(run(*config)["wall"])
    for label in scenes:
        m = rows[label]
        m["wall"] = statistics.median(walls[label])
        d = difference(m, ref)
        lines.append(f"| {label} | {m['steps']} | {m['points']} | {m['wall'] * 1e3:.0f} ms | {d['arrival'] * 1e6:.2f} us | "
                     f"{d['current']:.1e} | {bounce_text(d)} | {m['residual']:.1e} |")
    lines.append(f"| reference | {ref['steps']} | {ref['points']} | {ref['wall'] * 1e3:.0f} ms | - | - | - "
                 f"| {ref['residual']:.1e} |")
    lines += ["", "Sensitivity: the current rules' run with one input changed by 1 % each way, against the "
                  "unchanged run (the larger of the two changes):", "",
              "| input | arrival at the pole | coil current at 50 ms | bounces at the pole |", "|---|---|---|---|"]
    plain = rows["current rules"]
    for key in INPUTS:
        value = base.raw
        for part in key.split("."):
            value = value[part]
        moved = [difference(run(base.set(key, float(value) * (1.0 + rel)), 0.1, 1.0), plain) for rel in (-0.01, 0.01)]
        worst = max(moved, key=lambda d: d["bounce"])
        lines.append(f"| `{key}` {value:g} | {max(d['arrival'] for d in moved) * 1e6:.1f} us | "
                     f"{max(d['current'] for d in moved):.1e} | {bounce_text(worst)} |")

    relay = coupling.default_scene()
    ropts = relay.coupling
    rref = run(with_options(relay.update({"coupling.macro_step": ropts.macro_step / REFINE,
                                         "coupling.max_macro_step": ropts.max_macro_step / REFINE}),
                           reltol=relay.circuit.options.reltol / RELTOL_REFINE), 0.1 / REFINE, 1.0 / REFINE, fine)
    parts = []
    # (label: coil_time_scale_fraction, gap_change_fraction, coil_step_points or (points, point fraction))
    relay_configs = {"the current rules": (0.1, 1.0, POINTS), "fraction 0.2": (0.2, 1.0, POINTS),
                     "fraction 0.3": (0.3, 1.0, POINTS), "gap rule x2": (0.1, 2.0, POINTS),
                     "gap rule x4": (0.1, 4.0, POINTS),
                     "coil_point_fraction 1 (no bound from L/R)": (0.1, 1.0, (POINTS, 1.0)),
                     "coil_step_points 1, coil_point_fraction 1 (before them)": (0.1, 1.0, (1, 1.0))}
    relay_rows = {label: run(relay, *config) for label, config in relay_configs.items()}
    relay_walls = {label: [] for label in relay_rows}
    for _ in range(max(1, args.repeat // 2)):
        for label, config in relay_configs.items():
            relay_walls[label].append(run(relay, *config)["wall"])
    lines += ["", f"The default relay against its reference (the same rule: operate time {rref['operate'] * 1e3:.4f} ms, "
                  f"{rref['make_bounces']} make bounces, {rref['residual']:.1e} coil energy residual):", "",
              "| rules | macro steps | ngspice points | run time | operate time | make bounces | openings the "
              "reference lacks | coil energy residual |", "|---|---|---|---|---|---|---|---|"]
    for label, m in relay_rows.items():
        m["wall"] = statistics.median(relay_walls[label])
        # an opening more than 5 us from every one of the reference's
        extra = [t for t in m["openings"] if min((abs(t - r) for r in rref["openings"]), default=1.0) > 5e-6]
        lines.append(f"| {label} | {m['steps']} | {m['points']} | {m['wall'] * 1e3:.0f} ms | "
                     f"{abs(m['operate'] - rref['operate']) * 1e6:.1f} us | {m['make_bounces']} | "
                     f"{', '.join(f'{t * 1e3:.4f} ms' for t in extra) or '-'} | {m['residual']:.1e} |")
    lines += ["", load_line()]
    publish(DOC, BEGIN, END, lines, write=not args.no_write)


if __name__ == "__main__":
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    main()
