"""Plots are scaled to what each panel is for (hand-built run: bounces at 12 V, a fly-off spike)."""

from __future__ import annotations

import types

import numpy as np
import pandas as pd

from coupling.core.metrics import bounce_metrics
from plot_checks import assert_every_axis_has_a_unit


def _fake_result(t_end=5e-3):
    """Bounces between 1 and 2 ms (arc at 12 V, 1 A; closed 2 A) with a 5.3 kA re-ignition
    spike, then a final opening with a 300 V spike: what the plots must not be scaled by."""
    iv = [(1.0e-3, 1.2e-3), (1.3e-3, 2.0e-3)]
    t = np.linspace(0.0, t_end, 5001)
    closed = np.zeros_like(t, bool)
    for a, b in iv:
        closed |= (t >= a) & (t <= b)
    v = np.where(closed, 0.01, np.where(t < 1e-3, 24.0, 12.0))
    arc = np.where(closed | (t < 1e-3), 0.0, 1.0)
    contact = np.where(closed, 2.0, 0.0)
    k = np.searchsorted(t, 3e-3)
    v[k], arc[k] = 300.0, 20.0
    arc[np.searchsorted(t, 1.25e-3)] = 5300.0  # a re-ignition spike inside a bounce opening
    w = pd.DataFrame(dict(time=t, contact_voltage=v, contact_current=contact, load_current=contact + arc,
                          contact_resistance=np.where(closed, 0.005, np.inf), arc_current=arc,
                          gap=np.where(closed, 0.0, 1e-5)))
    bounce = bounce_metrics(iv, t_end, False, t, v, contact + arc, arc)
    return types.SimpleNamespace(waveforms=w, bounce=bounce, closed_intervals=iv,
                                 openings=pd.DataFrame(bounce["openings"]),
                                 scene=types.SimpleNamespace(t_end=t_end))


def _panel(fig, ylabel):
    """The axes of a figure whose y label is ``ylabel``."""
    (ax,) = [ax for ax in fig.axes if ax.get_ylabel() == ylabel]
    return ax


def test_bounce_window_panels_are_scaled_to_the_bounce():
    import matplotlib.pyplot as plt

    from coupling.app.plots import bounce_window, plot_waveforms

    res = _fake_result()
    lo, hi = bounce_window(res)
    assert lo < 1.0 and 2.0 < hi < 3.0  # first make to the last break (ms), not the fly-off
    fig = plot_waveforms(res)
    ax_v, ax_i = _panel(fig, "contact voltage (V)"), _panel(fig, "current (A)")
    assert 24.0 < ax_v.get_ylim()[1] < 30.0  # open-circuit 24 V before the make, not the 300 V spike
    assert 2.0 < ax_i.get_ylim()[1] < 3.0  # the 2 A loop, not the 5.3 kA spike
    labels = [t.get_text() for t in ax_i.get_legend().get_texts()]
    assert any("clipped (peak 5.3e+03 A)" in s for s in labels)
    # legends outside the data area
    assert all(ax.get_legend().get_bbox_to_anchor().x0 >= ax.get_window_extent().x1 - 1 for ax in fig.axes)
    plt.close(fig)


def test_all_run_plots_are_written(tmp_path):
    from coupling.app.plots import save_plots

    res = _fake_result()
    res.mechanics = None
    names = {p.name for p in save_plots(res, tmp_path)}
    assert names == {"waveforms.png", "waveforms_whole_run.png", "contact_voltage_log.png", "openings.png"}
    assert all((tmp_path / n).stat().st_size > 10_000 for n in names)


# --- a real run: the default relay (one rivet: contact point 1 does not exist), to 2 ms ---

_RUN = {}


def _relay():
    """The default scene to 2 ms: 6 bounces and the start of the closure (run once per module)."""
    if "res" not in _RUN:
        from coupling import builtin_scene, run

        _RUN["res"] = run(builtin_scene("relay_force").set("solver.t_end", 2e-3))
    return _RUN["res"]


def _unit_panel(fig, unit):
    """The one axes whose y label ends with "(unit)"."""
    (ax,) = [ax for ax in fig.axes if ax.get_ylabel().endswith(f"({unit})")]
    return ax


def _pressed(res, force):
    """Contact resistance of the samples where the contact is closed and pressed with at
    least ``force`` N: the closed contact's values, found from the normal force alone."""
    from coupling.app.panels import closed_mask

    c = res.waveform_columns
    keep = closed_mask(c["time"], res.closed_intervals) & (c["normal_force"] >= force) & np.isfinite(
        c["contact_resistance"])
    return c["contact_resistance"][keep]


def _open_lines(ax, hi):
    """(start, end) ms of the horizontal bars drawn above the data range (the open band)."""
    out = []
    for line in ax.get_lines():
        x, y = np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)
        if len(x) == 2 and y[0] == y[1] and y[0] > hi:
            out.append((x[0], x[1]))
    return out


