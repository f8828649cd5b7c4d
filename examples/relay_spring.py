"""A relay contact spring closing and opening a resistive and an inductive load.

The CuBe blade of examples/relay_spring.toml (clamped at one end, a silver rivet near
its free end, pushed by the armature at its middle) closes onto a fixed silver rivet,
bounces, settles, is held and released. The script runs it on

- the resistive load of the TOML (24 V, 10 ohm: 2.4 A),
- an inductive load (10 ohm + 10 mH, L/R = 1 ms), and in full mode the same with a
  flyback diode across the coil,
- the resistive load with friction made negligible (tribology.mu = 1e-6), closing only:
  the route for the beam-statics check below,

and reports per load the bounce count, settle time, break time, arc duration and arc
energy (bounces and break apart), and the contact force once settled against beam
statics: a force P at a from the clamp, the rivet at b, the contact force R solves

    P a^2 (3b - a)/(6EI) - R b^3/(3EI) + (weight terms) = g + (R/k)^(2/3)

(g the gap, k the Hertz stiffness of the rivet pair with effective radius R1 R2/(R1+R2)).
With friction the rivet's tangential force F_t <= mu R acts (h + r) below the blade's
axis and bends it too: the held force then lies within R0 (1 +- mu (h + r) 3/(2b)).

    .venv/bin/python examples/relay_spring.py [--fast] [--out DIR]
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
from scipy.optimize import brentq  # noqa: E402

from coupling import load_scene, run  # noqa: E402

import example_cli  # noqa: E402  (examples/example_cli.py, next to this script)

NAME = "relay_spring"
SCENE = Path(__file__).with_name(f"{NAME}.toml")
COIL_INDUCTANCE = 10e-3  # H, the inductive load's coil (with the TOML's 10 ohm)
HOLD_WINDOW = 0.5e-3  # s before the release over which the held contact force is averaged


def variants(fast: bool = False) -> dict:
    """name -> scene. Fast: looser mechanics tolerance, no flyback variant, a shorter
    frictionless closing run."""
    base = load_scene(SCENE)
    if fast:
        base = base.set("solver.rtol", 1e-5).set("output.plots", False)
    quiet = base.set("output.plots", False).set("output.csv", False)
    inductive = quiet.set("circuit.template", "inductive").set("circuit.load_inductance", COIL_INDUCTANCE)
    out = {"resistive": base, "inductive": inductive}
    if not fast:
        out["inductive + flyback diode"] = inductive.set("circuit.flyback", True)
    release = release_start(base)
    out["resistive, frictionless, closing only"] = (quiet.set("tribology.mu", 1e-6)
                                                    .set("solver.t_end", (4e-3 if fast else release - 0.5e-3)))
    return out


def release_start(sc) -> float:
    """s: when the armature force starts to fall (the last maximum of its table)."""
    f = sc.mech.forces[0]
    ts, vs = np.array(f.time), np.array(f.value)
    return float(ts[np.flatnonzero(vs == vs.max())[-1]])


def hertz_stiffness_pair(r1: float, e1: float, nu1: float, r2: float, e2: float, nu2: float) -> float:
    """N/m^1.5: k = 4/3 E* sqrt(R) of two spheres, R = R1 R2/(R1 + R2)."""
    e_star = 1.0 / ((1 - nu1**2) / e1 + (1 - nu2**2) / e2)
    return 4.0 / 3.0 * e_star * math.sqrt(r1 * r2 / (r1 + r2))


def beam_contact_force(P: float, a: float, b: float, EI: float, gap: float, k: float,
                       q: float = 0.0, span: float = 0.0, m_point_g: float = 0.0) -> float:
    """N: the contact force R of a cantilever (clamped, span m) pushed by P at a from the
    clamp onto a contact at b (a <= b) across ``gap`` m, Hertz stiffness k; q N/m its own
    weight per length, m_point_g N a weight at b (the rivet). Euler-Bernoulli statics."""
    w_free = (P * a * a * (3 * b - a) / (6 * EI) + q * b * b * (6 * span**2 - 4 * span * b + b * b) / (24 * EI)
              + m_point_g * b**3 / (3 * EI))
    f = lambda R: w_free - R * b**3 / (3 * EI) - gap - (R / k) ** (2.0 / 3.0)  # noqa: E731
    if f(0.0) <= 0.0:
        return 0.0
    return brentq(f, 0.0, 10.0 * P + 1.0, xtol=1e-14, rtol=1e-13)


def statics(sc) -> dict:
    """The closed-form held contact force and its friction band from the scene's values."""
    m = sc.mech
    bar, rv, f, blk = m.bar, m.rivets[0], m.forces[0], m.block
    L, clamp = bar.length, m.mount.position
    width, t = bar.width, bar.thickness
    EI = bar.youngs_modulus * width * t**3 / 12.0
    a, b = abs(clamp - f.position), abs(clamp - rv.position)
    k = hertz_stiffness_pair(rv.radius, rv.youngs_modulus, rv.poisson_ratio,
                             blk.radius, blk.youngs_modulus, blk.poisson_ratio)
    q = bar.density * width * t * m.gravity
    R0 = beam_contact_force(max(f.value), a, b, EI, m.initial.height, k, q=q, span=L, m_point_g=rv.mass * m.gravity)
    lever = abs(rv.offset) + rv.radius
    band = float(sc.tribology.laws.mu(0.0)) * lever * 1.5 / b
    return dict(closed_form_force=R0, hertz_stiffness=k, EI=EI, a=a, b=b, friction_lever=lever,
                friction_band_rel=band)


