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

The panels, their units and axis ranges are those of waveforms.png: both read
coupling.app.panels (the contact resistance over the closed contact's range with an
"open" band above it, currents scaled to the loop with clipped spikes marked, normal force
per contact point, ...). Each panel's legend stands at its right; the y axes say their
quantity and unit (SI, with prefixes on the ticks).

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
import os
from pathlib import Path

import numpy as np

from coupling.app.panels import axis, columns_of, dashed, panels_for, resistance_ticks
from coupling.app.quantities import WAVEFORM

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


def _array(values: np.ndarray) -> dict:
    """plotly.js's typed-array form: little-endian float64 samples in base64 (NaN: a gap)."""
    return {"dtype": "f8", "bdata": base64.b64encode(np.ascontiguousarray(values, dtype="<f8").tobytes()).decode()}


_SI = ((1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "\u00b5"), (1e-9, "n"), (1e-12, "p"))


def _si(value: float) -> str:
    """A tick number with an SI prefix, as plotly writes its own ("100\u00b5", "2m")."""
    for scale, prefix in _SI:
        if abs(value) >= scale * 0.9999:
            return f"{value / scale:.3g}{prefix}"
    return f"{value:.3g}"


def _panel(panel, traces, cols, t, k, rng, max_points):
    """The plotly traces and y axis of one panel (k: 1-based row)."""
    suffix = "" if k == 1 else str(k)
    legend = f"legend{suffix}"
    unit = panel.quantity.unit
    out = []
    for column, label, color in traces:
        y = cols[column]
        if panel.scale == "resistance":  # the data range only: onsets are marked, open is drawn in the band
            y = np.where(np.isfinite(y) & (y > 0) & (y <= rng.hi), y, np.nan)
        elif rng.log:
            y = np.where((y > 0) & np.isfinite(y), y, np.nan)
        idx = decimate(t, y, max_points)
        out.append({"type": "scattergl", "mode": "lines", "name": label, "legend": legend,
                    "line": {"width": 1, **({"color": color} if color else {}),
                             **({"dash": "dash", "width": 1.6} if dashed(panel, column) else {})},
                    "x": _array(t[idx]), "y": _array(y[idx]), "xaxis": f"x{suffix}", "yaxis": f"y{suffix}"})
    colors = {c: col for c, _, col in traces}
    for column, idx, peak in rng.clipped:
        y = cols[column][idx]
        edge = np.where(y > rng.hi, rng.hi, rng.lo)
        what = "above range (onset)" if panel.scale == "resistance" else "clipped"
        out.append({"type": "scatter", "mode": "markers", "name": f"{what} (peak {peak:.3g} {unit})",
                    "legend": legend, "marker": {"symbol": ["triangle-down" if panel.scale == "resistance" or v < rng.lo
                                                            else "triangle-up" for v in y],
                                                 "size": 7, "color": colors.get(column)},
                    "x": _array(t[idx]), "y": _array(edge), "customdata": _array(y),
                    "hovertemplate": "%{customdata:.4g} " + unit + "<extra></extra>",
                    "cliponaxis": False, "xaxis": f"x{suffix}", "yaxis": f"y{suffix}"})
    yaxis = {"title": {"text": panel.quantity.label()}, "tickformat": "~s"}
    if rng.band is not None:
        mid = float(np.sqrt(rng.band[0] * rng.band[1]))
        y = np.full(len(t), np.nan)
        y[rng.open] = mid
        idx = decimate(t, y, max_points)
        out.append({"type": "scattergl", "mode": "lines", "name": "open (no conduction)", "legend": legend,
                    "line": {"width": 6, "color": "#595959"}, "x": _array(t[idx]), "y": _array(y[idx]),
                    "hovertemplate": "open<extra></extra>", "xaxis": f"x{suffix}", "yaxis": f"y{suffix}"})
        ticks = resistance_ticks(rng)
        yaxis.update(tickvals=[v for v, _ in ticks], ticktext=[s or _si(v) for v, s in ticks])
    if rng.log:
        yaxis.update(type="log", range=[float(np.log10(rng.lo)), float(np.log10(rng.top))])
    else:
        yaxis.update(range=[rng.lo, rng.top])
    return out, yaxis


