"""Plots are scaled to what each panel is for (hand-built run: bounces at 12 V, a fly-off spike)."""

from __future__ import annotations

import types

import numpy as np
import pandas as pd

from coupling.core.metrics import bounce_metrics


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


def test_bounce_window_panels_are_scaled_to_the_bounce():
    import matplotlib.pyplot as plt

    from coupling.app.plots import bounce_window, plot_waveforms

    res = _fake_result()
    lo, hi = bounce_window(res)
    assert lo < 1.0 and 2.0 < hi < 3.0  # first make to the last break (ms), not the fly-off
    fig = plot_waveforms(res)
    ax_v, ax_i = fig.axes[0], fig.axes[1]
    assert 24.0 < ax_v.get_ylim()[1] < 30.0  # open-circuit 24 V before the make, not the 300 V spike
    assert 2.0 < ax_i.get_ylim()[1] < 3.0  # the 2 A loop, not the 5.3 kA spike
    labels = [t.get_text() for t in ax_i.get_legend().get_texts()]
    assert any("clipped (peak 5.3e+03 A)" in s for s in labels)
    # legends outside the data area
    assert all(ax.get_legend().get_bbox_to_anchor().x0 >= ax.get_window_extent().x1 - 1 for ax in fig.axes[:2])
    plt.close(fig)


def test_all_run_plots_are_written(tmp_path):
    from coupling.app.plots import save_plots

    res = _fake_result()
    res.mechanics = None
    names = {p.name for p in save_plots(res, tmp_path)}
    assert names == {"waveforms.png", "waveforms_whole_run.png", "contact_voltage_log.png", "openings.png"}
    assert all((tmp_path / n).stat().st_size > 10_000 for n in names)
