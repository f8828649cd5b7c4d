"""numba's ``njit`` for the compiled mechanics, with the on-disk cache put in place first.

Every module of compiled functions imports ``njit`` from here, so the cache folder
(mech.compiled_cache) is set before the first function is defined, whichever module is
imported first.
"""

from __future__ import annotations

from .compiled_cache import configure

configure()

from numba import njit  # noqa: E402  (after the cache folder is set)

__all__ = ["njit"]
