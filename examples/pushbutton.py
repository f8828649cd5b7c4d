"""A pushbutton: a pivoted lever with a torsion return spring, pressed by a finger, released.

The steel lever of examples/pushbutton.toml is hinged at one end (mount kind "pivot",
return spring k_t), carries a silver rivet near its free end and is pressed by a finger
force that rises, is held and is released. The script runs it (5 V, 1 kOhm logic input)
and, with friction made negligible (tribology.mu = 1e-6), the same press as the route for
the statics check. Checked against the closed form of the rigid lever: at rest the
moments about the hinge balance,

    R (d cos th + h sin th) = F d_F cos th + (weights) - k_t th,

with the rivet's penetration d sin th + h (1 - cos th) - g = (R/k)^(2/3) (d, h: the rivet
centre's distance along and offset from the axis, g the gap, k Hertz of cap on pad),
solved for the angle th and the contact force R. With friction, the pad's tangential
force (|F_t| <= mu R) acts below the hinge and moves R by at most mu R z/d (z: the contact
point's depth below the hinge). After the release the return spring must open the contact.

    .venv/bin/python examples/pushbutton.py [--fast] [--out DIR]
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

NAME = "pushbutton"
SCENE = Path(__file__).with_name(f"{NAME}.toml")
HOLD_WINDOW = 1e-3  # s before the release over which the held contact force and angle are averaged


def variants(fast: bool = False) -> dict:
    """name -> scene; fast: a looser mechanics tolerance."""
    base = load_scene(SCENE)
    if fast:
        base = base.set("solver.rtol", 1e-5).set("output.plots", False)
    quiet = base.set("output.plots", False).set("output.csv", False)
    return {"with friction": base, "frictionless": quiet.set("tribology.mu", 1e-6)}


def release_start(sc) -> float:
    """s: when the finger force starts to fall."""
    f = sc.mech.forces[0]
    ts, vs = np.array(f.time), np.array(f.value)
    return float(ts[np.flatnonzero(vs == vs.max())[-1]])


def lever_statics(sc) -> dict:
    """The rigid lever's rest angle th (rad) and contact force R (N) from the scene's values."""
    m = sc.mech
    bar, rv, f, mnt, blk = m.bar, m.rivets[0], m.forces[0], m.mount, m.block
    d, h, g = abs(mnt.position - rv.position), rv.offset, m.initial.height
    d_f = abs(mnt.position - f.position)
    e_star = 1.0 / ((1 - rv.poisson_ratio**2) / rv.youngs_modulus + (1 - blk.poisson_ratio**2) / blk.youngs_modulus)
    k = 4.0 / 3.0 * e_star * math.sqrt(rv.radius)
    grav = m.gravity
    m_bar = bar.density * bar.area * bar.length
    x_cm = abs(mnt.position - 0.5 * bar.length)
    F = max(f.value)

    def force(th):
        pen = d * math.sin(th) + h * (1.0 - math.cos(th)) - g
        return k * max(pen, 0.0) ** 1.5

    def moment(th):
        arm = d * math.cos(th) + h * math.sin(th)
        return ((F * d_f + m_bar * grav * x_cm + rv.mass * grav * d) * math.cos(th)
                + mnt.preload_torque - mnt.stiffness * th - force(th) * arm)

    th = brentq(moment, math.asin(g / d) * 0.999, 0.5, xtol=1e-15)
    depth = abs(h * math.cos(th) - d * math.sin(th)) + rv.radius  # contact point below the hinge
    mu = float(sc.tribology.laws.mu(0.0))
    return dict(angle=th, contact_force=force(th), hertz_stiffness=k, finger_torque=F * d_f * math.cos(th),
                spring_torque=mnt.stiffness * th, arm=d * math.cos(th) + h * math.sin(th),
                friction_band=mu * force(th) * depth / d)


def rigid_lever_make(sc) -> float:
    """s: when the rigid lever, I th'' = (F(t) d_F + weights) cos th - k_t th - c th' from
    rest, brings the rivet onto the pad (scipy's solve_ivp, independent of mech)."""
    from scipy.integrate import solve_ivp
    m = sc.mech
    bar, rv, f, mnt = m.bar, m.rivets[0], m.forces[0], m.mount
    m_bar = bar.density * bar.area * bar.length
    d, h, d_f = abs(mnt.position - rv.position), rv.offset, abs(mnt.position - f.position)
    inertia = m_bar * (bar.length**2 / 3 + bar.thickness**2 / 12) + rv.mass * (d * d + h * h + 0.4 * rv.radius**2)
    weights = m.gravity * (m_bar * abs(mnt.position - 0.5 * bar.length) + rv.mass * d)

    def rhs(t, y):
        torque = (np.interp(t, f.time, f.value) * d_f + weights) * math.cos(y[0]) + mnt.preload_torque
        return [y[1], (torque - mnt.stiffness * y[0] - mnt.damping * y[1]) / inertia]

    def touch(t, y):
        return d * math.sin(y[0]) + h * (1 - math.cos(y[0])) - m.initial.height
    touch.terminal, touch.direction = True, 1
    sol = solve_ivp(rhs, (0.0, sc.t_end), [0.0, 0.0], events=touch, rtol=1e-10, atol=1e-14)
    return float(sol.t_events[0][0]) if len(sol.t_events[0]) else float("nan")


def analyse(name: str, result, release: float) -> dict:
    b = result.bounce
    closed = [(a, e) for a, e in result.closed_intervals if a < release]
    held = next(((a, e) for a, e in closed if e >= release), None)
    h = result.mechanics.history
    sel = (h.time >= release - HOLD_WINDOW) & (h.time <= release)
    angle = 2.0 * np.arcsin(np.abs(h.qy[sel].to_numpy()))  # rotation about y from the level start
    out = dict(variant=name, wall_time_s=result.stats.get("wall_time"), first_make=closed[0][0],
               closing_bounces=len(closed) - 1, settle_time=(held[0] - closed[0][0]) if held else None,
               settled=bool(held and release - held[0] >= result.scene.metrics.settle_window),
               held_force=float(np.mean(h.normal_force_0[sel])), held_angle=float(np.mean(angle)),
               held_friction=float(np.mean(h.friction_x_0[sel])), final_state=b["final_state"],
               final_gap=float(h.tip_height_0.iloc[-1]), bounce_peak_voltage=b["peak_bounce_voltage"])
    fo = b["final_opening"]
    if fo is not None:
        out.update(break_time=fo["break_time"], break_delay=fo["break_time"] - release,
                   current_at_break=fo["current_at_break"])
    # the moment balance at the simulated angle, friction left out (the brief's closed form)
    sc = result.scene
    m = sc.mech
    th = out["held_angle"]
    d = abs(m.mount.position - m.rivets[0].position)
    arm = d * math.cos(th) + m.rivets[0].offset * math.sin(th)
    d_f = abs(m.mount.position - m.forces[0].position)
    m_bar = m.bar.density * m.bar.area * m.bar.length
    weights = (m_bar * abs(m.mount.position - 0.5 * m.bar.length) + m.rivets[0].mass * d) * m.gravity * math.cos(th)
    out["force_from_moments_at_angle"] = (max(m.forces[0].value) * d_f * math.cos(th) + weights
                                          + m.mount.preload_torque - m.mount.stiffness * th) / arm
    return out


def plot(results: dict, out: Path) -> Path:
    """press_release.png: contact voltage, contact force and gap over the whole press."""
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(9, 8))
    for k, r in results.items():
        w = r.waveforms
        h = r.mechanics.history
        axes[0].plot(w.time * 1e3, w.contact_voltage, lw=0.9, label=k)
        axes[1].plot(w.time * 1e3, w.normal_force, lw=0.9, label=k)
        axes[2].plot(h.time * 1e3, np.maximum(h.tip_height_0, 0.0) * 1e3, lw=0.9, label=k)
    axes[0].set_ylabel("contact voltage (V)")
    axes[1].set_ylabel("contact force (N)")
    axes[2].set_ylabel("gap (mm)")
    axes[2].set_xlabel("time (ms)")
    axes[0].set_title("pushbutton: pivoted lever, return spring, finger pressed then released")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "press_release.png", dpi=110)
    plt.close(fig)
    return out / "press_release.png"


