"""PNG plots of a run (matplotlib, Agg): bounce window, whole run, log |V|, openings, mechanics.

Each panel is scaled to what it is for: the bounce window's voltage to the bounce (not to a
fly-off spike, which is marked where it is clipped), its current panel to the loop current
(spikes clipped and marked with their peak), tip heights to the tip that strikes. Legends
sit outside the axes.
"""

from __future__ import annotations

import json
import os
import types
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure  # figures drawn without pyplot: no GUI backend, no global state


def _subplots(*grid, figsize, **kw):
    """(figure, axes) like pyplot.subplots, on a standalone Agg-rendered Figure (pyplot's
    import alone cost 0.4-0.7 s of each run's start-up, measured in benchmarks/bench_startup.py)."""
    fig = Figure(figsize=figsize)
    return fig, fig.subplots(*grid, **kw)


LEGEND = dict(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, borderaxespad=0.0)


def _shade(ax, intervals, lo=None, hi=None, label="contact closed"):
    for k, (a, b) in enumerate(intervals):
        if hi is not None and a * 1e3 > hi or lo is not None and b * 1e3 < lo:
            continue
        ax.axvspan(a * 1e3, b * 1e3, color="tab:green", alpha=0.15, lw=0, label=label if k == 0 else None)


def bounce_window(result) -> tuple[float, float]:
    """ms: first make to the start of the final closure (or to the last break when the run
    ends open), with a margin; the whole run when nothing switches."""
    b = result.bounce
    t_end = result.scene.t_end
    ops = b.get("openings") or []
    first = b.get("first_make")
    start = first if first is not None else (ops[0]["start"] if ops else None)
    if start is None:
        return 0.0, t_end * 1e3
    if b.get("final_state") == "closed":
        end = b.get("last_make") or start
    else:
        end = ops[-1]["start"] if ops else start
    span = end - start
    pad = max(0.12 * span, 50e-6)
    return max(0.0, start - pad) * 1e3, min(t_end, end + pad) * 1e3


def _in(t_ms, window):
    return (t_ms >= window[0]) & (t_ms <= window[1])


def _clip_marks(ax, t_ms, y, top, color, unit):
    """Mark samples above the axis top with a triangle at the top edge and the largest value."""
    over = np.flatnonzero(y > top)
    if not len(over):
        return
    ax.plot(t_ms[over], np.full(len(over), top), "^", color=color, ms=4, clip_on=False,
            label=f"clipped (peak {np.max(y[over]):.3g} {unit})")


def _robust_top(values, floor):
    """An axis top for values that may hold a few spikes: 1.15 x their 99.5th percentile of |y|."""
    a = np.abs(values[np.isfinite(values)])
    return max(1.15 * float(np.percentile(a, 99.5)) if len(a) else 0.0, floor)


