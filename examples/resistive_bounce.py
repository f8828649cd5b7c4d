"""Bounce-voltage waveform of a resistive load: bounces, contact voltage, an arc at each break.

A steel bar dropped on a block closes a 24 V / 12 ohm circuit (examples/resistive_bounce.toml).
The script runs the co-simulation and checks the waveform against closed forms:

- closed contact: the loop is a divider, I = E / (R_series + R_c(F_n, I)) and the contact
  voltage is I R_c (mV), with R_c from the (illustrative) tribometer fit at the force the
  mechanics gives;
- each break: 2 A exceeds the arc's minimum current and 24 V its minimum voltage, so an arc
  forms and holds the gap at U_min + E_col d + R_arc |i| while the bar is in the air; the
  arc current is then (E - U_arc) / R_series;
- the final opening: the arc goes out once the gap reaches d* = (E - U_min - I_min R)/E_col,
  and the wiring inductance rings into the contact capacitance, at most E + I_min sqrt(L/C).

    .venv/bin/python examples/resistive_bounce.py [--fast] [--out DIR]
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from coupling import load_scene, run  # noqa: E402

import example_cli  # noqa: E402  (examples/example_cli.py, next to this script)

NAME = "resistive_bounce"
SCENE = Path(__file__).with_name(f"{NAME}.toml")
SETTLE = 1e-6  # s after a make or break skipped by the closed-form checks (wiring L/R = 83 ns, C discharge)
FIRM = 1.0  # N: the divider check uses points with at least this normal force; near a make or a
            # break R_c(F) ~ F^-0.27 changes within ns, faster than the loop's L/R, so I lags it there


def scene(fast: bool = False):
    """The example's scene; fast: only the bounces (3 ms, the arc of the last break still
    burning at the end) and a looser mechanics tolerance."""
    sc = load_scene(SCENE)
    if fast:
        sc = sc.set("solver.t_end", 3e-3).set("solver.rtol", 1e-5)
    return sc


def circuit_constants(sc) -> dict:
    """SI values the closed forms need, read from the scene's circuit."""
    c = sc.circuit.circuit
    arc = c.arc
    return dict(E=c.source.voltage, R_series=c.source.source_resistance + c.wiring.wiring_resistance + c.load.load_resistance,
                L_wire=c.wiring.wiring_inductance, C_contact=c.contact_capacitance, U_min=arc.min_voltage,
                I_min=arc.min_current, E_col=arc.column_gradient, R_arc=arc.resistance)


def gap_at(result, times: np.ndarray) -> np.ndarray:
    """m: the smaller tip height above the block at ``times`` (0 while a tip touches),
    interpolated in the mechanics history: the arc's length as the coupling passes it."""
    h = result.mechanics.history
    heights = np.minimum(h.tip_height_0.to_numpy(), h.tip_height_1.to_numpy())
    return np.maximum(np.interp(times, h.time.to_numpy(), heights), 0.0)


