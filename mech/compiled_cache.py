"""Where numba keeps the compiled mechanics: a cache folder keyed by the mechanics' sources.

numba's on-disk cache (``cache=True``) checks each function against its own file only: a
compiled integrator that inlines the right-hand side of kernel.py is reused after
kernel.py changed (seen here: a stale cache ran the old inertia route). Keying the folder
by a hash of every source file of the package makes any change compile afresh; an
unchanged package reuses its cache. ``configure`` runs when mech.jit is imported (the
just-in-time route and the ahead-of-time build), before any compiled function is defined.
"""

from __future__ import annotations

import os
from pathlib import Path

try:  # CPython's own SHA-1: the same digest as hashlib's without loading OpenSSL (~2.5 ms a start)
    from _sha1 import sha1
except ImportError:  # an interpreter built without it
    from hashlib import sha1

PACKAGE = Path(__file__).resolve().parent


def source_key(folder: Path = PACKAGE) -> str:
    """12 hex digits of the SHA-1 of the package's .py files (names and contents, in order)."""
    digest = sha1()
    for path in sorted(folder.glob("*.py")):
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:12]


def cache_root() -> Path:
    """Where mech keeps what it compiles or solves once: NUMBA_CACHE_DIR, else mech/__pycache__
    (numba's cache, the ahead-of-time module, mech.eigen_cache's solutions)."""
    return Path(os.environ.get("NUMBA_CACHE_DIR") or PACKAGE / "__pycache__")


def configure() -> Path:
    """Point numba's cache at <NUMBA_CACHE_DIR or mech/__pycache__>/numba-<source key>."""
    import numba  # here, not at the top: mech.aot takes source_key from this module without numba

    folder = cache_root() / f"numba-{source_key()}"
    numba.config.CACHE_DIR = str(folder)
    return folder
