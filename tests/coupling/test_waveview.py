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
    assert set(by_name) >= {"contact voltage", "|contact voltage|", "load current", "contact current", "R_c"}
