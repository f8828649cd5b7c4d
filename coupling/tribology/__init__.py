"""Tribometer data and fits: gamma and mu(I) from friction, R_c(F_n, I) from resistance, as callables for the coupling.

Entry points: `read_tribometer_csv`, `fit_tribometer`, `default_fit` (the shipped
ILLUSTRATIVE dataset's fit), the laws `ContactLaws`, `MuLaw`, `ResistanceLaw` for inline
parameters, and `TribometerFit.from_json` for a saved fit. See docs/tribology.md.
"""

from __future__ import annotations

from functools import cache

from coupling.tribology.data import read_tribometer_csv, validate_tribometer_frame
from coupling.tribology.fits import TribometerFit, fit_tribometer
from coupling.tribology.laws import ContactLaws, MuLaw, ResistanceLaw

__all__ = [
    "ContactLaws", "MuLaw", "ResistanceLaw", "TribometerFit",
    "default_fit", "fit_tribometer", "illustrative_data_path", "read_tribometer_csv", "validate_tribometer_frame",
]


def illustrative_data_path():
    """Path of the shipped ILLUSTRATIVE (not measured) tribometer CSV."""
    from coupling.tribology.illustrative import ILLUSTRATIVE_CSV

    return ILLUSTRATIVE_CSV


@cache
def default_fit() -> TribometerFit:
    """The fit of the shipped illustrative dataset, computed once per process."""
    return fit_tribometer(read_tribometer_csv(illustrative_data_path()))
