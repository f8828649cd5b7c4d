"""The value checks of mech's parameter dataclasses, and the one did-you-mean of scene keys.

Every frozen dataclass of mech (mech/parameters.py, mech/beam_fe.py) checks its fields
with these functions, once, in ``__post_init__``; nothing downstream re-validates. Each
check raises ``ValueError`` naming the field, the value and what is allowed, on one line,
and returns the value in its checked form (a float, a tuple). The scene readers only add
the structure around them: sections, key names, the file (docs/scene_keys.md, "Where
values are checked"). coupling's own section dataclasses use these checks too, and
``suggest`` / ``unknown`` are the did-you-mean of every scene section, key and CSV column.
"""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import numpy as np


def check_finite(name: str, value) -> float:
    """Return ``value`` as float, or raise naming the field when it is not a finite number."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{name} = {value!r}: expected a number")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} = {value!r}: expected a finite number")
    return value


def check_positive(name: str, value, *, allow_inf: bool = False, high: float | None = None) -> float:
    """A number > 0; ``allow_inf`` accepts +inf (a bound that may be switched off); ``high``:
    the largest value allowed (mech.parameters' bounds)."""
    if allow_inf and isinstance(value, (float, np.floating)) and value == math.inf:
        return math.inf
    try:
        value = check_finite(name, value)
    except ValueError:
        if allow_inf:
            raise ValueError(f"{name} = {value!r}: expected a number > 0 or inf") from None
        raise
    if high is not None and not value <= high:
        raise ValueError(f"{name} = {value!r}: allowed range is (0, {high:g}]")
    if value <= 0.0:
        raise ValueError(f"{name} = {value!r}: must be > 0" + (" (inf allowed)" if allow_inf else ""))
    return value


def check_nonnegative(name: str, value, *, high: float | None = None) -> float:
    """A number >= 0 (and <= ``high`` when given)."""
    value = check_finite(name, value)
    if value < 0.0:
        raise ValueError(f"{name} = {value!r}: must be >= 0" + (f" (allowed range [0, {high:g}])" if high else ""))
    if high is not None and value > high:
        raise ValueError(f"{name} = {value!r}: allowed range is [0, {high:g}]")
    return value


def check_magnitude(name: str, value, high: float) -> float:
    """A finite number of absolute value <= ``high`` (either sign)."""
    value = check_finite(name, value)
    if abs(value) > high:
        raise ValueError(f"{name} = {value!r}: allowed range is [-{high:g}, {high:g}]")
    return value


def check_range(name: str, value, low: float, high: float, *, closed_low=False, closed_high=False) -> float:
    """A number inside (low, high); ``closed_*`` makes that end inclusive."""
    value = check_finite(name, value)
    ok_low = value >= low if closed_low else value > low
    ok_high = value <= high if closed_high else value < high
    if not (ok_low and ok_high):
        lo, hi = ("[" if closed_low else "("), ("]" if closed_high else ")")
        raise ValueError(f"{name} = {value!r}: allowed range is {lo}{low}, {high}{hi}")
    return value


def check_choice(name: str, value, choices) -> str:
    if isinstance(value, (list, dict)) or value not in choices:
        raise ValueError(f"{name} = {value!r}: allowed values are {', '.join(map(repr, choices))}")
    return value


def check_bool(name: str, value) -> bool:
    if not isinstance(value, bool):
        raise ValueError(f"{name} = {value!r}: expected true or false")
    return value


def check_whole(name: str, value, low: int = 0, high: int | None = None, *, note: str = "") -> int:
    """A whole number in [low, high] (no upper bound when ``high`` is None); ``note`` is
    added to the message, e.g. what 0 means."""
    if (isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < low
            or (high is not None and value > high)):
        allowed = f">= {low}" if high is None else f"in [{low}, {high}]"
        raise ValueError(f"{name} = {value!r}: expected a whole number {allowed}{note}")
    return int(value)


def check_count(name: str, value, high: int = 40, auto: bool = False):
    """A mode count: a whole number in [0, high], or "auto" when ``auto`` (chosen from the
    scene's contact time, mech/mode_count.py)."""
    if auto and value == "auto":
        return value
    return check_whole(name, value, 0, high, note=' or "auto"' if auto else "")


def check_vector3(name: str, value, high: float | None = None) -> tuple[float, float, float]:
    """Three finite numbers (each of absolute value <= ``high`` when given)."""
    try:
        items = list(value)
    except TypeError:
        raise ValueError(f"{name} = {value!r}: expected a list of 3 numbers") from None
    if isinstance(value, (str, dict)) or len(items) != 3:
        raise ValueError(f"{name} = {value!r}: expected a list of 3 numbers")
    if high is None:
        return tuple(check_finite(f"{name}[{i}]", v) for i, v in enumerate(items))
    return tuple(check_magnitude(f"{name}[{i}]", v, high) for i, v in enumerate(items))


def check_table(name: str, times, values=None, *, width: int | None = None, time_high: float | None = None,
                value_high: float | None = None, max_points: int | None = None):
    """A time table: times strictly increasing, finite, >= 0 (and <= ``time_high``); values
    finite, one per time (``width``: each value a list of that many numbers; each number of
    absolute value <= ``value_high``); at most ``max_points`` points. Returns (times,
    values) as tuples."""
    numbers = (int, float, np.integer, np.floating)
    items = list(times) if hasattr(times, "__iter__") and not isinstance(times, (str, dict)) else None
    if items is None or not all(isinstance(v, numbers) and not isinstance(v, bool) for v in items):
        raise ValueError(f"{name}.time = {_short(times)}: expected a list of numbers (s)")
    if max_points is not None and len(items) > max_points:
        raise ValueError(f"{name}.time: {len(items)} points; at most {max_points} allowed")
    ts = [float(v) for v in items]
    if not ts:
        raise ValueError(f"{name}.time: the table is empty; give at least one time")
    for k, t in enumerate(ts):
        if not math.isfinite(t) or t < 0.0:
            raise ValueError(f"{name}.time[{k}] = {t!r}: times must be finite and >= 0 s")
        if time_high is not None and t > time_high:
            raise ValueError(f"{name}.time[{k}] = {t!r}: allowed range is [0, {time_high:g}] s")
        if k and t <= ts[k - 1]:
            raise ValueError(f"{name}.time[{k}] = {t!r}: times must increase strictly "
                             f"(previous {ts[k - 1]!r})")
    if values is None:
        return tuple(ts), None
    try:
        if isinstance(values, (str, dict)):
            raise TypeError
        vals = list(values)
    except TypeError:
        raise ValueError(f"{name}: expected a list of values, one per time") from None
    if len(vals) != len(ts):
        raise ValueError(f"{name}: {len(vals)} values for {len(ts)} times; give one value per time")
    out = []
    for k, v in enumerate(vals):
        if width is None:
            out.append(check_finite(f"{name}[{k}]", v) if value_high is None
                       else check_magnitude(f"{name}[{k}]", v, value_high))
        else:
            out.append(check_vector3(f"{name}[{k}]", v, value_high))
    return tuple(ts), tuple(out)


def _short(value, limit: int = 80) -> str:
    """repr of a value, cut to ``limit`` characters (a table of 10^6 numbers is not quoted whole)."""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 5] + " ...]"


