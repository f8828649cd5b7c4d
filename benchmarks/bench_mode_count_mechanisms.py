"""Benchmark: what modes = "auto" holds for on switch mechanisms, coupled, over a whole closure.

Run: .venv/bin/python benchmarks/bench_mode_count_mechanisms.py [--no-write]

bench_mode_count.py checks the rule on free bars over their first impacts (1.2 ms). A switch
closure is more: a held blade or lever, an actuator, a bounce sequence of 5-10 contacts
ending in micro-bounces, an arc at each opening. For the coil-driven default relay (an
armature's card drives the clamped CuBe blade), the force-driven relay (relay_force), the
pushbutton example (pivoted steel lever), each run coupled as shipped, and the correct-by-
default audit's driven wire (a clamp lowered along an S-curve, mechanics only), this runs
the auto count, the count the floor would give where auto left a family the impact does
not load below it, and a ladder of explicit counts (modes per family, axial and bending)
and reports, per count, the metrics of `switchsim run --check` against the finest
count of the ladder: contact-state mismatch time, contacts, bounces, last make, total
bounce time, peak contact force, first contact's kinematic restitution, arc energy; and
the mechanics' accepted steps and the run's wall time. It then runs `switchsim run --check`
on the auto count (its refinements and its four reruns with the contact gap and restitution
changed by 1 %) and says, per row, whether the row's bounce count and last make lie inside
the range that check reports: whether what auto's check tells a user brackets the converged
answer. Writes the block between the mode-count-mechanisms markers of docs/accuracy-modes.md.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

from doc_block import write_block

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from coupling import builtin_scene, run, scene_from_dict  # noqa: E402
from coupling.app.accuracy import check, metrics_of, mismatch_time, mode_counts, time_tolerance, tip_intervals  # noqa: E402
from coupling.core.scene import load_scene  # noqa: E402
from mech.mode_count import FLOOR  # noqa: E402

DOC = ROOT / "docs" / "accuracy-modes.md"
BEGIN, END = "<!-- mode-count-mechanisms:begin -->", "<!-- mode-count-mechanisms:end -->"


def driven_wire():
    """The correct-by-default audit's driven blade: a 1 mm steel wire 30 mm long, clamped at
    one end 0.5 mm above a steel block, its clamp lowered 0.7 mm along an S-curve over 2 ms
    (pchip through 40 points) and held; no initial velocity, mechanics only, 4 ms. The block
    is under the free end: the contact point is a cap of the wire's radius at its end (a
    [[rivet]]), so the clamped end, lowered past the block's plane, touches nothing."""
    t = np.linspace(0.0, 2e-3, 40)
    s = t / 2e-3
    z = -0.7e-3 * (3 * s**2 - 2 * s**3)
    motion = {"time": [*map(float, t), 4e-3], "displacement": [[0.0, 0.0, float(v)] for v in (*z, z[-1])],
              "interpolation": "pchip"}
    return scene_from_dict({"bar": {"length": 0.03, "diameter": 0.001},
                            "rivet": [{"position": 0.0005, "radius": 0.0005}],
                            "mount": {"kind": "clamp", "position": 0.03, "base_motion": motion},
                            "initial": {"height": 0.0005}, "solver": {"t_end": 4e-3}}, name="driven_wire")


CASES = {
    "coil-driven relay (the default scene: coil, armature, card, clamped CuBe blade, 24 V / 10 ohm, arc)":
        lambda: builtin_scene("default"),
    "force-driven relay (relay_force: clamped CuBe blade, 24 V / 10 ohm, arc)": lambda: builtin_scene("relay_force"),
    "pushbutton (pivoted steel lever, 5 V / 1 kohm)": lambda: load_scene(ROOT / "examples" / "pushbutton.toml"),
    "driven wire (clamp lowered along an S-curve, mechanics only)": driven_wire,
}
LADDER = [(1, 3), (1, 6), (3, 5), (3, 8), (3, 12), (3, 16), (5, 20)]


def one(scene):
    t0 = time.perf_counter()
    res = run(scene)
    wall = time.perf_counter() - t0
    m = metrics_of(res)
    c = res.mechanics.contacts
    m["restitution"] = float(c.kinematic_restitution.iloc[0]) if len(c) else float("nan")
    return m, tip_intervals(res), wall, mode_counts(res), res


def inside(m: dict, auto: dict, ranges: dict, key: str) -> bool:
    """Whether m[key] lies in the range auto's check reports (its sensitivity range, or
    auto's value within the check's tolerance when the gap does not move the metric)."""
    if key in ranges:
        lo, hi = ranges[key]
        tol = 0 if key == "bounces" else time_tolerance(auto)
        return lo - tol <= m[key] <= hi + tol
    if key == "bounces":
        return m[key] == auto[key]
    return abs(m[key] - auto[key]) <= time_tolerance(auto)


def floor_row(base, auto_res) -> list:
    """("floor (a, b)", scene) when auto left a family the impact does not load below the
    floor (mech/mode_count.py): the count with that family raised to it, as before; else []."""
    chosen = auto_res.mechanics.model.mode_count
    if chosen is None or not chosen.unloaded:
        return []
    a, b = (max(FLOOR, n) if fam in chosen.unloaded else n
            for fam, n in (("axial", chosen.axial), ("bending", chosen.bending)))
    return [(f"floor ({a}, {b})", base.update({"bar.modes": {"axial": a, "bending": b}}))]


