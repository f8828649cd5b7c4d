"""The value checks of circuit's parameter dataclasses: errors name the key, the value and what is allowed.

The one validation module of circuit: every frozen dataclass (templates, arc, options,
schedule, netlist) checks its fields with these, once, in ``__post_init__``. Each dataclass
names its scene section (``SECTION``: "circuit", "circuit.arc", ...) and its fields are the
section's keys, declared with ``scene_key``, so an error names the key as a scene writes it
("circuit.load_resistance = 0 ohm is out of range ..."; docs/scene_keys.md, "Where values
are checked").
"""

from __future__ import annotations

import dataclasses
import math
import numbers


def check_range(
    owner: str,
    field: str,
    value: object,
    unit: str,
    low: float,
    high: float,
    *,
    low_open: bool = False,
    allow_inf: bool = False,
) -> float:
    """Return ``value`` as float if ``low <= value <= high`` (``low < value`` when ``low_open``).

    Ranges are wide on purpose: they catch unit slips (100 instead of 100e-12 F) and
    non-physical signs, not unusual designs.
    """
    u = f" {unit}" if unit else ""  # a dimensionless value has no unit to print
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(f"{owner}.{field} = {value!r}: must be a real number" + (f" in {unit}" if unit else ""))
    number = float(value)
    if math.isnan(number) or (math.isinf(number) and not allow_inf):
        raise ValueError(f"{owner}.{field} = {value!r}{u}: must be finite")
    too_low = number <= low if low_open else number < low
    if too_low or number > high:
        lower = f"{low:g} < value" if low_open else f"{low:g} <= value"
        raise ValueError(f"{owner}.{field} = {number:g}{u} is out of range: allowed {lower} <= {high:g}{u}")
    return number


def check_choice(owner: str, field: str, value: object, choices) -> str:
    """Return ``value`` if it is one of ``choices``."""
    if isinstance(value, (list, dict)) or value not in choices:
        raise ValueError(f"{owner}.{field} = {value!r}: allowed values are {', '.join(map(repr, choices))}")
    return value


# --- scene keys: each dataclass field that a scene key sets carries the key's description ---

def scene_key(default=dataclasses.MISSING, *, unit: str = "-", doc: str = "", default_factory=dataclasses.MISSING,
              shown: str | None = None, keys: tuple = ()):
    """A dataclass field that is a scene key of the dataclass's section (its ``SECTION``,
    e.g. "circuit.arc"), named as the field: its default, its SI unit ("-": none) and a
    one-line meaning, the row of docs/scene_keys.md (written by ``python -m
    coupling.app.keys_doc``). ``shown``: the default column when the default is not one value
    (it depends on another key, or the key is needed). ``keys``: a field that several keys
    set together instead, as rows ``(key, unit, doc)`` (ContactSchedule.intervals: make, break)."""
    meta = {"unit": unit, "doc": doc}
    if shown is not None:
        meta["default"] = shown
    if keys:
        meta["keys"] = tuple(keys)
    return dataclasses.field(default=default, default_factory=default_factory, metadata=meta)


def internal(default=dataclasses.MISSING, *, default_factory=dataclasses.MISSING):
    """A dataclass field that no scene key sets (a part built from other keys, a title)."""
    return dataclasses.field(default=default, default_factory=default_factory, metadata={"internal": True})
