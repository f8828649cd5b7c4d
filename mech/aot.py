"""The compiled mechanics ahead of time: one extension module built by numba.pycc, loaded without numba.

Why: loading numba and its on-disk cache costs most of a short run's start (numba's import,
its registry refresh and the cache load, ~0.6 s here); an extension module built once
imports in milliseconds and runs the same machine code (two compilations of the same
source: tests/mech/test_mech_aot.py compares their trajectories).

What is exported: every entry point of ``mech.compiled.ENTRY_POINTS``, each with the
signature the just-in-time dispatcher compiled when the Python side called it in small
warm-up runs of representative models (free 3D and planar bars, a clamped blade with a
rivet, a pivot, friction exact / regularized / none, stick, the dense output, the scipy
backend, the damping calibration). The signatures are never written by hand, so a kernel
signature that changes is picked up by the next build.

Where: ``<NUMBA_CACHE_DIR or mech/__pycache__>/aot-<key>/``, the key a hash of mech's
sources (mech.compiled_cache.source_key), numpy's version and the interpreter's extension
suffix. Built on first use in a child process (which imports numba and compiles: about a
minute on a 2-core machine, once per source change), in a temporary folder renamed into
place, under a file lock so that concurrent processes build once and never load half a
file. When the build cannot be done (no C compiler, numba.pycc gone, a failed compile) the
reason is kept in ``aot-<key>.failed`` and said once on stderr; the just-in-time route is
used then, and always with ``SWITCHSIM_JIT=1`` in the environment.

``compile_into(DEST)`` is what that child runs: warm up, collect, compile into DEST.
"""

from __future__ import annotations

import importlib.machinery
import importlib.util
import json
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import time
from pathlib import Path

from .compiled_cache import PACKAGE, source_key

FORCE_JIT = "SWITCHSIM_JIT"  # "1": numba's just-in-time route, no extension module
MODULE = "_mech_aot"  # the extension's module name (its init symbol is PyInit__mech_aot)
SIGNATURES = "signatures.json"  # beside the module: what each exported argument must be
BUILD_TIMEOUT = 1800.0  # s: a build that hangs is abandoned, the JIT route taken


def cache_root() -> Path:
    return Path(os.environ.get("NUMBA_CACHE_DIR") or PACKAGE / "__pycache__")


def build_key() -> str:
    import numpy

    suffix = importlib.machinery.EXTENSION_SUFFIXES[0]
    return f"{source_key()}-np{numpy.__version__}{suffix.rsplit('.', 1)[0]}"


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
    compiler = (sysconfig.get_config_var("CC") or "cc").split()[0]
    if shutil.which(compiler) is None:
        return f"no C compiler ({compiler!r} not found)"
    staging = Path(tempfile.mkdtemp(prefix=folder.name + ".build-", dir=folder.parent))
    _note("compiling the mechanics ahead of time (once per version of mech's sources; about a minute)")
    tick = time.perf_counter()
    env = dict(os.environ, **{FORCE_JIT: "1"})
    try:
        code = f"from mech.aot import compile_into; compile_into({str(staging)!r})"
        done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                              text=True, timeout=BUILD_TIMEOUT, cwd=str(PACKAGE.parent))
        if done.returncode != 0:
            tail = " ".join((done.stderr or done.stdout).strip().splitlines()[-1:]) or f"exit {done.returncode}"
            return tail
        if not (module_file(staging).is_file() and (staging / SIGNATURES).is_file()):
            return f"the build left no {module_file(staging).name}"
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
    for stale in folder.parent.glob("aot-*"):
        if stale.name.startswith(folder.name) or ".build-" in stale.name:
            continue
        if stale.is_dir():
            shutil.rmtree(stale, ignore_errors=True)
        else:
            stale.unlink(missing_ok=True)


# --- the child process -----------------------------------------------------------------


def warm_up() -> None:
    """Call every entry point through the Python side on small representative models."""
    import numpy as np

    from .contact_laws import calibrate_damping
    from .scene import scene_from_dict
    from .solver import ImpactSolver

    steel = dict(youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)
    bar3d = dict(length=0.1, diameter=0.006, tip_radius=0.003, modes=2, **steel)
    short = dict(t_end=3e-4)
    scenes = [
        # 3D free bar, exact friction, restitution calibrated; a stick on the block
        {"bar": bar3d, "initial": dict(height=1e-4, angle_deg=30.0, velocity=[0.3, 0.1, -1.0]),
         "friction": dict(model="exact", mu=0.8), "contact": dict(restitution=0.5), "solver": short},
        # planar free bar, regularized friction
        {"bar": bar3d, "initial": dict(height=1e-4, angle_deg=30.0, velocity=[0.0, 0.0, -1.0]),
         "friction": dict(model="regularized", mu=0.3), "solver": short},
        # no friction, the paper's law
        {"bar": bar3d, "initial": dict(height=1e-4, angle_deg=30.0, velocity=[0.0, 0.0, -1.0]),
         "friction": dict(mu=0.0), "contact": dict(law="paper", restitution=0.8), "solver": short},
        # a clamped blade with a rivet under a force ramp
        {"bar": dict(length=0.02, width=0.003, thickness=0.0003, tip_radius=0.0016, modes={"axial": 1, "bending": 3},
                     modal_damping=0.05, **steel),
         "mount": dict(kind="clamp", position=0.02), "rivet": [dict(position=0.0015, offset=0.0, radius=0.0015)],
         "force": [dict(position=0.01, time=[0.0, 0.001], value=[0.0, 3.0])],
         "initial": dict(height=2e-5), "friction": dict(model="exact", mu=0.3), "solver": dict(t_end=1e-3)},
        # a pivoted rigid arm on a spring
        {"bar": dict(length=0.05, diameter=0.005, tip_radius=0.0025, modes=0, **steel),
         "mount": dict(kind="pivot", position=0.05, stiffness=1.0, preload_torque=0.01),
         "spring": [dict(anchor=[0.01, 0.0, 0.01], position=0.01, stiffness=50.0, damping=0.01)],
         "initial": dict(height=1e-5), "solver": dict(t_end=5e-4)},
    ]
    for k, doc in enumerate(scenes):
        solver = ImpactSolver(scene_from_dict(doc), keep_dense=True)
        segment = solver.advance(doc["solver"]["t_end"] * 0.5)
        t = 0.5 * (segment.t_start + segment.t_end)
        segment.contact(t)
        segment.tip_forces(t)
        segment.state(t)
        solver.advance(doc["solver"]["t_end"])
        solver.contact_series(np.linspace(segment.t_start, solver.t, 5))
        result = solver.result()
        result.energy_table  # noqa: B018  (the compiled energy table)
        result.contacts  # noqa: B018  (dense contact evaluation where the solver asks for it)
        if k == 0:  # the scipy backends hand the right-hand side views of their own arrays
            for method in ("RK45", "Radau", "BDF", "LSODA"):
                ImpactSolver(scene_from_dict(doc), backend=f"scipy:{method}").run()
    calibrate_damping("hunt_crossley", 0.7, 1.0, 1e10, 0.01)


