"""Modes: convergence of the contact metrics in the number of modes per family (1 to 40)
for a slender and a stocky bar, against 40 modes per family.

    .venv/bin/python benchmarks/accuracy_modes.py      (part 2 of `make accuracy`)
"""

from __future__ import annotations

import math
import sys

from accuracy_common import Section, dump, errors_against, fmt, mech_metrics, mech_scene, plt, run_mech, us

BARS = {
    "slender (6 mm x 0.3 m, 3 mm tips)": {"length": 0.3, "diameter": 0.006, "tip_radius": 0.003},
    "paper's link (10 mm x 0.3 m, 5 mm tips)": {"length": 0.3, "diameter": 0.01, "tip_radius": 0.005},
    "stocky (20 mm x 0.1 m, 10 mm tips)": {"length": 0.1, "diameter": 0.02, "tip_radius": 0.01},
}
MODES = (1, 2, 3, 5, 7, 10, 14, 20, 28, 40)
REFERENCE = 40


def scene(bar: dict, modes: int):
    return mech_scene({"bar": dict(bar, modes=modes),
                       "initial": {"height": 1e-5, "angle_deg": 30.0, "velocity": [0.0, 0.0, -1.0]},
                       "contact": {"restitution": 0.8}, "solver": {"rtol": 1e-8, "t_end": 7e-4}})


def main() -> None:
    sec = Section("modes", "2. Modes: convergence in the number of modes per family",
                  ".venv/bin/python benchmarks/accuracy_modes.py")
    sec.add("Steel bars (E = 210 GPa) released 10 um above a steel block at 30 deg, falling at 1 m/s, "
            "restitution 0.8, no friction, 0.7 ms (several bending periods of the slender bar), rtol 1e-8, "
            f"n modes per family (axial and both bending planes), compared with n = {REFERENCE}. "
            "First contact: duration, energetic restitution and peak force of the first contact interval; "
            "sequence: contact and bounce counts and the contact-state mismatch time (both tips).", "")
    rows, data = [], {}
    p = plt()
    fig, axes = p.subplots(1, len(BARS), figsize=(17, 4.5))
    for b, (label, bar) in enumerate(BARS.items()):
        ref_res, ref_wall = run_mech(scene(bar, REFERENCE))
        ref = mech_metrics(ref_res)
        print(f"{label}: reference {ref_wall:.1f} s", file=sys.stderr, flush=True)
        series = []
        for n in MODES:
            if n == REFERENCE:
                res, wall, m = ref_res, ref_wall, ref
            else:
                try:
                    res, wall = run_mech(scene(bar, n))
                    m = mech_metrics(res)
                except Exception as err:  # noqa: BLE001
                    rows.append([label, n, f"failed: {type(err).__name__}: {err}"] + [""] * 8)
                    continue
            e = errors_against(m, ref)
            rel = lambda k: abs(m[k] - ref[k]) / abs(ref[k]) if (m[k] is not None and ref[k]) else math.nan  # noqa: E731
            series.append(dict(n=n, wall=wall, mismatch=e["mismatch"], duration=rel("first_duration"),
                               restitution=abs(m["first_restitution"] - ref["first_restitution"]),
                               first_peak=rel("first_peak_force"), contacts=m["contacts"], bounces=m["bounces"]))
            rows.append([label, n, f"{wall:.2f}", m["contacts"], m["bounces"], us(e["mismatch"]),
                         fmt(m["first_duration"] * 1e6, 4), fmt(m["first_restitution"], 4),
                         fmt(m["first_peak_force"], 4), fmt(m["peak_force"], 4), fmt(m["energy_residual"], 2)])
            print(f"{label} n={n}: {wall:.2f} s", file=sys.stderr, flush=True)
        data[label] = dict(reference={k: v for k, v in ref.items() if k != "tips"}, series=series)
        ax = axes[b]
        ns = [s["n"] for s in series if s["n"] != REFERENCE]
        for key, name in (("mismatch", "contact-state mismatch / contact time"),
                          ("duration", "first contact duration, rel. err"),
                          ("restitution", "first restitution, abs. err"),
                          ("first_peak", "first peak force, rel. err")):
            ys = [(s[key] / ref["contact_time"] if key == "mismatch" else s[key]) for s in series if s["n"] != REFERENCE]
            ax.semilogy(ns, [max(y, 1e-8) for y in ys], "o-", label=name)
        ax.set_xlabel("modes per family")
        ax.set_title(label)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"Convergence in the number of modes against {REFERENCE} per family (errors of 0 drawn at 1e-8)")
    sec.figure(fig, "modes_convergence", "Metric errors against the number of modes per family")
    sec.table(["bar", "modes", "wall (s)", "contacts", "bounces", "mismatch (us)", "first duration (us)",
               "first restitution", "first peak force (N)", "peak force (N)", "energy residual"], rows)
    sec.add(*observations(data))
    dump("modes", data)
    sec.write()


def observations(data) -> list[str]:
    out = ["What \"no change with five or seven modes\" holds for, read off the table "
           "(tolerances of `run --check`: 2 % for a duration or force, counts equal, mismatch <= 2 % of the "
           "contact time; 0.01 for a restitution):", ""]
    for label, d in data.items():
        s = {x["n"]: x for x in d["series"]}
        ct = d["reference"]["contact_time"]

        def first_from(pred):
            ok = [n for n in sorted(s) if all(pred(s[k]) for k in s if k >= n)]
            return ok[0] if ok else None

        first_contact = first_from(lambda x: x["duration"] <= 0.02 and x["first_peak"] <= 0.02
                                   and x["restitution"] <= 0.01)
        sequence = first_from(lambda x: x["contacts"] == s[REFERENCE]["contacts"]
                              and x["bounces"] == s[REFERENCE]["bounces"] and x["mismatch"] <= 0.02 * ct)
        out.append(f"- {label}: the first contact (duration, restitution, peak force) is converged from "
                   f"{first_contact} modes per family on; the contact sequence from {sequence} on"
                   + ("" if sequence is None or sequence <= 7 else
                      " -- so five or seven modes do NOT give the bounce pattern of this bar") + ".")
    out.append("")
    return out


if __name__ == "__main__":
    main()
