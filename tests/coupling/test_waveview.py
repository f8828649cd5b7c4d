"""waveforms.html: self-contained (JS embedded, nothing fetched), the data round-trip, decimation keeps spikes."""

from __future__ import annotations

import base64
import json
import re
import types

import numpy as np
import pytest

from coupling.app.waveview import decimate

pytest.importorskip("plotly")


def test_decimation_keeps_every_spike_and_the_ends():
    t = np.linspace(0.0, 1e-2, 1_000_001)
    y = np.sin(2e3 * t)
    spikes = [123_457, 500_001, 999_998]
    y[spikes] = [50.0, -70.0, 90.0]
    idx = decimate(t, y, max_points=2000)
    assert len(idx) <= 4 * 1000 and idx[0] == 0 and idx[-1] == len(t) - 1
    assert set(spikes) <= set(idx.tolist())
    # the envelope survives: each bucket's max is kept, so the kept max equals the true max per bucket
    assert np.max(y[idx]) == 90.0 and np.min(y[idx]) == -70.0
    short = np.arange(10.0)
    assert decimate(short, short, 2000).tolist() == list(range(10))


def _decode(values):
    if isinstance(values, dict) and "bdata" in values:
        return np.frombuffer(base64.b64decode(values["bdata"]), dtype=np.dtype(values["dtype"]))
    return np.asarray(values, dtype=float)


def test_page_is_self_contained_and_holds_the_data(tmp_path):
    from coupling.app.waveview import write_waveform_html

    t = np.linspace(0.0, 1e-3, 3001)
    v = np.where(t < 5e-4, 24.0, 0.01) + 3.0 * np.exp(-t / 1e-7) * np.sin(2 * np.pi * 5e7 * t)  # 50 ns ringing
    w = dict(time=t, contact_voltage=v, contact_current=np.where(t < 5e-4, 0.0, 2.0),
             load_current=np.where(t < 5e-4, 0.0, 2.0), arc_current=np.zeros_like(t),
             contact_resistance=np.where(t < 5e-4, np.inf, 0.005))
    w["v(snubber)"] = 0.5 * v
    res = types.SimpleNamespace(waveform_columns=w, closed_intervals=[(5e-4, 1e-3)], scene=types.SimpleNamespace(name="t"))
    path = tmp_path / "waveforms.html"
    assert write_waveform_html(res, path) == "written"
    html = path.read_text()
    # the plotly library is inside the page; nothing is loaded from elsewhere
    assert "plotly.js" in html.lower() and len(html) > 1_000_000
    assert not re.search(r"<script[^>]*\ssrc\s*=", html, re.I) and not re.search(r"<link[^>]*href\s*=", html, re.I)
    # the figure's data: the first Plotly.newPlot call carries the traces as JSON
    m = re.search(r'Plotly\.newPlot\(\s*"[^"]+",\s*(\[.*?\])\s*,\s*\{', html, re.S)
    traces = json.loads(m.group(1))
    by_name = {tr["name"]: tr for tr in traces}
    np.testing.assert_array_equal(_decode(by_name["contact voltage"]["x"]), t)
    np.testing.assert_array_equal(_decode(by_name["contact voltage"]["y"]), v)
    np.testing.assert_array_equal(_decode(by_name["v(snubber)"]["y"]), 0.5 * v)
    assert set(by_name) >= {"contact voltage", "|contact voltage|", "load (loop)", "contact (metallic)",
                            "contact resistance"}


def test_the_page_is_the_same_bytes_whether_the_kernel_or_python_copies_plotly_js(tmp_path, monkeypatch):
    """plotly.min.js goes into the page by os.sendfile; where that is missing or fails part
    way (a part already sent), the bytes are written from Python instead: the same page."""
    import os

    from coupling.app import waveview

    t = np.linspace(0.0, 1e-3, 101)
    res = types.SimpleNamespace(waveform_columns=dict(time=t, contact_voltage=24.0 * t), closed_intervals=[],
                                scene=types.SimpleNamespace(name="t"))
    pages = []
    real = os.sendfile

    def partly(out, src, offset, count):  # a first piece, then a failure
        if offset == 0:
            return real(out, src, offset, min(count, 65536))
        raise OSError("sendfile failed")

    for send in (real, None, partly):
        with monkeypatch.context() as patch:
            if send is None:
                patch.delattr(os, "sendfile")
            else:
                patch.setattr(os, "sendfile", send)
            path = tmp_path / f"page{len(pages)}.html"
            assert waveview.write_waveform_html(res, path) == "written"
            pages.append(path.read_bytes())
    script = waveview.plotly_js().read_bytes()
    assert pages[0] == pages[1] == pages[2] and pages[0].count(script) == 1


def test_a_script_with_carriage_returns_goes_in_as_text_mode_reads_it(tmp_path, monkeypatch):
    """A plotly.min.js with Windows line ends (plotly's own has none) is put into the page with
    universal newlines, as Python's text mode reads it, not copied byte for byte; an empty one
    adds nothing."""
    from coupling.app import waveview

    t = np.linspace(0.0, 1e-3, 11)
    res = types.SimpleNamespace(waveform_columns=dict(time=t, contact_voltage=24.0 * t), closed_intervals=[],
                                scene=types.SimpleNamespace(name="t"))
    for name, body, inserted in (("crlf.js", b"var a = 1;\r\nvar b = 2;\rvar c = 3;\n", b"var a = 1;\nvar b = 2;\nvar c = 3;\n"),
                                 ("empty.js", b"", b"")):
        script = tmp_path / name
        script.write_bytes(body)
        monkeypatch.setattr(waveview, "plotly_js", lambda script=script: script)
        page = tmp_path / f"{name}.html"
        assert waveview.write_waveform_html(res, page) == "written"
        html = page.read_bytes()
        head = b'<script charset="utf-8" type="text/javascript">'
        start = html.index(head) + len(head)
        assert html[start:start + len(inserted) + len(b"</script>")] == inserted + b"</script>"


