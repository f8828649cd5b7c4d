"""The named drive channels: what a caller changes during a run, linear in time within a step.

A model's channels (mech.model.BarModel.drive_names) are one of each contact kind below
per contact point i, named "<kind>.<i>", then "armature.force" when the scene has an
armature; the solver keeps their values in the drive array (kernel_layout D_*: value at
D_T0, slope, D_T0 per row), which the kernel reads through the model's index array
``cdrive`` (kernel_layout K_*) and ipar[I_ARM_DRIVE], never by name. What the solver must
know of a kind to step it, hold at rest or audit its energy is here; the kernel's use of
it is in mech.kernel.dynamics.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping

import numpy as np

from .kernel_layout import CONTACT_DRIVES, D_SLOPE, D_T0, D_VALUE
from .frozen import frozen


@frozen
class DriveKind:
    """What a kind of drive channel is.

    unit: of its values. minimum: the least value a caller may give. clipped: values below
    zero act as zero (the value at the step's start is stored clipped, as the kernel
    clips the value it reads). friction: a change may change what can stick, so the
    regimes are resolved again. moves_equilibrium: a change moves the bar's static
    equilibrium, so a hold at rest ends when it changes and none starts while it ramps.
    force: it does work on the bar, which the energy audit needs an input-work quadrature
    for.
    """

    unit: str
    minimum: float = -math.inf
    clipped: bool = False
    friction: bool = False
    moves_equilibrium: bool = False
    force: bool = False


CONTACT_KINDS = {
    # the friction coefficient of the generalized law |F_t| = mu F_n^(1 - gamma): moves no
    # equilibrium by itself; whether a stick survives a new mu the solver checks itself
    "mu": DriveKind("N^gamma", clipped=True, friction=True),
    # Holm's electrodynamic repulsion of the constriction (or any force the caller computes)
    # along the block's normal, away from it, on a touching contact point
    "repulsion": DriveKind("N", minimum=0.0, moves_equilibrium=True, force=True),
}
assert tuple(CONTACT_KINDS) == CONTACT_DRIVES  # one description per kernel column K_*
# the armature's drive: its force along q is this channel times the gain table at q (N,
# or N m for a clapper, with no table; the coupling passes a magnet's flux linkage
# squared, Wb^2, with the table h(g(q)) in N/Wb^2); positive towards the pole
ARMATURE_DRIVE = "armature.force"
KINDS = {**CONTACT_KINDS,
         "armature": DriveKind("N (N m for a clapper) per unit of the gain table", moves_equilibrium=True,
                               force=True)}


def kind_of(name: str) -> DriveKind:
    """The kind of channel ``name`` ("<kind>.<point>")."""
    return KINDS[name.split(".", 1)[0]]


def _label(name: str | None) -> str:
    """How an error names a step's value of channel ``name`` (None: the ``mu`` argument)."""
    return "mu" if name is None else f"drives[{name!r}]"


def _pair(kind: DriveKind, value, name: str | None) -> tuple[float, float]:
    """(start, end) of one channel's value over a step (a number is constant), checked
    against its kind; ``name``: the channel's, for an error (None: the ``mu`` argument's)."""
    try:
        if type(value) is tuple and len(value) == 2 and type(value[0]) is float and type(value[1]) is float:
            start, end = value  # (what a co-simulation passes at every macro step: np.shape is ~2 us)
        elif isinstance(value, (int, float, np.number)) and not isinstance(value, bool):
            start = end = float(value)
        elif isinstance(value, (tuple, list, np.ndarray)) and np.shape(value) == (2,):
            start, end = float(value[0]), float(value[1])
        else:
            raise TypeError
    except (TypeError, ValueError):
        raise ValueError(f"{_label(name)} = {value!r}: expected a number or a (start, end) pair") from None
    for v in (start, end):
        if not (v >= kind.minimum and math.isfinite(v)):
            allowed = "a finite number" + (f" >= {kind.minimum:g}" if kind.minimum > -math.inf else "")
            raise ValueError(f"{_label(name)} = {value!r}: must be {allowed} ({kind.unit})")
    return start, end


