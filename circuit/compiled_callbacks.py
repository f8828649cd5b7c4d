"""ngspice's source and step-control callbacks compiled from C (circuit/callbacks.c):
building, caching, loading.

Why: ngspice calls the EXTERNAL sources' callbacks some 60 000 times in a relay run, most
of them at a time already asked (Newton iterations), for a constant, for the coil's gap (a
polynomial of the mechanics' dense output) or for an arc's state (a constant between
accepted points), and GetSyncData 12 000 times; cffi's dispatch into Python and the Python
body cost ~1 us a call. The C callbacks answer those without Python and call Python only
for the other channels and the step control's rarer cases (circuit/ngspice.py installs
them; what runs where is described in callbacks.c). An arc's gap channel is held at its
last value, with no call, while the arc is out and its contact open (callbacks.c's
sw_held; the Python route's _on_vsrc applies the same rule).

Where: ``<NUMBA_CACHE_DIR or circuit/__pycache__>/callbacks-<key>/libswitchsim_callbacks.so``,
the key a hash of callbacks.c, the flags and the machine. Built at first use
by running the C compiler (``$CC``, else the interpreter's, else ``cc``) with
``-O2 -fPIC -shared -ffp-contract=off`` (no -ffast-math: the arithmetic stays IEEE
double, operation for operation as written, which is what makes both routes agree to the
bit), into a temporary folder renamed into place, under a file lock. When the build
cannot be done (no compiler, a failed compile) the reason is kept in
``callbacks-<key>.failed`` and said once on stderr, and the Python callbacks are used;
always with ``SWITCHSIM_PYTHON_CALLBACKS=1`` in the environment.

The library is loaded through cffi's out-of-line ABI module circuit/_callbacks_ffi.py
(kept in the repository: no C parser at a start), generated from ``DECLARATIONS`` with
``python -m circuit.compiled_callbacks``.
"""

from __future__ import annotations

import functools
import os
import sys
from pathlib import Path

from ._callbacks_ffi import ffi

PACKAGE = Path(__file__).resolve().parent
SOURCE = PACKAGE / "callbacks.c"
LIBRARY = "libswitchsim_callbacks.so"
MODULE = "circuit._callbacks_ffi"
FORCE_PYTHON = "SWITCHSIM_PYTHON_CALLBACKS"  # "1": the Python callbacks, no compiled library
FLAGS = ("-O2", "-fPIC", "-shared", "-ffp-contract=off")
LIBRARIES = ("-lm",)  # (after the source: exp and log of the arcs' rules)
BUILD_TIMEOUT = 120.0  # s

#: The part of callbacks.c that Python uses (must match the C source's definitions).
DECLARATIONS = """
typedef int (*sw_evaluate_fn)(int index, double t, double *out);
typedef int (*sw_learn_fn)(char *name);
typedef int (*sw_sync_fn)(double ckttime, double *pdelta, double olddelta, int redostep, int ident,
                          int location, void *user);
typedef int (*sw_data_fn)(void *values, int count, int ident, void *user);

typedef struct sw_channel {
    char *name;
    int kind;
    double last_t;
    double last_value;
    long long calls;
    double constant;
    double lo, hi, start, offset, scale;
    long n;
    const double *ends, *t0, *h, *coefficients;
    long windows;
    const double *lows, *highs, *befores;
    const double *gate_arc;
    int gate_conductance;
} sw_channel;

typedef struct sw_arc {
    char *name;
    const double *value;
} sw_arc;

typedef struct sw_arc_rule {
    double *cells;
    int conductance;
} sw_arc_rule;

typedef struct sw_state {
    int failed;
    sw_evaluate_fn evaluate;
    sw_learn_fn learn;
    sw_learn_fn learn_arc;
    int channels_used;
    sw_channel *channels;
    int arcs_used, arcs_size;
    sw_arc *arcs;
    sw_sync_fn sync_python;
    int has_arcs;
    double accepting, target, max_step, deadline, arc_from, arc_step, arc_land, landing_tolerance;
    int landings_head, landings_used, landings_size;
    double *landings;
    int arc_rules_used;
    sw_arc_rule *arc_rules;
    int rejections_used, rejections_size;
    double *rejections;
    double pause_at;
    int python_data;
} sw_state;

void sw_install(sw_state *s);
void sw_install_data(sw_data_fn fn);
int sw_data(void *values, int count, int ident, void *user);
int sw_vsrc(double *out, double t, char *name, int ident, void *user);
int sw_isrc(double *out, double t, char *name, int ident, void *user);
int sw_sync(double ckttime, double *pdelta, double olddelta, int redostep, int ident, int location, void *user);
double sw_table_value(const sw_channel *ch, double t);
int sw_layout(long *out, int size);
"""

