"""Checks on matplotlib figures shared by the plot tests: every axis that shows numbers says its unit."""

from __future__ import annotations

import re


def numeric_ticks(axis) -> bool:
    """Whether an axis shows numbers (a category axis -- run names -- shows words only)."""
    texts = [re.sub(r"\\math\w+", "", t.get_text()) for t in axis.get_ticklabels() if t.get_visible()]
    return any(re.fullmatch(r"[-\u2212+.\d\s${}^e\u00b5unmkMG]*\d[-\u2212+.\d\s${}^e\u00b5unmkMG]*", s)
               for s in texts)


def assert_every_axis_has_a_unit(fig, name):
    """Every axis that shows numbers has a label ending in "(unit)" (stacked panels show the
    time axis's numbers on the bottom one only, which carries the label)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig).draw()
    for ax in fig.axes:
        for axis, label in ((ax.xaxis, ax.get_xlabel()), (ax.yaxis, ax.get_ylabel())):
            if not numeric_ticks(axis):
                continue
            assert re.search(r"\([^()]+\)$", label), f"{name}: axis {label!r} has no unit"
    return True
