"""``modes = "auto"``: how many free-free modes per family a scene needs.

Rule: every mode whose frequency lies below the cutoff f_cut = SAFETY / t_c, with t_c
the Hertz contact duration of the scene's first impact (rigid-bar effective mass of the
impacting tip, the scene's impact speed, the contact stiffness), counted per family
(axial; bending, the more flexible plane for a rectangular section), then held within
[FLOOR, CAP]. Modes well above 1/t_c respond quasi-statically to a contact pulse and
change neither the contact intervals nor the forces; the factor SAFETY was chosen by
measurement (benchmarks/bench_mode_count.py, table in docs/accuracy-modes.md).

The floor is for a family the impact loads: above the cutoff a mode still adds its static
compliance at the contact point (1/k^2 of the first's, for a free-free bar's axial modes at
its tip), and a bar struck on its end converges slowly in its axial count. A family the
first impact's normal does not load (the axial modes of a blade or lever struck across its
axis) keeps the cutoff's count where the other family reaches the floor: raising it adds
nothing the contact feels, and its highest mode would set the explicit integrator's
stability-limited step. Where both families fall short, both are raised as before.
Measured in docs/accuracy-modes.md.
"""

from __future__ import annotations

import math

import numpy as np
from .frozen import frozen

SAFETY = 3.0  # f_cut = SAFETY / t_c
CAP = 40  # the largest count bar.modes accepts
FLOOR = 3  # the paper's count, and never fewer than an explicit default used to give


@frozen
class ModeCount:
    """The count chosen per family and why. cutoff: Hz. contact_time: s. impact_speed: m/s."""

    axial: int
    bending: int
    cutoff: float
    contact_time: float
    impact_speed: float
    safety: float
    capped: tuple[str, ...] = ()
    floored: tuple[str, ...] = ()
    # families short of the floor left at the cutoff's count: the impact does not load them
    unloaded: tuple[str, ...] = ()
    # Hz: the lowest frequency of each family left out (inf: none known, or capped): a
    # faster impact than the estimate changes the count only once its cutoff passes one
    next_frequencies: tuple[float, float] = (math.inf, math.inf)

    @property
    def reason(self) -> str:
        """One line for summary.solver, e.g. "auto: 3 axial, 7 bending modes below 26.6 kHz
        = 2 / t_c (t_c = 75.2 us at 0.99 m/s)"."""
        text = (f"auto: {self.axial} axial, {self.bending} bending modes below {self.cutoff / 1e3:.3g} kHz "
                f"= {self.safety:g} / t_c (t_c = {self.contact_time * 1e6:.3g} us at {self.impact_speed:.3g} m/s)")
        notes = [f"{fam} capped at {CAP}" for fam in self.capped]
        notes += [f"{fam} raised to the floor {FLOOR}" for fam in self.floored]
        notes += [f"{fam} not raised to the floor (the impact's normal does not load it)" for fam in self.unloaded]
        return text + ("; " + ", ".join(notes) if notes else "")


def count_below(frequencies, cutoff: float) -> int:
    """Number of entries of ``frequencies`` (Hz, ascending) strictly below ``cutoff`` (Hz)."""
    f = np.asarray(frequencies, dtype=float)
    return int(np.count_nonzero(f < cutoff))


def choose_mode_count(axial_frequencies, bending_frequencies, contact_time: float, *,
                      impact_speed: float = math.nan, safety: float = SAFETY, cap: int = CAP,
                      floor: int = FLOOR, unloaded: tuple[str, ...] = ()) -> ModeCount:
    """Modes per family below f_cut = safety / contact_time, held within [floor, cap]; a
    family named in ``unloaded`` ("axial", "bending") keeps the cutoff's count below the
    floor where the other family reaches the floor below the cutoff.

    axial_frequencies, bending_frequencies: Hz, ascending, the first ``cap`` (at least)
    of each family. contact_time: s, > 0. impact_speed: m/s, only reported.
    """
    if not (contact_time > 0.0 and math.isfinite(contact_time)):
        raise ValueError(f"contact_time = {contact_time!r}: must be a finite time > 0 s")
    if not safety > 0.0:
        raise ValueError(f"safety = {safety!r}: must be > 0")
    cutoff = safety / contact_time
    families = (("axial", axial_frequencies), ("bending", bending_frequencies))
    admitted = {fam: count_below(freqs, cutoff) for fam, freqs in families}
    counts, capped, floored, below, following = {}, [], [], [], []
    for fam, freqs in families:
        k = admitted[fam]
        other = admitted["bending" if fam == "axial" else "axial"]
        if k >= cap:
            k = cap
            capped.append(fam)
        elif k < floor and fam in unloaded and other >= floor:
            below.append(fam)
        elif k < floor:
            k = floor
            floored.append(fam)
        counts[fam] = k
        f = np.asarray(freqs, dtype=float)
        following.append(float(f[k]) if k < min(cap, len(f)) else math.inf)
    return ModeCount(axial=counts["axial"], bending=counts["bending"], cutoff=cutoff,
                     contact_time=contact_time, impact_speed=impact_speed, safety=safety,
                     capped=tuple(capped), floored=tuple(floored), unloaded=tuple(below),
                     next_frequencies=tuple(following))
