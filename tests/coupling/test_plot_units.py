"""Units of what the plots draw: the one table (coupling.app.quantities) agrees with the
docs' unit columns, knows every number a sweep row holds, and the sweep plots put a
quantity and unit on every axis, colour bar and legend value."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from plot_checks import assert_every_axis_has_a_unit

DOCS = Path(__file__).resolve().parents[2] / "docs"


def _scene_key_units() -> dict[str, str]:
    """"section.key" -> unit, from docs/scene_keys.md's tables."""
    out, section = {}, None
    for line in (DOCS / "scene_keys.md").read_text().splitlines():
        m = re.match(r"^## \[\[?([a-z_.]+)\]\]?", line)
        if m:
            section = m.group(1)
            continue
        m = re.match(r"^\| `([a-z_]+)` \|([^|]*)\|", line)
        if m and section:
            out[f"{section}.{m.group(1)}"] = m.group(2).strip()
    return out


def _bounce_units(section: str = "Bounce metrics", prefix: str = "bounce") -> dict[str, str]:
    """"bounce.key" -> unit, from docs/coupling.md's bounce-metrics table (or another
    section's), where a meaning starts with its unit ("s, first and last make ...")."""
    out = {}
    inside = False
    for line in (DOCS / "coupling.md").read_text().splitlines():
        if line.startswith("#"):
            inside = line.startswith(f"### {section}")
            continue
        m = re.match(r"^\| ((?:`\w+`(?:, )?)+) \| (s|V|J|A|ohm)[,;] ", line)
        if inside and m:
            for key in re.findall(r"`(\w+)`", m.group(1)):
                out[f"{prefix}.{key}"] = m.group(2)
    return out


def test_scene_key_units_are_those_of_docs_scene_keys():
    from coupling.app.quantities import SCENE

    doc = _scene_key_units()
    table = {f"{section}.{key}": unit for section, keys in SCENE.items() for key, unit in keys.items()}
    assert len(doc) > 100
    assert table == doc


def test_bounce_units_are_those_of_docs_coupling():
    from coupling.app.quantities import SUMMARY

    doc = _bounce_units()
    assert len(doc) >= 8  # first/last make, times, the three peaks, arc energy
    assert {k: SUMMARY[k].unit for k in doc} == doc
    logic = _bounce_units("Digital inputs", "logic")
    assert len(logic) >= 4  # first and last edge, burst, margin
    assert {k: SUMMARY[k].unit for k in logic} == logic


def _summaries():
    """Summaries of a run of each kind: the coil-driven default relay (relay, armature and
    coil blocks, a make and a break), coupled with material laws (relay_force), coupled with
    fitted laws (their parameters), mechanics only, a prescribed schedule."""
    from coupling import builtin_scene, load_scene, run
    from coupling.core.scene import scene_from_dict

    relay = builtin_scene("relay_force").set("solver.t_end", 1e-3)
    schedule = scene_from_dict({"solver": {"t_end": 2e-3}, "circuit": {
        "template": "resistive", "voltage": 24.0, "load_resistance": 12.0,
        "schedule": {"make": [2e-4], "break": [1e-3], "closed_resistance": 0.01}}}, name="schedule")
    fitted = load_scene(Path(__file__).resolve().parents[2] / "examples" / "resistive_bounce.toml")
    scenes = (builtin_scene("default"), relay, fitted.set("solver.t_end", 1e-3),
              relay.without("circuit", "tribology", "coupling"), schedule)
    assert [s.kind for s in scenes] == ["coupled", "coupled", "coupled", "mechanics", "circuit"]
    return [run(s).summary for s in scenes]


def test_every_number_a_sweep_row_holds_has_a_unit():
    """A sweep row is the flattened summary: each of its numbers is in the table (a new
    summary key needs its unit there, or its axis would say "unit unknown")."""
    from coupling.app.quantities import quantity
    from coupling.app.sweep import flatten_summary

    missing, seen = [], 0
    for summary in _summaries():
        for key, value in flatten_summary(summary).items():
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                seen += 1
                if quantity(key) is None:
                    missing.append(key)
    assert seen > 60 and not missing, missing


