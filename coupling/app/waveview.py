"""waveforms.html: a self-contained, zoomable page of a run's waveforms (plotly.js).

Why plotly: one standalone HTML file with its JavaScript embedded (the page works
offline, nothing is fetched), zoom and pan with the mouse (box zoom on the time axis from
the whole run down to nanoseconds, double click to reset, linked time axes on every
panel), maintained (plotly, MIT), no server. Time is in seconds with SI prefixes on the
axis (ms, us, ns).

The page is written here directly: plotly.min.js from the installed plotly package's
file, then one ``Plotly.newPlot`` call with the traces (samples as base64 float64, the
encoding plotly.py itself uses) and a layout of stacked panels on linked time axes, as
plotly's make_subplots lays them out. Importing plotly's Python side and building its
figure objects cost ~0.5 s of every run for the same page.

Decimation (``decimate``): a trace with more than ``max_points`` samples is cut into
max_points / 2 buckets of equal time width, and each bucket keeps its first, last, smallest
and largest sample (in time order). Spikes survive (each bucket's extremes are kept), and a
bucket with at most four samples keeps all of them; zoomed in below a bucket's width the
page shows that envelope, not every sample (the CSV/parquet files have every sample). The
default limit (200 000 points per trace) leaves a coupled run of typical length whole.
"""

from __future__ import annotations

import base64
import importlib.util
import json
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


def _rows(w: dict):
    """(title, [(column, label)], log) per panel, for the columns the waveform has (w: name -> array)."""
    rows = [("contact voltage (V)", [("contact_voltage", "contact voltage")], False),
            ("|contact voltage| (V, log)", [("abs_voltage", "|contact voltage|")], True),
            ("current (A)", [(c, c.replace("_", " ")) for c in ("load_current", "contact_current", "arc_current")
                             if c in w and np.isfinite(w[c]).all()], False)]
    if "contact_resistance" in w:
        rows.append(("contact resistance (ohm, log)", [("contact_resistance", "R_c")], True))
    if "gap" in w:
        rows.append(("gap (m)", [("gap", "gap")], False))
    probes = [c for c in w if c[:2].lower() in ("v(", "i(")]
    if probes:
        rows.append(("probes (V, A)", [(c, c) for c in probes], False))
    return rows


def _array(values: np.ndarray) -> dict:
    """plotly.js's typed-array form: little-endian float64 samples in base64 (NaN: a gap)."""
    return {"dtype": "f8", "bdata": base64.b64encode(np.ascontiguousarray(values, dtype="<f8").tobytes()).decode()}


def waveform_page(result, max_points: int = MAX_POINTS) -> tuple[list, dict]:
    """(traces, layout) of a run's waveforms: one panel per quantity, linked time axes."""
    cols = dict(result.waveform_columns)
    cols["abs_voltage"] = np.abs(cols["contact_voltage"])
    rows = _rows(cols)
    n = len(rows)
    spacing = 0.02
    height = (1.0 - spacing * (n - 1)) / n
    t = np.asarray(cols["time"], dtype=float)
    traces = []
    layout = {"annotations": [], "shapes": []}
    for k, (title, columns, log) in enumerate(rows, start=1):
        top = 1.0 - (k - 1) * (height + spacing)
        suffix = "" if k == 1 else str(k)
        for column, label in columns:
            y = np.asarray(cols[column], dtype=float)
            if log:
                y = np.where((y > 0) & np.isfinite(y), y, np.nan)
            idx = decimate(t, y, max_points)
            traces.append({"type": "scattergl", "mode": "lines", "name": label, "line": {"width": 1},
                           "x": _array(t[idx]), "y": _array(y[idx]), "xaxis": f"x{suffix}", "yaxis": f"y{suffix}"})
        layout[f"xaxis{suffix}"] = {"anchor": f"y{suffix}", "domain": [0.0, 1.0], "exponentformat": "SI",
                                    "ticksuffix": "s", "showspikes": True, "spikemode": "across",
                                    **({"matches": f"x{n}", "showticklabels": False} if k < n else
                                       {"title": {"text": "time"}})}
        layout[f"yaxis{suffix}"] = {"anchor": f"x{suffix}", "domain": [top - height, top],
                                    **({"type": "log"} if log else {})}
        layout["annotations"].append({"text": title, "x": 0.5, "y": top, "xref": "paper", "yref": "paper",
                                      "xanchor": "center", "yanchor": "bottom", "showarrow": False,
                                      "font": {"size": 16}})
    for a, b in result.closed_intervals:
        layout["shapes"].append({"type": "rect", "xref": "x", "yref": "paper", "x0": float(a), "x1": float(b),
                                 "y0": 0.0, "y1": 1.0, "fillcolor": "green", "opacity": 0.12,
                                 "line": {"width": 0}, "layer": "below"})
    name = getattr(result.scene, "name", "run")
    layout.update(height=230 * n + 120, title={"text": f"{name}: waveforms (drag to zoom, double-click to reset)"},
                  hovermode="x unified", legend={"orientation": "h", "y": 1.0, "yanchor": "bottom"},
                  margin={"l": 70, "r": 20, "t": 110, "b": 50}, template={"layout": {"plot_bgcolor": "#E5ECF6", "xaxis": {"gridcolor": "white"},
                                                                          "yaxis": {"gridcolor": "white"}}})
    return traces, layout


def plotly_js() -> Path | None:
    """The installed plotly package's plotly.min.js (found without importing plotly), or None."""
    spec = importlib.util.find_spec("plotly")
    if spec is None or not spec.submodule_search_locations:
        return None
    path = Path(list(spec.submodule_search_locations)[0]) / "package_data" / "plotly.min.js"
    return path if path.is_file() else None


def write_waveform_html(result, path, max_points: int = MAX_POINTS) -> str:
    """Write the page; returns "written" or why it was skipped (plotly absent, no waveforms)."""
    if result.waveform_columns is None or not len(result.waveform_columns["time"]):
        return "skipped: no waveforms"
    js = plotly_js()
    if js is None:
        return PLOTLY_MISSING
    traces, layout = waveform_page(result, max_points)
    config = {"scrollZoom": True, "displaylogo": False, "responsive": True}
    div = "switchsim-waveforms"
    script = js.read_bytes()  # copied as bytes: decoding 4.8 MB of JavaScript and encoding it again cost ~10 ms
    if b"\r" in script:  # (not so in plotly's file) as text mode reads it: universal newlines
        script = js.read_text(encoding="utf-8").encode("utf-8")
    with open(Path(path), "wb") as fh:
        fh.write(b'<html>\n<head><meta charset="utf-8" /></head>\n<body>\n<div>\n'
                 b'<script type="text/javascript">window.PlotlyConfig = {MathJaxConfig: \'local\'};</script>\n'
                 b'<script charset="utf-8" type="text/javascript">')
        fh.write(script)
        tail = (f'</script>\n<div id="{div}" class="plotly-graph-div" style="height:{layout["height"]}px; '
                'width:100%;"></div>\n<script type="text/javascript">\n'
                f'Plotly.newPlot("{div}", {json.dumps(traces)}, {json.dumps(layout)}, {json.dumps(config)});\n'
                '</script>\n</div>\n</body>\n</html>\n')
        fh.write(tail.encode("utf-8"))
    return "written"