#: The channel kinds of callbacks.c.
PYTHON, CONSTANT, TABLE = 0, 1, 2

#: The structures, in the order of callbacks.c's sw_layout (their sizes first).
STRUCTS = ("sw_channel", "sw_arc", "sw_arc_rule", "sw_state")

#: (struct, field) in the order of callbacks.c's sw_layout, after the structures' sizes
#: (then come the ArcState cells' indices, circuit.arc.ARC_CELLS).
LAYOUT = tuple(("sw_channel", f) for f in ("name", "kind", "last_t", "last_value", "calls", "constant", "lo",
                                           "hi", "start", "offset", "scale", "n", "ends", "t0", "h",
                                           "coefficients", "windows", "lows", "highs", "befores", "gate_arc",
                                           "gate_conductance")) + \
    (("sw_arc", "name"), ("sw_arc", "value"), ("sw_arc_rule", "cells"), ("sw_arc_rule", "conductance")) + \
    tuple(("sw_state", f) for f in ("failed", "evaluate", "learn", "learn_arc", "channels_used", "channels",
                                    "arcs_used", "arcs_size", "arcs", "sync_python", "has_arcs", "accepting",
                                    "target", "max_step", "deadline", "arc_from", "arc_step", "arc_land",
                                    "landing_tolerance", "landings_head", "landings_used", "landings_size",
                                    "landings", "arc_rules_used", "arc_rules", "rejections_used",
                                    "rejections_size", "rejections", "pause_at", "python_data"))


def fill_table(cell, table) -> None:
    """Point the C channel ``cell`` (a ``sw_channel *``) at a TableChannel's numbers and arrays
    (the table must stay alive while the cell is read)."""
    buffer = ffi.from_buffer
    cell.kind = TABLE
    cell.lo, cell.hi, cell.start = table.lo, table.hi, table.start
    cell.offset, cell.scale = table.offset, table.scale
    cell.n = len(table.ends)
    cell.ends = buffer("double[]", table.ends)
    cell.t0 = buffer("double[]", table.t0)
    cell.h = buffer("double[]", table.h)
    cell.coefficients = buffer("double[]", table.coefficients)
    windows = table.windows
    if windows is None:
        cell.windows = 0
    else:
        cell.windows = len(windows[0])
        cell.lows, cell.highs, cell.befores = (buffer("double[]", w) for w in windows)


def table_values(library, table, times) -> list[float]:
    """The compiled callbacks' values of the TableChannel ``table`` at ``times`` (s), as the
    vsrc callback computes them (tests hold them to the table's Python function)."""
    cell = ffi.new("sw_channel *")
    fill_table(cell, table)
    return [library.sw_table_value(cell, float(t)) for t in times]


def compiler() -> list[str]:
    """The C compiler's command: $CC, else the interpreter's, else cc."""
    import shlex
    import sysconfig  # (only to build)

    text = os.environ.get("CC") or sysconfig.get_config_var("CC") or "cc"
    return shlex.split(text) or ["cc"]


def cache_root() -> Path:
    return Path(os.environ.get("NUMBA_CACHE_DIR") or PACKAGE / "__pycache__")


@functools.lru_cache(maxsize=None)
def build_key() -> str:
    """The source's and flags' hash with the machine (once per process: asked at each load;
    the compiler is not in it, as sysconfig is not imported at a start)."""
    machine = os.uname().machine if hasattr(os, "uname") else os.environ.get("PROCESSOR_ARCHITECTURE", "")
    try:  # (hashlib loads OpenSSL, ~4 ms of a start that needs no other hash)
        from _sha2 import sha256  # Python 3.12 and later
    except ImportError:
        try:
            from _sha256 import sha256
        except ImportError:
            from hashlib import sha256
    digest = sha256(SOURCE.read_bytes())
    digest.update(repr((FLAGS, LIBRARIES, machine, sys.platform)).encode())
    return digest.hexdigest()[:16]


