"""Relay coil (inductive load) with the arc model: the opening spike is set by the arc, not by numerics.

examples/relay_coil_arc.toml: a 24 ohm, 2 mH coil on 24 V, switched by the bouncing bar.
Every break carries more than the arc's minimum current I_min, so an arc forms and holds
the gap near U_min + E_col d while the coil current flows through it. After the last
bounce the bar flies off, the gap lengthens, the arc voltage rises and the arc goes out
when the current falls to I_min: the coil current is chopped at I_min and rings into the
gap capacitance, so the opening spike is

    V_peak ~ E + I_min sqrt(L / C)       (1.8 kV for 0.4 A, 2 mH, 100 pF)

set by the arc's I_min and the circuit's L and C. Variants of the same scene:

- flyback diode across the coil: the chopped current freewheels, the contact sees about
  E + one diode drop (+ the wiring inductance ringing into C);
- RC snubber across the contact: the chopped current goes into 100 nF, a few tens of volts;
- no arc model: nothing holds the gap at the breaks, the coil's full current rings into
  100 pF at a micrometre gap (kV across a gap that would really break down);
- no arc model and no capacitance across the contact: nothing physical limits the spike;
  switchsim refuses the circuit before running (ngspice would give up, "timestep too
  small": any value would be numerics);
- (full mode) the arc variant with ngspice RELTOL 1e-6 instead of 1e-4, a 0.2 us step
  bound and half the macro step: the spike moves by less than 1 %, it is physics;
- (full mode) the flyback variant at RELTOL 1e-6: what is left with the coil clamped is
  the 1 uH wiring ringing into 100 pF at 16 MHz, the same as at 1e-4 (64.8 against 64.4
  V; it was 38 V at 1e-4 before the arc model's first step after an extinction was
  shortened: circuit/arc.py).

    .venv/bin/python examples/relay_coil_arc.py [--fast] [--out DIR]
"""

from __future__ import annotations

import json
import math
import re
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from coupling import CoupledRunError, load_scene, run  # noqa: E402

import example_cli  # noqa: E402  (examples/example_cli.py, next to this script)

NAME = "relay_coil_arc"
SCENE = Path(__file__).with_name(f"{NAME}.toml")
DIODE_DROP_MAX = 1.5  # V: generous bound on the flyback diode's forward drop at <= 1 A


def variants(fast: bool) -> dict:
    """name -> scene. fast: 5.2 ms (past the final extinction near 3.9 ms), looser
    mechanics tolerance, no extra numerics variants."""
    base = load_scene(SCENE)
    if fast:
        base = base.set("solver.t_end", 5.2e-3).set("solver.rtol", 1e-5)
    quiet = base.set("output.plots", False).set("output.csv", False)
    out = {
        "arc": base,
        "arc + flyback diode": quiet.set("circuit.flyback", True),
        "arc + RC snubber": quiet.set("circuit.snubber", {"resistance": 100.0, "capacitance": 100e-9}),
        "no arc model": quiet.set("circuit.arc", False),
    }
    try:
        out["no arc model, no gap capacitance"] = quiet.set("circuit.arc", False).set("circuit.contact_capacitance", 0.0)
    except ValueError as err:  # refused: nothing physical would bound the opening dv/dt
        out["no arc model, no gap capacitance"] = err
    if not fast:
        out["arc, finer numerics"] = (quiet.set("circuit.reltol", 1e-6).set("circuit.max_step", 2e-7)
                                      .set("coupling.macro_step", 1e-6))
        # the flyback leaves only the wiring's 16 MHz ring, which gear at RELTOL 1e-4 damps
        out["arc + flyback diode, RELTOL 1e-6"] = quiet.set("circuit.flyback", True).set("circuit.reltol", 1e-6)
    return out


def constants(sc) -> dict:
    c = sc.circuit.circuit
    arc = load_scene(SCENE).circuit.circuit.arc  # the scene's arc, also for the variants without one
    L = c.load.load_inductance + c.wiring.wiring_inductance
    C = c.contact_capacitance
    return dict(E=c.source.voltage, R_series=c.source.source_resistance + c.wiring.wiring_resistance + c.load.load_resistance,
                L=L, C=C, L_wire=c.wiring.wiring_inductance, U_min=arc.min_voltage, I_min=arc.min_current,
                E_col=arc.column_gradient, R_arc=arc.resistance, Z=math.sqrt(L / C) if C > 0 else math.inf,
                snubber=c.snubber)