def closing_metrics(result, release: float) -> dict:
    """Bounces, settle time and held force of the closing (before the armature lets go)."""
    sc = result.scene
    closed = [(a, e) for a, e in result.closed_intervals if a < release]
    first = closed[0][0]
    held = next(((a, e) for a, e in closed if e >= min(release, sc.t_end) * (1 - 1e-9)), None)
    window = sc.metrics.settle_window
    out = dict(first_make=first, closing_bounces=len(closed) - 1,
               settled=held is not None and min(release, sc.t_end) - held[0] >= window,
               settle_time=(held[0] - first) if held is not None else None)
    w = result.waveforms
    t_hold = min(release, sc.t_end)
    sel = (w.time >= t_hold - HOLD_WINDOW) & (w.time <= t_hold)
    fn, tw = w.normal_force[sel].to_numpy(), w.time[sel].to_numpy()
    # the time average (the circuit's points are not evenly spaced: a plain mean of them
    # weights where ngspice stepped finely)
    held = float(np.trapezoid(fn, tw) / (tw[-1] - tw[0])) if len(tw) > 1 else float(fn.mean())
    out.update(held_force=held, held_force_min=float(np.min(fn)), held_force_max=float(np.max(fn)))
    # the summary's own figure (operations[].held.force): the median over the whole held closure
    out["summary_held_force"] = next((op["held"]["force"] for op in result.operations
                                      if "force" in op.get("held", {})), None)
    return out


def analyse(name: str, result, release: float) -> dict:
    b = result.bounce
    out = dict(variant=name, wall_time_s=result.stats.get("wall_time"))
    out.update(closing_metrics(result, release))
    bounce_rows = [o for o in b["openings"] if o["reclosed"]]
    out["bounce_arc_energy"] = float(sum(o["arc_energy"] for o in bounce_rows))
    out["bounce_peak_voltage"] = b["peak_bounce_voltage"]
    out["final_state"] = b["final_state"]
    fo = b["final_opening"]
    if fo is not None:
        out.update(break_time=fo["break_time"], break_delay=fo["break_time"] - release,
                   current_at_break=fo["current_at_break"], break_arc_duration=fo["arc_duration"],
                   break_arc_energy=fo["arc_energy"], break_peak_voltage=fo["peak_voltage"])
    out["arc_energy"] = b["arc_energy"]
    return out


