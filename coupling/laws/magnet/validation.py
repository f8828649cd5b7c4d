"""The value checks of the magnet's dataclasses: each raises ValueError on one line naming
the field as the scene spells it, the value and what is allowed, and returns the value in
its checked form. (The magnet imports nothing of mech, whose own checks these mirror.)"""

from __future__ import annotations

import math

import numpy as np

NUMBERS = (int, float, np.integer, np.floating)


def check_finite(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, NUMBERS):
        raise ValueError(f"{name} = {value!r}: expected a number")
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} = {value!r}: expected a finite number")
    return value


def check_positive(name: str, value, unit: str = "") -> float:
    value = check_finite(name, value)
    if value <= 0.0:
        raise ValueError(f"{name} = {value!r}: must be > 0{' ' + unit if unit else ''}")
    return value


def check_nonnegative(name: str, value, unit: str = "") -> float:
    value = check_finite(name, value)
    if value < 0.0:
        raise ValueError(f"{name} = {value!r}: must be >= 0{' ' + unit if unit else ''}")
    return value


def check_numbers(name: str, values, unit: str) -> tuple[float, ...]:
    """A list of finite numbers, as a tuple of floats."""
    if isinstance(values, (str, dict, bytes)) or not hasattr(values, "__iter__"):
        raise ValueError(f"{name} = {values!r}: expected a list of numbers ({unit})")
    return tuple(check_finite(f"{name}[{j}]", v) for j, v in enumerate(values))


def check_increasing(name: str, values: tuple[float, ...], unit: str) -> None:
    """Strictly increasing, or the first offending entry named."""
    for j in range(1, len(values)):
        if values[j] <= values[j - 1]:
            raise ValueError(f"{name}[{j}] = {values[j]!r}: must increase strictly "
                             f"(previous {values[j - 1]!r} {unit})")


def check_instance(name: str, value, classes, what: str):
    if not isinstance(value, classes):
        raise ValueError(f"{name}: expected {what}, got {type(value).__name__}")
    return value


def unknown(where: str, name: str, allowed, kind: str) -> ValueError:
    """The error for an unknown name: a did-you-mean and the allowed names."""
    import difflib  # (here: only an error asks for it; ~1 ms of every run's start otherwise)

    close = difflib.get_close_matches(str(name), [str(a) for a in allowed], n=1)
    hint = f" (did you mean {close[0]!r}?)" if close else ""
    return ValueError(f"{where}: unknown {kind} {name!r}{hint}; allowed: {', '.join(sorted(allowed))}")