# --- the page of a real run: the default relay to 2 ms (one rivet: contact point 1 does not exist) ---

_PAGE = {}


def _relay_page():
    """(result, traces, layout) read back from the written page (run once per module)."""
    if "page" not in _PAGE:
        import tempfile
        from pathlib import Path

        from coupling import builtin_scene, run
        from coupling.app.waveview import write_waveform_html

        res = run(builtin_scene("relay_force").set("solver.t_end", 2e-3))
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "waveforms.html"
            assert write_waveform_html(res, path) == "written"
            html = path.read_text()
        m = re.search(r'Plotly\.newPlot\(\s*"[^"]+",\s*(\[.*?\])\s*,\s*(\{.*?\})\s*,\s*\{"scrollZoom"', html, re.S)
        _PAGE["page"] = (res, json.loads(m.group(1)), json.loads(m.group(2)))
    return _PAGE["page"]


def _panels(layout):
    """y axis name ("y", "y2", ...) -> its layout entry."""
    return {("y" + k[5:]): v for k, v in layout.items() if k.startswith("yaxis")}


def _axis_of(layout, unit):
    (name,) = [k for k, v in _panels(layout).items() if v.get("title", {}).get("text", "").endswith(f"({unit})")]
    return name, _panels(layout)[name]


def test_page_resistance_axis_spans_the_closed_contact_and_draws_open_as_open():
    """As waveforms.png (tests/coupling/test_plots.py): the axis holds the contact pressed
    with >= 10 mN, not the 2e18 ohm onsets; the samples without conduction are a trace in
    the band above the axis, named "open"; the R_c trace holds no sample beyond the axis."""
    res, traces, layout = _relay_page()
    c = res.waveform_columns
    t, r, f = c["time"], c["contact_resistance"], c["normal_force"]
    name, yaxis = _axis_of(layout, "ohm")
    assert yaxis["type"] == "log"
    lo, top = 10.0 ** np.array(yaxis["range"])
    (band,) = [s for s in layout["shapes"] if s.get("yref") == name]
    closed = np.zeros(len(t), bool)
    for a, b in res.closed_intervals:
        closed |= (t >= a) & (t <= b)
    pressed = r[closed & (f >= 0.01) & np.isfinite(r)]
    assert lo <= pressed.min() and pressed.max() <= band["y0"]
    assert top < 1e-6 * np.max(r[np.isfinite(r)])
    on_axis = [tr for tr in traces if tr["yaxis"] == name]
    by_name = {tr["name"]: tr for tr in on_axis}
    open_trace = by_name["open (no conduction)"]
    y_open = _decode(open_trace["y"])
    assert np.array_equal(np.isfinite(y_open), ~np.isfinite(r))  # exactly the samples without conduction
    assert np.all((y_open[np.isfinite(y_open)] > band["y0"]) & (y_open[np.isfinite(y_open)] < band["y1"]))
    y_r = _decode(by_name["contact resistance"]["y"])
    assert np.nanmax(y_r) <= band["y0"]
    onset = [k for k in by_name if k.startswith("above range")]
    assert len(onset) == 1 and np.max(_decode(by_name[onset[0]]["customdata"])) == np.max(r[np.isfinite(r)])
    ticks = dict(zip(yaxis["tickvals"], yaxis["ticktext"]))
    assert [v for v, s in ticks.items() if v > band["y0"]] == [v for v, s in ticks.items() if s == "open"]


def test_page_has_a_normal_force_panel_per_contact_point_that_touches():
    res, traces, layout = _relay_page()
    name, yaxis = _axis_of(layout, "N")
    assert yaxis["title"]["text"] == "normal force (N)"
    on_axis = {tr["name"]: tr for tr in traces if tr["yaxis"] == name}
    assert set(on_axis) == {"contact point 0"}  # the relay's one rivet; row 1 has no contact point
    np.testing.assert_array_equal(_decode(on_axis["contact point 0"]["y"]), res.waveform_columns["normal_force_0"])
    np.testing.assert_array_equal(_decode(on_axis["contact point 0"]["x"]), res.waveform_columns["time"])


def test_page_axes_have_units_and_legends_stand_beside_their_panels():
    """Every y axis names its quantity and unit, the time axis its unit; each panel's
    legend stands right of the plotting area (x > 1, left-anchored, so it covers no panel,
    title or axis) at the top of its own panel, and holds that panel's traces only."""
    res, traces, layout = _relay_page()
    panels = _panels(layout)
    assert len(panels) >= 6
    for name, yaxis in panels.items():
        assert re.search(r"\([^()]+\)$", yaxis["title"]["text"]), yaxis
    bottom = [v for k, v in layout.items() if k.startswith("xaxis") and "title" in v]
    assert [x["title"]["text"] for x in bottom] == ["time (s)"]
    legends = {k: v for k, v in layout.items() if k.startswith("legend")}
    assert len(legends) == len(panels)
    for name, yaxis in panels.items():
        legend = legends["legend" + name[1:]]
        assert legend["x"] > 1.0 and legend["xanchor"] == "left"
        lo, hi = yaxis["domain"]
        assert lo < legend["y"] <= hi + 1e-12 and legend["yanchor"] == "top"
    for tr in traces:
        assert tr["legend"] == "legend" + tr["yaxis"][1:]
        assert "e+06" not in tr["name"] and "tip" not in tr["name"]
    assert not layout.get("annotations")  # no titles over the panels for a legend to cover