def step_targets(names: tuple, drives, mu) -> dict[int, tuple[float, float]]:
    """drive row -> (start, end) for the channels a step is given, checked: ``drives`` maps
    channel names of ``names`` to a number or a (start, end) pair; ``mu`` sets every "mu.<i>"."""
    out: dict[int, tuple[float, float]] = {}
    if mu is not None:
        pair = _pair(KINDS["mu"], mu, None)
        out.update({row: pair for row, name in enumerate(names) if name.startswith("mu.")})
    if drives is None:
        return out
    if type(drives) is not dict and not isinstance(drives, Mapping):  # (the ABC's check skipped for a dict)
        raise ValueError(f"drives = {drives!r}: expected a mapping of channel names to values "
                         f"(channels: {', '.join(names)})")
    channels = _channels(names if type(names) is tuple else tuple(names))  # (a list is not hashable)
    for name, value in drives.items():
        channel = channels.get(name)
        if channel is None:
            raise ValueError(f"drives: unknown channel {name!r}; this model's channels are {', '.join(names)}")
        if mu is not None and name.startswith("mu."):
            raise ValueError(f"drives[{name!r}] and mu = {mu!r} both given: mu sets every mu.<i>; give one")
        # (the channel's name, not its message: built only for an error, not once a macro step)
        out[channel[0]] = _pair(channel[1], value, name)
    return out


@functools.lru_cache(maxsize=64)
def _channels(names: tuple) -> dict[str, tuple[int, DriveKind]]:
    """name -> (row, kind) of each channel of ``names`` (its first row, as names.index):
    looked up once per names tuple, not by index() and kind_of() once a macro step."""
    out: dict[str, tuple[int, DriveKind]] = {}
    for row, name in enumerate(names):
        if name not in out:
            out[name] = (row, kind_of(name))
    return out


def values_at(drive: np.ndarray, t: float) -> np.ndarray:
    """Every channel's value at t (s), as the kernel evaluates it (before clipping)."""
    return drive[:, D_VALUE] + drive[:, D_SLOPE] * (t - drive[:, D_T0])


def set_step(drive: np.ndarray, kinds: tuple, targets: dict, t: float, t_end: float) -> list[int]:
    """Write the drive for a step from t to t_end (s): each channel of ``targets`` linear
    from its start to its end value (constant if t_end <= t), every other one held at its
    value at t. ``kinds``: the DriveKind of each row. Returns the rows given a new value at
    t (as the kernel reads it: clipped kinds compared after clipping), and those of kinds
    that move the equilibrium that now ramp."""
    changed = []
    # (each row read as floats once: numpy's scalar indexing cost ~1 us a macro step; the
    # arithmetic is the same double arithmetic)
    for row, now in enumerate(drive.tolist()):
        target = targets.get(row)
        if target is None:
            if now[D_SLOPE] != 0.0:  # a ramp of an earlier step ends where that step ended
                drive[row, D_VALUE] = now[D_VALUE] + now[D_SLOPE] * (t - now[D_T0])
                drive[row, D_SLOPE] = 0.0
                drive[row, D_T0] = t
            continue
        kind = kinds[row]
        old = now[D_VALUE] + now[D_SLOPE] * (t - now[D_T0])
        start, end = target
        value = max(start, 0.0) if kind.clipped else start
        slope = (end - start) / (t_end - t) if t_end > t else 0.0
        drive[row, D_VALUE] = value
        drive[row, D_T0] = t
        drive[row, D_SLOPE] = slope
        if kind.clipped:
            old = max(old, 0.0)
        if value != old or (kind.moves_equilibrium and slope != 0.0):
            changed.append(row)
    return changed