def check_position(name: str, value, length: float) -> float:
    """A position along the bar (m from tip 0) inside [0, length]."""
    x = check_finite(name, value)
    if not 0.0 <= x <= length:
        raise ValueError(f"{name} = {x!r}: must lie on the bar, in [0, {length!r}] m from tip 0")
    return x


NAME_PATTERN = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,31}")


def check_name(name: str, value) -> str:
    """A name a scene gives a part (a contact point, a fixed contact) for other keys, the
    results and a circuit to refer to: a letter, then up to 31 letters, digits or '_'."""
    if not isinstance(value, str) or not NAME_PATTERN.fullmatch(value):
        raise ValueError(f"{name} = {_short(value)}: expected a name: a letter, then up to 31 letters, "
                         "digits or '_'")
    return value


def check_file(name: str, path) -> Path:
    """A file a scene or command names, as a Path: a missing file is FileNotFoundError; a
    folder, a device (``/dev/null``), a pipe or a socket a ValueError saying which. The
    file's content is not read here (and never quoted)."""
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{name}: {str(path)!r} is a folder, not a file")
    if not path.exists():
        raise FileNotFoundError(f"{name}: file {str(path)!r} not found")
    if not path.is_file():
        raise ValueError(f"{name}: {str(path)!r} is not a regular file (a device, pipe or socket)")
    return path


def suggest(word: str, allowed) -> str:
    """The did-you-mean of every scene section, key and CSV column: ' (did you mean 'x'?)'
    for the closest allowed name, or '' when none is close."""
    import difflib  # (here: only an error asks for it; ~1 ms of every run's start otherwise)

    close = difflib.get_close_matches(str(word), [str(a) for a in allowed], n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def unknown(where: str, name: str, allowed, kind: str = "key") -> ValueError:
    """The error for an unknown ``kind`` ("key", "section"): the name, a did-you-mean and
    the allowed names."""
    shown = f"[{name}]" if kind == "section" else repr(name)
    return ValueError(f"{where}: unknown {kind} {shown}{suggest(name, allowed)}; "
                      f"allowed {kind}s: {', '.join(sorted(allowed))}")


def check_keys(where: str, table: dict, allowed, kind: str = "key") -> dict:
    """``table`` when every key of it is allowed, else the ``unknown`` error of the first one."""
    for key in table:
        if key not in allowed:
            raise unknown(where, key, allowed, kind)
    return table


# --- scene keys: each dataclass field that a scene key sets carries the key's description ---

def scene_key(default=dataclasses.MISSING, *, unit: str, doc: str = "", default_factory=dataclasses.MISSING,
        shown: str | None = None, name: str | None = None):
    """A dataclass field that is a scene key: its default, its SI unit ("-": none) and a one-line
    meaning, the row of docs/scene_keys.md (written by ``python -m coupling.app.keys_doc``).
    ``shown``: the default column when the default is not one value (it depends on another key,
    or it is computed); ``name``: the scene key when it differs from the field's name (bar.modes
    sets axial_modes and bending_modes)."""
    meta = {"unit": unit, "doc": doc}
    if shown is not None:
        meta["default"] = shown
    if name is not None:
        meta["key"] = name
    return dataclasses.field(default=default, default_factory=default_factory, metadata=meta)


def internal(default=dataclasses.MISSING, *, default_factory=dataclasses.MISSING):
    """A dataclass field that no scene key sets (an entry's place in its list, for messages)."""
    return dataclasses.field(default=default, default_factory=default_factory, metadata={"internal": True})
