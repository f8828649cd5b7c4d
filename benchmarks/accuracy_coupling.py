"""Coupling error against the macro step and against run time, for each scheme:
(a) the co-simulation against the monolithic reference (benchmarks/bench_coupling_order.py's
study, here with the bounce metrics), (b) the arc: the default scene against itself at a
4x finer macro step (the monolithic reference has no arc).

    .venv/bin/python benchmarks/accuracy_coupling.py      (part 3 of `make accuracy`)
"""

from __future__ import annotations

import sys
import time

from accuracy_common import (
    Section, coupled_errors, coupled_metrics, dump, fmt, plt, short_default_scene, us,
)
from bench_coupling_order import SCENE, reference, study

from coupling import load_scene, run

STEPS = (4e-5, 2e-5, 1e-5, 5e-6, 2.5e-6, 1.25e-6)
ARC_STEPS = (4e-5, 2e-5, 1e-5, 5e-6, 2.5e-6)
ARC_REFERENCE_STEP = 6.25e-7


def main() -> None:
    sec = Section("coupling", "3. Coupling: error against macro step and run time, per scheme",
                  ".venv/bin/python benchmarks/accuracy_coupling.py")
    data: dict = {"monolithic": [], "arc": []}
    p = plt()
    fig, axes = p.subplots(2, 2, figsize=(12, 8.5))

    # (a) against the monolithic reference
    base = load_scene(SCENE)
    ref_res, ref_wall = reference(base)
    ref = coupled_metrics(ref_res)
    sec.add("**(a) Against the monolithic reference** (`coupling/core/monolithic.py`: mechanics and the series "
            "loop in one Radau solve, no coupling error) on tests/coupling/scenes/impact_inrush.toml "
            f"(capacitive inrush while the tip slides, mu doubling with the current; rtol "
            f"{base.mech.solver.rtol:g}, RELTOL {base.circuit.options.reltol:g}). Reference: "
            f"{ref['contacts']} contact(s), {ref_wall:.1f} s. Speed error: largest difference of the centre-of-mass "
            "tangential speed (m/s); current: RMS load-current difference (A); bounce metrics as in `run --check`.", "")
    rows = []
    for row in study(base, ref_res, steps=STEPS):
        e = coupled_errors(coupled_metrics(row["result"]), ref)
        rows.append([row["scheme"], f"{row['h'] * 1e6:g}", f"{row['wall'] * 1e3:.0f}",
                     f"{row['speed_error']:.2e}", f"{row['current_error']:.2e}", us(e["mismatch"]),
                     f"{e['contacts']:+d}", us(e["first_make"]), us(e["last_make"]), fmt(e["peak_voltage"], 2)])
        data["monolithic"].append(dict(scheme=row["scheme"], h=row["h"], wall=row["wall"],
                                       speed=row["speed_error"], current=row["current_error"], **e))
        print(f"monolithic {row['scheme']} {row['h']:g}: {row['wall']:.2f} s", file=sys.stderr, flush=True)
    sec.table(["scheme", "macro step (us)", "wall (ms)", "speed error (m/s)", "RMS current error (A)",
               "mismatch (us)", "d contacts", "first make err (us)", "last make err (us)",
               "peak contact voltage rel err"], rows)
    for scheme in ("mechanics_first", "jacobi"):
        pts = [d for d in data["monolithic"] if d["scheme"] == scheme]
        axes[0][0].loglog([d["h"] for d in pts], [d["speed"] for d in pts], "o-", label=f"{scheme}: speed (m/s)")
        axes[0][0].loglog([d["h"] for d in pts], [d["current"] for d in pts], "s--", label=f"{scheme}: RMS current (A)")
        axes[0][1].loglog([d["wall"] for d in pts], [d["speed"] for d in pts], "o-", label=f"{scheme}: speed (m/s)")
        axes[0][1].loglog([d["wall"] for d in pts], [d["current"] for d in pts], "s--", label=f"{scheme}: RMS current (A)")
    axes[0][0].set_xlabel("macro step (s)")
    axes[0][1].set_xlabel("wall time (s)")
    axes[0][0].set_title("(a) against the monolithic reference")
    axes[0][1].set_title("(a) error against run time")

    # (b) the arc: against the same scene at a fine macro step
    arc_base = short_default_scene()
    run(arc_base)  # warm-up
    refs = {}
    for scheme in ("mechanics_first", "jacobi"):
        tick = time.perf_counter()
        refs[scheme] = coupled_metrics(run(arc_base.update({"coupling.scheme": scheme,
                                                            "coupling.macro_step": ARC_REFERENCE_STEP})))
        print(f"arc reference {scheme}: {time.perf_counter() - tick:.1f} s", file=sys.stderr, flush=True)
    aref = refs["mechanics_first"]
    cross = coupled_errors(refs["jacobi"], aref)
    sec.add("", f"**(b) The arc**: the built-in free-drop scene (24 V, 12 ohm, arc, 3 modes), released 20 um above the "
            f"block, 2 ms, against itself with mechanics_first at a macro step of {ARC_REFERENCE_STEP * 1e6:g} us "
            f"({aref['contacts']} contacts, {aref['bounces']} bounces, arc energy {aref['arc_energy'] * 1e3:.4g} mJ, "
            f"peak contact voltage {aref['peak_contact_voltage']:.4g} V). Jacobi at the same step differs from it by: "
            f"mismatch {cross['mismatch'] * 1e6:.3g} us, arc energy {fmt(cross['arc_energy'], 2)} (relative), "
            f"RMS contact voltage {cross['rms_voltage']:.3g} V.", "")
    rows = []
    for scheme in ("mechanics_first", "jacobi"):
        pts = []
        for h in ARC_STEPS:
            tick = time.perf_counter()
            r = run(arc_base.update({"coupling.scheme": scheme, "coupling.macro_step": h}))
            wall = time.perf_counter() - tick
            e = coupled_errors(coupled_metrics(r), aref)
            pts.append(dict(h=h, wall=wall, **e))
            rows.append([scheme, f"{h * 1e6:g}", f"{wall * 1e3:.0f}", us(e["mismatch"]), f"{e['bounces']:+d}",
                         us(e["last_make"]), fmt(e["arc_energy"], 2), fmt(e["peak_voltage"], 2),
                         f"{e['rms_voltage']:.3g}"])
            print(f"arc {scheme} {h:g}: {wall:.2f} s", file=sys.stderr, flush=True)
        data["arc"].append(dict(scheme=scheme, points=pts))
        axes[1][0].loglog([d["h"] for d in pts], [max(d["arc_energy"] or 0, 1e-8) for d in pts], "o-",
                          label=f"{scheme}: arc energy (rel)")
        axes[1][0].loglog([d["h"] for d in pts], [max(d["mismatch"], 1e-10) / max(aref["contact_time"], 1e-12)
                                                   for d in pts], "s--", label=f"{scheme}: mismatch / contact time")
        axes[1][1].loglog([d["wall"] for d in pts], [max(d["arc_energy"] or 0, 1e-8) for d in pts], "o-",
                          label=f"{scheme}: arc energy (rel)")
    sec.table(["scheme", "macro step (us)", "wall (ms)", "mismatch (us)", "d bounces", "last make err (us)",
               "arc energy rel err", "peak contact voltage rel err", "RMS contact voltage err (V)"], rows)
    axes[1][0].set_xlabel("macro step (s)")
    axes[1][1].set_xlabel("wall time (s)")
    axes[1][0].set_title(f"(b) default scene with arc, against {ARC_REFERENCE_STEP * 1e6:g} us")
    axes[1][1].set_title("(b) error against run time")
    for ax in axes.flat:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Coupling error per scheme")
    sec.figure(fig, "coupling_error", "Coupling error against macro step and run time")
    dump("coupling", data)
    sec.write()


if __name__ == "__main__":
    main()
