"""The contact current's step rules where the current is stationary: a sliding contact on an
AC load, its current passing peaks and zeros, with and without the current's curvature in the
change rule (the rule the coil's psi^2 got, docs/coupling.md "Where the drive is hard to
extrapolate").

    .venv/bin/python benchmarks/bench_current_peaks.py [--no-write]

Scene tests/coupling/scenes/ac_slide.toml (the bar of examples/mu_feedback.toml sliding on
both tips at 10 mm/s, 24 V peak AC through 12.1 ohm, mu(|I|) of the illustrative fit) over
3 ms at 50 Hz (a zero and no peak yet), 1 kHz and 10 kHz, each against its run at
macro_step = max_macro_step = 0.125 us. Rows: the current rules at macro steps 8 .. 1 us (the default is 2 us); the same
with the loop current's curvature passed into ``StepPolicy.plan`` and the growth's steady
test (the prototype, a policy in this process that reads the contact link's tail, as the
coil's rule reads its own); and no growth at all (``growth_cap`` 1: every step in the
closed contact at most one macro step), the most any rule at the stationary points could
gain. Then a load loop ringing after the make while the tip slides (the coupling-order
scene with an underdamped L-C loop) against the monolithic reference, the shipped scenes'
macro steps, and two drops' errors, each with and without the prototype. Writes the block
"bench-current-peaks" of docs/coupling.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path

import numpy as np

from doc_block import command_line, load_line, publish

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "tests" / "coupling" / "scenes" / "ac_slide.toml"
DOC = ROOT / "docs" / "coupling.md"
BEGIN, END = "<!-- bench-current-peaks:begin -->", "<!-- bench-current-peaks:end -->"
FREQUENCIES = (50.0, 1e3, 1e4)  # Hz
STEPS = (8e-6, 4e-6, 2e-6, 1e-6)  # s
REFERENCE_STEP = 0.125e-6  # s
T_END = 3e-3  # s: the slide lasts ~3.5 ms
RINGING = {"circuit.wiring_inductance": 4e-6, "circuit.load_capacitance": 10e-6, "circuit.load_resistance": 0.3,
           "circuit.voltage": 3.0}  # H, F, ohm, V
RINGING_STEPS = (10e-6, 5e-6, 2e-6)  # s
PEAK = 0.95  # a step "at a peak" starts where |I| is above this fraction of its largest
ZERO = 0.2  # ... and "near a zero" where it is below this fraction


def curvature_policy(cs):
    """A StepPolicy for ``cs`` whose change rule, in ``plan`` and in the growth's ``steady``
    test, takes the loop current's curvature from the contact link's last points (the
    prototype, module docstring)."""
    from coupling.core.policy import StepPolicy

    class CurvaturePolicy(StepPolicy):
        def _curvature(self) -> float:
            link = cs.contact
            return (link.tail.derivatives(self.macro_step)[1] or 0.0) if link is not None else 0.0

        def plan(self, *args, curvature=None, **kwargs):
            object.__setattr__(self, "planning", True)  # (plan's own first test: the slope alone)
            try:
                return super().plan(*args, curvature=self._curvature() if curvature is None else curvature, **kwargs)
            finally:
                object.__setattr__(self, "planning", False)

        def steady(self, current, rate, span, curvature=None):
            if curvature is None:  # the master's growth test after a step
                curvature = 0.0 if getattr(self, "planning", False) else self._curvature()
            return super().steady(current, rate, span, curvature)

    return CurvaturePolicy(**{f.name: getattr(cs.policy, f.name) for f in dataclasses.fields(StepPolicy)})


def run_with(scene, rule: str):
    """(CoupledResult, mu_log array, wall s) of ``scene`` under ``rule``: "current",
    "curvature" (the prototype) or "no growth"."""
    from coupling.core.master import CoSimulation

    cs = CoSimulation(scene)
    if rule == "curvature":
        cs.policy = curvature_policy(cs)
    elif rule == "no growth":
        cs.policy = dataclasses.replace(cs.policy, growth_cap=1.0)
    tick = time.perf_counter()
    result = cs.run()
    wall = time.perf_counter() - tick
    return result, np.array(cs.mu_log if cs.contact is not None else []), wall


def errors(result, log, ref) -> dict:
    """Against ``ref``: the largest difference of the bar's axial speed (m/s), the RMS of mu's
    (N^gamma) over the run; the longest macro step, and the longest starting at a peak of |I|."""
    grid = np.linspace(0.0, T_END, 6001)
    h, hr = result.mechanics.history, ref.mechanics.history
    w, wr = result.waveforms, ref.waveforms
    dv = np.max(np.abs(np.interp(grid, h.time, h.vx) - np.interp(grid, hr.time, hr.vx)))
    dmu = np.sqrt(np.mean((np.interp(grid, w.time, w.mu) - np.interp(grid, wr.time, wr.mu)) ** 2))
    span = log[:, 1] - log[:, 0]
    i_start = np.abs(np.interp(log[:, 0], wr.time, wr.load_current))
    peak = i_start >= PEAK * np.max(np.abs(wr.load_current))
    return dict(speed=float(dv), mu=float(dmu), longest=float(span.max()),
                at_peak=float(span[peak].max()) if peak.any() else 0.0, steps=len(log))


def _mu_near_zero(result, ref):
    grid = np.linspace(0.0, T_END, 30001)
    wr, w = ref.waveforms, result.waveforms
    i = np.abs(np.interp(grid, wr.time, wr.load_current))
    d2 = (np.interp(grid, w.time, w.mu) - np.interp(grid, wr.time, wr.mu)) ** 2
    return i < ZERO * i.max(), d2


def zero_share(result, ref) -> float:
    """The share of the squared mu error (against ``ref``) where abs(I) is near its zeros."""
    near, d2 = _mu_near_zero(result, ref)
    return float(d2[near].sum() / d2.sum())


def near_zero(ref) -> float:
    """The share of the time abs(I) is near its zeros."""
    return float(_mu_near_zero(ref, ref)[0].mean())


def ac_rows(base) -> tuple[list[str], dict]:
    lines = ["| AC | rule | macro step | macro steps | longest step | longest at a peak of abs(I) | "
             "speed error (m/s) | RMS mu error | wall |", "|---|---|---|---|---|---|---|---|---|"]
    orders, notes = {}, []
    for f in FREQUENCIES:
        sc = base.set("circuit.params.freq", f)
        ref, _, wref = run_with(sc.set("coupling.macro_step", REFERENCE_STEP)
                                .set("coupling.max_macro_step", REFERENCE_STEP), "current")
        print(f"{f:g} Hz: reference {wref:.1f} s", flush=True)
        for rule, steps in (("current", STEPS), ("curvature", STEPS), ("no growth", (2e-6,))):
            errs = []
            for h in steps:
                result, log, wall = run_with(sc.set("coupling.macro_step", h), rule)
                e = errors(result, log, ref)
                errs.append(e["speed"])
                name = {"current": "the current rules", "curvature": "with the current's curvature",
                        "no growth": "no growth (growth_cap 1)"}[rule]
                # (the first peak is a quarter period in: 50 Hz reaches none before T_END)
                at_peak = f"{e['at_peak'] * 1e6:.2f} us" if f * T_END >= 0.25 else "no peak"
                lines.append(f"| {f:g} Hz | {name} | {h * 1e6:g} us | {e['steps']} | {e['longest'] * 1e6:.2f} us | "
                             f"{at_peak} | {e['speed']:.2e} | {e['mu']:.1e} | {wall * 1e3:.0f} ms |")
                print(lines[-1], flush=True)
            if len(steps) > 1:
                orders[(f, rule)] = float(np.polyfit(np.log(steps), np.log(errs), 1)[0])
        result, _, _ = run_with(sc.set("coupling.macro_step", 2e-6), "current")
        notes.append(f"- {f:g} Hz, the current rules at 2 us: {zero_share(result, ref):.0%} of the squared mu "
                     f"error falls where abs(I) < {ZERO:g} of its largest ({near_zero(ref):.0%} of the time)")
    return lines + [""] + notes, orders


def shipped_rows() -> list[str]:
    """Macro steps of every shipped coupled scene under the current rules and the prototype."""
    import sys

    sys.path.insert(0, str(ROOT / "benchmarks"))
    from scene_fingerprints import scenes

    lines = ["| scene | macro steps, current rules | with the current's curvature | waveforms |", "|---|---|---|---|"]
    changed = total = 0
    for name, sc in scenes():
        if sc.kind != "coupled":
            continue
        a, b = (run_with(sc, rule)[0] for rule in ("current", "curvature"))
        wa, wb = a.waveform_columns, b.waveform_columns
        same = wa.keys() == wb.keys() and all(np.array_equal(wa[k], wb[k], equal_nan=True) for k in wa)
        changed += not same
        total += 1
        lines.append(f"| {name} | {a.stats['macro_steps']} | {b.stats['macro_steps']} | "
                     f"{'identical' if same else 'changed'} |")
        print(lines[-1], flush=True)
    lines += ["", f"- The prototype changes the waveforms of {changed} of these {total} scenes."]
    return lines


def scene_errors(name: str, scene) -> list[str]:
    """The drop scenes' errors against their run at an eighth of the macro steps."""
    h, hmax = scene.coupling.macro_step, scene.coupling.max_macro_step
    ref, _, _ = run_with(scene.set("coupling.macro_step", h / 8).set("coupling.max_macro_step", hmax / 8), "current")
    grid = np.linspace(0.0, scene.t_end, 5001)
    hr, wr = ref.mechanics.history, ref.waveforms
    out = []
    for rule in ("current", "curvature"):
        result, log, _ = run_with(scene, rule)
        hh, w = result.mechanics.history, result.waveforms
        dv = np.max(np.abs(np.interp(grid, hh.time, hh.vz) - np.interp(grid, hr.time, hr.vz)))
        di = np.sqrt(np.mean((np.interp(grid, w.time, w.load_current) - np.interp(grid, wr.time, wr.load_current)) ** 2))
        dmu = np.sqrt(np.mean((np.interp(grid, w.time, w.mu) - np.interp(grid, wr.time, wr.mu)) ** 2))
        label = "the current rules" if rule == "current" else "with the current's curvature"
        out.append(f"| {name} | {label} | {len(log)} | {dv:.2e} | {di:.2e} | {dmu:.2e} |")
        print(out[-1], flush=True)
    return out