def analyse(result) -> dict:
    """Peak contact voltage, arc intervals, extinction (current, gap, time), closed forms."""
    sc = result.scene
    k = constants(sc)
    w = result.waveforms
    t = w.time.to_numpy()
    v = w.contact_voltage.to_numpy()
    i_arc = w.arc_current.to_numpy()
    closed = result.closed_intervals
    b = result.bounce
    after_make = t > closed[0][0]
    j_peak = int(np.argmax(np.abs(v) * after_make))
    out = dict(status=result.status, bounces=b["bounces"], peak_contact_voltage=float(abs(v[j_peak])),
               peak_time=float(t[j_peak]), arc_energy=b["arc_energy"])
    burning = np.abs(i_arc) >= k["I_min"]
    out["arc_time"] = float(np.sum(np.diff(t)[burning[:-1]]))
    out["arc_voltage_min"] = float(np.min(np.abs(v[burning]))) if burning.any() else None
    # breaks that arced: the arc burns right after the break
    breaks = [e for _, e in closed if e < sc.t_end * (1 - 1e-9)]
    out["breaks"] = len(breaks)
    out["breaks_that_arced"] = int(sum(bool(np.any(burning[(t > e) & (t < e + 5e-6)])) for e in breaks))
    out["extinction_time"] = out["extinction_current"] = out["extinction_gap_mm"] = None
    out["peak_after_extinction"] = None
    if burning.any() and breaks and breaks[-1] > closed[-1][0]:
        j = int(np.flatnonzero(burning)[-1])
        if j < len(t) - 1 and t[j] > breaks[-1]:
            h = result.mechanics.history
            heights = np.minimum(h.tip_height_0.to_numpy(), h.tip_height_1.to_numpy())
            out["extinction_time"] = float(t[j])
            out["extinction_current"] = float(abs(i_arc[j]))
            out["extinction_gap_mm"] = float(np.interp(t[j], h.time.to_numpy(), heights) * 1e3)
            out["peak_after_extinction"] = float(np.max(np.abs(v[j + 1:])))
    # closed forms
    out["spike_closed_form"] = k["E"] + k["I_min"] * k["Z"]  # chopped at I_min, lossless LC
    # lossless bound: the LC swings about E with amplitude hypot(I Z, E - V0), V0 >= U_min the
    # gap voltage at extinction
    out["spike_energy_bound"] = k["E"] + math.hypot(k["I_min"] * k["Z"], k["E"] - k["U_min"])
    out["extinction_gap_quasi_static_mm"] = 1e3 * (k["E"] - k["U_min"] - k["I_min"] * (k["R_series"] + k["R_arc"])) / k["E_col"]
    if k["C"] > 0:
        # flyback: the coil freewheels, only the wiring's I_min rings into C about E + V_d
        top = k["E"] + DIODE_DROP_MAX
        out["flyback_bound"] = top + math.hypot(k["I_min"] * math.sqrt(k["L_wire"] / k["C"]), top - k["U_min"])
    if k["snubber"] is not None:
        s = k["snubber"]
        # chopped I_min into R_s + C_s: v_C swings at most I_min sqrt(L/C_s) + (E - U_min) about E,
        # plus the step I_min R_s across the resistor
        out["snubber_bound"] = (k["E"] + k["I_min"] * (s.resistance + math.sqrt(k["L"] / s.capacitance))
                                + (k["E"] - k["U_min"]))
    return out


