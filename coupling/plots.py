"""PNG plots of a run: bounce waveform, normal force, tip heights, energy audit (matplotlib, Agg)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def _shade(ax, intervals, label="contact closed"):
    for k, (a, b) in enumerate(intervals):
        ax.axvspan(a * 1e3, b * 1e3, color="tab:green", alpha=0.15, lw=0, label=label if k == 0 else None)


def _window(result) -> tuple[float, float]:
    """ms: the bounce window with a margin, or the whole run when nothing closes."""
    iv = result.closed_intervals
    t_end = result.scene.t_end
    if not iv:
        return 0.0, t_end * 1e3
    a, b = iv[0][0], iv[-1][1]
    pad = max(0.15 * (b - a), 50e-6)
    return max(0.0, a - pad) * 1e3, min(t_end, b + pad) * 1e3


def plot_waveforms(result, whole_run: bool = False):
    """Contact voltage and current vs time, closed intervals shaded, over the bounce window
    (or the whole run)."""
    w = result.waveforms
    fig, (ax_v, ax_i) = plt.subplots(2, 1, sharex=True, figsize=(9, 6))
    t = w.time.to_numpy() * 1e3
    ax_v.plot(t, w.contact_voltage, lw=0.9, color="tab:blue")
    ax_v.set_ylabel("contact voltage (V)")
    ax_i.plot(t, w.contact_current, lw=0.9, color="tab:red", label="contact (metallic)")
    if "arc_current" in w and np.any(w.arc_current != 0):
        ax_i.plot(t, w.arc_current, lw=0.9, color="tab:orange", label="arc")
    if "load_current" in w and np.all(np.isfinite(w.load_current)):
        ax_i.plot(t, w.load_current, lw=0.8, color="k", ls="--", label="load")
    ax_i.set_ylabel("current (A)")
    ax_i.set_xlabel("time (ms)")
    for ax in (ax_v, ax_i):
        _shade(ax, result.closed_intervals)
        ax.grid(alpha=0.3)
    ax_i.set_xlim(*((0.0, result.scene.t_end * 1e3) if whole_run else _window(result)))
    ax_i.legend(loc="best", fontsize=8)
    b = result.bounce
    ax_v.set_title(f"bounce waveform: {b.get('bounces', 0)} bounce(s), "
                   f"peak {b.get('peak_contact_voltage') or 0:.3g} V, arc energy {b.get('arc_energy') or 0:.3g} J")
    fig.tight_layout()
    return fig


def _per_tip(result, column: str, scale: float, ylabel: str, window: bool):
    """A history column of both tips against time (ms)."""
    h = result.mechanics.history
    fig, ax = plt.subplots(figsize=(9, 4))
    for i in range(2):
        ax.plot(h.time * 1e3, h[f"{column}_{i}"] * scale, lw=0.9, label=f"tip {i}")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel(ylabel)
    if window:
        ax.set_xlim(*_window(result))
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    return fig, ax


def plot_normal_force(result):
    """Normal force of each tip vs time (mechanics history), over the bounce window."""
    return _per_tip(result, "normal_force", 1.0, "normal force (N)", window=True)[0]


def plot_tip_heights(result):
    """Height of each tip's lowest point above the block vs time (negative: penetration)."""
    fig, ax = _per_tip(result, "tip_height", 1e3, "tip height (mm)", window=False)
    ax.axhline(0.0, color="k", lw=0.6)
    return fig


def plot_energy(result):
    """Energy audit vs time: where the initial energy went (J), and the residual."""
    en = result.mechanics.energy_table
    fig, (ax, ax_r) = plt.subplots(2, 1, sharex=True, figsize=(9, 6), height_ratios=(3, 1))
    t = en.time * 1e3
    parts = ["kinetic", "elastic", "contact_stored", "normal_dissipation", "friction_dissipation",
             "modal_dissipation"]
    ax.stackplot(t, [en[p] for p in parts], labels=parts, alpha=0.8)
    ax.plot(t, -en.potential, color="k", lw=1.0, ls="--", label="- potential change")
    ax.set_ylabel("energy (J)")
    ax.legend(loc="upper left", fontsize=7, ncol=2)
    ax.grid(alpha=0.3)
    ax_r.plot(t, en.residual, color="tab:red", lw=0.9)
    ax_r.set_ylabel("residual (J)")
    ax_r.set_xlabel("time (ms)")
    ax_r.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def save_plots(result, out_dir) -> list[Path]:
    """Write the plots that apply to this run's kind into out_dir; returns their paths."""
    out = Path(out_dir)
    figures = []
    if result.waveforms is not None:
        figures.append(("waveforms.png", plot_waveforms))
        figures.append(("waveforms_whole_run.png", lambda r: plot_waveforms(r, whole_run=True)))
    if result.mechanics is not None:
        figures += [("normal_force.png", plot_normal_force), ("tip_heights.png", plot_tip_heights),
                    ("energy.png", plot_energy)]
    paths = []
    for name, make in figures:
        fig = make(result)
        fig.savefig(out / name, dpi=120)
        plt.close(fig)
        paths.append(out / name)
    return paths
