"""The compiled mechanics ahead of time: one extension module built by numba.pycc, loaded without numba.

Why: loading numba and its on-disk cache costs most of a short run's start (numba's import,
its registry refresh and the cache load, ~0.6 s here); an extension module built once
imports in milliseconds and runs the same machine code (two compilations of the same
source: tests/mech/test_mech_aot.py compares their trajectories).

What is exported: every entry point of ``mech.compiled.ENTRY_POINTS``, each with the
signature the just-in-time dispatcher compiled when the Python side called it in small
warm-up runs of representative models (mech.aot_build.warm_up: free 3D and planar bars,
a clamped blade with a rivet, a pivot, friction exact / regularized / none, stick, the
dense output, the scipy backend, the damping calibration). The signatures are never written by hand, so a kernel
signature that changes is picked up by the next build.

Where: ``<NUMBA_CACHE_DIR or mech/__pycache__>/aot-<key>/``, the key a hash of mech's
sources (mech.compiled_cache.source_key), numpy's version and the interpreter's extension
suffix. Built on first use in a child process (which imports numba and compiles: about a
minute on a 2-core machine, once per source change), in a temporary folder renamed into
place, under a file lock so that concurrent processes build once and never load half a
file. When the build cannot be done (no C compiler, numba.pycc gone, a failed compile) the
reason is kept in ``aot-<key>.failed`` and said once on stderr; the just-in-time route is
used then, and always with ``SWITCHSIM_JIT=1`` in the environment.

This module is the loader: where the module lives, loading it, starting its build and
checking the arguments of its functions; it imports nothing of mech but the cache key
(mech.compiled_cache). What the build child runs -- the warm-up and numba.pycc's
compile -- is mech.aot_build, which imports the solver and is never imported here.
"""

from __future__ import annotations

import functools
import importlib.machinery
import importlib.util
import json
import os
import sys
from pathlib import Path

import numpy as np

from .compiled_cache import PACKAGE, cache_root, source_key

FORCE_JIT = "SWITCHSIM_JIT"  # "1": numba's just-in-time route, no extension module
MODULE = "_mech_aot"  # the extension's module name (its init symbol is PyInit__mech_aot)
SIGNATURES = "signatures.json"  # beside the module: what each exported argument must be
BUILD_TIMEOUT = 1800.0  # s: a build that hangs is abandoned, the JIT route taken


def build_key() -> str:
    suffix = importlib.machinery.EXTENSION_SUFFIXES[0]
    return f"{source_key()}-np{np.__version__}{suffix.rsplit('.', 1)[0]}"


def module_folder(root: Path | None = None) -> Path:
    return (root or cache_root()) / f"aot-{build_key()}"


def module_file(folder: Path) -> Path:
    return folder / (MODULE + importlib.machinery.EXTENSION_SUFFIXES[0])


def _note(text: str) -> None:
    print(f"switchsim: {text}", file=sys.stderr, flush=True)


def load():
    """(extension module, its folder), built first if missing; None: use the JIT route (said why)."""
    if os.environ.get(FORCE_JIT, "") not in ("", "0"):
        return None
    folder = module_folder()
    failed = folder.with_name(folder.name + ".failed")
    if not module_file(folder).is_file():
        if failed.is_file():
            _note(f"using numba's just-in-time compilation: the ahead-of-time build failed before "
                  f"({failed.read_text().strip()}; remove {failed} to retry)")
            return None
        reason = _build_locked(folder)
        if reason is not None:
            _note(f"using numba's just-in-time compilation: the ahead-of-time build failed ({reason})")
            return None
    try:
        return _import(module_file(folder)), folder
    except ImportError as err:  # a file that does not load (another machine's CPU, a damaged file)
        _note(f"using numba's just-in-time compilation: {module_file(folder)} does not load ({err})")
        return None


