"""Coupled scenes with [[fixed]] contacts and a circuit of one contact (a bridge's two circuit
contacts, each fed by its own fixed contact: tests/coupling/test_bridge.py).

One fixed contact through [[fixed]] is the [block] scene in the circuit too: the mechanics
agree bit for bit (tests/mech/test_mech_pairs.py), so the circuit's inputs and every
waveform do. A scene whose circuit contact does not stand for one electrical fixed contact
(a changeover's NO and NC, a stop feeding it, an electrical contact left out) says so in
its result's warnings, and its results are what they were without the line.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest

from coupling import builtin_scene, run
from coupling.core.diagnostics import pairs_warning
from coupling.core.scene import scene_from_dict

T_END = 1.5e-3  # s: the force-driven relay's first make (0.8 ms) and bounces


def relay_doc() -> dict:
    doc = copy.deepcopy(builtin_scene("relay_force").raw)
    doc["solver"]["t_end"] = T_END
    return doc


def as_fixed(doc: dict) -> dict:
    """The force-driven relay's [block] (a silver rivet head, its top at z = 0) as one [[fixed]] entry."""
    doc = copy.deepcopy(doc)
    doc["fixed"] = [dict(point="rivet0", name="NO", height=0.0, **doc.pop("block"))]
    return doc


def changeover(nc: dict | None = None) -> dict:
    """The force-driven relay with a second rivet on the blade's top and an NC contact above it,
    0.1 mm away (``nc`` patches the NC entry)."""
    doc = as_fixed(relay_doc())
    rivet = doc["rivet"][0]
    doc["rivet"].append(dict(rivet, offset=-rivet["offset"], mass=0.0, name="top"))
    doc["fixed"].append(dict(doc["fixed"][0], point="top", name="NC", facing="down", gap=1e-4, **(nc or {})))
    del doc["fixed"][1]["height"]
    return doc


@pytest.fixture(scope="module")
def block_run():
    return run(scene_from_dict(relay_doc()))


def test_one_fixed_contact_runs_the_block_scene_in_the_circuit_too(block_run):
    """The same mechanics to the last bit gives ngspice the same inputs at the same times:
    every waveform column equal, bit for bit, the same bounce metrics, and no line about
    the contacts (one electrical fixed contact is what the circuit's contact stands for)."""
    res = run(scene_from_dict(as_fixed(relay_doc())))
    a, b = block_run.waveform_columns, res.waveform_columns
    assert block_run.summary["bounce"]["bounces"] > 0  # (a make with bounces, not an idle run)
    assert set(a) == set(b)
    for name in a:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)
    assert block_run.summary["bounce"] == res.summary["bounce"]
    assert not any("[[fixed]]" in w for w in res.warnings)


def test_a_changeover_in_the_circuit_warns_that_its_contacts_are_one_parallel_contact():
    """NO and NC both electrical: the run's warnings (summary.json's too) say the circuit's
    one contact stands for both in parallel and names the templates that give each its own
    circuit contact (template "changeover": tests/coupling/test_changeover.py). The
    run itself goes on as before the pairs: the blade goes down onto NO and bounces; NC is
    never struck."""
    res = run(scene_from_dict(changeover()))
    lines = [w for w in res.warnings if w.startswith("[[fixed]]")]
    assert len(lines) == 1 and "\n" not in lines[0]
    line = lines[0]
    assert "pairs 0 (rivet0 on NO) and 1 (top on NC) in parallel, as one circuit contact" in line
    assert 'circuit.template = "bridge" (two in series), "changeover" (NO and NC)' in line
    assert line in res.summary["warnings"]
    w = res.waveform_columns
    assert res.summary["bounce"]["bounces"] > 0 and np.all(w["normal_force_1"] == 0.0)


@pytest.mark.parametrize("nc, words", [
    (dict(electrical=False), "the stop 'NC' (electrical = false) among them"),
])
def test_a_stop_feeding_the_circuit_contact_is_named(nc, words):
    line = pairs_warning(scene_from_dict(changeover(nc)))
    assert line is not None and words in line


def test_an_electrical_contact_beyond_the_first_two_pairs_is_named():
    """The circuit's contact reads the first two pairs; a third electrical one is not in it."""
    doc = changeover(dict(electrical=False))
    doc["rivet"].append(dict(doc["rivet"][0], position=0.005, name="far"))
    doc["fixed"].append(dict(doc["fixed"][0], point="far", name="other", height=None, gap=1e-4))
    del doc["fixed"][2]["height"]
    line = pairs_warning(scene_from_dict(doc))
    assert line is not None and "the electrical pair 2 (far on other) is not in the circuit" in line


def test_one_electrical_contact_and_a_mechanics_alone_have_no_line():
    assert pairs_warning(scene_from_dict(as_fixed(relay_doc()))) is None
    assert pairs_warning(scene_from_dict(relay_doc())) is None  # ([block]: one fixed contact)
    doc = changeover()
    del doc["tribology"]
    doc.pop("circuit", None)
    doc.pop("coupling", None)
    assert pairs_warning(scene_from_dict(doc)) is None  # (no circuit: nothing stands for the contacts)