def plot(results: dict, numbers: dict, out: Path) -> list[Path]:
    """variants.png: |contact voltage| of every variant (log); extinction.png: the arc
    variant around the final extinction with the closed-form spike."""
    paths = []
    fig, axes = plt.subplots(2, 1, figsize=(9, 7))
    first = results["arc"]
    a0, b0 = first.closed_intervals[0][0], first.closed_intervals[-1][1]
    for name, r in results.items():
        if r is None or r.waveforms is None:
            continue
        w = r.waveforms
        for ax in axes:
            ax.semilogy(w.time * 1e3, np.maximum(np.abs(w.contact_voltage), 1e-3), lw=0.8,
                        label=f"{name}: peak {numbers[name]['peak_contact_voltage']:.3g} V")
    axes[0].set_xlim((a0 - 50e-6) * 1e3, (b0 + 200e-6) * 1e3)
    axes[0].set_title("bounces: contact voltage (closed: mV; arcing: ~12 V)")
    t_ext = numbers["arc"]["extinction_time"]
    if t_ext is not None:
        axes[1].set_xlim((t_ext - 30e-6) * 1e3, (t_ext + 60e-6) * 1e3)
        axes[1].set_title("final opening: the arc goes out at I_min, the coil rings into the gap capacitance")
    for ax in axes:
        ax.axhline(numbers["arc"]["spike_closed_form"], color="k", ls=":", lw=0.8,
                   label="E + I_min sqrt(L/C)")
        ax.set_ylabel("|contact voltage| (V)")
        ax.grid(alpha=0.3, which="both")
    axes[1].set_xlabel("time (ms)")
    axes[1].legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    fig.savefig(out / "variants.png", dpi=110)
    plt.close(fig)
    paths.append(out / "variants.png")

    if t_ext is not None:
        w = first.waveforms
        m = (w.time > t_ext - 20e-6) & (w.time < t_ext + 20e-6)
        fig, (ax_v, ax_i) = plt.subplots(2, 1, sharex=True, figsize=(9, 6))
        ms = w.time[m] * 1e3
        ax_v.plot(ms, w.contact_voltage[m], lw=0.9)
        ax_v.axhline(numbers["arc"]["spike_closed_form"], color="k", ls=":", lw=0.8, label="E + I_min sqrt(L/C)")
        ax_v.set_ylabel("contact voltage (V)")
        ax_v.legend(fontsize=8)
        ax_i.plot(ms, w.load_current[m], "k", lw=0.9, label="coil current")
        ax_i.plot(ms, w.arc_current[m], color="tab:orange", lw=0.9, label="arc current")
        ax_i.axhline(constants(first.scene)["I_min"], color="tab:orange", ls=":", lw=0.8, label="I_min")
        ax_i.set_ylabel("current (A)")
        ax_i.set_xlabel("time (ms)")
        ax_i.legend(fontsize=8)
        for ax in (ax_v, ax_i):
            ax.axvline(t_ext * 1e3, color="gray", lw=0.6)
            ax.grid(alpha=0.3)
        ax_v.set_title("arc extinction at the final opening (relay coil 24 ohm, 2 mH; 100 pF across the gap)")
        fig.tight_layout()
        fig.savefig(out / "extinction.png", dpi=110)
        plt.close(fig)
        paths.append(out / "extinction.png")
    return paths


def _slug(name: str) -> str:
    """A directory name: 'arc + flyback diode' -> 'arc_flyback_diode'."""
    return re.sub(r"[^0-9A-Za-z]+", "_", name).strip("_")


def main(fast: bool = False, out: str | Path | None = None) -> dict:
    out = Path(out) if out is not None else Path("runs/examples") / NAME
    out.mkdir(parents=True, exist_ok=True)
    results, numbers = {}, {}
    for name, sc in variants(fast).items():
        if isinstance(sc, ValueError):
            numbers[name] = dict(status="refused", error=str(sc).splitlines()[0])
            results[name] = None
            continue
        try:
            r = run(sc)
        except CoupledRunError as err:  # the variant without physics limiting the spike
            r = err.partial
            numbers[name] = dict(status="failed", error=str(err).splitlines()[0])
            if r is not None and r.waveforms is not None and len(r.waveforms):
                v = r.waveforms.contact_voltage.to_numpy()
                numbers[name]["peak_before_failure"] = float(np.max(np.abs(v)))
            results[name] = None
            continue
        r.save(out / _slug(name))
        results[name] = r
        numbers[name] = analyse(r)
        numbers[name]["wall_time_s"] = r.stats.get("wall_time")
    plot(results, numbers, out)
    (out / "example.json").write_text(json.dumps(numbers, indent=2))
    return numbers


def _summary(numbers: dict) -> str:
    a = numbers["arc"]
    lines = [f"{a['bounces']} bounce(s); {a['breaks_that_arced']} of {a['breaks']} breaks arced "
             f"(arc voltage >= {a['arc_voltage_min']:.2f} V, arc energy {a['arc_energy'] * 1e3:.1f} mJ)"]
    if a["extinction_time"] is not None:
        lines.append(f"final arc out at {a['extinction_time'] * 1e3:.3f} ms at {a['extinction_current']:.4f} A, gap "
                     f"{a['extinction_gap_mm']:.3f} mm (quasi-static {a['extinction_gap_quasi_static_mm']:.3f} mm)")
    lines.append(f"opening spike with the arc model: {a['peak_contact_voltage']:.1f} V; closed form "
                 f"E + I_min sqrt(L/C) = {a['spike_closed_form']:.1f} V")
    for name, n in numbers.items():
        if name == "arc":
            continue
        if n.get("status") in ("failed", "refused"):
            lines.append(f"  {name}: run {n['status']} ({n['error'][:90]}...)")
        else:
            lines.append(f"  {name}: peak contact voltage {n['peak_contact_voltage']:.1f} V, "
                         f"arc energy {n['arc_energy'] * 1e3:.1f} mJ")
    return "\n".join(lines)


def cli(argv=None) -> int:
    return example_cli.run(__doc__, NAME, main, _summary, argv, fast_help='short run (a few seconds), looser tolerance')


if __name__ == "__main__":
    sys.exit(cli())