def table(name: str, base) -> tuple[list[str], dict]:
    auto = ("auto", *one(base))
    rows = floor_row(base, auto[5]) + [(f"{a}, {b}", base.update({"bar.modes": {"axial": a, "bending": b}}))
                                       for a, b in LADDER]
    results = [auto] + [(label, *one(sc)) for label, sc in rows]
    ref_m, ref_iv = results[-1][1], results[-1][2]
    auto_m, auto_res = results[0][1], results[0][5]
    acc = check(base, auto_res)
    ranges = acc["sensitivity_ranges"]
    rule = auto_res.summary["solver"].get("modes_rule", "")
    fastest = auto_res.mechanics.contacts.normal_speed_in.abs().max() if len(auto_res.mechanics.contacts) else float("nan")
    lines = [f"**{name}**: auto chose \"{rule}\"; the run's fastest impact {fastest:.3g} m/s. Against the finest "
             f"count ({results[-1][0]}):", "",
             "| modes (axial, bending) | mismatch (us) | contacts | bounces | last make (ms) | total bounce time (ms) "
             "| peak force (N) | first restitution | arc energy (mJ) | bounces, last make inside auto's range "
             "| mechanics steps | wall (s) |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for label, m, iv, wall, counts, res in results:
        mism = sum(mismatch_time(iv.get(k, []), ref_iv.get(k, [])) for k in set(iv) | set(ref_iv))
        shown = label if label != "auto" else f"auto ({counts['axial']}, {counts['bending']})"
        arc = m.get("arc_energy")
        ins = ", ".join("yes" if inside(m, auto_m, ranges, k) else "NO" for k in ("bounces", "last_make"))
        lines.append(
            f"| {shown} | {mism * 1e6:.0f} | {m['contacts']} | {m['bounces']} | {m['last_make'] * 1e3:.3f} | "
            f"{m['total_bounce_time'] * 1e3:.3f} | {m['peak_force']:.2f} | {m['restitution']:.3f} | "
            f"{'-' if arc is None else f'{arc * 1e3:.2f}'} | {ins} | {res.mechanics.stats['steps']} | {wall:.2f} |")
        print(lines[-1], flush=True)
    spans = ", ".join(f"{k} {lo:.4g}-{hi:.4g}" if k in ("contacts", "bounces") else f"{k} {lo * 1e3:.4g}-{hi * 1e3:.4g} ms"
                      for k, (lo, hi) in ranges.items() if k in ("contacts", "bounces", "last_make", "total_bounce_time"))
    lines += ["", f"`--check` at auto: status **{acc['status']}**; over a 1 % change of the contact gap or restitution: "
                  f"{spans or 'nothing moves'}; {min(e['agreeing_contacts'] for e in acc['refinements'] + acc['sensitivity'] if e['status'] == 'ok')} "
                  f"first closures agree in every rerun."]
    print(lines[-1], flush=True)
    return lines + [""] + scan(base, auto_m), dict(ref=ref_m)


SCAN = [("contact gap", "initial.height", f) for f in (0.998, 0.999, 1.001, 1.002)] + [
    ("contact restitution", "contact.restitution", f) for f in (0.99, 1.01)] + [
    ("friction coefficient", "tribology.mu", 1.05), ("modal damping", "bar.modal_damping", 1.05)]


def scan(base, auto_m: dict) -> list[str]:
    """Smaller and other input changes at the auto count: how ill-conditioned the tail is."""
    out = ["Inputs changed by less, and other inputs, at the auto count (mechanics and circuit as "
           "shipped; first make, bounces, last make against the unchanged run):", "",
           "| input changed | first make (ms) | bounces | last make (ms) |", "|---|---|---|---|",
           f"| none | {auto_m['first_make'] * 1e3:.4f} | {auto_m['bounces']} | {auto_m['last_make'] * 1e3:.3f} |"]
    for label, key, factor in SCAN:
        value = _lookup(base, key)
        if value is None:  # a key the scene does not have (no [tribology] in a mechanics-only scene)
            continue
        m = one(base.set(key, value * factor))[0]
        out.append(f"| {label} x {factor:g} | {m['first_make'] * 1e3:.4f} | {m['bounces']} | "
                   f"{m['last_make'] * 1e3:.3f} |")
        print(out[-1], flush=True)
    return out + [""]


def _lookup(scene, key: str) -> float | None:
    node = scene.raw
    for part in key.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return float(node)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-write", action="store_true")
    args = ap.parse_args()
    lines = []
    for name, make in CASES.items():
        part, _ = table(name, make())
        lines += part
    text = "\n".join([f"`.venv/bin/python benchmarks/bench_mode_count_mechanisms.py`; rows in modes per family "
                      f"(axial, bending); mismatch: contact-state mismatch time against the last row.", ""] + lines
                     + [f"Load average at the end of the run: {os.getloadavg()[0]:.1f} (2 cores)."])
    if not args.no_write:
        write_block(DOC, BEGIN, END, text)
        print(f"written to {DOC.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