def signatures(jit) -> dict:
    """name -> numba Signature of each entry point as the warm-up compiled it; a function
    compiled for array arguments of several layouts is exported for any layout ('A')."""
    out = {}
    for name in jit.ENTRY_POINTS:
        sigs = getattr(jit, name).nopython_signatures
        if not sigs:
            raise RuntimeError(f"the warm-up never called {name}: add a model that reaches it to mech.aot.warm_up")
        if len(sigs) > 1:
            sigs = [_merge_layouts(name, sigs)]
        out[name] = sigs[0]
    return out


def _merge_layouts(name: str, sigs):
    from numba.core import types

    first = sigs[0]
    args = list(first.args)
    for sig in sigs[1:]:
        if len(sig.args) != len(args) or sig.return_type != first.return_type:
            raise RuntimeError(f"{name} was compiled for different argument kinds: {sigs}")
        for i, (a, b) in enumerate(zip(args, sig.args)):
            if a == b:
                continue
            if isinstance(a, types.Array) and isinstance(b, types.Array) and (a.dtype, a.ndim) == (b.dtype, b.ndim):
                args[i] = a.copy(layout="A")
            else:
                raise RuntimeError(f"{name} was compiled for different argument types: {a} and {b}")
    return first.return_type(*args)


def compile_into(dest) -> None:
    """Warm up on the JIT route, then compile every entry point into ``dest`` (a folder)."""
    import warnings

    warnings.filterwarnings("ignore", message=".*pycc.*")
    from numba.pycc import CC

    from . import compiled as jit

    if jit.ROUTE != "jit":
        raise RuntimeError(f"the build must run on the just-in-time route (set {FORCE_JIT}=1)")
    warm_up()
    cc = CC(MODULE, source_module=__name__)
    cc.output_dir = str(dest)
    cc.target_cpu = "host"  # built where it runs: the same instructions the JIT would use
    sigs = signatures(jit)
    for name, sig in sigs.items():
        cc.export(name, sig)(getattr(jit, name).py_func)
    cc.compile()
    (Path(dest) / SIGNATURES).write_text(json.dumps({name: [_kind(a) for a in sig.args]
                                                     for name, sig in sigs.items()}, indent=1))


def _kind(t):
    """What an argument of numba type ``t`` must be for the exported function (JSON):
    ["array", dtype, ndim, layout], ["tuple", [kinds]] or ["scalar", name]."""
    from numba.core import types

    if isinstance(t, types.Array):
        return ["array", str(t.dtype), t.ndim, t.layout]
    if isinstance(t, types.BaseTuple):
        return ["tuple", [_kind(e) for e in t.types]]
    return ["scalar", str(t)]


def argument_checks(folder: Path) -> dict:
    """name -> check(args) raising TypeError for an argument the exported function would
    misread (numba.pycc's wrappers do not check an array's dtype, rank or layout).

    The checks run before every compiled call (thousands per coupled run), so passing is
    kept cheap: a test per argument with no string built unless it fails, and the model and
    work tuples, passed unchanged on every call, checked once."""
    import numpy as np

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
            seen = {}  # id -> tuple already checked (held, so its id is not reused)

            def ok(a):
                if seen.get(id(a)) is a:
                    return True
                if not (isinstance(a, tuple) and len(a) == len(parts)
                        and all(part is None or part(item) for part, item in zip(parts, a))):
                    return False
                if len(seen) > 256:
                    seen.clear()
                seen[id(a)] = a
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
    for name, kinds in json.loads((folder / SIGNATURES).read_text()).items():
        checks = tuple((k, c) for k, c in enumerate(checker(kind) for kind in kinds) if c is not None)

        def check_all(args, name=name, checks=checks, kinds=kinds):
            for k, ok in checks:
                if not ok(args[k]):
                    raise TypeError(describe(kinds[k], args[k], f"{name} argument {k}"))
        out[name] = check_all
    return out