def _sweep_frame():
    """A grid sweep's rows (made up: the plots only read the columns)."""
    r = np.repeat([22.0, 47.0, 100.0], 3)
    c = np.tile([22e-9, 100e-9, 470e-9], 3)
    return pd.DataFrame({"run_id": [f"run{k:04d}" for k in range(9)], "status": "ok",
                         "circuit.snubber.resistance": r, "circuit.snubber.capacitance": c,
                         "bounce.peak_contact_voltage": 300.0 / (1.0 + r * c * 1e6),
                         "bounce.arc_energy": 0.04 + 1e-3 * r / 100.0})


def test_sweep_plots_say_quantity_and_unit_on_every_axis(tmp_path):
    from coupling.app.sweep_plots import plot_map, plot_metric, plot_overlay

    units = {**_scene_key_units(), **_bounce_units()}
    df = _sweep_frame()
    fig = plot_metric(df, "bounce.peak_contact_voltage", "circuit.snubber.capacitance",
                      by="circuit.snubber.resistance", limit=100.0)
    ax = fig.axes[0]
    assert ax.get_xlabel() == f"circuit snubber capacitance ({units['circuit.snubber.capacitance']})"
    assert ax.get_ylabel() == f"peak contact voltage ({units['bounce.peak_contact_voltage']})"
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert legend == ["circuit snubber resistance = 22 ohm", "circuit snubber resistance = 47 ohm",
                      "circuit snubber resistance = 100 ohm", "limit 100 V"]
    assert_every_axis_has_a_unit(fig, "plot_metric")
    fig = plot_map(df, "bounce.arc_energy", "circuit.snubber.capacitance", "circuit.snubber.resistance")
    labels = [a.get_ylabel() for a in fig.axes] + [fig.axes[0].get_xlabel()]
    assert labels == ["circuit snubber resistance (ohm)", "arc energy (J)", "circuit snubber capacitance (F)"]
    assert_every_axis_has_a_unit(fig, "plot_map")
    # a column the table does not know (one the user derived) says so, unless labelled
    df["bounce_ms"] = df["bounce.arc_energy"] * 1e3
    fig = plot_metric(df, "bounce_ms", "circuit.snubber.capacitance")
    assert fig.axes[0].get_ylabel() == "bounce_ms (unit unknown)"
    fig = plot_metric(df, "bounce_ms", "circuit.snubber.capacitance", labels={"bounce_ms": "bounce time (ms)"})
    assert fig.axes[0].get_ylabel() == "bounce time (ms)"
    # the overlay of kept waveforms: scaled and labelled as the run's own panel
    from coupling import builtin_scene, run

    res = run(builtin_scene("relay_force").set("solver.t_end", 2e-3))
    (tmp_path / "waveforms").mkdir()
    res.waveforms.to_parquet(tmp_path / "waveforms" / "run0000.parquet")
    fig = plot_overlay(tmp_path, ["run0000"], "contact_resistance", label=["circuit.snubber.resistance"],
                       results=df)
    ax = fig.axes[0]
    assert ax.get_ylabel() == "contact resistance (ohm)"
    r = res.waveform_columns["contact_resistance"]
    assert ax.get_ylim()[1] < 1e-6 * np.max(r[np.isfinite(r)])  # not scaled by the onsets
    assert [t.get_text() for t in ax.get_yticklabels()][-1] == "open"
    assert fig.legends[0].get_texts()[0].get_text() == "circuit snubber resistance = 22 ohm"
    assert_every_axis_has_a_unit(fig, "plot_overlay")


def test_a_named_contacts_columns_have_their_base_columns_unit():
    """A circuit of several contacts writes each one's columns with its name (a changeover's
    load_current_NO, mu_NC): each has its base column's unit, named after its contact."""
    from coupling.app.quantities import quantity

    for column, base in (("load_current_NO", "load_current"), ("contact_voltage_NC", "contact_voltage"),
                         ("mu_a", "mu"), ("gap_b", "gap")):
        q = quantity(column)
        assert q is not None and q.unit == quantity(base).unit and q.name.endswith(column.rsplit("_", 1)[1])
