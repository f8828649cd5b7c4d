"""mu(I) feedback on vs off: what the contact current does to the friction and to the motion.

The illustrative tribometer fit has mu rising with current: mu(0) = 0.20 N^0.7, mu(2 A)
= 0.31 N^0.7 (+55 %). Two scenes, each run with [tribology] feedback = true and false:

1. the drop of resistive_bounce.toml (2 A through the bouncing tip). Friction follows
   |F_t| = mu F_n^(1 - gamma) with gamma = 0.7: at impact forces of 10^2-10^3 N,
   F_t / F_n = mu F_n^-0.7 is a few 1e-3, so the tangential impulse is a few 1e-3 of the
   normal one. Feedback raises it by the mu ratio, yet the motion changes by much less than
   a percent: quantified per impact (tangential impulse, change of the bar's horizontal
   velocity, tip slip velocity at separation, restitution, bounce times);
2. mu_feedback.toml: the bar lying on both tips (F_n = m g / 2 = 0.91 N each) sliding at
   10 mm/s. Here friction decides the motion: the tips slip until they stop, then stick,
   after t_stop = v0 m / (mu sum F_i^(1 - gamma)) (closed form, F_i = m g / 2): feedback
   shortens the slip phase by the factor mu(0) / mu(2 A).

Checks: feedback off keeps mu = mu(0) everywhere; with feedback mu = mu(0) where no
current flows and follows mu(I) of the loop current elsewhere (the master extrapolates I
linearly over each macro step, so right after a make it overshoots for one step).

    .venv/bin/python examples/mu_feedback.py [--fast] [--out DIR]
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

NAME = "mu_feedback"
HERE = Path(__file__).parent
SLIDING = HERE / "mu_feedback.toml"
IMPACT = HERE / "resistive_bounce.toml"
# The mu(I) tracking check leaves out the exchange's lag where the current jumps: 10 us after
# each make (zero-order hold, then one extrapolated step) and one macro step before each
# break (as F_n -> 0, R_c(F_n) grows and the arc takes over at ~1 A within the last step).
AFTER_MAKE = 10e-6  # s
BEFORE_BREAK = 2e-6  # s


def scenes(fast: bool) -> dict:
    """{"impact": base scene, "sliding": base scene}; fast: shorter runs, looser mechanics rtol,
    a 5 mm/s slide."""
    impact = load_scene(IMPACT)
    sliding = load_scene(SLIDING)
    if fast:
        impact = impact.set("solver.t_end", 2.5e-3).set("solver.rtol", 1e-5)
        sliding = sliding.set("initial.velocity", [0.005, 0.0, 0.0]).set("solver.t_end", 3e-3).set("solver.rtol", 1e-5)
    return {"impact": impact, "sliding": sliding}


def mu_checks(result) -> dict:
    """How the mu the mechanics used relates to mu(0) and mu(I_load)."""
    laws = result.scene.tribology.laws
    w = result.waveforms
    t = w.time.to_numpy()
    mu = w.mu.to_numpy()
    i = w.load_current.to_numpy()
    mu0 = float(laws.mu(0.0))
    out = dict(mu_min=float(mu.min()), mu_max=float(mu.max()), mu_zero_current=mu0)
    out["max_dev_from_mu0"] = float(np.max(np.abs(mu - mu0)))
    no_current = np.abs(i) < 1e-6
    out["max_dev_from_mu0_without_current"] = float(np.max(np.abs(mu[no_current] - mu0))) if no_current.any() else None
    touching = np.zeros(len(t), bool)
    settled = np.zeros(len(t), bool)
    for a, e in result.closed_intervals:
        touching |= (t >= a) & (t <= e)
        settled |= (t > max(a, 0.0) + AFTER_MAKE) & (t < e - BEFORE_BREAK)
    if result.scene.tribology.feedback and settled.any():
        target = laws.mu(i[settled])
        out["tracking_max_rel_dev"] = float(np.max(np.abs(mu[settled] / target - 1.0)))
        out["overshoot_after_make"] = float(np.max(mu[touching] - laws.mu(i[touching])))
    return out


def impact_numbers(result) -> dict:
    m = result.mechanics
    h = m.history
    t = h.time.to_numpy()
    c = m.contacts
    rows = []
    for _, r in c.iterrows():
        tip = int(r.tip)
        sel = (t >= r.t_start) & (t <= r.t_end)
        ft = np.hypot(h[f"friction_x_{tip}"].to_numpy(), h[f"friction_y_{tip}"].to_numpy())
        j_t = float(np.trapezoid(ft[sel], t[sel])) if sel.sum() > 1 else 0.0
        k0, k1 = np.flatnonzero(sel)[[0, -1]]
        rows.append(dict(
            tip=tip, t_start=float(r.t_start), t_end=float(r.t_end), peak_force=float(r.peak_force),
            normal_impulse=float(r.impulse), tangential_impulse=j_t,
            tangential_to_normal=j_t / float(r.impulse) if r.impulse > 0 else None,
            dvx=float(h.vx.iloc[k1] - h.vx.iloc[k0]), dwy=float(h.wy.iloc[k1] - h.wy.iloc[k0]),
            slip_speed_at_separation=float(h[f"slip_speed_{tip}"].iloc[k1]),
            kinematic_restitution=float(r.kinematic_restitution),
            stick_time=float(sum(p.t_end - p.t_start for p in m.phases.itertuples()
                                 if p.tip == tip and p.regime == "stick" and p.t_start >= r.t_start - 1e-12
                                 and p.t_end <= r.t_end + 1e-12)),
        ))
    return dict(contacts=rows, bounces=result.bounce["bounces"], last_make=result.bounce["last_make"],
                friction_dissipation=m.energy["friction_dissipation"], vx_end=float(h.vx.iloc[-1]),
                wy_end=float(h.wy.iloc[-1]), mu=mu_checks(result))


def sliding_numbers(result) -> dict:
    sc = result.scene
    m = result.mechanics
    h = m.history
    ph = m.phases
    laws = sc.tribology.laws
    bar = sc.mech.bar
    v0 = float(sc.mech.initial.velocity[0])
    stick = ph[ph.regime == "stick"]
    t_stop = float(stick.t_start.min()) if len(stick) else None
    x0 = float(h.x.iloc[0])
    slip = (h.time > 20e-6) & (h.time < (t_stop if t_stop else sc.t_end))
    mu_used = float(np.median(result.waveforms.mu[(result.waveforms.time > 20e-6)
                                                  & (result.waveforms.time < (t_stop or sc.t_end))]))
    weight = bar.mass * sc.mech.gravity
    decel = mu_used * 2.0 * (0.5 * weight) ** (1.0 - laws.gamma) / bar.mass
    out = dict(v0=v0, t_stop=t_stop, t_stop_closed_form=v0 / decel,
               distance=float(h.x[h.time <= (t_stop or sc.t_end)].iloc[-1] - x0) if t_stop else None,
               distance_closed_form=v0 ** 2 / (2.0 * decel), mu_used=mu_used,
               friction_to_load=mu_used * (0.5 * weight) ** (-laws.gamma),
               normal_force_tips=[float(h.normal_force_0[slip].mean()), float(h.normal_force_1[slip].mean())],
               current=float(np.median(result.waveforms.load_current)),
               friction_dissipation=m.energy["friction_dissipation"],
               kinetic_energy_initial=0.5 * bar.mass * v0 ** 2, mu=mu_checks(result))
    return out


def plot_impact(results: dict, out: Path) -> Path:
    fig, ax = plt.subplots(3, 1, sharex=True, figsize=(9, 8))
    for fb, r in results.items():
        label = "feedback on" if fb else "feedback off"
        w = r.waveforms
        h = r.mechanics.history
        ax[0].plot(w.time * 1e3, w.mu, lw=0.9, label=label)
        ft = np.hypot(h.friction_x_0, h.friction_y_0)
        ax[1].plot(h.time * 1e3, ft, lw=0.9, label=label)
        ax[2].plot(h.time * 1e3, h.vx * 1e3, lw=0.9, label=label)
    r = results[True]
    for a_ in ax:
        for a, e in r.closed_intervals:
            a_.axvspan(a * 1e3, e * 1e3, color="tab:green", alpha=0.15, lw=0)
        a_.grid(alpha=0.3)
        a_.legend(fontsize=8)
    ax[0].set_ylabel("mu (N^gamma)")
    ax[1].set_ylabel("friction force, tip 0 (N)")
    ax[2].set_ylabel("centroid v_x (mm/s)")
    ax[2].set_xlabel("time (ms)")
    iv = r.closed_intervals
    ax[2].set_xlim((iv[0][0] - 50e-6) * 1e3, (iv[-1][1] + 100e-6) * 1e3)
    ax[0].set_title("drop impacts, 2 A: mu with and without feedback, friction force, horizontal velocity")
    fig.tight_layout()
    path = out / "impact.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_sliding(results: dict, numbers: dict, out: Path) -> Path:
    fig, ax = plt.subplots(2, 1, sharex=True, figsize=(9, 6))
    for fb, r in results.items():
        label = "feedback on" if fb else "feedback off"
        h = r.mechanics.history
        line, = ax[0].plot(h.time * 1e3, h.slip_speed_0 * 1e3, lw=1.0, label=f"{label}: tip 0 slip speed")
        n = numbers[fb]
        tt = np.linspace(0.0, n["t_stop_closed_form"], 50)
        ax[0].plot(tt * 1e3, (n["v0"] - n["v0"] * tt / n["t_stop_closed_form"]) * 1e3, ls=":", color=line.get_color(),
                   label=f"{label}: closed form, t_stop = {n['t_stop_closed_form'] * 1e3:.2f} ms")
        ax[1].plot(r.waveforms.time * 1e3, r.waveforms.mu, lw=1.0, label=label)
    ax[0].set_ylabel("slip speed (mm/s)")
    ax[1].set_ylabel("mu (N^gamma)")
    ax[1].set_xlabel("time (ms)")
    for a_ in ax:
        a_.grid(alpha=0.3)
        a_.legend(fontsize=8)
    ax[0].set_title("bar sliding on both tips, 2 A through the contact: slip, then stick")
    fig.tight_layout()
    path = out / "sliding.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(fast: bool = False, out: str | Path | None = None) -> dict:
    out = Path(out) if out is not None else Path("runs/examples") / NAME
    out.mkdir(parents=True, exist_ok=True)
    numbers: dict = {}
    for case, base in scenes(fast).items():
        results = {}
        for fb in (True, False):
            sc = base.set("tribology.feedback", fb).set("output.plots", False)
            r = run(sc)
            r.save(out / f"{case}_feedback_{'on' if fb else 'off'}")
            results[fb] = r
        if case == "impact":
            numbers[case] = {"on": impact_numbers(results[True]), "off": impact_numbers(results[False])}
            plot_impact(results, out)
        else:
            per = {fb: sliding_numbers(r) for fb, r in results.items()}
            numbers[case] = {"on": per[True], "off": per[False]}
            plot_sliding(results, per, out)
    imp, sl = numbers["impact"], numbers["sliding"]
    laws = load_scene(SLIDING).tribology.laws
    numbers["summary"] = dict(
        mu0=float(laws.mu(0.0)), mu_at_current=sl["on"]["mu_used"],
        friction_dissipation_ratio_impact=imp["on"]["friction_dissipation"] / imp["off"]["friction_dissipation"],
        first_impact_tangential_impulse_ratio=(imp["on"]["contacts"][0]["tangential_impulse"]
                                               / imp["off"]["contacts"][0]["tangential_impulse"]),
        first_impact_tangential_to_normal_on=imp["on"]["contacts"][0]["tangential_to_normal"],
        vx_end_difference=imp["on"]["vx_end"] - imp["off"]["vx_end"],
        restitution_max_difference=float(max(abs(a["kinematic_restitution"] - b["kinematic_restitution"])
                                             for a, b in zip(imp["on"]["contacts"], imp["off"]["contacts"]))),
        last_make_shift=imp["on"]["last_make"] - imp["off"]["last_make"],
        stop_time_ratio=sl["on"]["t_stop"] / sl["off"]["t_stop"],
        stop_time_ratio_closed_form=float(laws.mu(0.0)) / sl["on"]["mu_used"],
    )
    (out / "example.json").write_text(json.dumps(numbers, indent=2))
    return numbers


def _summary(n: dict) -> str:
    s = n["summary"]
    imp, sl = n["impact"], n["sliding"]
    c_on, c_off = imp["on"]["contacts"][0], imp["off"]["contacts"][0]
    return "\n".join([
        f"mu(0) = {s['mu0']:.3f}, mu at the contact current = {s['mu_at_current']:.3f} N^0.7 "
        f"(+{100 * (s['mu_at_current'] / s['mu0'] - 1):.0f} %)",
        f"impacts: first impact tangential impulse {c_on['tangential_impulse'] * 1e3:.3f} vs "
        f"{c_off['tangential_impulse'] * 1e3:.3f} mN s (x{s['first_impact_tangential_impulse_ratio']:.2f}), "
        f"{100 * s['first_impact_tangential_to_normal_on']:.2f} % of the normal impulse; friction dissipation "
        f"x{s['friction_dissipation_ratio_impact']:.2f} ({imp['on']['friction_dissipation'] * 1e3:.3f} vs "
        f"{imp['off']['friction_dissipation'] * 1e3:.3f} mJ)",
        f"  motion: final v_x differs by {s['vx_end_difference'] * 1e3:.3f} mm/s, restitutions by at most "
        f"{s['restitution_max_difference']:.1e}, last make moves {s['last_make_shift'] * 1e9:.0f} ns; stick during "
        f"impacts {sum(c['stick_time'] for c in imp['on']['contacts']) * 1e6:.2f} vs "
        f"{sum(c['stick_time'] for c in imp['off']['contacts']) * 1e6:.2f} us",
        f"sliding at {sl['on']['v0'] * 1e3:.0f} mm/s on both tips (F_n {sl['on']['normal_force_tips'][0]:.3f}/"
        f"{sl['on']['normal_force_tips'][1]:.3f} N, F_t/F_n {sl['on']['friction_to_load']:.2f} with feedback): "
        f"stops after {sl['on']['t_stop'] * 1e3:.3f} ms with feedback, {sl['off']['t_stop'] * 1e3:.3f} ms without "
        f"(closed forms {sl['on']['t_stop_closed_form'] * 1e3:.3f} / {sl['off']['t_stop_closed_form'] * 1e3:.3f} ms); "
        f"ratio {s['stop_time_ratio']:.4f} vs mu(0)/mu(I) = {s['stop_time_ratio_closed_form']:.4f}; slides "
        f"{sl['on']['distance'] * 1e6:.2f} vs {sl['off']['distance'] * 1e6:.2f} um",
    ])


def cli(argv=None) -> int:
    return example_cli.run(__doc__, NAME, main, _summary, argv, fast_help='short runs (a few seconds), looser tolerance')


if __name__ == "__main__":
    sys.exit(cli())
