"""Benchmark: is modes = "auto" converged? Auto against 1.5x and 2x its count per scene.

Run: .venv/bin/python benchmarks/bench_mode_count.py [--safety 1 2 3] [--no-write]

For each safety factor s (f_cut = s / t_c, mech/mode_count.py) and each scene, runs the
auto count N (per family), round(1.5 N) and 2 N (capped at 40) and compares the first
two with the 2 N run on: contact-state mismatch time (total time over the run where
"tip i touches" differs, summed over the tips), number of contacts, first contact start
and last contact end, peak force, first contact's kinematic restitution. Scenes: steel
bars 6 mm (slender, 3 mm tips) and 12 mm (stocky, 6 mm tips), 0.3 m, released 0.1 mm
above the block at 1 m/s down; vertical (90 deg), tilted (30 deg) and grazing (axis
10 deg to the surface, 80 deg from the vertical); elastic without friction, and damped
(restitution 0.8) with friction (mu = 0.3 N^0.7, gamma = 0.7); 1.2 ms each. Then, on the
scenes where the floor raises a family, auto and the cutoff's own count against a finer one.
Writes the tables between the mode-count markers of docs/accuracy-modes.md.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from doc_block import write_block

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mech import Bar, Contact, Friction, ImpactSolver, Initial, MechScene, SolverOptions  # noqa: E402
from mech.mode_count import CAP, SAFETY, count_below  # noqa: E402
from mech.model import family_frequencies, resolve_auto_modes  # noqa: E402

DOC = ROOT / "docs" / "accuracy-modes.md"
BEGIN, END = "<!-- mode-count:begin -->", "<!-- mode-count:end -->"
T_END = 1.2e-3
BARS = {"slender 6 mm": dict(diameter=0.006, tip_radius=0.003), "stocky 12 mm": dict(diameter=0.012, tip_radius=0.006)}
ANGLES = {"vertical": 90.0, "tilted 30": 30.0, "grazing 80": 10.0}
CONTACTS = {
    "elastic": (dict(damping=0.0, restitution=None), dict(mu=0.0)),
    "damped+friction": (dict(restitution=0.8), dict(mu=0.3, gamma=0.7)),
}
# tolerances of "agrees" (issue 9): a contact-pattern change shows in several metrics at once
TOL = dict(mismatch_abs=2e-6, mismatch_rel=0.05, time_abs=1e-6, time_rel=0.03, force_rel=0.05, restitution=0.05)


def scene(bar: str, angle: str, contact: str, modes=("auto", "auto"), t_end: float = T_END) -> MechScene:
    con, fr = CONTACTS[contact]
    return MechScene(
        bar=Bar(axial_modes=modes[0], bending_modes=modes[1], **BARS[bar]),
        contact=Contact(**con), friction=Friction(**fr),
        initial=Initial(height=1e-4, angle_deg=ANGLES[angle], velocity=(0.0, 0.0, -1.0)),
        solver=SolverOptions(t_end=t_end),
    )


def intervals(res) -> dict:
    c = res.contacts
    return {i: [(float(a), float(b)) for a, b in zip(c.t_start[c.tip == i], c.t_end[c.tip == i])] for i in (0, 1)}


def measure_of(ivs) -> float:
    return sum(b - a for a, b in ivs)


def mismatch_time(a: dict, b: dict) -> float:
    """Total time where 'tip i touches' differs between the two runs, summed over tips."""
    total = 0.0
    for i in (0, 1):
        cuts = sorted({x for iv in a[i] + b[i] for x in iv})
        for lo, hi in zip(cuts[:-1], cuts[1:]):
            mid = 0.5 * (lo + hi)
            ina = any(s <= mid <= e for s, e in a[i])
            inb = any(s <= mid <= e for s, e in b[i])
            if ina != inb:
                total += hi - lo
    return total


def metrics(res) -> dict:
    c = res.contacts
    ivs = intervals(res)
    return dict(
        intervals=ivs, contacts=len(c), contact_time=sum(measure_of(v) for v in ivs.values()),
        first=float(c.t_start.min()) if len(c) else np.nan, last=float(c.t_end.max()) if len(c) else np.nan,
        peak=float(c.peak_force.max()) if len(c) else np.nan,
        restitution=float(c.kinematic_restitution.iloc[0]) if len(c) else np.nan,
    )


def compare(m: dict, ref: dict) -> dict:
    d = dict(
        mismatch=mismatch_time(m["intervals"], ref["intervals"]),
        d_contacts=m["contacts"] - ref["contacts"],
        d_first=abs(m["first"] - ref["first"]), d_last=abs(m["last"] - ref["last"]),
        d_peak=abs(m["peak"] / ref["peak"] - 1.0), d_rest=abs(m["restitution"] - ref["restitution"]),
    )
    t_tol = TOL["time_abs"] + TOL["time_rel"] * ref["contact_time"]
    d["agrees"] = bool(
        d["mismatch"] <= TOL["mismatch_abs"] + TOL["mismatch_rel"] * ref["contact_time"]
        and d["d_contacts"] == 0 and d["d_first"] <= t_tol and d["d_last"] <= t_tol
        and d["d_peak"] <= TOL["force_rel"] and not (d["d_rest"] > TOL["restitution"]))
    return d


_cache: dict = {}


def run(bar, angle, contact, modes) -> tuple[dict, float]:
    key = (bar, angle, contact, modes)
    if key not in _cache:
        t0 = time.perf_counter()
        res = ImpactSolver(scene(bar, angle, contact, modes)).run()
        _cache[key] = (metrics(res), time.perf_counter() - t0)
    return _cache[key]


def auto_count(bar, angle, contact, safety) -> tuple[int, int]:
    s, _ = resolve_auto_modes(scene(bar, angle, contact), safety=safety)
    return s.bar.axial_modes, s.bar.bending_modes


def scaled(n: tuple[int, int], f: float) -> tuple[int, int]:
    return tuple(min(CAP, int(round(f * k))) for k in n)


def floor_table() -> list[str]:
    """The floor on a family the impact loads: each scene where auto (s = SAFETY) raised a
    family to the floor, at auto, at the cutoff's own count (no floor) and at a finer count
    (10 axial, twice the bending), the first two against the third, with the mechanics'
    accepted steps (the explicit step is held near the stability bound of the highest mode)."""
    lines = ["### The floor, on the scenes where it raises a family (s = 3)", "",
             "| scene | modes (axial, bending) | vs finer: mismatch (us) | contacts | d last (us) | d peak | "
             "first restitution (finer) | agrees | mechanics steps |", "|---|---|---|---|---|---|---|---|---|"]
    for bar in BARS:
        for angle in ANGLES:
            for contact in CONTACTS:
                _, ch = resolve_auto_modes(scene(bar, angle, contact), safety=SAFETY)
                if not ch.floored:
                    continue
                axial, bend = family_frequencies(scene(bar, angle, contact).bar, CAP)
                cut = (count_below(axial, ch.cutoff), count_below(bend, ch.cutoff))
                fine = (10, min(CAP, 2 * ch.bending))
                mf = run_steps(bar, angle, contact, fine)
                for label, n in (("auto", (ch.axial, ch.bending)), ("cutoff only", cut), ("finer", fine)):
                    m = run_steps(bar, angle, contact, n)
                    d = compare(m, mf)
                    lines.append(
                        f"| {bar}, {angle}, {contact} | {label} ({n[0]}, {n[1]}) | {d['mismatch'] * 1e6:.1f} | "
                        f"{m['contacts']} / {mf['contacts']} | {d['d_last'] * 1e6:.2f} | {d['d_peak']:.2%} | "
                        f"{m['restitution']:.3f} ({mf['restitution']:.3f}) | {'yes' if d['agrees'] else 'NO'} | "
                        f"{m['steps']} |")
                    print(lines[-1], flush=True)
    return lines + [""]


def run_steps(bar, angle, contact, modes) -> dict:
    res = ImpactSolver(scene(bar, angle, contact, modes)).run()
    return dict(metrics(res), steps=res.stats["steps"])


def main() -> None:
    import mech.mode_count as mc

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--safety", type=float, nargs="*", default=[1.0, 2.0, 3.0, 4.0])
    ap.add_argument("--no-write", action="store_true")
    args = ap.parse_args()
    lines = []
    summary = []
    for s in args.safety:
        lines += [f"### safety factor s = {s:g} (f_cut = {s:g} / t_c)", "",
                  "| scene | auto (axial, bending) | vs 2x: mismatch (us) | contacts | d first / last (us) | d peak | d e | 1.5x vs 2x: mismatch (us) | agrees (auto, 1.5x) | wall auto / 2x (s) |",
                  "|---|---|---|---|---|---|---|---|---|---|"]
        n_ok = 0
        n_all = 0
        for bar in BARS:
            for angle in ANGLES:
                for contact in CONTACTS:
                    n = auto_count(bar, angle, contact, s)
                    m1, w1 = run(bar, angle, contact, n)
                    m15, _ = run(bar, angle, contact, scaled(n, 1.5))
                    m2, w2 = run(bar, angle, contact, scaled(n, 2.0))
                    d1 = compare(m1, m2)
                    d15 = compare(m15, m2)
                    n_all += 1
                    n_ok += d1["agrees"]
                    lines.append(
                        f"| {bar}, {angle}, {contact} | {n[0]}, {n[1]} | {d1['mismatch'] * 1e6:.1f} | "
                        f"{m1['contacts']} / {m2['contacts']} | {d1['d_first'] * 1e6:.2f} / {d1['d_last'] * 1e6:.2f} | "
                        f"{d1['d_peak']:.2%} | {d1['d_rest']:.3f} | {d15['mismatch'] * 1e6:.1f} | "
                        f"{'yes' if d1['agrees'] else 'NO'}, {'yes' if d15['agrees'] else 'NO'} | {w1:.2f} / {w2:.2f} |")
                    print(lines[-1], flush=True)
        summary.append(f"- s = {s:g}: auto agrees with 2x its count on {n_ok} of {n_all} scenes.")
        lines.append("")
    text = "\n".join(
        [f"Tolerances of 'agrees': mismatch <= {TOL['mismatch_abs'] * 1e6:g} us + {TOL['mismatch_rel']:.0%} of the "
         f"reference's total contact time, same number of contacts, first/last within {TOL['time_abs'] * 1e6:g} us "
         f"+ {TOL['time_rel']:.0%} of that contact time, "
         f"peak force within {TOL['force_rel']:.0%}, first restitution within {TOL['restitution']}. "
         f"Shipped: s = {mc.SAFETY:g}, floor {mc.FLOOR}, cap {mc.CAP}.", ""]
        + summary + [""] + lines + floor_table()
        + [f"Load average at the end of the run: {os.getloadavg()[0]:.1f} (2 cores)."])
    print("\n".join(summary))
    if not args.no_write:
        write_block(DOC, BEGIN, END, text)
        print(f"written to {DOC.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
