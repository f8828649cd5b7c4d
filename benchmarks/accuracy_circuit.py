"""Circuit: error of the bounce waveform against ngspice RELTOL and the macro step,
including the closed-contact voltage, on the default scene (arc) released close to the block.

    .venv/bin/python benchmarks/accuracy_circuit.py      (part 4 of `make accuracy`)
"""

from __future__ import annotations

import sys
import time

from accuracy_common import Section, coupled_errors, coupled_metrics, dump, fmt, plt, short_default_scene, us

from coupling import run

RELTOLS = (1e-3, 1e-4, 1e-5, 1e-6)
STEPS = (2e-5, 5e-6)
REFERENCE = dict(reltol=1e-7, macro_step=1.25e-6)


def main() -> None:
    sec = Section("circuit", "4. Circuit: bounce waveform against RELTOL and macro step",
                  ".venv/bin/python benchmarks/accuracy_circuit.py")
    base = short_default_scene()
    run(base)  # warm-up
    tick = time.perf_counter()
    ref_res = run(base.update({"circuit.reltol": REFERENCE["reltol"], "coupling.macro_step": REFERENCE["macro_step"]}))
    ref = coupled_metrics(ref_res)
    sec.add(f"The free-drop scene (`builtin_scene('free_drop')`: 24 V, 12 ohm, 1 uH wiring, arc; 3 modes), 20 um above the block, 2 ms, "
            f"against RELTOL {REFERENCE['reltol']:g} with a {REFERENCE['macro_step'] * 1e6:g} us macro step "
            f"({time.perf_counter() - tick:.1f} s; {ref['bounces']} bounces, peak contact voltage "
            f"{ref['peak_contact_voltage']:.4g} V, closed-contact voltage {ref['closed_voltage'] * 1e3:.4g} mV "
            f"(time average of |v| while closed, 2 us clear of makes and breaks), arc energy {ref['arc_energy'] * 1e3:.4g} mJ). Waveform errors: "
            "RMS difference of the contact voltage and of the load current over the reference's bounce window "
            "(first make to last break); the closed-contact voltage error is relative.", "")
    rows, data = [], []
    for h in STEPS:
        for reltol in RELTOLS:
            tick = time.perf_counter()
            r = run(base.update({"circuit.reltol": reltol, "coupling.macro_step": h}))
            wall = time.perf_counter() - tick
            e = coupled_errors(coupled_metrics(r), ref)
            data.append(dict(h=h, reltol=reltol, wall=wall, **e))
            rows.append([f"{h * 1e6:g}", f"{reltol:g}", f"{wall * 1e3:.0f}", f"{e['rms_voltage']:.3g}",
                         f"{e['rms_current']:.3g}", fmt(e["closed_voltage"], 2), fmt(e["peak_voltage"], 2),
                         fmt(e["arc_energy"], 2), us(e["mismatch"]), f"{e['bounces']:+d}"])
            print(f"circuit h={h:g} reltol={reltol:g}: {wall:.2f} s", file=sys.stderr, flush=True)
    sec.table(["macro step (us)", "RELTOL", "wall (ms)", "RMS contact voltage err (V)", "RMS load current err (A)",
               "closed-contact voltage rel err", "peak contact voltage rel err", "arc energy rel err",
               "mismatch (us)", "d bounces"], rows)
    p = plt()
    fig, axes = p.subplots(1, 2, figsize=(12, 4.5))
    for h in STEPS:
        pts = [d for d in data if d["h"] == h]
        rt = [d["reltol"] for d in pts]
        axes[0].loglog(rt, [max(d["rms_voltage"], 1e-9) for d in pts], "o-", label=f"RMS contact voltage (V), H = {h * 1e6:g} us")
        axes[0].loglog(rt, [max(d["closed_voltage"] or 0, 1e-9) for d in pts], "s--",
                       label=f"closed-contact voltage (rel), H = {h * 1e6:g} us")
        axes[0].loglog(rt, [max(d["arc_energy"] or 0, 1e-9) for d in pts], "^:", label=f"arc energy (rel), H = {h * 1e6:g} us")
        axes[1].loglog([d["wall"] for d in pts], [max(d["rms_voltage"], 1e-9) for d in pts], "o-",
                       label=f"RMS contact voltage (V), H = {h * 1e6:g} us")
    axes[0].set_xlabel("ngspice RELTOL")
    axes[1].set_xlabel("wall time (s)")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.suptitle("Bounce waveform error against RELTOL and macro step (reference RELTOL "
                 f"{REFERENCE['reltol']:g}, H = {REFERENCE['macro_step'] * 1e6:g} us)")
    sec.figure(fig, "circuit_error", "Bounce waveform error against RELTOL, macro step and run time")
    dump("circuit", data)
    sec.write()


if __name__ == "__main__":
    main()