def plot(results: dict, out: Path) -> list[Path]:
    """bounce_window.png: contact voltage and normal force while the contact bounces shut,
    for both loads; break.png: |contact voltage| around the break (log)."""
    paths = []
    shown = {k: r for k, r in results.items() if "frictionless" not in k}
    first = min(r.bounce["first_make"] for r in shown.values())
    last = max(r.bounce["last_make"] for r in shown.values())
    pad = 0.1 * (last - first) + 50e-6
    n = len(shown)
    fig, axes = plt.subplots(n + 1, 1, sharex=True, figsize=(9, 2.4 * (n + 1)))
    for row, (k, r) in enumerate(shown.items()):
        w = r.waveforms
        sel = (w.time >= first - pad) & (w.time <= last + pad)
        axes[row].plot(w.time[sel] * 1e3, w.contact_voltage[sel], lw=0.8, color=f"C{row}", label=k)
        axes[row].set_ylabel("contact voltage (V)")
        axes[n].plot(w.time[sel] * 1e3, w.normal_force[sel], lw=0.9, color=f"C{row}", label=k)
    axes[n].set_ylabel("contact force (N)")
    axes[n].set_xlabel("time (ms)")
    axes[0].set_title("relay contact spring closing: 24 V, 10 ohm against 10 ohm + 10 mH")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "bounce_window.png", dpi=110)
    plt.close(fig)
    paths.append(out / "bounce_window.png")
    fig, ax = plt.subplots(figsize=(9, 4.5))
    for k, r in shown.items():
        fo = r.bounce["final_opening"]
        if fo is None:
            continue
        w = r.waveforms
        sel = (w.time >= fo["break_time"] - 0.2e-3) & (w.time <= fo["break_time"] + 2.5e-3)
        ax.semilogy(w.time[sel] * 1e3, np.maximum(np.abs(w.contact_voltage[sel]), 1e-4), lw=0.9, label=k)
    ax.set_ylabel("|contact voltage| (V)")
    ax.set_xlabel("time (ms)")
    ax.set_title("the break: arc, extinction, the coil's spike")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "break.png", dpi=110)
    plt.close(fig)
    paths.append(out / "break.png")
    return paths


def main(fast: bool = False, out: str | Path | None = None) -> dict:
    out = Path(out) if out is not None else Path("runs/examples") / NAME
    out.mkdir(parents=True, exist_ok=True)
    scenes = variants(fast)
    release = release_start(scenes["resistive"])
    results, rows = {}, []
    for name, sc in scenes.items():
        r = run(sc)
        results[name] = r
        rows.append(analyse(name, r, release))
    results["resistive"].save(out)
    numbers = dict(release_start=release, statics=statics(scenes["resistive"]), variants=rows)
    plot(results, out)
    (out / "example.json").write_text(json.dumps(numbers, indent=2))
    return numbers


def _summary(n: dict) -> str:
    s = n["statics"]
    lines = [f"closed form (beam statics + Hertz, k = {s['hertz_stiffness']:.4g} N/m^1.5): held contact force "
             f"R0 = {s['closed_form_force']:.4f} N; with friction within +-{s['friction_band_rel'] * 100:.1f} %"]
    for v in n["variants"]:
        line = (f"{v['variant']}: {v['closing_bounces']} bounce(s), first make {v['first_make'] * 1e3:.3f} ms, "
                f"settle time {v['settle_time'] * 1e3:.3f} ms, held force {v['held_force']:.4f} N "
                f"({(v['held_force'] / s['closed_form_force'] - 1) * 100:+.2f} % of R0)")
        if "break_time" in v:
            line += (f"; break {v['break_time'] * 1e3:.3f} ms ({v['break_delay'] * 1e3:.3f} ms after the release) "
                     f"at {v['current_at_break']:.2f} A, arc {v['break_arc_duration'] * 1e3:.3f} ms, "
                     f"{v['break_arc_energy'] * 1e3:.2f} mJ, peak {v['break_peak_voltage']:.1f} V; "
                     f"arc energy while bouncing {v['bounce_arc_energy'] * 1e3:.3f} mJ")
        lines.append(line)
    return "\n".join(lines)


def cli(argv=None) -> int:
    return example_cli.run(__doc__, NAME, main, _summary, argv)


if __name__ == "__main__":
    sys.exit(cli())
