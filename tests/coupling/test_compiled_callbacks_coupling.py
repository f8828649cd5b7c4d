"""A coupled relay through ngspice's compiled source callbacks (circuit/callbacks.c) and
through its Python callbacks: the same results to the bit; the coil's gap channel, a
TableChannel of the armature's dense output, evaluated in C as mech's Segment.armature and
CoilLink's gap evaluate it in Python, bit for bit at random times.
"""

from __future__ import annotations

import random
import struct
from pathlib import Path

import numpy as np
import pytest

from circuit import TableChannel, compiled_callbacks
from coupling import load_scene, run
from coupling.core import exchange
from coupling.core.scene import default_scene

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _run(scene, python: bool, monkeypatch):
    if python:
        monkeypatch.setenv(compiled_callbacks.FORCE_PYTHON, "1")
    else:
        monkeypatch.delenv(compiled_callbacks.FORCE_PYTHON, raising=False)
    return run(scene)


@pytest.mark.parametrize("scene", ["default", "relay_coil_arc"])
def test_a_relay_runs_to_the_same_bits_on_both_routes(scene, monkeypatch):
    """The default relay (its coil's gap a TableChannel, the contact's arcs) and a relay
    breaking an inductive load's arc."""
    scene = default_scene() if scene == "default" else load_scene(EXAMPLES / f"{scene}.toml")
    compiled, python = _run(scene, False, monkeypatch), _run(scene, True, monkeypatch)
    assert str(compiled.status) == str(python.status)
    assert compiled.waveform_columns.keys() == python.waveform_columns.keys()
    for key, column in compiled.waveform_columns.items():
        assert column.tobytes() == python.waveform_columns[key].tobytes(), key
    assert compiled.summary == python.summary or _same_numbers(compiled.summary, python.summary)


def _same_numbers(a, b) -> bool:
    """Summaries equal but for run statistics and timings."""
    skip = {"run", "wall_time", "solver_seconds", "timing"}
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(k in skip or _same_numbers(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return len(a) == len(b) and all(_same_numbers(x, y) for x, y in zip(a, b))
    if isinstance(a, float):
        return struct.pack("<d", a) == struct.pack("<d", b)
    return a == b


def test_the_coil_gap_table_is_the_armatures_dense_output_bit_for_bit(monkeypatch):
    monkeypatch.delenv(compiled_callbacks.FORCE_PYTHON, raising=False)
    library = compiled_callbacks.load()
    assert library is not None
    tables = []
    inputs = exchange.CoilLink.inputs

    def kept(self, seg):
        out = inputs(self, seg)
        tables.extend(out.values())
        return out

    monkeypatch.setattr(exchange.CoilLink, "inputs", kept)
    run(default_scene())
    assert tables and all(isinstance(t, TableChannel) for t in tables)
    moving = [t for t in tables if len(t.ends) > 1 and np.ptp(t.coefficients[:, 0]) > 0.0]
    assert moving  # the armature moved over some steps
    rng = random.Random(3)
    for table in rng.sample(moving, min(40, len(moving))) + tables[:3]:
        lo, hi = table.lo, table.hi
        times = [rng.uniform(lo, hi) for _ in range(100)] + [lo, hi, lo - 1e-9, hi + 1e-9]
        times += table.ends.tolist() + table.t0.tolist()
        c = compiled_callbacks.table_values(library, table, times)
        python = [table.function(t) for t in times]  # CoilLink's gap over Segment.armature
        assert [struct.pack("<d", v) for v in c] == [struct.pack("<d", v) for v in python]
