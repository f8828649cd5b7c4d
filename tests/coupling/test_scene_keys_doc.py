"""docs/scene_keys.md lists every section and key the scene validators accept (and no other)."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

from coupling import scene as cs
from coupling.metrics import MetricSettings
from mech.scene import ENVIRONMENT_KEYS, LIST_SECTIONS, SECTIONS

DOC = Path(__file__).resolve().parents[2] / "docs" / "scene_keys.md"


def _documented() -> dict[str, set[str]]:
    out: dict[str, set[str]] = {}
    section = None
    for line in DOC.read_text().splitlines():
        m = re.match(r"^## \[\[?([a-z_.]+)\]\]?", line)  # [section] or [[array of tables]]
        if m:
            section = m.group(1)
            out[section] = set()
            continue
        m = re.match(r"^\| `([a-z_]+)` \|", line)
        if m and section:
            out[section].add(m.group(1))
    return out


def _fields(cls) -> set[str]:
    return {f.name for f in dataclasses.fields(cls)}


def test_every_accepted_key_is_documented_and_nothing_else():
    doc = _documented()
    expected = {name: _fields(cls) for name, cls in SECTIONS.items()}
    # [bar] modes stands for axial_modes/bending_modes
    expected["bar"] = (expected["bar"] - {"axial_modes", "bending_modes"}) | {"modes"}
    expected["initial"] = expected["initial"]
    expected["environment"] = set(ENVIRONMENT_KEYS)
    for name, (_field, cls) in LIST_SECTIONS.items():  # [[force]], [[spring]], [[rivet]]
        expected[name] = _fields(cls) - {"name"}  # (the name is the entry's place, force[0], ...)
    expected["tribology"] = {"source", "fit", "data", "mu", "resistance", "feedback"}
    expected["circuit"] = set(cs.CIRCUIT_KEYS)
    expected["circuit.schedule"] = {"make", "break", "closed_resistance", "edge_time", "opening_speed"}
    expected["coupling"] = _fields(cs.CouplingOptions)
    expected["output"] = _fields(cs.OutputOptions)
    expected["metrics"] = _fields(MetricSettings)
    assert set(doc) == set(expected), "sections of docs/scene_keys.md differ from the scene's"
    for section, keys in expected.items():
        assert doc[section] == keys, f"[{section}]: missing {keys - doc[section]}, extra {doc[section] - keys}"


def test_readme_relay_quick_start_scene_is_valid():
    """The README's "model my relay" scene validates as written (and uses the material law)."""
    import tomllib

    from coupling.scene import scene_from_dict

    text = (DOC.parents[1] / "README.md").read_text()
    block = re.search(r"```toml\n(# relay\.toml.*?)```", text, re.S).group(1)
    scene = scene_from_dict(tomllib.loads(block), name="relay")
    assert scene.kind == "coupled" and scene.tribology.laws.resistance_law.materials == ("AgNi10", "Ag")
    assert scene.mech.initial.height == 0.4e-3 and scene.circuit.circuit.load.resistance == 5.0
