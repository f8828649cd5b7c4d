"""Benchmark: why `run --check` calls the changeover relay's NO contact "not converged".

Run: .venv/bin/python benchmarks/bench_changeover_modes.py [--no-write] [--set KEY=VALUE ...]
(--set: the scene with those keys changed, e.g. armature.stop_stiffness=3e3; only printed)

examples/changeover_relay.toml at modes = "auto" (2 axial, 11 bending): its --check finds
the NO contact's bounce sequence moved 13.5 us by 1.5x the modes against 9.1 us by a 1 %
input change. This measures, for the NO and NC contacts alone (their own contact pairs):

- each contact's Hertz contact time at its own fastest impact of the run, the cutoff
  3 / t_c and the count it gives, against auto's (which takes 1 m/s, the scene's
  contact.reference_speed), and the armature's pole-stop contact time (the other short
  impact that loads the blade, through the card);
- a ladder of mode counts (axial, bending) against the finest: contact-state mismatch,
  closures, the shortest opening;
- the NO sequence's sensitivity at auto's count, shifted onto NO's own first make as the
  check does: initial.height (what the check changes as "the gap") by 1 %, NO's own gap
  (fixed[0].gap) by 0.5 and 1 %, the restitution by 1 %.

Writes the block between the changeover-modes markers of docs/accuracy-modes.md.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from doc_block import command_line, load_line, write_block  # noqa: E402

from coupling import run  # noqa: E402
from coupling.app.accuracy import (aligned_on_first_make, contact_groups, contact_metrics,  # noqa: E402
                                   mismatch_time, mode_counts, tip_intervals)
from coupling.core.metrics import DEFAULT_SETTLE_WINDOW  # noqa: E402
from coupling.core.results import merge_intervals  # noqa: E402
from coupling.core.scene import load_scene  # noqa: E402
from mech.model import armature_scales, resolve_auto_modes  # noqa: E402

DOC = ROOT / "docs" / "accuracy-modes.md"
BEGIN, END = "<!-- changeover-modes:begin -->", "<!-- changeover-modes:end -->"
SCENE = ROOT / "examples" / "changeover_relay.toml"
LADDER = [(3, 11), (4, 11), (2, 12), (2, 13), (2, 14), (3, 17), (4, 22)]
FINEST = (6, 30)


def contacts_of(res) -> dict:
    """{contact name: (its tips' intervals, closed at the end)} of a run."""
    tips = tip_intervals(res)
    return {name: ({i: tips.get(i, []) for i in pairs}, res.contact_closed[name][1])
            for name, pairs in contact_groups(res).items()}


def settle(res) -> float:
    """s: the run's settle window (a closure at least this long is held), as the check takes it."""
    metrics = getattr(res.scene, "metrics", None)
    return metrics.settle_window if metrics is not None else DEFAULT_SETTLE_WINDOW


def mismatch(a: dict, b: dict) -> float:
    return sum(mismatch_time(a.get(k, []), b.get(k, [])) for k in set(a) | set(b))


def openings(tips: dict) -> list[float]:
    u = merge_intervals([iv for v in tips.values() for iv in v])
    return [u[i + 1][0] - u[i][1] for i in range(len(u) - 1)]


def timed(scene):
    t0 = time.perf_counter()
    res = run(scene)
    return res, time.perf_counter() - t0


def contact_times(base, res) -> list[str]:
    """Each contact's Hertz time at its fastest impact of the run, and the armature stop's."""
    mech = base.mech
    auto = res.mechanics.model.mode_count
    c = res.mechanics.contacts
    lines = ["| impact | speed (m/s) | t_c (us) | 3 / t_c (kHz) | modes below it (axial, bending) |",
             "|---|---|---|---|---|",
             f"| auto's estimate (contact.reference_speed) | {auto.impact_speed:.3g} | {auto.contact_time * 1e6:.3g} "
             f"| {auto.cutoff / 1e3:.3g} | {auto.axial}, {auto.bending} |"]
    for name, pairs in contact_groups(res).items():
        speeds = c.normal_speed_in[c.tip.isin(list(pairs)) & (c.normal_speed_in > 0)]
        # both pairs: silver rivet on silver rivet at the same blade point: one stiffness, one mass
        _, choice = resolve_auto_modes(mech, impact_speed=float(speeds.max()))
        lines.append(f"| {name} (its fastest) | {speeds.max():.3g} | {choice.contact_time * 1e6:.3g} "
                     f"| {choice.cutoff / 1e3:.3g} | {choice.axial}, {choice.bending} |")
    t_stop = armature_scales(mech.armature).contact_time
    lines.append(f"| armature on its pole stop (pi sqrt(I / k_stop)) | - | {t_stop * 1e6:.3g} "
                 f"| {3 / t_stop / 1e3:.3g} | (not in the rule) |")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-write", action="store_true")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="a scene key changed (float)")
    args = ap.parse_args()
    base = load_scene(SCENE)
    if args.set:
        base = base.update({k: float(v) for k, v in (item.split("=", 1) for item in args.set)})
    run(base)  # (a first run loads the compiled mechanics and ngspice: not timed)
    auto_res, auto_wall = timed(base)
    rows = [("auto", auto_res, auto_wall)]
    for a, b in LADDER + [FINEST]:
        res, wall = timed(base.update({"bar.modes": {"axial": a, "bending": b}}))
        rows.append(("", res, wall))
    ref = contacts_of(rows[-1][1])
    lines = [f"`{command_line()}`; contact-state mismatch of each contact's own pairs against the "
             f"finest count ({FINEST[0]}, {FINEST[1]}); auto's check allows "
             f"{contact_metrics(*contacts_of(auto_res)['NO'], settle(auto_res))['window_contact_time'] * 0.02 * 1e6:.3g} "
             f"us on NO (2 % of its contact time while it switches).", ""]
    lines += contact_times(base, auto_res) + [""]
    lines += ["| modes (axial, bending) | NO mismatch (us) | NO closures | NO's shortest opening (us) "
              "| NC mismatch (us) | NC closures | wall (s) |", "|---|---|---|---|---|---|---|"]
    for label, res, wall in rows:
        mine = contacts_of(res)
        counts = mode_counts(res)
        no, nc = mine["NO"][0], mine["NC"][0]
        lines.append(f"| {label + ' ' if label else ''}({counts['axial']}, {counts['bending']}) | {mismatch(no, ref['NO'][0]) * 1e6:.2f} "
                     f"| {len(merge_intervals([i for v in no.values() for i in v]))} "
                     f"| {min(openings(no)) * 1e6:.2f} | {mismatch(nc, ref['NC'][0]) * 1e6:.1f} "
                     f"| {len(merge_intervals([i for v in nc.values() for i in v]))} | {wall:.2f} |")
    m = base.mech
    h, g, e = m.initial.height, m.fixed[0].gap, m.contact.restitution
    changes = [("initial.height x 0.99 (the check's gap)", "initial.height", h * 0.99),
               ("initial.height x 1.01 (the check's gap)", "initial.height", h * 1.01),
               ("NO's gap (fixed[0].gap) x 0.99", "fixed[0].gap", g * 0.99),
               ("NO's gap x 0.995", "fixed[0].gap", g * 0.995),
               ("NO's gap x 1.005", "fixed[0].gap", g * 1.005),
               ("NO's gap x 1.01", "fixed[0].gap", g * 1.01),
               ("contact.restitution x 0.99", "contact.restitution", e * 0.99),
               ("contact.restitution x 1.01", "contact.restitution", e * 1.01)]
    no_base, no_closed = contacts_of(auto_res)["NO"]
    first = contact_metrics(no_base, no_closed, settle(auto_res))["first_make"]
    lines += ["", "NO at auto's count with one input changed, shifted onto NO's first make (as the check does):", "",
              "| input changed | NO's first make moved (us) | NO mismatch (us) | NO closures |", "|---|---|---|---|"]
    for label, key, value in changes:
        res = run(base.set(key, value))
        tips, closed = contacts_of(res)["NO"]
        m0 = contact_metrics(tips, closed, settle(res))
        dt, shifted, _ = aligned_on_first_make(first, m0, tips, closed, settle(res))
        lines.append(f"| {label} | {-dt * 1e6:+.2f} | {mismatch(shifted, no_base) * 1e6:.2f} "
                     f"| {len(merge_intervals([i for v in tips.values() for i in v]))} |")
    lines.append("")
    lines.append(load_line(bullet=False))
    text = "\n".join(lines)
    print(text)
    if not (args.no_write or args.set):
        write_block(DOC, BEGIN, END, text)
        print(f"written to {DOC.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