def test_resistance_axis_spans_the_closed_contact_and_marks_open_as_open():
    """The axis holds every sample of the contact pressed with >= 10 mN (1/1000 of the 13 N
    impact, 1/160 of the closure's 1.6 N), not the conduction-onset samples (up to 2e18 ohm
    as the force goes through zero); every opening of the bounce metrics is drawn in the
    band above the axis, which carries the word "open" and no number."""
    from coupling.app.plots import bounce_window, plot_waveforms

    res = _relay()
    r = res.waveform_columns["contact_resistance"]
    onset = np.max(r[np.isfinite(r)])
    assert onset > 1e10  # the run has the spikes this test is about
    for whole_run in (False, True):
        fig = plot_waveforms(res, whole_run=whole_run)
        ax = _unit_panel(fig, "ohm")
        lo, top = ax.get_ylim()
        pressed = _pressed(res, 0.01)
        assert len(pressed) > 500
        assert lo <= pressed.min() and pressed.max() < top  # the closed contact on the axis
        assert top < 1e-6 * onset  # the onsets are not what scales it
        numbers = [t.get_position()[1] for t in ax.get_yticklabels() if t.get_text() != "open"]
        (band,) = [t.get_position()[1] for t in ax.get_yticklabels() if t.get_text() == "open"]
        data_top = max(numbers)
        assert pressed.max() < band and band > data_top  # below the band, which carries no number
        texts = [t.get_text() for t in ax.get_legend().get_texts()]
        assert any(s.startswith("open") for s in texts) and any(s.startswith("above range") for s in texts)
        bars = _open_lines(ax, data_top)
        window = (0.0, 2.0) if whole_run else bounce_window(res)
        for op in res.bounce["openings"]:
            mid = 0.5 * (op["start"] + op["end"]) * 1e3
            if window[0] < mid < window[1]:
                assert any(a <= mid <= b for a, b in bars), f"opening at {mid:.4g} ms not drawn as open"
        # nothing drawn as open while the contact is pressed
        c = res.waveform_columns
        t_pressed = c["time"][(c["normal_force"] >= 0.01)] * 1e3
        assert not any(np.any((t_pressed > a) & (t_pressed < b)) for a, b in bars)


def test_contact_points_that_do_not_exist_or_never_touch_are_not_drawn_as_if_they_did():
    """The relay has one rivet: mech's history keeps a second row of contact columns holding
    a placeholder height (1000 m) and no force. Neither plot draws it or prints its
    placeholder; a contact point that exists but never touches is named, with no force curve."""
    import types

    from coupling.app.plots import plot_normal_force, plot_tip_heights

    res = _relay()
    for make in (plot_normal_force, plot_tip_heights):
        fig = make(res)
        ax = fig.axes[0]
        texts = [t.get_text() for t in ax.get_legend().get_texts()]
        assert texts == ["contact point 0"], texts
        drawn = [ln for ln in ax.get_lines() if len(ln.get_xdata()) > 2]
        assert len(drawn) == 1
        assert np.max(np.abs(drawn[0].get_ydata())) < 1e3  # mm or N: no placeholder height among the data
    # a free bar whose tip 1 stays 5 mm above the block while tip 0 strikes
    h = res.mechanics.history.copy()
    h["tip_height_1"] = 5e-3 + 0.0 * h["time"]
    h["normal_force_1"] = 0.0
    bar = types.SimpleNamespace(mechanics=types.SimpleNamespace(history=h), waveforms=None)
    fig = plot_normal_force(bar)
    texts = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert texts == ["contact point 0", "contact point 1: never touches"]
    assert len([ln for ln in fig.axes[0].get_lines() if len(ln.get_xdata()) > 2]) == 1
    fig = plot_tip_heights(bar)
    texts = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert texts == ["contact point 0", "contact point 1 (off scale: 5 to 5 mm), never touches"]


def test_every_axis_of_every_run_plot_has_a_unit(tmp_path):
    from coupling.app import plots

    res = _relay()
    res_fake = _fake_result()
    res_fake.mechanics = None
    for name, make in (("waveforms", plots.plot_waveforms), ("whole run", lambda r: plots.plot_waveforms(r, True)),
                       ("log voltage", plots.plot_log_voltage), ("openings", plots.plot_openings),
                       ("normal force", plots.plot_normal_force), ("tip heights", plots.plot_tip_heights),
                       ("energy", plots.plot_energy)):
        assert_every_axis_has_a_unit(make(res), name)
    assert_every_axis_has_a_unit(plots.plot_waveforms(res_fake), "hand-built run")
    acc = {"status": "converged", "closed": res.closed_intervals,
           "refinements": [{"name": "rtol / 10", "closed": res.closed_intervals}]}
    res.accuracy = acc
    try:
        assert_every_axis_has_a_unit(plots.plot_accuracy(res), "accuracy")
    finally:
        res.accuracy = None
