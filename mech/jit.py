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
never given): ``borrowing_violations`` finds one that does, and the ahead-of-time build,
which compiles every function afresh, refuses to build while it finds any.
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


def borrowing_violations(functions=None) -> list[str]:
    """Each compiled signature of ``functions`` (default: every njit_borrowing function,
    as far as this process has compiled them) whose return value holds a reference-counted
    value (an array, or a tuple with one): "module.name: signature" for each."""
    from numba.core.registry import cpu_target

    models = cpu_target.target_context.data_model_manager
    bad = []
    for fn in BORROWING if functions is None else functions:
        for sig in fn.nopython_signatures:
            if models[sig.return_type].contains_nrt_meminfo():
                bad.append(f"{fn.py_func.__module__}.{fn.py_func.__name__}: {sig}")
    return bad


__all__ = ["njit", "njit_borrowing", "BORROWING", "borrowing_violations"]
