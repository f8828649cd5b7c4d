"""Capacitive inrush through the bouncing contact, and what it does to mu(I) and R_c.

examples/capacitive_inrush.toml: a 47 uF input capacitor behind 5.6 ohm (plus 1 kohm
bleed) on 24 V. At the first make the capacitor is empty and the contact carries
E / R_series = 4.2 A, 175 times the 24 mA steady current; the inrush decays with
R_series C = 0.27 ms, so every bounce re-closes on a partly charged capacitor with the
current (E - V_C) / R_series. A break with E - V_C above the arc's minimum voltage
U_min = 12 V arcs, and the arc keeps charging the capacitor; below it the breaks do not
arc (here none does: the first contact lasts 0.34 ms, longer than R_series C).

What the current does to the contact laws (the ILLUSTRATIVE tribometer fit):
- mu(I) rises from mu(0) towards mu(4.2 A) while the inrush flows and falls back as it
  decays; the coupling applies it to the friction of the touching tip;
- R_c(F_n, I) = g(|I|) R_c(F_n, 0): the current factor g lowers the resistance at the
  same force by up to a third during the inrush (ngspice solves it with the current).

Checks against closed forms: the first-make peak against E / R_series, each re-make's
peak against (E - V_C) / R_series with V_C integrated from the load current, and R_c
against the law at the force and current of each point.

    .venv/bin/python examples/capacitive_inrush.py [--fast] [--out DIR]
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from coupling import load_scene, run  # noqa: E402

import example_cli  # noqa: E402  (examples/example_cli.py, next to this script)

NAME = "capacitive_inrush"
SCENE = Path(__file__).with_name(f"{NAME}.toml")
FIRM = 1.0  # N: law checks use points with at least this force (R_c changes within ns near make/break)


def scene(fast: bool = False):
    """fast: the bounces only (2.5 ms) with a looser mechanics tolerance."""
    sc = load_scene(SCENE)
    if fast:
        sc = sc.set("solver.t_end", 2.5e-3).set("solver.rtol", 1e-5)
    return sc


def constants(sc) -> dict:
    c = sc.circuit.circuit
    return dict(E=c.source.voltage, R_series=c.source.source_resistance + c.wiring.wiring_resistance + c.load.load_resistance,
                C=c.load.load_capacitance, R_bleed=c.load.bleed_resistance, I_min=c.arc.min_current,
                U_min=c.arc.min_voltage)


def capacitor_voltage(t: np.ndarray, i_load: np.ndarray, C: float, R_bleed: float) -> np.ndarray:
    """V: the load capacitor's voltage from C dV/dt = I_load - V / R_bleed, V(0) = 0
    (trapezoidal rule on ngspice's points, exact for the linear ODE between them)."""
    v = np.zeros(len(t))
    for n in range(1, len(t)):
        h = t[n] - t[n - 1]
        a = h / (2.0 * R_bleed * C)
        v[n] = (v[n - 1] * (1.0 - a) + h * 0.5 * (i_load[n] + i_load[n - 1]) / C) / (1.0 + a)
    return v


def analyse(result) -> dict:
    sc = result.scene
    k = constants(sc)
    laws = sc.tribology.laws
    w = result.waveforms
    t = w.time.to_numpy()
    i_load = w.load_current.to_numpy()
    i_c = w.contact_current.to_numpy()
    r_c = w.contact_resistance.to_numpy()
    f_n = w.normal_force.to_numpy()
    mu = w.mu.to_numpy()
    v_cap = capacitor_voltage(t, i_load, k["C"], k["R_bleed"])
    b = result.bounce
    out = dict(bounces=b["bounces"], first_make=b["first_make"], arc_energy=b["arc_energy"],
               inrush_closed_form_a=k["E"] / k["R_series"], mu_at_zero_current=float(laws.mu(0.0)),
               steady_current_a=k["E"] / (k["R_series"] + k["R_bleed"]))
    i_arc = w.arc_current.to_numpy()
    contacts = []
    for a, e in result.closed_intervals:
        m = (t > a) & (t < e)
        firm = m & (f_n >= FIRM) & np.isfinite(r_c)
        j = np.flatnonzero(m)[int(np.argmax(i_load[m]))]
        v_make = float(np.interp(a, t, v_cap))
        r0 = laws.contact_resistance(f_n[firm], 0.0)
        joule = float(np.sum(0.5 * np.diff(t[m]) * ((i_c[m] ** 2 * np.where(np.isfinite(r_c[m]), r_c[m], 0.0))[1:]
                                                       + (i_c[m] ** 2 * np.where(np.isfinite(r_c[m]), r_c[m], 0.0))[:-1])))
        contacts.append(dict(
            make=float(a), brk=float(e),
            peak_current=float(i_load[j]),
            capacitor_voltage_at_make=v_make,
            predicted_peak=(k["E"] - v_make) / k["R_series"],
            current_before_break=float(i_load[np.flatnonzero(firm)[-1]]),  # last point with F_n >= FIRM
            mu_max=float(np.max(mu[m])), mu_at_peak_current=float(laws.mu(i_load[j])),
            current_factor_min=float(np.min(r_c[firm] / r0)) if firm.any() else None,
            resistance_law_max_rel_error=float(np.max(np.abs(r_c[firm] / laws.contact_resistance(f_n[firm], i_c[firm])
                                                             - 1.0))) if firm.any() else None,
            contact_joule_mj=joule * 1e3,
            # an arc needs the gap voltage E - V_C to reach U_min and a current >= I_min
            gap_voltage_available=float(k["E"] - np.interp(e, t, v_cap)),
            arced_after_break=bool(np.any(np.abs(i_arc[(t > e) & (t < e + 5e-6)]) >= k["I_min"])),
        ))
    out["contacts"] = contacts
    out["inrush_peak_a"] = contacts[0]["peak_current"]
    out["inrush_rel_error"] = contacts[0]["peak_current"] / out["inrush_closed_form_a"] - 1.0
    out["remake_peak_max_rel_error"] = float(max(abs(c["peak_current"] / c["predicted_peak"] - 1.0) for c in contacts))
    out["capacitor_voltage_end"] = float(v_cap[-1])
    out["current_factor_min"] = float(min(c["current_factor_min"] for c in contacts))
    out["current_factor_closed_form_at_peak"] = float(laws.resistance_law.current_factor(out["inrush_peak_a"]))
    out["mu_max"] = float(np.max(mu))
    out["mu_at_inrush_peak"] = float(laws.mu(out["inrush_peak_a"]))
    burning = np.abs(w.arc_current.to_numpy()) >= k["I_min"]
    out["arc_time"] = float(np.sum(np.diff(t)[burning[:-1]]))
    out["_series"] = dict(v_cap=v_cap)
    return out


def plot(result, numbers: dict, out: Path) -> Path:
    sc = result.scene
    k = constants(sc)
    laws = sc.tribology.laws
    w = result.waveforms
    t = w.time.to_numpy()
    ms = t * 1e3
    v_cap = numbers["_series"]["v_cap"]
    fig, ax = plt.subplots(4, 1, sharex=True, figsize=(9, 10))
    ax[0].plot(ms, w.load_current, "k", lw=0.9, label="load current")
    ax[0].plot(ms, w.arc_current, color="tab:orange", lw=0.9, label="arc current")
    ax[0].plot(ms, (k["E"] - v_cap) / k["R_series"], "b:", lw=0.9, label="(E - V_C) / R_series")
    ax[0].set_ylabel("current (A)")
    ax[0].legend(fontsize=8)
    ax[1].plot(ms, v_cap, "tab:blue", lw=0.9, label="V_C (from the load current)")
    ax[1].plot(ms, w.contact_voltage, "tab:red", lw=0.9, label="contact voltage")
    ax[1].set_ylabel("voltage (V)")
    ax[1].legend(fontsize=8)
    ax[2].plot(ms, w.mu, "k", lw=0.9, label="mu used by the mechanics")
    ax[2].plot(ms, laws.mu(w.load_current.to_numpy()), "g:", lw=0.9, label="mu(I_load) from the fit")
    ax[2].axhline(float(laws.mu(0.0)), color="gray", ls="--", lw=0.8, label="mu(0)")
    ax[2].set_ylabel("mu (N^gamma)")
    ax[2].legend(fontsize=8)
    closed = np.isfinite(w.contact_resistance.to_numpy()) & (w.normal_force.to_numpy() >= FIRM)
    r0 = np.full(len(t), np.nan)
    r0[closed] = laws.contact_resistance(w.normal_force.to_numpy()[closed], 0.0)
    rc = np.where(closed, w.contact_resistance.to_numpy(), np.nan)
    ax[3].semilogy(ms, rc * 1e3, "k", lw=0.9, label="R_c(F_n, I)")
    ax[3].semilogy(ms, r0 * 1e3, "tab:purple", ls=":", lw=0.9, label="R_c(F_n, 0): same force, no current")
    ax[3].set_ylabel(f"R_c (mOhm, F_n >= {FIRM:g} N)")
    ax[3].set_xlabel("time (ms)")
    ax[3].legend(fontsize=8)
    for a_ in ax:
        for a, e in result.closed_intervals:
            a_.axvspan(a * 1e3, e * 1e3, color="tab:green", alpha=0.15, lw=0)
        a_.grid(alpha=0.3)
    iv = result.closed_intervals
    ax[3].set_xlim((iv[0][0] - 50e-6) * 1e3, min(sc.t_end, iv[-1][1] + 400e-6) * 1e3)
    ax[0].set_title(f"capacitive inrush: peak {numbers['inrush_peak_a']:.2f} A "
                    f"(E/R_series = {numbers['inrush_closed_form_a']:.2f} A), {numbers['bounces']} bounce(s)")
    fig.tight_layout()
    path = out / "inrush.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(fast: bool = False, out: str | Path | None = None) -> dict:
    out = Path(out) if out is not None else Path("runs/examples") / NAME
    out.mkdir(parents=True, exist_ok=True)
    result = run(scene(fast))
    result.save(out)
    numbers = analyse(result)
    plot(result, numbers, out)
    numbers.pop("_series")
    numbers["wall_time_s"] = result.stats.get("wall_time")
    (out / "example.json").write_text(json.dumps(numbers, indent=2))
    return numbers


def _summary(n: dict) -> str:
    lines = [f"inrush peak {n['inrush_peak_a']:.3f} A (E / R_series = {n['inrush_closed_form_a']:.3f} A, "
             f"{100 * n['inrush_rel_error']:+.2f} %), steady current {1e3 * n['steady_current_a']:.0f} mA; "
             f"{n['bounces']} bounce(s)"]
    for c in n["contacts"]:
        lines.append(f"  make {c['make'] * 1e3:.3f} ms: V_C {c['capacitor_voltage_at_make']:5.2f} V, peak "
                     f"{c['peak_current']:.3f} A (predicted {c['predicted_peak']:.3f} A), mu up to {c['mu_max']:.3f}, "
                     f"R_c down to {c['current_factor_min']:.3f} x R_c(F, 0), contact Joule heat "
                     f"{c['contact_joule_mj']:.3f} mJ; parting at {c['current_before_break']:.2f} A with "
                     f"E - V_C = {c['gap_voltage_available']:.1f} V: {'arc' if c['arced_after_break'] else 'no arc'}")
    lines.append(f"mu(0) = {n['mu_at_zero_current']:.3f}, mu at the inrush peak {n['mu_at_inrush_peak']:.3f}; "
                 f"arc {1e3 * n['arc_time']:.3f} ms in total ({1e3 * n['arc_energy']:.2f} mJ); V_C at the end "
                 f"{n['capacitor_voltage_end']:.2f} V")
    return "\n".join(lines)


def cli(argv=None) -> int:
    return example_cli.run(__doc__, NAME, main, _summary, argv, fast_help='short run (a few seconds), looser tolerance')


if __name__ == "__main__":
    sys.exit(cli())
