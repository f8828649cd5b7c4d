"""waveforms.html: a self-contained, zoomable page of a run's waveforms (plotly, imported lazily).

Why plotly: it writes one standalone HTML file with its JavaScript embedded
(``include_plotlyjs=True``: the page works offline, nothing is fetched), zooms and pans
with the mouse (box zoom on the time axis from the whole run down to nanoseconds, double
click to reset, linked time axes on every panel), is maintained (plotly.py, MIT) and needs
no server. Time is in seconds with SI prefixes on the axis (ms, us, ns).

Decimation (``decimate``): a trace with more than ``max_points`` samples is cut into
max_points / 2 buckets of equal time width, and each bucket keeps its first, last, smallest
and largest sample (in time order). Spikes survive (each bucket's extremes are kept), and a
bucket with at most four samples keeps all of them; zoomed in below a bucket's width the
page shows that envelope, not every sample (the CSV/parquet files have every sample). The
default limit (200 000 points per trace) leaves a coupled run of typical length whole.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

MAX_POINTS = 200_000
PLOTLY_MISSING = "skipped: plotly is not installed (pip install plotly, or switchsim with its default dependencies)"


def decimate(t: np.ndarray, y: np.ndarray, max_points: int = MAX_POINTS) -> np.ndarray:
    """Indices of the samples to keep (sorted): all of them up to max_points, else per time
    bucket (max_points // 2 buckets) the first, last, min and max sample."""
    n = len(t)
    if n <= max_points:
        return np.arange(n)
    buckets = max(1, max_points // 2)
    edges = np.linspace(t[0], t[-1], buckets + 1)
    which = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, buckets - 1)
    starts = np.flatnonzero(np.r_[True, which[1:] != which[:-1]])
    ends = np.r_[starts[1:], n]
    keep = [starts, ends - 1]
    finite = np.where(np.isfinite(y), y, np.nan)
    # per bucket argmin/argmax via reduceat on (value, index) ordering
    lo = np.empty(len(starts), int)
    hi = np.empty(len(starts), int)
    for k, (a, b) in enumerate(zip(starts, ends)):
        seg = finite[a:b]
        if np.all(np.isnan(seg)):
            lo[k] = hi[k] = a
        else:
            lo[k] = a + int(np.nanargmin(seg))
            hi[k] = a + int(np.nanargmax(seg))
    keep += [lo, hi]
    return np.unique(np.concatenate(keep))


def _rows(w):
    """(title, [(column, label)], log) per panel, for the columns the waveform has."""
    rows = [("contact voltage (V)", [("contact_voltage", "contact voltage")], False),
            ("|contact voltage| (V, log)", [("abs_voltage", "|contact voltage|")], True),
            ("current (A)", [(c, c.replace("_", " ")) for c in ("load_current", "contact_current", "arc_current")
                             if c in w and np.isfinite(w[c]).all()], False)]
    if "contact_resistance" in w:
        rows.append(("contact resistance (ohm, log)", [("contact_resistance", "R_c")], True))
    if "gap" in w:
        rows.append(("gap (m)", [("gap", "gap")], False))
    probes = [c for c in w.columns if c[:2].lower() in ("v(", "i(")]
    if probes:
        rows.append(("probes (V, A)", [(c, c) for c in probes], False))
    return rows


def waveform_figure(result, max_points: int = MAX_POINTS):
    """The plotly figure of a run's waveforms (one panel per quantity, linked time axes)."""
    from plotly.subplots import make_subplots
    import plotly.graph_objects as go

    w = result.waveforms.copy()
    w["abs_voltage"] = np.abs(w.contact_voltage)
    rows = _rows(w)
    fig = make_subplots(rows=len(rows), cols=1, shared_xaxes=True, vertical_spacing=0.02,
                        subplot_titles=[r[0] for r in rows])
    t = w.time.to_numpy()
    for k, (_, columns, log) in enumerate(rows, start=1):
        for column, label in columns:
            y = w[column].to_numpy(dtype=float)
            if log:
                y = np.where((y > 0) & np.isfinite(y), y, np.nan)
            idx = decimate(t, y, max_points)
            fig.add_trace(go.Scattergl(x=t[idx], y=y[idx], mode="lines", name=label, line=dict(width=1)),
                          row=k, col=1)
        if log:
            fig.update_yaxes(type="log", row=k, col=1)
    for a, b in result.closed_intervals:
        fig.add_vrect(x0=a, x1=b, fillcolor="green", opacity=0.12, line_width=0)
    fig.update_xaxes(exponentformat="SI", ticksuffix="s", showspikes=True, spikemode="across")
    fig.update_xaxes(title_text="time", row=len(rows), col=1)
    name = getattr(result.scene, "name", "run")
    fig.update_layout(height=230 * len(rows) + 120, title=f"{name}: waveforms (drag to zoom, double-click to reset)",
                      hovermode="x unified", legend=dict(orientation="h", y=1.0, yanchor="bottom"),
                      margin=dict(l=70, r=20, t=110, b=50))
    return fig


def write_waveform_html(result, path, max_points: int = MAX_POINTS) -> str:
    """Write the page; returns "written" or why it was skipped (plotly absent, no waveforms)."""
    if result.waveforms is None or not len(result.waveforms):
        return "skipped: no waveforms"
    try:
        import plotly  # noqa: F401
    except ImportError:
        return PLOTLY_MISSING
    fig = waveform_figure(result, max_points)
    fig.write_html(Path(path), include_plotlyjs=True, full_html=True, include_mathjax=False,
                   config={"scrollZoom": True, "displaylogo": False})
    return "written"