def waveform_page(result, max_points: int = MAX_POINTS) -> tuple[list, dict]:
    """(traces, layout) of a run's waveforms: the panels of coupling.app.panels on linked
    time axes, each scaled by its rule over the whole run, its legend at its right."""
    cols = columns_of(result)
    panels = panels_for(cols)
    n = len(panels)
    spacing = 0.025
    height = (1.0 - spacing * (n - 1)) / n
    t = np.asarray(cols["time"], dtype=float)
    sel = np.ones(len(t), bool)
    traces = []
    layout = {"shapes": []}
    for k, (panel, drawn) in enumerate(panels, start=1):
        top = 1.0 - (k - 1) * (height + spacing)
        suffix = "" if k == 1 else str(k)
        rng = axis(panel, t, [(c, cols[c]) for c, _, _ in drawn], sel, bounce=getattr(result, "bounce", None),
                   closed_intervals=result.closed_intervals)
        new, yaxis = _panel(panel, drawn, cols, t, k, rng, max_points)
        traces += new
        layout[f"xaxis{suffix}"] = {"anchor": f"y{suffix}", "domain": [0.0, 1.0], "tickformat": "~s",
                                    "ticksuffix": "s", "showspikes": True, "spikemode": "across",
                                    **({"matches": f"x{n}", "showticklabels": False} if k < n else
                                       {"title": {"text": WAVEFORM["time"].label()}})}
        layout[f"yaxis{suffix}"] = {"anchor": f"x{suffix}", "domain": [top - height, top], **yaxis}
        layout[f"legend{suffix}"] = {"x": 1.01, "xanchor": "left", "y": top, "yanchor": "top", "yref": "paper",
                                     "font": {"size": 11}, "tracegroupgap": 2}
        if rng.band is not None:
            layout["shapes"].append({"type": "rect", "xref": f"x{suffix} domain", "yref": f"y{suffix}",
                                     "x0": 0.0, "x1": 1.0, "y0": rng.band[0], "y1": rng.band[1],
                                     "fillcolor": "#d9d9d9", "opacity": 0.7, "line": {"width": 0}, "layer": "below"})
        for a, b in result.closed_intervals:  # shaded within each panel, not across the gaps between them
            layout["shapes"].append({"type": "rect", "xref": f"x{suffix}", "yref": f"y{suffix} domain",
                                     "x0": float(a), "x1": float(b), "y0": 0.0, "y1": 1.0, "fillcolor": "green",
                                     "opacity": 0.12, "line": {"width": 0}, "layer": "below"})
    name = getattr(result.scene, "name", "run")
    layout.update(height=230 * n + 110,
                  title={"text": f"{name}: waveforms (drag to zoom, double-click to reset; green: contact closed)",
                         "x": 0.0, "xanchor": "left"},
                  hovermode="x unified", showlegend=True, margin={"l": 80, "r": 250, "t": 60, "b": 50},
                  template={"layout": {"plot_bgcolor": "#E5ECF6", "xaxis": {"gridcolor": "white"},
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
    cols = getattr(result, "waveform_columns", None)
    if cols is None and getattr(result, "waveforms", None) is not None:  # a result folder read back
        cols = result.waveforms
    if cols is None or not len(cols["time"]):
        return "skipped: no waveforms"
    js = plotly_js()
    if js is None:
        return PLOTLY_MISSING
    traces, layout = waveform_page(result, max_points)
    config = {"scrollZoom": True, "displaylogo": False, "responsive": True}
    div = "switchsim-waveforms"
    # copied as bytes (decoding 4.8 MB of JavaScript and encoding it again cost ~10 ms) where the
    # file has no carriage return (plotly's has none), else as text mode reads it: universal newlines
    size, plain = _plain_size(js)
    with open(Path(path), "wb") as fh:
        fh.write(b'<html>\n<head><meta charset="utf-8" /></head>\n<body>\n<div>\n'
                 b'<script type="text/javascript">window.PlotlyConfig = {MathJaxConfig: \'local\'};</script>\n'
                 b'<script charset="utf-8" type="text/javascript">')
        if not (plain and _send_file(fh, js, size)):
            fh.write(js.read_bytes() if plain else js.read_text(encoding="utf-8").encode("utf-8"))
        tail = (f'</script>\n<div id="{div}" class="plotly-graph-div" style="height:{layout["height"]}px; '
                'width:100%;"></div>\n<script type="text/javascript">\n'
                f'Plotly.newPlot("{div}", {json.dumps(traces)}, {json.dumps(layout)}, {json.dumps(config)});\n'
                '</script>\n</div>\n</body>\n</html>\n')
        fh.write(tail.encode("utf-8"))
    return "written"


def _plain_size(source: Path) -> tuple[int, bool]:
    """(bytes, True if the file has no carriage return) of ``source``, searched in a read-only
    mapping of it: reading plotly's 4.8 MB into a bytes object to search it cost ~3.5 ms of
    every page, the mapping ~0.8 ms (both measured warm). Where it cannot be mapped (an
    empty file, no mmap): read."""
    try:
        import mmap

        with open(source, "rb") as src, mmap.mmap(src.fileno(), 0, access=mmap.ACCESS_READ) as view:
            return len(view), view.find(b"\r") < 0
    except (ImportError, OSError, ValueError):
        data = source.read_bytes()
        return len(data), b"\r" not in data


def _send_file(fh, source: Path, size: int) -> bool:
    """Append ``source``'s first ``size`` bytes to the open binary file ``fh`` by
    ``os.sendfile`` (the kernel copies the pages: ~3 ms for plotly's 4.8 MB against 8-15 ms
    for Python's write of the same bytes, measured on this project's Linux machines);
    False, nothing appended, where there is no sendfile or it fails."""
    send = getattr(os, "sendfile", None)
    if send is None:
        return False
    fh.flush()
    out = fh.fileno()
    start = os.lseek(out, 0, os.SEEK_CUR)
    done = 0
    try:
        with open(source, "rb") as src:
            while done < size:
                sent = send(out, src.fileno(), done, size - done)
                if sent == 0:
                    break
                done += sent
    except OSError:
        pass
    if done == size:  # (sendfile moved the page's offset past what it wrote)
        return True
    os.lseek(out, start, os.SEEK_SET)  # (a part sent is written over)
    os.ftruncate(out, start)
    return False