def _import(path: Path):
    loader = importlib.machinery.ExtensionFileLoader(MODULE, str(path))
    spec = importlib.util.spec_from_file_location(MODULE, str(path), loader=loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


def _build_locked(folder: Path) -> str | None:
    """Build into ``folder`` unless another process did while we waited; None or why not."""
    try:
        folder.parent.mkdir(parents=True, exist_ok=True)
        lock = open(folder.with_name(folder.name + ".lock"), "w")
    except OSError as err:
        return f"cannot write {folder.parent}: {err.strerror or err}"
    with lock:
        try:
            import fcntl

            fcntl.flock(lock, fcntl.LOCK_EX)
        except ImportError:  # no fcntl (Windows): the atomic rename still keeps half files out
            pass
        if module_file(folder).is_file():
            return None  # built by the process that held the lock
        failed = folder.with_name(folder.name + ".failed")
        if failed.is_file():
            return failed.read_text().strip()
        reason = _build(folder)
        if reason is not None and reason != "interrupted":
            failed.write_text(reason + "\n")
        return reason


def _build(folder: Path) -> str | None:
    """Compile in a child process into a temporary folder beside ``folder``, then rename it."""
    # (imported here: a run that loads the built module needs none of them; subprocess
    # alone is ~3 ms of a mechanics-only run's start)
    import shutil
    import subprocess
    import sysconfig
    import tempfile
    import time

    compiler = (sysconfig.get_config_var("CC") or "cc").split()[0]
    if shutil.which(compiler) is None:
        return f"no C compiler ({compiler!r} not found)"
    staging = Path(tempfile.mkdtemp(prefix=folder.name + ".build-", dir=folder.parent))
    _note("compiling the mechanics ahead of time (once per version of mech's sources; about a minute)")
    tick = time.perf_counter()
    # The child's warm-up must compile every entry point itself: numba registers a
    # signature on a function's dispatcher only when it compiles it, and a function loaded
    # from numba's on-disk cache compiles none of the functions it calls (measured: after a
    # run with SWITCHSIM_JIT=1 had filled the cache, the build failed with "the warm-up
    # never called energies"). So the child gets an empty cache folder of its own.
    jit_cache = staging / "jit-cache"
    env = dict(os.environ, **{FORCE_JIT: "1", "NUMBA_CACHE_DIR": str(jit_cache)})
    try:
        code = f"from mech.aot_build import compile_into; compile_into({str(staging)!r})"
        done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                              text=True, timeout=BUILD_TIMEOUT, cwd=str(PACKAGE.parent))
        if done.returncode != 0:
            tail = " ".join((done.stderr or done.stdout).strip().splitlines()[-1:]) or f"exit {done.returncode}"
            return tail
        if not (module_file(staging).is_file() and (staging / SIGNATURES).is_file()):
            return f"the build left no {module_file(staging).name}"
        shutil.rmtree(jit_cache, ignore_errors=True)
        os.rename(staging, folder)
    except subprocess.TimeoutExpired:
        return f"no result after {BUILD_TIMEOUT:.0f} s"
    except KeyboardInterrupt:
        return "interrupted"
    except OSError as err:
        return f"{type(err).__name__}: {err}"
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    _note(f"compiled in {time.perf_counter() - tick:.0f} s: {module_file(folder)}")
    remove_stale(folder)
    return None


def remove_stale(folder: Path) -> None:
    """Delete the builds of earlier sources beside ``folder`` (a loaded one stays mapped),
    with their lock files and failure notes; keep ``folder``'s own and builds under way."""
    import shutil  # (after a build only: see _build)

    for stale in folder.parent.glob("aot-*"):
        if stale.name.startswith(folder.name) or ".build-" in stale.name:
            continue
        if stale.is_dir():
            shutil.rmtree(stale, ignore_errors=True)
        else:
            stale.unlink(missing_ok=True)


@functools.lru_cache(maxsize=None)
def signatures(folder: Path) -> dict:
    """name -> the argument kinds of each exported function (the module's signatures file),
    read once per folder and process (a start asks for it eight times: ~0.5 ms each)."""
    return json.loads((folder / SIGNATURES).read_text())


def argument_count(folder: Path, name: str) -> int:
    """How many arguments the exported function ``name`` takes."""
    return len(signatures(folder)[name])


