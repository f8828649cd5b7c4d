"""docs/scene_keys.md's key tables, written from the dataclass fields that define the keys.

Each scene key is defined once, as a field of the dataclass its section maps onto, declared
with ``scene_key(default, unit=..., doc=...)`` (mech.validation, circuit.validation): the
field's default is the key's default, and its unit and one-line meaning are the table's
row. ``python -m coupling.app.keys_doc`` rewrites every table of the page that stands
between a ``<!-- keys [section] ... -->`` line and ``<!-- end keys -->``, keeping the prose
around them; ``--check`` only says whether the page is current (tests/coupling/
test_scene_keys_doc.py runs it). A field without that description stops the generator
with a message naming the field and what to add.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import re
import sys
from pathlib import Path

import circuit as ck

DOC = Path(__file__).resolve().parents[2] / "docs" / "scene_keys.md"
COMMAND = "python -m coupling.app.keys_doc"
HEADER = ("| key | unit | default | meaning |", "|---|---|---|---|")
_TABLE = re.compile(r"(<!-- keys \[([a-z_.]+)\][^\n]*-->\n)(.*?)(<!-- end keys -->)", re.S)


def section_classes() -> dict[str, tuple]:
    """Scene section (as docs/scene_keys.md heads it, without brackets) -> the dataclasses
    whose fields are its keys, in the order of their rows."""
    from circuit.coil_drive import CoilDrive
    from mech.parameters import MechScene
    from mech.scene import LIST_SECTIONS, SECTIONS

    from coupling.core.device import DeviceSpec
    from coupling.core.duty import DutySettings, LifeLimits
    from coupling.laws.magnet import FluxTubeMagnet, TableMagnet
    from coupling.core.metrics import MetricSettings
    from coupling.core.scene import CouplingOptions, OutputOptions, TribologySpec

    out = {name: (cls,) for name, cls in SECTIONS.items()}
    out.update({name: (cls,) for name, (_, cls) in LIST_SECTIONS.items()})
    out["environment"] = (MechScene,)  # gravity; its other fields are the sections
    out["circuit"] = _circuit_classes()
    out.update({cls.SECTION: (cls,) for cls in (ck.Snubber, ck.FlybackDiode, ck.ArcModel, ck.ContactSchedule)})
    out["tribology"] = (TribologySpec,)
    out["coil"] = (CoilDrive,)  # (and the winding's resistance and turns, which make its CoilBlock)
    out["magnet"] = (DeviceSpec, FluxTubeMagnet, TableMagnet)  # its own keys, then each model's
    out["duty"] = (DutySettings,)
    out["duty.life"] = (LifeLimits,)
    out["coupling"] = (CouplingOptions,)
    out["output"] = (OutputOptions,)
    out["metrics"] = (MetricSettings,)
    return out


def _circuit_classes() -> tuple:
    """[circuit]'s dataclasses: the scene's own fields (template, ...), each template's, the
    ngspice options."""
    from coupling.core.scene import TEMPLATES, CircuitSpec, template_classes

    out = [CircuitSpec]
    for template in TEMPLATES:
        out += [cls for cls in template_classes(template) if cls not in out]
    return tuple(out) + (ck.SimulationOptions,)


def _template_defaults(key: str) -> str | None:
    """A [circuit] key's default where templates differ, "12 (inductive: 24; capacitive:
    0.5)": the first template's, then each other's that differs; None where all agree."""
    from coupling.core.scene import TEMPLATES, template_classes

    shown = {}
    for template in TEMPLATES:
        for cls in template_classes(template):
            row = next((r for r in field_rows(cls) if r[0] == key), None)
            if row is not None:
                shown.setdefault(template, row[2])
    values = list(shown.values())
    if len(set(values)) < 2:
        return None
    others = [f"{t}: {v}" for t, v in shown.items() if v != values[0]]
    return f"{values[0]} ({'; '.join(others)})"