def ringing_rows() -> list[str]:
    """The make's ringing: tests/coupling/scenes/impact_inrush.toml with an underdamped load
    loop (RINGING), against the monolithic reference (coupling.core.monolithic)."""
    from coupling import load_scene
    from coupling.core.monolithic import run_monolithic

    base = load_scene(ROOT / "tests" / "coupling" / "scenes" / "impact_inrush.toml")
    for key, value in RINGING.items():
        base = base.set(key, value)
    tick = time.perf_counter()
    ref = run_monolithic(base)
    wall = time.perf_counter() - tick
    a, b = ref.closed_intervals[0]
    hr, wr = ref.mechanics.history, ref.waveforms
    i_peak = float(np.max(np.abs(wr.load_current)))
    zeta = RINGING["circuit.load_resistance"] / 2 * np.sqrt(RINGING["circuit.load_capacitance"]
                                                           / RINGING["circuit.wiring_inductance"])
    lines = [f"The make's ringing: tests/coupling/scenes/impact_inrush.toml with "
             + ", ".join(f"`{k}` = {v:g}" for k, v in RINGING.items())
             + f" (a load loop ringing at {1e-3 / (2 * np.pi * np.sqrt(RINGING['circuit.wiring_inductance'] * RINGING['circuit.load_capacitance'])):.0f} kHz, "
             f"damping ratio {zeta:.2f} from the load resistor, {i_peak:.2f} A at its first peak) while the tip slides in its contact from {a * 1e6:.1f} to "
             f"{b * 1e6:.1f} us, against the monolithic reference ({wall:.0f} s): the largest difference of the bar's "
             "speed vx and the RMS difference of the load current over the run (as in section 3).", "",
             "| rule | macro step | macro steps | longest step in the contact | speed error (m/s) | RMS current error (A) |",
             "|---|---|---|---|---|---|"]
    grid = np.linspace(0.01, 1.0, 600) * base.t_end
    for rule in ("current", "curvature"):
        for h in RINGING_STEPS:
            result, log, _ = run_with(base.set("coupling.macro_step", h), rule)
            hh, w = result.mechanics.history, result.waveforms
            dv = np.max(np.abs(np.interp(grid, hh.time, hh.vx) - np.interp(grid, hr.time, hr.vx)))
            di = np.sqrt(np.mean((np.interp(grid, w.time, w.load_current) - np.interp(grid, wr.time, wr.load_current)) ** 2))
            inside = (log[:, 0] >= a) & (log[:, 1] <= b)
            label = "the current rules" if rule == "current" else "with the current's curvature"
            lines.append(f"| {label} | {h * 1e6:g} us | {len(log)} | {(log[inside, 1] - log[inside, 0]).max() * 1e6:.2f} us | "
                         f"{dv:.2e} | {di:.2e} |")
            print(lines[-1], flush=True)
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-write", action="store_true", help="print only; leave docs/coupling.md alone")
    args = ap.parse_args()
    from coupling import builtin_scene, load_scene

    base = load_scene(SCENE).set("solver.t_end", T_END)
    lines = [f"`{command_line()}`: {SCENE.relative_to(ROOT)} over {T_END * 1e3:g} ms (sliding throughout), "
             f"against its run at {REFERENCE_STEP * 1e6:g} us macro steps; speed error: the largest difference "
             "of the bar's axial speed (v0 = 1e-2 m/s); a step at a peak starts where abs(I) is above "
             f"{PEAK:g} of its largest.", ""]
    ac, orders = ac_rows(base)
    lines += ac + [""]
    lines += [f"- Observed order ({f:g} Hz, {'the current rules' if rule == 'current' else 'with the curvature'}, "
              f"speed error, least squares over {STEPS[0] * 1e6:g} .. {STEPS[-1] * 1e6:g} us): **{p:.2f}**"
              for (f, rule), p in orders.items()]
    lines += [""] + ringing_rows()
    lines += ["", "The shipped scenes' macro steps:", ""] + shipped_rows()
    lines += ["", "Two drops against their runs at an eighth of every macro step (vz: the bar's vertical speed, m/s; "
              "RMS of the load current, A, and of mu over the run):", "",
              "| scene | rule | macro steps | largest vz error | RMS current error | RMS mu error |",
              "|---|---|---|---|---|---|"]
    lines += scene_errors("builtin free_drop", builtin_scene("free_drop"))
    lines += scene_errors("examples/resistive_bounce.toml", load_scene(ROOT / "examples" / "resistive_bounce.toml"))
    lines.append(load_line())
    publish(DOC, BEGIN, END, lines, write=not args.no_write)


if __name__ == "__main__":
    main()