def main(fast: bool = False, out: str | Path | None = None) -> dict:
    out = Path(out) if out is not None else Path("runs/examples") / NAME
    out.mkdir(parents=True, exist_ok=True)
    scenes = variants(fast)
    release = release_start(scenes["with friction"])
    results = {name: run(sc) for name, sc in scenes.items()}
    results["with friction"].save(out)
    numbers = dict(release_start=release, statics=lever_statics(scenes["with friction"]),
                   rigid_lever_make=rigid_lever_make(scenes["with friction"]),
                   variants=[analyse(k, r, release) for k, r in results.items()])
    plot(results, out)
    (out / "example.json").write_text(json.dumps(numbers, indent=2))
    return numbers


def _summary(n: dict) -> str:
    s = n["statics"]
    lines = [f"rigid lever at rest: angle {math.degrees(s['angle']):.3f} deg, finger torque "
             f"{s['finger_torque'] * 1e3:.3f} mN m, return spring {s['spring_torque'] * 1e3:.3f} mN m, arm "
             f"{s['arm'] * 1e3:.3f} mm: contact force R0 = {s['contact_force']:.4f} N "
             f"(friction band +-{s['friction_band']:.4f} N); the rigid lever touches at "
             f"{n['rigid_lever_make'] * 1e3:.4f} ms"]
    for v in n["variants"]:
        lines.append(f"{v['variant']}: {v['closing_bounces']} bounce(s), first make {v['first_make'] * 1e3:.3f} ms, "
                     f"settle time {v['settle_time'] * 1e3:.3f} ms; held force {v['held_force']:.4f} N at "
                     f"{math.degrees(v['held_angle']):.3f} deg ({v['held_force'] - s['contact_force']:+.4f} N from R0; "
                     f"moments at that angle {v['force_from_moments_at_angle']:.4f} N); opens "
                     f"{v.get('break_delay', float('nan')) * 1e3:.3f} ms after the release, ends "
                     f"{v['final_state']} with a {v['final_gap'] * 1e3:.3f} mm gap")
    return "\n".join(lines)


def cli(argv=None) -> int:
    return example_cli.run(__doc__, NAME, main, _summary, argv)


if __name__ == "__main__":
    sys.exit(cli())