def analyse(result) -> dict:
    """Key numbers of the run and their closed-form checks (SI)."""
    sc = result.scene
    k = circuit_constants(sc)
    w = result.waveforms
    t = w.time.to_numpy()
    v = w.contact_voltage.to_numpy()
    i_load = w.load_current.to_numpy()
    i_arc = w.arc_current.to_numpy()
    r_c = w.contact_resistance.to_numpy()
    closed = result.closed_intervals
    b = result.bounce
    out = {k2: b[k2] for k2 in ("bounces", "first_make", "last_make", "total_bounce_time", "final_state",
                                "peak_contact_voltage", "arc_energy")}

    # closed contact: divider and Ohm's law across the contact
    inside = np.zeros(len(t), bool)
    for a, e in closed:
        inside |= (t > a + SETTLE) & (t < e - SETTLE)
    inside &= np.isfinite(r_c)
    out["closed_resistance_range_mohm"] = [float(np.min(r_c[inside]) * 1e3), float(np.max(r_c[inside]) * 1e3)]
    inside &= w.normal_force.to_numpy() >= FIRM
    divider = k["E"] / (k["R_series"] + r_c[inside])
    out["closed_points"] = int(inside.sum())
    out["closed_resistance_mohm"] = [float(np.min(r_c[inside]) * 1e3), float(np.max(r_c[inside]) * 1e3)]
    out["closed_voltage_mv"] = [float(np.min(v[inside]) * 1e3), float(np.max(v[inside]) * 1e3)]
    out["closed_voltage_ohm_max_abs_error"] = float(np.max(np.abs(v[inside] - w.contact_current.to_numpy()[inside]
                                                                  * r_c[inside])))
    out["closed_current_a"] = [float(np.min(i_load[inside])), float(np.max(i_load[inside]))]
    out["divider_max_rel_error"] = float(np.max(np.abs(i_load[inside] / divider - 1.0)))
    laws = sc.tribology.laws
    r_law = laws.contact_resistance(w.normal_force.to_numpy()[inside], w.contact_current.to_numpy()[inside])
    out["resistance_law_max_rel_error"] = float(np.max(np.abs(r_c[inside] / r_law - 1.0)))

    # open intervals after each break: did an arc form, and does it sit at U_min + E_col d + R_arc i?
    breaks = [e for _, e in closed if e < sc.t_end * (1 - 1e-9)]
    makes = [a for a, _ in closed]
    arced, burning_mask = [], np.zeros(len(t), bool)
    for e in breaks:
        nxt = next((a for a in makes if a > e), sc.t_end)
        window = (t > e + SETTLE) & (t < nxt - SETTLE)
        burning = window & (np.abs(i_arc) >= k["I_min"])
        arced.append(bool(burning[window][:3].all()) if window.any() else False)
        burning_mask |= burning
    out["breaks"] = len(breaks)
    out["breaks_that_arced"] = int(sum(arced))
    if burning_mask.any():
        gap = gap_at(result, t[burning_mask])
        u_arc = k["U_min"] + k["E_col"] * gap + k["R_arc"] * np.abs(i_arc[burning_mask])
        out["arc_time"] = float(np.sum(np.diff(t)[burning_mask[:-1]]))
        out["arc_voltage_min"] = float(np.min(v[burning_mask]))
        out["arc_voltage_max"] = float(np.max(v[burning_mask]))
        out["arc_voltage_max_abs_error"] = float(np.max(np.abs(v[burning_mask] - u_arc)))
        i_pred = (k["E"] - v[burning_mask]) / k["R_series"]
        out["arc_current_max_abs_error"] = float(np.max(np.abs(i_arc[burning_mask] - i_pred)))
        out["arc_gap_max_mm"] = float(np.max(gap) * 1e3)
    # final extinction (full run only: the bar flies off and the gap grows)
    d_star = (k["E"] - k["U_min"] - k["I_min"] * (k["R_series"] + k["R_arc"])) / k["E_col"]
    out["extinction_gap_closed_form_mm"] = d_star * 1e3
    out["ringing_bound_v"] = k["E"] + k["I_min"] * math.sqrt(k["L_wire"] / k["C_contact"])
    last_break = breaks[-1] if breaks and breaks[-1] > makes[-1] else None
    out["extinction_time"] = out["extinction_gap_mm"] = None
    if last_break is not None:
        after = t > last_break + SETTLE
        lit = after & (np.abs(i_arc) >= k["I_min"] * 0.5)
        if lit.any() and np.flatnonzero(lit)[-1] < len(t) - 1:
            j = np.flatnonzero(lit)[-1]
            out["extinction_time"] = float(t[j])
            out["extinction_gap_mm"] = float(gap_at(result, t[j:j + 1])[0] * 1e3)
    return out


