"""Tribometer data and fits: gamma and mu(I) from friction, R_c(F_n, I) from resistance, as callables for the coupling.

Entry points: `read_tribometer_csv`, `fit_tribometer`, `default_fit` (the shipped
ILLUSTRATIVE dataset's fit), the laws `ContactLaws`, `MuLaw`, `ResistanceLaw` for inline
parameters, and `TribometerFit.from_json` for a saved fit. See docs/tribology.md.
"""

from __future__ import annotations

import dataclasses
import json
from functools import cache
from pathlib import Path

from coupling import lazy_attributes
from coupling.laws.tribology.laws import ContactLaws, MuLaw, ResistanceLaw

__all__ = [
    "ContactLaws", "MuLaw", "ResistanceLaw", "TribometerFit",
    "default_fit", "fit_tribometer", "illustrative_data_path", "read_tribometer_csv", "validate_tribometer_frame",
]


# Reading and fitting data need pandas (0.3 s to import): loaded on first use (PEP 562), so
# a scene whose laws are given inline (the default scene) never imports it.
_LAZY = {"read_tribometer_csv": "data", "validate_tribometer_frame": "data", "TribometerFit": "fits",
         "fit_tribometer": "fits"}


__getattr__ = lazy_attributes(__name__, _LAZY)


def illustrative_data_path():
    """Path of the shipped ILLUSTRATIVE (not measured) tribometer CSV."""
    from coupling.laws.tribology.illustrative import ILLUSTRATIVE_CSV

    return ILLUSTRATIVE_CSV


# The default scene's fit, stored: fitting it (and importing scipy.optimize and
# scipy.stats for it) was a large part of the start of every default run. It is used only
# while its key, a hash of the dataset and of the fitting code, matches; otherwise the
# dataset is fitted as before (tests/coupling/test_tribology_data.py checks it is current).
DEFAULT_FIT_CACHE = Path(__file__).resolve().parent.parent / "data" / "tribometer_illustrative_fit.json"
_FIT_SOURCES = ("data.py", "fits.py", "laws.py", "models.py")


def default_fit_key() -> str:
    """sha256 of the illustrative CSV and of the modules that read and fit it."""
    import hashlib  # (here: a scene with inline laws never asks, and hashlib loads OpenSSL, ~2.5 ms)

    digest = hashlib.sha256(Path(illustrative_data_path()).read_bytes())
    for name in _FIT_SOURCES:
        digest.update((Path(__file__).resolve().parent / name).read_bytes())
    return digest.hexdigest()


@cache
def default_fit() -> TribometerFit:
    """The fit of the shipped illustrative dataset, once per process: from the stored fit
    when it is current, else fitted."""
    from coupling.laws.tribology.data import read_tribometer_csv
    from coupling.laws.tribology.fits import TribometerFit, fit_tribometer

    try:
        doc = json.loads(DEFAULT_FIT_CACHE.read_text())
        if doc.get("key") == default_fit_key():
            # stored without the machine's path to the dataset: it is this installation's
            return dataclasses.replace(TribometerFit.from_dict(doc["fit"]), source=str(illustrative_data_path()))
    except (OSError, ValueError, KeyError):
        pass
    return fit_tribometer(read_tribometer_csv(illustrative_data_path()))


def write_default_fit_cache() -> Path:
    """Fit the illustrative dataset and store the fit for default_fit (after changing the
    dataset or the fitting code)."""
    from coupling.laws.tribology.data import read_tribometer_csv
    from coupling.laws.tribology.fits import fit_tribometer

    fit = fit_tribometer(read_tribometer_csv(illustrative_data_path()))
    doc = fit.to_dict()
    doc["source"] = "coupling/laws/data/" + illustrative_data_path().name  # default_fit puts the installed path back
    DEFAULT_FIT_CACHE.write_text(json.dumps({"key": default_fit_key(), "fit": doc}, indent=1) + "\n")
    return DEFAULT_FIT_CACHE
