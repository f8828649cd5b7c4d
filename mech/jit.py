"""numba's ``njit`` for the compiled mechanics, with the on-disk cache put in place first.

Every module of compiled functions imports ``njit`` from here, so the cache folder
(mech.compiled_cache) is set before the first function is defined, whichever module is
imported first.

``njit_borrowing``: the hot functions of the right-hand side and the step, compiled
without numba's reference counting (its ``_nrt=False``). numba otherwise increments and
decrements, with an atomic instruction each, the count of every array argument at the
entry and exit of every compiled call: measured with perf on the default scene, ~300
such operations per right-hand side (its 47 arrays at ``dynamics`` alone) took ~10 % of a
whole `switchsim run`. A function so compiled only borrows the arrays its caller holds
for the call: it must not allocate (numba refuses to compile an allocation without the
reference counts) and must return no array (its caller would release a reference it was
never given); tests/mech/test_mech_kernel.py checks every one's compiled return types.
"""

from __future__ import annotations

import functools

from .compiled_cache import configure

configure()

import numba  # noqa: E402  (after the cache folder is set)

# Reference counting stated on every function, not left to numba's default: a function
# that does not set it inherits its first caller's, so an allocating function first
# called from a borrowing one would be compiled without it (and fail to compile).
njit = functools.partial(numba.njit, _nrt=True)
BORROWING = []  # every function compiled by njit_borrowing (the tests check their return types)


def njit_borrowing(fn):
    """``njit(cache=True)`` without reference counting (see the module's docstring)."""
    compiled = numba.njit(cache=True, _nrt=False)(fn)
    BORROWING.append(compiled)
    return compiled


__all__ = ["njit", "njit_borrowing", "BORROWING"]
