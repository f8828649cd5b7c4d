"""The compiled mechanics as the Python side calls it: the one place that loads it.

The solver, the results, the scipy backend and the damping calibration take every
compiled function from here, never from mech.kernel or mech.integrator directly, and read
the kernel's indices from mech.kernel_layout; so how the compiled code is obtained is
decided in this module alone:
- ``ROUTE == "aot"``: the extension module built ahead of time by numba.pycc from the
  same sources (mech.aot: built on first use, cached by a hash of the sources); numba is
  not imported. Its functions read their arguments as the warm-up's types, unchecked, so
  each call is checked here first (a few microseconds); an argument of another type
  (a new call the warm-up does not make) goes to the JIT function instead, with a
  RuntimeWarning that names it (an error in the test suite);
- ``ROUTE == "jit"``: numba's just-in-time functions with their on-disk cache
  (mech.compiled_cache), when the module cannot be built or ``SWITCHSIM_JIT=1``.
"""

from __future__ import annotations

import importlib
import warnings

import numpy as np

from . import aot
from .kernel_layout import F_BETA, I_MOUNT, I_N, I_PLANAR

# every compiled function the Python side calls (mech.aot exports exactly these), and the
# module of its numba source
ENTRY_POINTS = {
    "dense_contact": "integrator", "dense_eval": "integrator", "dense_tip_forces": "integrator",
    "dense_pair_forces": "integrator",
    "event_values": "integrator", "integrate": "integrator", "dynamics": "kernel", "energies": "kernel",
    "energy_table": "kernel", "make_work": "kernel", "project_to_stick": "kernel", "scaled_rebound": "kernel",
    "armature_table": "kernel", "armature_force": "kernel",
}
# entry points whose last argument is the armature's arrays (kernel.dynamics: ``arm``, None
# without an armature): numba compiles them once for each, and the module exports the
# second as "<name>_armature"; a call is routed by that argument (None when left out)
VARIANTS = ("dense_contact", "dynamics", "energies", "energy_table", "event_values", "integrate",
            "project_to_stick")
ARMATURE_SUFFIX = "_armature"


class CompiledArgumentWarning(RuntimeWarning):
    """An ahead-of-time function was called with arguments it was not built for."""


def _jit(name: str):
    # imported when first asked for, not at the top: mech.kernel and mech.integrator import
    # numba (~0.6 s of a run's start), which the ahead-of-time route never loads
    return getattr(importlib.import_module(f".{ENTRY_POINTS[name]}", __package__), name)


def jit_dispatcher(name: str):
    """numba's just-in-time dispatcher of the entry point ``name`` (imports numba): for
    code that calls it from its own compiled functions, as the benchmarks' timing loops
    do; everything else calls the module-level function of the same name."""
    if name not in ENTRY_POINTS:
        raise ValueError(f"name = {name!r}: allowed values are {', '.join(sorted(ENTRY_POINTS))}")
    return _jit(name)


def _jit_instead(name: str, err: TypeError, args: tuple):
    """The just-in-time ``name`` on ``args``, which the ahead-of-time function was not built
    for (``err``: the argument check's complaint), with a warning that points at the code
    that called the entry point."""
    warnings.warn(f"{err}: calling numba's just-in-time {name} instead (add the call to "
                  "mech.aot_build.warm_up)", CompiledArgumentWarning, stacklevel=3)
    return _jit(name)(*args)


def _checked(name: str, fn, check):
    def call(*args):
        try:
            check(args)
        except TypeError as err:
            return _jit_instead(name, err, args)
        return fn(*args)

    call.__name__ = call.__qualname__ = name
    call.__doc__ = f"{name} from the ahead-of-time module, its arguments checked first"
    return call


def _variant(name: str, plain, armature, count: int, checks: tuple):
    """A VARIANTS entry point: ``plain`` or ``armature`` (the module's two functions) by its
    last argument, the armature's arrays (``count`` arguments in all; left out: None), its
    arguments checked first as _checked does (``checks``: plain's and armature's check). One
    function, not a choice that calls a _checked one: a Python call and the arguments'
    repacking less at each compiled call (a coupled macro step makes one or two)."""
    plain_check, armature_check = checks

    def call(*args):
        if len(args) < count:
            args = args + (None,)
        fn, check = (plain, plain_check) if args[-1] is None else (armature, armature_check)
        try:
            check(args)
        except TypeError as err:
            return _jit_instead(name, err, args)
        return fn(*args)

    call.__name__ = call.__qualname__ = name
    call.__doc__ = (f"{name} from the ahead-of-time module, its arguments checked first (for a model "
                    f"with an armature: {name}{ARMATURE_SUFFIX})")
    return call


def _load_aot(module, folder) -> dict:
    checks = aot.argument_checks(folder)
    out = {}
    for name in ENTRY_POINTS:
        if name in VARIANTS:
            arm = name + ARMATURE_SUFFIX
            out[name] = _variant(name, getattr(module, name), getattr(module, arm), aot.argument_count(folder, name),
                                 (checks[name], checks[arm]))
        else:
            out[name] = _checked(name, getattr(module, name), checks[name])
    return out


def dense_force_arguments(t_valid, t0, h, coef, mdl) -> tuple:
    """The argument ``args`` of ``dense_tip_forces`` and ``dense_pair_forces`` for a dense
    output (t_valid, t0, h, coef: the steps' ends, starts and sizes, s, and their
    coefficients) of the model arrays ``mdl`` (model.BarModel.kernel_arrays): that dense
    output, what the functions read of the model (psi, xc, cpar; the mode count, planar
    flag and mount kind of ipar; fpar's beta) and a float64 scratch vector of
    mech.integrator.dense_force_scratch_size (the same formula). Made once and passed,
    the same object, at every call: the compiled call converts each array it is given at
    every call (~70 ns each) and checks an argument on the Python side unless it is the
    previous call's object (with the whole model tuple and each array apart, ~1.1 us of
    a 2.2 us call)."""
    fpar, ipar, psi, xc, cpar = mdl[0], mdl[1], mdl[6], mdl[8], mdl[9]
    n = int(ipar[I_N])
    scratch = np.zeros(coef.shape[2] + 2 * cpar.shape[0] + 2 * n + 24)
    return (t_valid, t0, h, coef, psi, xc, cpar, n, int(ipar[I_PLANAR]), int(ipar[I_MOUNT]), float(fpar[F_BETA]),
            scratch)


_loaded = aot.load()
if _loaded is not None:
    ROUTE = "aot"
    globals().update(_load_aot(*_loaded))
else:
    ROUTE = "jit"
    globals().update({name: _jit(name) for name in ENTRY_POINTS})

__all__ = list(ENTRY_POINTS) + ["ROUTE", "VARIANTS", "ARMATURE_SUFFIX", "jit_dispatcher", "dense_force_arguments"]
