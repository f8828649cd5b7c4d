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


def _open_spans(t_ms, idx):
    """(start, end) ms of the runs of consecutive sample indices ``idx``: from a run's first
    sample to the sample after its last (the state holds until the next sample changes it)."""
    if not len(idx):
        return []
    breaks = np.flatnonzero(np.diff(idx) > 1)
    starts = np.r_[idx[0], idx[breaks + 1]]
    ends = np.minimum(np.r_[idx[breaks], idx[-1]] + 1, len(t_ms) - 1)
    return [(t_ms[a], t_ms[b]) for a, b in zip(starts, ends)]


def _resistance_ticks(ax, rng, factor):
    """Numbers on the data range, "open" on the band above it (panels.resistance_ticks)."""
    from matplotlib.ticker import NullLocator

    from coupling.app.panels import resistance_ticks

    ticks = resistance_ticks(rng)

    def text(v):
        e = np.log10(v)
        return f"$10^{{{int(round(e))}}}$" if abs(e - round(e)) < 1e-9 else f"{v:g}"

    ax.set_yticks([v * factor for v, _ in ticks], [s or text(v * factor) for v, s in ticks])
    ax.yaxis.set_minor_locator(NullLocator())


def draw_panel(ax, panel, traces, cols, t_ms, rng, *, notes: bool = True, band_row: tuple = (0, 1),
               peaks: bool = True):
    """One panel (coupling.app.panels) on ``ax``: its traces (column, label, colour) from
    ``cols`` against ``t_ms``, in the panel's PNG unit; the axis ``rng`` (panels.axis):
    limits, clipped samples marked at the edge with their peak, the open band.
    ``notes``: label the marks in the legend (once per axis when several runs share it);
    ``band_row``: (k, n) the k-th of n rows of the open band (one per run); ``peaks``: the
    marks' legend entries give the peak (one run per axis)."""
    from coupling.app.panels import dashed

    unit, factor = panel.png_unit
    unit = unit or panel.quantity.unit
    for column, label, color in traces:
        y = cols[column] * factor
        if panel.scale == "resistance":
            shown = np.isfinite(y) & (y > 0) & (y <= rng.hi * factor)
            ax.semilogy(t_ms[shown], y[shown], ".", ms=1.5, color=color, label=label)
        elif rng.log and panel.key == "contact_resistances":  # each contact's: broken where it is open
            ax.semilogy(t_ms, np.where(np.isfinite(y) & (y > 0), y, np.nan), lw=0.8, color=color, label=label)
        elif rng.log:
            pos = np.isfinite(y) & (y > 0)
            ax.semilogy(t_ms[pos], y[pos], lw=0.8, color=color, label=label)
        elif dashed(panel, column):
            ax.plot(t_ms, y, lw=1.6, color=color, label=label, ls="--", zorder=1)
        else:
            ax.plot(t_ms, y, lw=1.0, color=color, label=label, zorder=3)
    top = rng.hi * factor
    colors = {c: col for c, _, col in traces}
    for column, idx, peak in rng.clipped:
        if panel.scale == "resistance":  # inside the axis, under the open band
            ax.plot(t_ms[idx], np.full(len(idx), top), "v", color=colors.get(column), ms=4,
                    label=None if not notes else "above range (onset)" + (
                        f" (peak {peak * factor:.3g} {unit})" if peaks else ""))
            continue
        up = cols[column][idx] > 0.0
        edge = np.where(up, top, rng.lo * factor)
        label = None if not notes else "clipped" + (f" (peak {peak * factor:.3g} {unit})" if peaks else "")
        for mask, marker in ((up, "^"), (~up, "v")):
            if mask.any():
                ax.plot(t_ms[idx][mask], edge[mask], marker, color=colors.get(column), ms=4, clip_on=False,
                        label=label)
                label = None
    if rng.band is not None:
        b0, b1 = rng.band[0] * factor, rng.band[1] * factor
        ax.axhspan(b0, b1, color="0.88", lw=0, zorder=0)
        k, n = band_row
        y = b0 * (b1 / b0) ** ((k + 0.5) / n)
        color = "0.35" if n == 1 else traces[0][2]
        for j, (a, b) in enumerate(_open_spans(t_ms, rng.open)):
            ax.plot([a, b], [y, y], color=color, lw=4 if n == 1 else 2.5, solid_capstyle="butt",
                    label="open (no conduction)" if j == 0 and notes else None)
        _resistance_ticks(ax, rng, factor)
        ax.set_ylim(rng.lo * factor, b1)
    else:
        ax.set_ylim(rng.lo * factor, rng.top * factor)
    ax.set_ylabel(panel.quantity.label(unit))