def plot(result, out: Path) -> list[Path]:
    """bounce_waveform.png (the bounce window) and whole_run.png."""
    w = result.waveforms
    t = w.time.to_numpy()
    closed = result.closed_intervals
    gap = gap_at(result, t)
    paths = []
    a0, b0 = closed[0][0], closed[-1][1]
    pad = 0.1 * (b0 - a0) + 50e-6
    for name, window in (("bounce_waveform.png", (a0 - pad, b0 + pad)), ("whole_run.png", (0.0, result.scene.t_end))):
        fig, axes = plt.subplots(4, 1, sharex=True, figsize=(9, 9))
        ms = t * 1e3
        axes[0].plot(ms, w.contact_voltage, lw=0.9)
        axes[0].set_ylabel("contact voltage (V)")
        axes[1].semilogy(ms, np.maximum(np.abs(w.contact_voltage), 1e-4), lw=0.9)
        axes[1].set_ylabel("|contact voltage| (V, log)")
        axes[2].plot(ms, w.load_current, "k", lw=0.9, label="load")
        axes[2].plot(ms, w.arc_current, color="tab:orange", lw=0.9, label="arc")
        axes[2].set_ylabel("current (A)")
        axes[2].legend(fontsize=8)
        axes[3].plot(ms, w.normal_force, color="tab:green", lw=0.9, label="normal force (N)")
        ax_g = axes[3].twinx()
        ax_g.plot(ms, gap * 1e3, color="tab:purple", lw=0.9)
        ax_g.set_ylabel("gap (mm)", color="tab:purple")
        seen = (t >= window[0]) & (t <= window[1])
        ax_g.set_ylim(0.0, 1.1e3 * max(float(np.max(gap[seen], initial=0.0)), 1e-6))
        axes[3].set_ylabel("normal force (N)", color="tab:green")
        axes[3].set_xlabel("time (ms)")
        for ax in axes:
            for a, e in closed:
                ax.axvspan(a * 1e3, e * 1e3, color="tab:green", alpha=0.15, lw=0)
            ax.grid(alpha=0.3)
        axes[3].set_xlim(window[0] * 1e3, window[1] * 1e3)
        b = result.bounce
        axes[0].set_title(f"resistive load 24 V / 12 ohm: {b['bounces']} bounce(s), arc at each break "
                          "(green: contact closed)")
        fig.tight_layout()
        fig.savefig(out / name, dpi=110)
        plt.close(fig)
        paths.append(out / name)
    return paths


def main(fast: bool = False, out: str | Path | None = None) -> dict:
    out = Path(out) if out is not None else Path("runs/examples") / NAME
    out.mkdir(parents=True, exist_ok=True)
    result = run(scene(fast))
    result.save(out)
    numbers = analyse(result)
    numbers["wall_time_s"] = result.stats.get("wall_time")
    plot(result, out)
    (out / "example.json").write_text(json.dumps(numbers, indent=2))
    return numbers


def _summary(n: dict) -> str:
    lines = [
        f"{n['bounces']} bounce(s): first make {n['first_make'] * 1e3:.3f} ms, last make "
        f"{n['last_make'] * 1e3:.3f} ms, bounce time {n['total_bounce_time'] * 1e3:.3f} ms; "
        f"contact {n['final_state']} at the end",
        f"closed (F_n >= {FIRM:g} N): R_c {n['closed_resistance_mohm'][0]:.2f}-{n['closed_resistance_mohm'][1]:.2f} "
        f"mOhm, contact voltage {n['closed_voltage_mv'][0]:.1f}-{n['closed_voltage_mv'][1]:.1f} mV at "
        f"{n['closed_current_a'][1]:.3f} A (divider closed form within {n['divider_max_rel_error']:.1e})",
        f"{n['breaks_that_arced']} of {n['breaks']} breaks arced; arc voltage {n.get('arc_voltage_min', 0):.2f}-"
        f"{n.get('arc_voltage_max', 0):.2f} V (U_min + E_col d + R_arc i within "
        f"{n.get('arc_voltage_max_abs_error', 0) * 1e3:.2f} mV), arc energy {n['arc_energy'] * 1e3:.1f} mJ",
    ]
    if n["extinction_time"] is not None:
        lines.append(f"final arc out at {n['extinction_time'] * 1e3:.3f} ms, gap {n['extinction_gap_mm']:.3f} mm "
                     f"(closed form {n['extinction_gap_closed_form_mm']:.3f} mm); peak contact voltage "
                     f"{n['peak_contact_voltage']:.1f} V (bound E + I_min sqrt(L/C) = {n['ringing_bound_v']:.1f} V)")
    else:
        lines.append(f"the last break's arc still burns at the end of the run (gap "
                     f"{n.get('arc_gap_max_mm', 0):.3f} mm of the {n['extinction_gap_closed_form_mm']:.2f} mm that "
                     "put it out); peak contact voltage " f"{n['peak_contact_voltage']:.2f} V")
    return "\n".join(lines)


def cli(argv=None) -> int:
    return example_cli.run(__doc__, NAME, main, _summary, argv, fast_help='short run (a few seconds), looser tolerance')


if __name__ == "__main__":
    sys.exit(cli())
