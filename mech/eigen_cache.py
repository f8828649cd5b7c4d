"""The finite-element eigenproblems' solutions kept on disk, per machine.

A held bar's model solves a few generalized eigenproblems (mech.beam_fe: the shift-inverted
problem of each family, the eigenvalues alone when the mode count is chosen): ~25-30 ms of
a relay's ~0.6 s command, most of it the first LAPACK calls of the process, for the same
matrices at every run of the same device. ``cached`` keeps each solution in
``<NUMBA_CACHE_DIR or mech/__pycache__>/eigen/<key>.npy`` (as the compiled mechanics are
kept) and reads it back at the next run: the arrays the solver returned, bit for bit
(``numpy.save``'s format, no pickle).

The key is a SHA-1 of everything the solution depends on: both matrices (their shapes and
their nonzero entries' places and bits),
whether the vectors are asked, the solver's own code, numpy's version and its BLAS, the
platform and this machine's processor (the BLAS kernels chosen for it round differently
from another's). Nothing else decides the solution, so a hit is what solving would give
here. A file that does not read back as such a solution (damaged, another shape) is solved
again and replaced; where the folder cannot be written the solution is only computed.
``SWITCHSIM_EIGEN_CACHE=0`` solves every time and reads and writes nothing (the test suite
sets it: its tests of the modes test the solver). At most ``FILES_MAX`` solutions are kept,
the least recently written removed first (a sweep over bar geometries adds one per design;
a relay's bending solution is ~60 kB).
"""

from __future__ import annotations

import os
import sys
from functools import lru_cache
from pathlib import Path

import numpy as np

from .compiled_cache import cache_root, sha1

ENV = "SWITCHSIM_EIGEN_CACHE"  # "0": solve every time, nothing read or written
FILES_MAX = 256
FOLDER = "eigen"


def enabled() -> bool:
    return os.environ.get(ENV, "") != "0"


def folder() -> Path:
    return cache_root() / FOLDER


@lru_cache(maxsize=1)
def _machine() -> bytes:
    """numpy's version and BLAS, the platform and the processor (Linux: /proc/cpuinfo's
    first model name and flags; elsewhere the machine type)."""
    parts = [np.__version__, sys.platform, os.uname().machine if hasattr(os, "uname") else ""]
    try:
        parts.append(repr(np.__config__.CONFIG.get("Build Dependencies", {}).get("blas")))
    except AttributeError:
        parts.append("")
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as info:
            wanted = {"model name": None, "flags": None}
            for line in info:
                name, _, value = line.partition(":")
                name = name.strip()
                if name in wanted and wanted[name] is None:
                    wanted[name] = value.strip()
                if all(v is not None for v in wanted.values()):
                    break
        parts.extend(v or "" for v in wanted.values())
    except OSError:
        pass
    return "\n".join(parts).encode()


def key(a: np.ndarray, b: np.ndarray, vectors: bool, solve) -> str:
    """The solution's name: a SHA-1 of what it depends on (module docstring)."""
    digest = sha1(b"switchsim eigen 1\n")
    for m in (a, b):
        # each matrix as its entries whose bits are not all zero (their flat indices and bit
        # patterns, -0.0 included): exactly the matrix, and of a banded FE matrix a few
        # percent of its bytes (hashing a relay's whole matrices took 11 ms of the 14 saved)
        bits = np.ascontiguousarray(m, dtype=float).view(np.uint64).ravel()
        where = np.flatnonzero(bits)
        digest.update(repr(m.shape).encode())
        digest.update(where.tobytes())
        digest.update(bits[where].tobytes())
    code = solve.__code__
    digest.update(b"vectors" if vectors else b"values")
    digest.update(code.co_code)
    digest.update(repr(code.co_consts).encode())
    digest.update(repr(code.co_names).encode())
    digest.update(_machine())
    return digest.hexdigest()


def cached(a: np.ndarray, b: np.ndarray, vectors: bool, solve):
    """``solve(a, b, vectors)`` -> (mu, vectors or None), read from the cache when this
    machine solved the same problem before, else solved and kept (module docstring)."""
    if not enabled():
        return solve(a, b, vectors)
    name = key(a, b, vectors, solve)
    path = folder() / f"{name}.npy"
    n = len(a)
    found = _read(path, n, vectors)
    if found is not None:
        return found
    mu, w = solve(a, b, vectors)
    _write(path, np.vstack([mu[None, :], w]) if vectors else mu[None, :])
    return mu, w


def _read(path: Path, n: int, vectors: bool):
    try:
        data = np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError):
        return None
    if data.dtype != np.float64 or data.shape != ((n + 1, n) if vectors else (1, n)):
        return None
    return (data[0].copy(), data[1:].copy()) if vectors else (data[0].copy(), None)


def _write(path: Path, data: np.ndarray) -> None:
    """Write atomically (a reader sees the old file, the new one or none); give up quietly
    where the folder cannot be written. Then keep at most FILES_MAX solutions."""
    tmp = path.with_name(f".{path.stem}.{os.getpid()}.tmp")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(tmp, "wb") as out:
            np.save(out, data, allow_pickle=False)
        os.replace(tmp, path)
    except OSError:
        try:
            tmp.unlink(missing_ok=True)
        except OSError:
            pass
        return
    _prune(path.parent)


def _prune(where: Path) -> None:
    try:
        files = [(p.stat().st_mtime, p) for p in where.glob("*.npy")]
    except OSError:
        return
    if len(files) <= FILES_MAX:
        return
    files.sort()
    for _, p in files[:len(files) - FILES_MAX]:
        try:
            p.unlink()
        except OSError:
            pass