def plot_waveforms(result, whole_run: bool = False):
    """Contact voltage and currents (and, in the bounce window, contact resistance with the gap,
    and arc power) against time; closed intervals shaded."""
    w = result.waveforms
    b = result.bounce
    t = w.time.to_numpy() * 1e3
    window = (0.0, result.scene.t_end * 1e3) if whole_run else bounce_window(result)
    sel = _in(t, window)
    rows = 2 if whole_run else 4
    fig, axes = _subplots(rows, 1, sharex=True, figsize=(10, 2.4 * rows + 1.2))
    ax_v, ax_i = axes[0], axes[1]
    v = w.contact_voltage.to_numpy()
    ax_v.plot(t, v, lw=0.9, color="tab:blue", label="contact voltage")
    if whole_run:
        top = max(np.nanmax(np.abs(v[sel])) if sel.any() else 1.0, 1.0) * 1.08
    else:
        # the bounce's own peak, and the open-circuit voltage before the first make
        peak = b.get("peak_bounce_voltage") or 0.0
        first = b.get("first_make")
        k = int(np.searchsorted(t, first * 1e3, side="left")) - 1 if first is not None else -1
        top = 1.15 * max(peak, float(abs(v[k])) if k >= 0 else 0.0, 1.0)
        _clip_marks(ax_v, t[sel], np.abs(v[sel]), top, "tab:blue", "V")
    ax_v.set_ylim(-0.08 * top if np.nanmin(v[sel] if sel.any() else v) > -0.08 * top else -top, top)
    ax_v.set_ylabel("contact voltage (V)")

    loop = w.load_current.to_numpy() if "load_current" in w and np.all(np.isfinite(w.load_current)) else None
    contact = w.contact_current.to_numpy()
    arc = w.arc_current.to_numpy() if "arc_current" in w else np.zeros_like(t)
    if loop is not None:
        ax_i.plot(t, loop, lw=1.6, color="0.55", ls="--", label="load (loop)", zorder=1)
    ax_i.plot(t, contact, lw=1.0, color="tab:red", label="contact (metallic)", zorder=3)
    if np.any(arc != 0):
        ax_i.plot(t, arc, lw=1.0, color="tab:orange", label="arc", zorder=2)
    ref = loop if loop is not None else contact
    itop = _robust_top(ref[sel] if sel.any() else ref, 1e-6)
    for y, color in ((contact, "tab:red"), (arc, "tab:orange")):
        _clip_marks(ax_i, t[sel], np.abs(y[sel]), itop, color, "A")
    ax_i.set_ylim(-0.1 * itop, itop)
    ax_i.set_ylabel("current (A)")

    if not whole_run:
        ax_r = axes[2]
        r = w.contact_resistance.to_numpy()
        finite = np.isfinite(r) & (r > 0)
        ax_r.semilogy(t[finite], r[finite], ".", ms=1.5, color="tab:purple", label="contact resistance")
        ax_r.set_ylabel("R_c (ohm)")
        if "gap" in w:
            ax_g = ax_r.twinx()
            gap = w.gap.to_numpy() * 1e6
            ax_g.plot(t, gap, lw=0.9, color="tab:brown", label="gap")
            gsel = gap[sel] if sel.any() else gap
            ax_g.set_ylim(0, max(float(np.nanmax(gsel)) * 1.1, 1e-3))
            ax_g.set_ylabel("gap (um)")
            ax_r.plot([], [], lw=0.9, color="tab:brown", label="gap (right axis)")
        ax_p = axes[3]
        power = np.abs(v * arc)
        ax_p.plot(t, power, lw=0.9, color="tab:orange", label="arc power |V i_arc|")
        ax_p.set_ylim(0, _robust_top(power[sel] if sel.any() else power, 1e-9))
        _clip_marks(ax_p, t[sel], power[sel], ax_p.get_ylim()[1], "tab:orange", "W")
        ax_p.set_ylabel("arc power (W)")
    for ax in axes:
        _shade(ax, result.closed_intervals, *window)
        ax.grid(alpha=0.3)
        ax.legend(**(dict(LEGEND, bbox_to_anchor=(1.08, 1.0)) if not whole_run and ax is axes[2] else LEGEND))
    axes[-1].set_xlim(*window)
    axes[-1].set_xlabel("time (ms)")
    title = "whole run" if whole_run else "bounce window"
    peak = b.get("peak_bounce_voltage")
    final = b.get("peak_final_opening_voltage")
    settle = ("settled, settle time " + f"{b['settle_time'] * 1e3:.4g} ms") if b.get("settled") else (
        "not settled" + (" (ends open)" if b.get("final_state") == "open" else ""))
    ax_v.set_title(f"{title}: {b.get('bounces', 0)} bounce(s), {settle}; "
                   + (f"peak in bounces {peak:.3g} V" if peak is not None else "no bounce peak")
                   + (f", final opening {final:.3g} V" if final else "")
                   + f"; arc energy {b.get('arc_energy') or 0:.3g} J", fontsize=9)
    fig.tight_layout()
    return fig


def plot_log_voltage(result):
    """log10 |contact voltage| over the whole run: from the mV of a closed contact to the kV of
    an opening spike on one scale."""
    w = result.waveforms
    t = w.time.to_numpy() * 1e3
    v = np.abs(w.contact_voltage.to_numpy())
    fig, ax = _subplots(figsize=(10, 4))
    pos = v > 0
    ax.semilogy(t[pos], v[pos], lw=0.8, color="tab:blue", label="|contact voltage|")
    _shade(ax, result.closed_intervals)
    lo = max(np.nanmin(v[pos]) if pos.any() else 1e-6, 1e-9)
    ax.set_ylim(lo / 2, max(np.nanmax(v) * 2, lo * 10))
    ax.set_xlim(0, result.scene.t_end * 1e3)
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("|V| (V)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(**LEGEND)
    fig.tight_layout()
    return fig


def plot_openings(result):
    """Per-opening bars: open duration, peak voltage, arc energy (bounce openings and the final one)."""
    ops = result.openings
    fig, axes = _subplots(1, 3, figsize=(11, 3.6))
    if not len(ops):
        for ax in axes:
            ax.text(0.5, 0.5, "no openings", ha="center", va="center", transform=ax.transAxes)
        fig.tight_layout()
        return fig
    x = np.arange(1, len(ops) + 1)
    colors = ["tab:blue" if k == "bounce" else "tab:red" for k in ops.kind]
    for ax, column, scale, label in ((axes[0], "open_duration", 1e6, "open duration (us)"),
                                     (axes[1], "peak_voltage", 1.0, "peak voltage (V)"),
                                     (axes[2], "arc_energy", 1e3, "arc energy (mJ)")):
        values = ops[column].astype(float).fillna(0.0).to_numpy() * scale
        ax.bar(x, values, color=colors)
        ax.set_xticks(x)
        ax.set_xlabel("opening")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3, axis="y")
    from matplotlib.patches import Patch

    fig.legend(handles=[Patch(color="tab:blue", label="bounce opening"), Patch(color="tab:red", label="final opening")],
               loc="upper center", ncol=2, fontsize=8)
    fig.tight_layout(rect=(0, 0, 1, 0.92))
    return fig


