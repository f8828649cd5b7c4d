"""Plots of a sweep (matplotlib, Agg, no pyplot): a metric against one or two parameters,
a metric as a map over two parameters, and overlays of the waveforms of selected runs.

    from coupling.app.sweep import read_results
    from coupling.app.sweep_plots import plot_metric, plot_map, plot_overlay
    df = read_results("out/")
    plot_metric(df, "bounce.peak_contact_voltage", "circuit.snubber.capacitance",
                by="circuit.snubber.resistance").savefig("peak.png")
    plot_overlay("out/", df.run_id[:4], "contact_voltage", label=["circuit.snubber.capacitance"])

Every function returns a matplotlib Figure; only runs with status "ok" are drawn. Every
axis, colour bar and legend entry names its quantity and unit from one table
(coupling.app.quantities: summary keys, scene keys, waveform columns).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from coupling.app.panels import merged, panel_of
from coupling.app.quantities import label as _label
from coupling.app.quantities import quantity, value_text


def _figure(size=(7.5, 4.8)):
    from matplotlib.figure import Figure

    return Figure(figsize=size, layout="constrained")


def _ok(df, *columns):
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise ValueError(f"no column {missing[0]!r} in the sweep results; columns: {', '.join(df.columns)}")
    return df[df.status == "ok"] if "status" in df.columns else df


def _si_ticks(axis, values) -> None:
    """SI prefixes on the ticks ("470n", "2.2k") where the values are far from 1: the
    label gives the unit."""
    v = np.abs(np.asarray(values, float))
    v = v[np.isfinite(v) & (v > 0)]
    if len(v) and (v.max() < 1e-2 or v.min() >= 1e4):
        from matplotlib.ticker import EngFormatter

        axis.set_major_formatter(EngFormatter(sep=""))


_PREFIX = {-12: "p", -9: "n", -6: "\u00b5", -3: "m", 0: "", 3: "k", 6: "M", 9: "G"}


def _number(value: float) -> str:
    """A cell's value to 3 digits, with an SI prefix like the axes' ("774\u00b5")."""
    if not np.isfinite(value) or value == 0.0:
        return f"{value:.3g}"
    e = int(np.clip(np.floor(np.log10(abs(value)) / 3.0) * 3, -12, 9))
    return f"{value / 10.0 ** e:.3g}{_PREFIX[e]}"


def _log_axis(values) -> bool:
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    return len(v) > 1 and np.all(v > 0) and v.max() / v.min() >= 20.0


def _name(key: str, labels: dict | None) -> str:
    """The axis label of a column: ``labels`` first (a column you derived), else the unit table."""
    return (labels or {}).get(key) or _label(key)


def plot_metric(df, metric: str, x: str, *, by: str | None = None, limit: float | None = None,
                labels: dict | None = None):
    """``metric`` against parameter ``x``; with ``by``, one line per value of that second
    parameter. ``limit``: a horizontal line (a design limit, in the metric's unit). Log
    axes where values span more than a factor 20. ``labels``: axis labels for columns the
    unit table (coupling.app.quantities) does not know, e.g. {"bounce_ms": "bounce time (ms)"}."""
    ok = _ok(df, metric, x, *([by] if by else []))
    fig = _figure()
    ax = fig.add_subplot()
    groups = [(None, ok)] if by is None else list(ok.groupby(by, sort=True))
    for value, part in groups:
        part = part.sort_values(x)
        ax.plot(part[x], part[metric], "o-", ms=4, lw=1.2, label=None if by is None else value_text(by, value))
    if limit is not None:
        q = quantity(metric)
        ax.axhline(limit, color="k", ls="--", lw=0.9,
                   label=f"limit {limit:g}" + (f" {q.unit}" if q is not None and q.unit != "-" else ""))
    if _log_axis(ok[x]):
        ax.set_xscale("log")
    if _log_axis(ok[metric]):
        ax.set_yscale("log")
    ax.set_xlabel(_name(x, labels))
    ax.set_ylabel(_name(metric, labels))
    _si_ticks(ax.xaxis, ok[x])
    _si_ticks(ax.yaxis, ok[metric])
    ax.grid(alpha=0.3, which="both")
    if by is not None or limit is not None:
        ax.legend(fontsize=8)
    return fig


def plot_map(df, metric: str, x: str, y: str, *, cmap: str = "viridis", labels: dict | None = None):
    """``metric`` coloured over the (x, y) plane: cells for a grid design, points for a
    sampled one. ``labels`` as for plot_metric."""
    ok = _ok(df, metric, x, y)
    fig = _figure()
    ax = fig.add_subplot()
    xs, ys = np.unique(ok[x].to_numpy(float)), np.unique(ok[y].to_numpy(float))
    table = ok.pivot_table(index=y, columns=x, values=metric, aggfunc="mean")
    if len(xs) * len(ys) == len(ok) and table.notna().all().all() and len(xs) > 1 and len(ys) > 1:
        mesh = ax.pcolormesh(_edges(xs), _edges(ys), table.to_numpy(float), cmap=cmap, shading="flat")
        for (i, yv) in enumerate(ys):
            for (j, xv) in enumerate(xs):
                ax.text(xv, yv, _number(table.iloc[i, j]), ha="center", va="center", fontsize=7, color="w")
    else:
        mesh = ax.scatter(ok[x], ok[y], c=ok[metric], cmap=cmap, s=40)
    bar = fig.colorbar(mesh, ax=ax, label=_name(metric, labels))
    ax.set_xlabel(_name(x, labels))
    ax.set_ylabel(_name(y, labels))
    _si_ticks(ax.xaxis, xs)
    _si_ticks(ax.yaxis, ys)
    _si_ticks(bar.ax.yaxis, ok[metric])
    return fig


def _edges(values: np.ndarray) -> np.ndarray:
    mid = 0.5 * (values[1:] + values[:-1])
    return np.concatenate([[values[0] - (mid[0] - values[0])], mid, [values[-1] + (values[-1] - mid[-1])]])


def plot_overlay(out_dir, run_ids, column: str = "contact_voltage", *, label: list[str] | None = None,
                 window: tuple[float, float] | None = None, results=None):
    """The ``column`` waveform of each run in ``run_ids`` over time (ms), one line each, from
    the waveforms the sweep kept (sweep waveforms = true). label: parameters to name the
    lines by; window: (t0, t1) in s."""
    from coupling.app.sweep import read_results, read_waveforms

    rows = None
    if label:
        df = results if results is not None else read_results(out_dir)
        rows = df.set_index("run_id")
    runs = []
    for run_id in run_ids:
        w = read_waveforms(out_dir, run_id)
        if column not in w.columns:
            raise ValueError(f"run {run_id}: no column {column!r} in its waveforms; kept: {', '.join(w.columns)}")
        if window is not None:
            w = w[(w.time >= window[0]) & (w.time <= window[1])]
        text = run_id
        if rows is not None and run_id in rows.index:
            text = ", ".join(value_text(p, rows.loc[run_id, p]) for p in label)
        runs.append((text, w.time.to_numpy(float), w[column].to_numpy(float)))
    fig = _figure()
    ax = fig.add_subplot()
    panel = panel_of(column)
    if panel is None or not runs:
        for text, t, y in runs:
            ax.plot(t * 1e3, y, lw=0.9, label=text)
        ax.set_ylabel(_label(column))
    else:  # scaled as the run's own waveform panel is (coupling.app.panels)
        from coupling.app.plots import draw_panel

        axes = merged(panel, [(t, [(column, y)]) for _, t, y in runs])
        for k, ((text, t, y), rng) in enumerate(zip(runs, axes)):
            draw_panel(ax, panel, [(column, text, f"C{k}")], {column: y}, t * 1e3, rng, notes=k == 0,
                       band_row=(k, len(runs)), peaks=len(runs) == 1)
    ax.set_xlabel("time (ms)")
    ax.grid(alpha=0.3)
    fig.legend(loc="outside lower center", fontsize=7, ncol=2)  # below the axes: the open band stays clear
    return fig


def save(fig, path) -> Path:
    """Write a figure as PNG (dpi 120) and free it."""
    path = Path(path)
    fig.savefig(path, dpi=120)
    fig.clear()
    return path