def field_rows(cls) -> list[tuple[str, str, str, str]]:
    """(key, unit, default, meaning) of each scene key among ``cls``'s fields, in field order
    (a key two fields share, bar.modes, once). A field declared neither ``scene_key`` nor
    ``internal`` is a ValueError naming it and what to add."""
    rows, seen = [], set()
    for f in dataclasses.fields(cls):
        meta = f.metadata
        if meta.get("internal"):
            continue
        if "unit" not in meta:
            raise ValueError(
                f"{cls.__module__}.{cls.__name__}.{f.name}: no scene-key description; declare it as "
                f"`{f.name}: ... = scene_key(<default>, unit=\"<SI unit or ->\", doc=\"<one line>\")` "
                "(mech.validation or circuit.validation), or `internal(<default>)` when no scene key sets it; "
                f"then run `{COMMAND}`")
        for key, unit, doc in meta.get("keys", ()):  # a field several keys set: each its row, no default
            rows.append((key, unit, "-", doc))
        if "keys" in meta:
            continue
        key = meta.get("key", f.name)
        if key in seen:
            continue
        seen.add(key)
        if "default" in meta:
            shown = meta["default"]
        elif f.default is not dataclasses.MISSING:
            shown = format_value(f.default)
        else:
            shown = format_value(f.default_factory())
        rows.append((key, meta["unit"], shown, meta["doc"]))
    return rows


def format_value(value) -> str:
    """A default as the TOML value a scene would write ('-': None, no value)."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return _number(value)
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(format_value(v) for v in value) + "]"
    raise ValueError(f"default {value!r}: no TOML form; give the field scene_key(..., shown=\"...\")")


def _number(x: float) -> str:
    if x == 0.0 or (x == int(x) and abs(x) < 1e6):
        return str(int(x))
    if 1e-3 <= abs(x) < 1e6:
        return repr(x)
    mantissa, exponent = f"{x:.6e}".split("e")
    plain = f"{mantissa.rstrip('0').rstrip('.')}e{int(exponent)}"  # 1e-14, not 1.000000e-14 or 10e-15
    third = 3 * math.floor(math.log10(abs(x)) / 3)
    engineering = f"{x / 10.0 ** third:.6g}e{third}"  # 210e9, not 2.1e11
    return min(plain, engineering, key=len)


def table(section: str) -> list[str]:
    """The markdown table of one section's keys."""
    classes = section_classes().get(section)
    if classes is None:
        raise ValueError(f"docs/scene_keys.md: no dataclass defines the keys of [{section}]; known sections: "
                         f"{', '.join(sorted(section_classes()))}")
    lines, seen = list(HEADER), set()
    for cls in classes:
        for key, unit, shown, doc in field_rows(cls):
            if key not in seen:
                seen.add(key)
                if section == "circuit":
                    shown = _template_defaults(key) or shown
                cell = doc.replace("|", "\\|")
                lines.append(f"| `{key}` | {unit} | {shown} | {cell} |" if cell else f"| `{key}` | {unit} | {shown} | |")
    return lines


def render(text: str) -> str:
    """The page with every generated table rewritten; a section of section_classes() without
    its table on the page is a ValueError."""
    found = [m.group(2) for m in _TABLE.finditer(text)]
    missing = [s for s in section_classes() if s not in found]
    if missing:
        raise ValueError(f"docs/scene_keys.md has no generated table for [{'], ['.join(missing)}]: add "
                         f"'<!-- keys [{missing[0]}] -->' and '<!-- end keys -->' lines under its heading")
    return _TABLE.sub(lambda m: m.group(1) + "\n".join(table(m.group(2))) + "\n" + m.group(4), text)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog=COMMAND, description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="only say whether the page is current (exit 1: stale)")
    parser.add_argument("--doc", type=Path, default=DOC, help="the page (default: docs/scene_keys.md)")
    args = parser.parse_args(argv)
    text = args.doc.read_text()
    new = render(text)
    if args.check:
        if new != text:
            print(f"{args.doc} is stale: run `{COMMAND}`", file=sys.stderr)
            return 1
        return 0
    if new != text:
        args.doc.write_text(new)
    print(f"{args.doc}: {len(_TABLE.findall(new))} key tables {'written' if new != text else 'current'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