def _per_tip(result, column: str, scale: float, ylabel: str, window: bool):
    """A history column of both tips against time (ms)."""
    h = result.mechanics.history
    fig, ax = _subplots(figsize=(10, 4))
    for i in range(2):
        ax.plot(h.time * 1e3, h[f"{column}_{i}"] * scale, lw=0.9, label=f"tip {i}")
    ax.set_xlabel("time (ms)")
    ax.set_ylabel(ylabel)
    if window and result.waveforms is not None:
        ax.set_xlim(*bounce_window(result))
    ax.grid(alpha=0.3)
    ax.legend(**LEGEND)
    fig.tight_layout()
    return fig, ax


def plot_normal_force(result):
    """Normal force of each tip vs time (mechanics history), over the bounce window."""
    return _per_tip(result, "normal_force", 1.0, "normal force (N)", window=True)[0]


def plot_tip_heights(result):
    """Height of each tip's lowest point above the block vs time (negative: penetration),
    scaled to the tip that strikes (the other may be off scale: its legend entry says so)."""
    h = result.mechanics.history
    fig, ax = _per_tip(result, "tip_height", 1e3, "tip height (mm)", window=False)
    ax.axhline(0.0, color="k", lw=0.6)
    heights = [h[f"tip_height_{i}"].to_numpy() * 1e3 for i in range(2)]
    striking = int(np.argmin([np.min(x) for x in heights]))
    y = heights[striking]
    top = max(float(np.max(y)), 1e-6) * 1.1
    bottom = min(float(np.min(y)) * 1.1, -0.02 * top)
    ax.set_ylim(bottom, top)
    other = heights[1 - striking]
    if np.min(other) > top or np.max(other) < bottom:
        handles, labels = ax.get_legend_handles_labels()
        labels[1 - striking] += f" (off scale: {np.min(other):.3g}-{np.max(other):.3g} mm)"
        ax.legend(handles, labels, **LEGEND)
        fig.tight_layout()
    return fig


def plot_energy(result):
    """Energy audit vs time: where the initial energy went (J), and the residual."""
    en = result.mechanics.energy_table
    fig, (ax, ax_r) = _subplots(2, 1, sharex=True, figsize=(10, 6), height_ratios=(3, 1))
    t = en.time * 1e3
    parts = ["kinetic", "elastic", "contact_stored", "normal_dissipation", "friction_dissipation",
             "modal_dissipation"]
    ax.stackplot(t, [en[p] for p in parts], labels=parts, alpha=0.8)
    ax.plot(t, -en.potential, color="k", lw=1.0, ls="--", label="- potential change")
    ax.set_ylabel("energy (J)")
    ax.legend(**LEGEND)
    ax.grid(alpha=0.3)
    ax_r.plot(t, en.residual, color="tab:red", lw=0.9)
    ax_r.set_ylabel("residual (J)")
    ax_r.set_xlabel("time (ms)")
    ax_r.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def plot_accuracy(result):
    """The contact's closed intervals of the run and of every rerun of ``run --check``
    (refinements, then the input-perturbed runs aligned on the first make), one row each,
    over the switching window: where the sequences part is where the prediction ends."""
    acc = result.accuracy
    rows = [("this run", acc["closed"], "tab:green")]
    rows += [(e["name"], e["closed"], "tab:blue") for e in acc["refinements"] if "closed" in e]
    rows += [(e["name"] + " (aligned)", e["closed"], "tab:orange") for e in acc.get("sensitivity", []) if "closed" in e]
    fig, ax = _subplots(figsize=(10, 0.9 + 0.42 * len(rows)))
    starts = [iv[0][0] for _, iv, _ in rows if iv]
    ends = [iv[-1][0] if len(iv) > 1 else iv[0][1] for _, iv, _ in rows if iv]  # the last make
    for k, (label, intervals, color) in enumerate(rows):
        y = len(rows) - 1 - k
        ax.broken_barh([(a * 1e3, (b - a) * 1e3) for a, b in intervals], (y - 0.35, 0.7), color=color)
    ax.set_yticks(range(len(rows)), [label for label, _, _ in reversed(rows)], fontsize=8)
    if starts:
        lo, hi = min(starts), max(ends)
        pad = max(0.08 * (hi - lo), 50e-6)
        ax.set_xlim((lo - pad) * 1e3, (hi + pad) * 1e3)
    ax.set_ylim(-0.6, len(rows) - 0.4)
    ax.set_xlabel("time (ms)")
    ax.set_title(f"contact closed, per run of --check: {acc['status']}", fontsize=9)
    ax.grid(alpha=0.3, axis="x")
    fig.tight_layout()
    return fig