def argument_checks(folder: Path) -> dict:
    """name -> check(args) raising TypeError for an argument the exported function would
    misread (numba.pycc's wrappers do not check an array's dtype, rank or layout).

    The checks run before every compiled call (thousands per coupled run), so passing is
    kept cheap: a test per argument with no string built unless it fails, the model and
    work tuples, passed unchanged on every call, checked once, and an argument that is the
    very object the previous call of the same function passed there (a segment's dense
    output at each of the circuit's times) not checked again: what is checked -- an
    array's dtype, rank and layout -- stays as it was for an object that is still held
    (nothing here reassigns an array's dtype, shape or strides in place)."""
    ndarray = np.ndarray

    def checker(kind):
        """ok(a) -> bool for one argument of this kind, or None for a number (converted by the wrapper)."""
        if kind[0] == "array":
            dtype, ndim, layout = np.dtype(kind[1]), kind[2], kind[3]
            if layout == "C":
                return lambda a: (type(a) is ndarray or isinstance(a, ndarray)) and a.dtype == dtype and \
                    a.ndim == ndim and a.flags.c_contiguous
            if layout == "F":
                return lambda a: isinstance(a, ndarray) and a.dtype == dtype and a.ndim == ndim and a.flags.f_contiguous
            return lambda a: isinstance(a, ndarray) and a.dtype == dtype and a.ndim == ndim
        if kind[0] == "tuple":
            parts = [checker(k) for k in kind[1]]
            # The last tuple checked, held (so the same object again is not checked again):
            # one only. A cache of 256 held every tuple of fresh views a solver passed (its
            # history's rows) and with them the buffers those views were cut from, long
            # after the history had grown into new ones (a coupled run whose steps
            # collapsed kept ~2x its history's memory).
            last_tuple = [None]
            checks = tuple((k, part) for k, part in enumerate(parts) if part is not None)

            def ok(a):
                last = last_tuple[0]
                if a is last:
                    return True
                if not (isinstance(a, tuple) and len(a) == len(parts)):
                    return False
                # an item that is the object the last tuple held there is not checked again: a
                # segment's model tuple (a new tuple of the same 14 arrays and a copy of the
                # drive) is checked at the segment's first compiled call, the coupling's first
                # tip_forces (measured, warm, an energies call with a new model tuple: 6.1 us
                # with its 15 arrays checked, 3.9 us with its drive only)
                for k, part in checks:  # (a loop: all() over a generator cost more)
                    item = a[k]
                    if (last is None or item is not last[k]) and not part(item):
                        return False
                last_tuple[0] = a
                return True
            return ok
        return None

    def describe(kind, a, where) -> str:
        """Why ``a`` is not of ``kind`` (only when a check failed)."""
        if kind[0] == "tuple":
            if not isinstance(a, tuple) or len(a) != len(kind[1]):
                return f"{where}: exported for a tuple of {len(kind[1])}, got {type(a).__name__}"
            for k, (part, item) in enumerate(zip(kind[1], a)):
                ok = checker(part)
                if ok is not None and not ok(item):
                    return describe(part, item, f"{where}[{k}]")
        got = (f"{a.dtype} {a.ndim}-d {'C' if a.flags.c_contiguous else 'non-C'} array"
               if isinstance(a, np.ndarray) else type(a).__name__)
        return f"{where}: exported for a {np.dtype(kind[1])} {kind[2]}-d {kind[3]} array, got {got}"

    out = {}
    for name, kinds in signatures(folder).items():
        checks = tuple((k, c) for k, c in enumerate(checker(kind) for kind in kinds) if c is not None)

        def check_all(args, name=name, checks=checks, kinds=kinds, last=[None] * len(kinds)):
            for k, ok in checks:
                a = args[k]
                if a is last[k]:
                    continue
                if not ok(a):
                    raise TypeError(describe(kinds[k], a, f"{name} argument {k}"))
                last[k] = a  # (held until another object replaces it: one argument set per function)
        out[name] = check_all
    return out