def plot_waveforms(result, whole_run: bool = False):
    """The waveform panels of coupling.app.panels (voltage, |V|, currents, contact
    resistance, normal force per contact point, gap, arc power, probes: those the run has)
    against time over the bounce window (or the whole run); closed intervals shaded."""
    from coupling.app.panels import axis, columns_of, panels_for

    b = result.bounce or {}  # (an actuator alone has no contact to bounce)
    cols = columns_of(result)
    t_s = cols["time"]
    t = t_s * 1e3
    window = (0.0, result.scene.t_end * 1e3) if whole_run else bounce_window(result)
    sel = _in(t, window)
    panels = panels_for(cols)
    fig, axes = _subplots(len(panels), 1, sharex=True, figsize=(10, 1.9 * len(panels) + 1.0), squeeze=False)
    axes = axes[:, 0]
    for ax, (panel, traces) in zip(axes, panels):
        rng = axis(panel, t_s, [(c, cols[c]) for c, _, _ in traces], sel, bounce=b, whole_run=whole_run,
                   closed_intervals=result.closed_intervals)
        draw_panel(ax, panel, traces, cols, t, rng)
        _shade(ax, result.closed_intervals, *window)
        ax.grid(alpha=0.3)
        ax.legend(**LEGEND)
    axes[-1].set_xlim(*window)
    axes[-1].set_xlabel("time (ms)")
    title = "whole run" if whole_run else "bounce window"
    if "contact_voltage" not in cols:
        axes[0].set_title(f"{title}: coil and armature (no contact)", fontsize=9, loc="left")
        fig.tight_layout()
        return fig
    peak = b.get("peak_bounce_voltage")
    final = b.get("peak_final_opening_voltage")
    settle = ("settled, settle time " + f"{b['settle_time'] * 1e3:.4g} ms") if b.get("settled") else (
        "not settled" + (" (ends open)" if b.get("final_state") == "open" else ""))
    axes[0].set_title(f"{title}: {b.get('bounces', 0)} bounce(s), {settle}; "
                      + (f"peak in bounces {peak:.3g} V" if peak is not None else "no bounce peak")
                      + (f", final opening {final:.3g} V" if final else "")
                      + f"; arc energy {b.get('arc_energy') or 0:.3g} J", fontsize=9, loc="left")
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
    ax.set_ylabel("|contact voltage| (V)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(**LEGEND)
    fig.tight_layout()
    return fig


def plot_openings(result):
    """Per-opening bars: open duration, peak voltage, arc energy (bounce openings and the final one)."""
    ops = result.openings
    fig, axes = _subplots(1, 3, figsize=(11, 3.6))
    bars = ((axes[0], "open_duration", 1e6, "open duration (us)"), (axes[1], "peak_voltage", 1.0, "peak voltage (V)"),
            (axes[2], "arc_energy", 1e3, "arc energy (mJ)"))
    for ax, _, _, label in bars:
        ax.set_xlabel("opening, in order (-)")
        ax.set_ylabel(label)
    if not len(ops):
        for ax in axes:
            ax.text(0.5, 0.5, "no openings", ha="center", va="center", transform=ax.transAxes)
        fig.tight_layout()
        return fig
    x = np.arange(1, len(ops) + 1)
    colors = ["tab:blue" if k == "bounce" else "tab:red" for k in ops.kind]
    for ax, column, scale, _ in bars:
        values = ops[column].astype(float).fillna(0.0).to_numpy() * scale
        ax.bar(x, values, color=colors)
        ax.set_xticks(x)
        ax.grid(alpha=0.3, axis="y")
    from matplotlib.patches import Patch

    fig.legend(handles=[Patch(color="tab:blue", label="bounce opening"), Patch(color="tab:red", label="final opening")],
               loc="upper center", ncol=2, fontsize=8)
    fig.tight_layout(rect=(0, 0, 1, 0.92))
    return fig


ABSENT_HEIGHT = 1e3  # m: mech's history holds this height, at every record, for a row without a contact point


def contact_points(history) -> list[int]:
    """The contact points a run has (0, 1). mech's history keeps two rows of contact columns
    (``_0``, ``_1``); a row the scene has no contact point for (a single rivet, an end cap
    inside the clamp) holds the height ABSENT_HEIGHT at every record and no force."""
    return [i for i in range(2) if f"tip_height_{i}" in history
            and not np.all(history[f"tip_height_{i}"].to_numpy() == ABSENT_HEIGHT)]


def _touches(history, i: int) -> bool:
    return bool(np.any(history[f"normal_force_{i}"].to_numpy() > 0.0))


def plot_normal_force(result):
    """Normal force of each contact point that touches vs time (mechanics history), over
    the bounce window; one that never touches is named, not drawn as a zero curve."""
    from coupling.app.quantities import WAVEFORM

    h = result.mechanics.history
    fig, ax = _subplots(figsize=(10, 4))
    points = contact_points(h)
    for i in points:
        if _touches(h, i):
            ax.plot(h.time * 1e3, h[f"normal_force_{i}"], lw=0.9, label=f"contact point {i}")
        else:
            ax.plot([], [], " ", label=f"contact point {i}: never touches")
    if not any(_touches(h, i) for i in points):
        ax.text(0.5, 0.5, "no contact", ha="center", va="center", transform=ax.transAxes)
    ax.set_xlabel("time (ms)")
    ax.set_ylabel(WAVEFORM["normal_force"].label())
    if result.waveforms is not None and len(result.waveforms) > 1:
        ax.set_xlim(*bounce_window(result))
    ax.grid(alpha=0.3)
    if points:
        ax.legend(**LEGEND)
    fig.tight_layout()
    return fig


def plot_tip_heights(result):
    """Height of each contact point's lowest point above the block vs time (negative:
    penetration), scaled to the one that strikes; another one off that scale has its real
    range in its legend entry."""
    from coupling.app.quantities import WAVEFORM

    h = result.mechanics.history
    fig, ax = _subplots(figsize=(10, 4))
    points = contact_points(h)
    heights = {i: h[f"tip_height_{i}"].to_numpy() * 1e3 for i in points}
    ax.axhline(0.0, color="k", lw=0.6)
    if heights:
        striking = min(heights, key=lambda i: float(np.min(heights[i])))
        y = heights[striking]
        top = max(float(np.max(y)), 1e-6) * 1.1
        bottom = min(float(np.min(y)) * 1.1, -0.02 * top)
        for i, z in heights.items():
            label = f"contact point {i}"
            if np.min(z) > top or np.max(z) < bottom:
                label += f" (off scale: {np.min(z):.3g} to {np.max(z):.3g} mm)"
            if not _touches(h, i):
                label += ", never touches"
            ax.plot(h.time * 1e3, z, lw=0.9, label=label)
        ax.set_ylim(bottom, top)
        ax.legend(**LEGEND)
    ax.set_xlabel("time (ms)")
    ax.set_ylabel(WAVEFORM["tip_height"].label("mm"))
    ax.grid(alpha=0.3)
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
    waves = result.waveforms
    # an actuator alone (a coil, its magnet and armature, no contact): its panels over the run
    contact = waves is None or "contact_voltage" in waves.columns
    if waves is not None and len(waves) > 1 and not contact:
        figures.append(("waveforms.png", lambda r: plot_waveforms(r, whole_run=True)))
    elif waves is not None and len(waves) > 1:  # (a run that failed before the circuit started has none)
        figures.append(("waveforms.png", plot_waveforms))
        figures.append(("waveforms_whole_run.png", lambda r: plot_waveforms(r, whole_run=True)))
        figures.append(("contact_voltage_log.png", plot_log_voltage))
        figures.append(("openings.png", plot_openings))
    if result.mechanics is not None and contact:
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
    if "per_contact" in summary:  # several circuit contacts: the switch's, as the run read them
        from coupling.core.metrics import intersection

        own = [merge_intervals(map(tuple, c["closed_intervals"])) for c in summary["per_contact"].values()]
        closed = own[0]
        if summary.get("arrangement") == "series":  # a bridge: while every one is closed
            for other in own[1:]:
                closed = intersection(closed, other)
    elif "contacts" in summary:
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
