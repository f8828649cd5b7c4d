"""Figures of a tribometer fit, after the paper's Fig. 2 (friction and resistance vs load) and Fig. 3 (mu vs current).

Built on `matplotlib.figure.Figure` directly (no pyplot, no global backend state), so
they work headless and can be saved or shown by the caller.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from coupling.laws.tribology.fits import TribometerFit, friction_band, mu_band, resistance_band

# The paper's symbols for 0, 1, 2, 5 A, then more for other levels.
MARKERS = ("o", "^", "*", "D", "s", "v", "P", "X")
FRICTION_RESISTANCE_PNG = "friction_resistance_vs_load.png"
#: Most data points drawn: a larger table is shown by a fixed random subset of this size
#: (seed 0; the fit uses every row), said in the figure's title.
MAX_PLOTTED_POINTS = 20_000
MU_CURRENT_PNG = "mu_vs_current.png"


def _illustrative_note(fit: TribometerFit) -> str:
    return " (ILLUSTRATIVE data)" if any("ILLUSTRATIVE" in line for line in fit.header) else ""


def plot_friction_resistance(fit: TribometerFit, df: pd.DataFrame) -> Figure:
    """Fig. 2: (a) friction force (N) and (b) contact resistance (mOhm) against load (N).

    One series per current level: data points, the chosen model's curve and its
    pointwise 95 % confidence band.
    """
    fig = Figure(figsize=(10.0, 4.2), layout="constrained")
    ax_f, ax_r = fig.subplots(1, 2)
    shown = ""
    left_out = sorted({o.row for o in fit.friction.outliers + fit.resistance.outliers})
    if left_out:
        df = df.drop(index=df.index[left_out])
        shown = f", {len(left_out)} outlier row(s) not shown"
    if len(df) > MAX_PLOTTED_POINTS:
        keep = np.sort(np.random.default_rng(0).choice(len(df), MAX_PLOTTED_POINTS, replace=False))
        shown += f", {MAX_PLOTTED_POINTS} of {len(df)} points shown"
        df = df.iloc[keep]
    lo, hi = fit.data_range.load_range_N
    loads = np.linspace(lo, hi, 100)
    current = np.abs(df["current_A"].to_numpy(float))
    for k, level in enumerate(fit.data_range.currents_A):
        color = f"C{k % 10}"
        marker = MARKERS[k % len(MARKERS)]
        sel = current == level
        label = f"{level:g} A"
        ax_f.plot(df["load_N"][sel], df["friction_N"][sel], marker, color=color, mfc="none", label=label)
        c, b_lo, b_hi = friction_band(fit, loads, level)
        ax_f.plot(loads, c, "-", color=color)
        ax_f.fill_between(loads, b_lo, b_hi, color=color, alpha=0.2, lw=0)
        ax_r.plot(df["load_N"][sel], 1e3 * df["resistance_ohm"][sel], marker, color=color, mfc="none", label=label)
        c, b_lo, b_hi = resistance_band(fit, loads, level)
        ax_r.plot(loads, 1e3 * c, "-", color=color)
        ax_r.fill_between(loads, 1e3 * b_lo, 1e3 * b_hi, color=color, alpha=0.2, lw=0)
    fr = fit.friction
    ax_f.set_title(f"(a) friction force: gamma = {fit.gamma:.3f}, mu(I) {fr.mu_selection.chosen.name}", fontsize=10)
    ax_f.set_xlabel("normal load F_n (N)")
    ax_f.set_ylabel("friction force F_t (N)")
    ax_r.set_title(f"(b) contact resistance: {fit.resistance.selection.chosen.name}", fontsize=10)
    ax_r.set_xlabel("normal load F_n (N)")
    ax_r.set_ylabel("contact resistance R_c (mOhm)")
    for ax in (ax_f, ax_r):
        ax.legend(title="current", fontsize=8)
        ax.grid(alpha=0.3)
    fig.suptitle(f"Tribometer fit, 95 % confidence bands{shown}{_illustrative_note(fit)}", fontsize=11)
    return fig


def plot_mu_current(fit: TribometerFit) -> Figure:
    """Fig. 3: mu (N^gamma) against current (A): per-current estimates with 95 % intervals,
    the chosen mu(I) model with its 95 % band."""
    fig = Figure(figsize=(5.5, 4.2), layout="constrained")
    ax = fig.subplots()
    levels = np.array([c.current_A for c in fit.friction.per_current])
    mu = np.array([c.mu for c in fit.friction.per_current])
    ci = np.array([c.ci95 for c in fit.friction.per_current])
    ax.errorbar(levels, mu, yerr=[mu - ci[:, 0], ci[:, 1] - mu], fmt="o", color="k", capsize=3,
                label="per-current estimate, 95 % CI")
    lo, hi = fit.data_range.current_range_A
    currents = np.linspace(lo, hi, 200)
    c, b_lo, b_hi = mu_band(fit, currents)
    chosen = fit.friction.mu_selection.chosen
    ax.plot(currents, c, "-", color="C0", label=f"{chosen.name} (chosen by {fit.friction.mu_selection.criterion})")
    ax.fill_between(currents, b_lo, b_hi, color="C0", alpha=0.2, lw=0, label="95 % band")
    ax.set_xlabel("current |I| (A)")
    ax.set_ylabel(f"mu (N^{fit.gamma:.2f})")
    ax.set_title(f"mu(I), gamma = {fit.gamma:.3f}{_illustrative_note(fit)}", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def save_plots(fit: TribometerFit, df: pd.DataFrame, out_dir) -> list[Path]:
    """Write both figures as PNG into out_dir (created if missing); returns the paths."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / FRICTION_RESISTANCE_PNG, out / MU_CURRENT_PNG]
    plot_friction_resistance(fit, df).savefig(paths[0], dpi=120)
    plot_mu_current(fit).savefig(paths[1], dpi=120)
    return paths