def library_folder(root: Path | None = None) -> Path:
    return (root or cache_root()) / f"callbacks-{build_key()}"


def _note(text: str) -> None:
    print(f"switchsim: {text}", file=sys.stderr, flush=True)


_LOADED: dict[Path, object] = {}


def load(root: Path | None = None):
    """The compiled callbacks' library (a cffi library object of ``DECLARATIONS``), built
    first if missing; None: use the Python callbacks (said why on stderr, once per process)."""
    if os.environ.get(FORCE_PYTHON, "") not in ("", "0"):
        return None
    folder = library_folder(root)
    if folder in _LOADED:
        return _LOADED[folder]
    library = None
    failed = folder.with_name(folder.name + ".failed")
    path = folder / LIBRARY
    if not path.is_file() and failed.is_file():
        _note(f"using the Python ngspice callbacks: their C build failed before "
              f"({failed.read_text().strip()}; remove {failed} to retry)")
    elif not path.is_file() and (reason := _build_locked(folder)) is not None:
        _note(f"using the Python ngspice callbacks: their C build failed ({reason})")
    else:
        try:
            library = ffi.dlopen(str(path))
        except OSError as err:  # a file that does not load (another machine's, a damaged file)
            _note(f"using the Python ngspice callbacks: {path} does not load ({err})")
    _LOADED[folder] = library
    return library


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
        if (folder / LIBRARY).is_file():
            return None  # built by the process that held the lock
        failed = folder.with_name(folder.name + ".failed")
        if failed.is_file():
            return failed.read_text().strip()
        reason = _build(folder)
        if reason is not None and reason != "interrupted":
            failed.write_text(reason + "\n")
        return reason


def _build(folder: Path) -> str | None:
    """Run the compiler into a temporary folder beside ``folder``, then rename it."""
    import shutil  # (these three only to build: a run that loads the library imports none)
    import subprocess
    import tempfile

    command = compiler()
    if shutil.which(command[0]) is None:
        return f"no C compiler ({command[0]!r} not found)"
    staging = Path(tempfile.mkdtemp(prefix=folder.name + ".build-", dir=folder.parent))
    try:
        done = subprocess.run([*command, *FLAGS, "-o", str(staging / LIBRARY), str(SOURCE), *LIBRARIES],
                              capture_output=True, text=True, timeout=BUILD_TIMEOUT)
        if done.returncode != 0:
            return " ".join((done.stderr or done.stdout).strip().splitlines()[-1:]) or \
                f"{command[0]} exited with {done.returncode}"
        if not (staging / LIBRARY).is_file():
            return f"{command[0]} left no {LIBRARY}"
        os.rename(staging, folder)
    except subprocess.TimeoutExpired:
        return f"no result after {BUILD_TIMEOUT:.0f} s"
    except KeyboardInterrupt:
        return "interrupted"
    except OSError as err:
        return f"{type(err).__name__}: {err}"
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    _remove_stale(folder)
    return None


def _remove_stale(folder: Path) -> None:
    """Delete the builds of earlier sources beside ``folder`` (a loaded one stays mapped),
    with their lock files and failure notes; keep ``folder``'s own and builds under way."""
    import shutil

    for stale in folder.parent.glob("callbacks-*"):
        if stale.name.startswith(folder.name) or ".build-" in stale.name:
            continue
        if stale.is_dir():
            shutil.rmtree(stale, ignore_errors=True)
        else:
            stale.unlink(missing_ok=True)


def write_module(path: Path | None = None) -> Path:
    """Parse ``DECLARATIONS`` with cffi (this imports pycparser) and write the out-of-line
    module to ``path`` (default: circuit/_callbacks_ffi.py beside this file)."""
    from cffi import FFI

    builder = FFI()
    builder.cdef(DECLARATIONS)
    builder.set_source(MODULE, None)
    target = Path(path) if path is not None else PACKAGE / (MODULE.rsplit(".", 1)[1] + ".py")
    builder.emit_python_code(str(target))
    return target


if __name__ == "__main__":
    print(write_module())