def save_plots(result, out_dir) -> list[Path]:
    """Write the plots that apply to this run's kind into out_dir; returns their paths."""
    out = Path(out_dir)
    figures = []
    if result.waveforms is not None and len(result.waveforms) > 1:  # (a run that failed before the circuit started has none)
        figures.append(("waveforms.png", plot_waveforms))
        figures.append(("waveforms_whole_run.png", lambda r: plot_waveforms(r, whole_run=True)))
        figures.append(("contact_voltage_log.png", plot_log_voltage))
        figures.append(("openings.png", plot_openings))
    if result.mechanics is not None:
        figures += [("normal_force.png", plot_normal_force), ("tip_heights.png", plot_tip_heights),
                    ("energy.png", plot_energy)]
    if (getattr(result, "accuracy", None) or {}).get("closed") is not None:
        figures.append(("accuracy.png", plot_accuracy))
    paths = []
    for name, make in figures:
        fig = make(result)
        tmp = out / f".{name}.tmp"
        fig.savefig(tmp, dpi=110, format="png")
        os.replace(tmp, out / name)  # a reader of the folder never sees half a picture
        paths.append(out / name)
    return paths


def stored_result(folder) -> types.SimpleNamespace:
    """A result folder read back with what the plots use: summary.json, waveforms.parquet
    (or .csv), openings.csv, history.csv (its energy columns give the energy plot). The
    mechanics curves are those of history.csv, thinned as [output] history_resolution says.
    FileNotFoundError when the folder holds no summary.json."""
    import pandas as pd

    from coupling.core.metrics import merge_intervals

    folder = Path(folder)
    summary = json.loads((folder / "summary.json").read_text())
    bounce = summary.get("bounce") or {}
    waves = None
    if (folder / "waveforms.parquet").is_file():
        waves = pd.read_parquet(folder / "waveforms.parquet")
    elif (folder / "waveforms.csv").is_file():
        waves = pd.read_csv(folder / "waveforms.csv")
    mechanics = None
    if (folder / "history.csv").is_file():
        history = pd.read_csv(folder / "history.csv")
        energy = [c for c in ("time", "kinetic", "elastic", "potential", "contact_stored", "normal_dissipation",
                              "friction_dissipation", "modal_dissipation", "spring_stored", "load_dissipation",
                              "work_in", "residual") if c in history]
        mechanics = types.SimpleNamespace(history=history, energy_table=history[energy])
    ends = [float(f.time.iloc[-1]) for f in (waves, mechanics and mechanics.history) if f is not None and len(f)]
    t_end = max(ends, default=0.0)
    if "contacts" in summary:
        closed = merge_intervals((c["t_start"], c["t_end"] if c["t_end"] is not None else t_end)
                                 for c in summary["contacts"])
    else:  # a prescribed schedule: closed from the first make, between the openings
        closed, start = [], bounce.get("first_make")
        for op in bounce.get("openings") or []:
            if start is not None:
                closed.append((start, op["start"]))
            start = op["end"] if op.get("reclosed") else None
        if start is not None:
            closed.append((start, t_end))
    openings = pd.DataFrame(bounce.get("openings") or [],
                            columns=["start", "end", "open_duration", "reclosed", "kind", "current_at_break",
                                     "peak_voltage", "arc_duration", "arc_energy"])
    scene = types.SimpleNamespace(name=summary.get("scene", "run"), t_end=t_end)
    return types.SimpleNamespace(scene=scene, summary=summary, bounce=bounce, waveforms=waves, openings=openings,
                                 mechanics=mechanics, closed_intervals=closed, accuracy=summary.get("accuracy"))
