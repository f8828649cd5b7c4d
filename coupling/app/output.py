"""Writing a result folder (a run's, a fit's): complete or not there at all.

- The destination is checked before anything runs (``ResultFolder``): an empty name, an
  existing file or device, a folder that cannot be written, the current folder itself,
  or a non-empty folder that is not a previous result of the same scene (of the same data
  file, for a fit) without ``overwrite`` are refused with one line.
- Everything is written into a fresh hidden folder beside the destination (same parent,
  same file system), ``summary.json`` last; that folder then takes the destination's place:
  where the destination exists, the two are exchanged in one atomic rename (Linux
  ``renameat2(RENAME_EXCHANGE)``), so the destination always holds a whole result, the old
  or the new. A previous result there is replaced whole (its old files never mix with the
  new ones), except files put into the folder during the run: they are carried over into
  the new result (one whose name the result also writes makes the run refuse to replace
  anything, without ``overwrite``). An interruption or error while writing removes the
  unfinished folder and leaves the previous result as it was.
- Where the exchange is not available, the previous result is first renamed aside to
  ``.switchsim-old.<token>.<name>``; a kill between that rename and the next leaves no
  folder at the destination, and the next ``switchsim run`` or ``switchsim plot`` of it
  puts the previous result back (``recover``).
- The mechanics history is thinned (``thin_history``) to ``[output] history_resolution``,
  coarser where ``history_max_rows`` needs it: its size is bounded by that row budget
  plus the events, however many steps the solver took.
"""

from __future__ import annotations

import dataclasses
import errno
import fcntl
import io
import itertools
import json
import math
import os
import re
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np

STAGING_PREFIX = ".switchsim-"  # hidden working folders beside the destination
OLD_PREFIX = ".switchsim-old."  # the previous result set aside, where no atomic exchange exists
_OLD_NAME = re.compile(r"^\.switchsim-old\.[0-9a-f]{8}\.(.+)$", re.S)
_STAGING_NAME = re.compile(r"^\.switchsim-(.+)-[a-z0-9_]{8}$", re.S)  # tempfile.mkdtemp's names
RENAME_EXCHANGE = 2  # linux/fs.h


class DestinationError(ValueError):
    """The result folder cannot be used; raised before the run starts."""


def scene_identity(scene, scene_path: str | None) -> dict:
    """What marks a result folder as this scene's: the scene's name and its file (absolute)."""
    return {"scene": getattr(scene, "name", "scene"),
            "scene_file": None if scene_path is None else str(Path(scene_path).resolve())}


def fit_identity(data_path: str) -> dict:
    """What marks a folder as a fit of this data file: its fit.json names the same file."""
    return {"marker": "fit.json", "data_file": str(Path(data_path).resolve()), "what": "a fit of this data file"}


def previous_result_of(folder: Path, identity: dict) -> bool:
    """True if ``folder`` holds a switchsim result (summary.json with a status) of the same
    scene (same scene file; for the built-in default scene, the same name), or for a fit's
    identity a fit.json of the same data file."""
    marker = identity.get("marker", "summary.json")
    try:
        doc = json.loads((folder / marker).read_text())
    except (OSError, ValueError, RecursionError):
        return False
    if not isinstance(doc, dict):
        return False
    if marker == "fit.json":
        source = doc.get("source")
        try:
            return isinstance(source, str) and str(Path(source).resolve()) == identity["data_file"]
        except (OSError, RuntimeError, ValueError):
            return False
    if "status" not in doc:
        return False
    if identity["scene_file"] is not None or doc.get("scene_file") is not None:
        return doc.get("scene_file") == identity["scene_file"]
    return doc.get("scene") == identity["scene"]


def recover(out: str, marker: str = "summary.json") -> str | None:
    """What a killed replacement of ``out`` left (see the module docstring): with no folder
    at ``out`` and the previous result set aside beside it, that result is put back. Hidden
    working folders of a killed run are named, never deleted (after a kill right after the
    exchange one may hold files put into the folder during that run). Returns the lines to
    show, or None."""
    if not isinstance(out, str) or not out.strip():
        return None
    try:
        path = Path(out).expanduser().absolute()
        if not path.parent.is_dir():
            return None
        siblings = list(path.parent.iterdir())
        aside = sorted((p for p in siblings
                        if (m := _OLD_NAME.match(p.name)) and m.group(1) == path.name
                        and p.is_dir() and not p.is_symlink() and (p / marker).is_file()),
                       key=lambda p: p.stat().st_mtime)
        lines = []
        if aside and not (path.exists() or path.is_symlink()):
            os.rename(aside.pop(), path)
            lines.append(f"restored {out}: a replacement of it was interrupted and had set its previous result aside")
        left = aside + [p for p in siblings if (m := _STAGING_NAME.match(p.name)) and m.group(1) == path.name
                        and p.is_dir() and not p.is_symlink() and not _in_use(p)]
        if left:
            lines.append(f"{', '.join(sorted(p.name for p in left))} beside {out}: left by a run that was killed; "
                         "delete it when you no longer need it")
        return "; ".join(lines) or None
    except OSError:  # a place that cannot be listed: the destination's own check says so
        return None


@dataclasses.dataclass
class ResultFolder:
    """A checked destination for one run's files (see the module docstring)."""

    path: Path
    identity: dict
    overwrite: bool = False
    before: frozenset | None = None  # the names in the folder when it was checked (None: no folder)
    notes: list = dataclasses.field(default_factory=list)  # what the swap left for the user to know

    @classmethod
    def check(cls, out: str, identity: dict, *, overwrite: bool = False) -> "ResultFolder":
        """Validate ``out`` (as the user wrote it) before the run; DestinationError if unusable."""
        try:
            return cls._check(out, identity, overwrite)
        except OSError as err:  # e.g. a folder on the way that cannot be read
            raise DestinationError(f"--out {out!r}: {err.strerror or err}") from None

    @classmethod
    def _check(cls, out: str, identity: dict, overwrite: bool) -> "ResultFolder":
        if not isinstance(out, str) or not out.strip():
            raise DestinationError("--out '': give the name of a result folder, e.g. --out runs/my_scene")
        path = Path(out).expanduser()
        where = f"--out {out!r}"
        if path.is_symlink() and path.is_dir():
            path = path.resolve()  # a link to a folder: the folder it names is the destination
        if path.exists() or path.is_symlink():
            if not path.is_dir():
                kind = "a file" if path.is_file() else "not a folder (a device or special file)"
                raise DestinationError(f"{where} is {kind}; give a folder name")
            resolved = path.resolve()
            cwd = Path.cwd().resolve()
            try:
                home = Path.home().resolve()
            except RuntimeError:  # no home folder known
                home = None
            if resolved == cwd or resolved in cwd.parents or resolved == home:
                raise DestinationError(f"{where} is the current folder, one of its parents or the home "
                                       "folder, which a result would replace; give a sub-folder")
            if any(path.iterdir()):
                if not previous_result_of(path, identity):
                    if not overwrite:
                        what = identity.get("what", "a switchsim result of this scene")
                        raise DestinationError(f"{where} holds files that are not {what}; give another --out, "
                                               "or --overwrite to replace the folder whole")
                    if any(p.is_dir() and not p.is_symlink() for p in path.iterdir()):
                        raise DestinationError(
                            f"{where} holds sub-folders (switchsim never writes any): it is not a result "
                            "folder, and --overwrite will not delete it; give another --out")
            if not os.access(path, os.W_OK | os.X_OK):
                raise DestinationError(f"{where} is read-only; give a folder you can write")
        parent = path.absolute().parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
            probe = tempfile.mkdtemp(prefix=STAGING_PREFIX + "probe-", dir=parent)
            os.rmdir(probe)
        except OSError as err:
            raise DestinationError(f"{where}: cannot create a folder in {str(parent)!r}: "
                                   f"{err.strerror or err}") from None
        before = frozenset(os.listdir(path)) if path.is_dir() else None
        return cls(path=path.absolute(), identity=identity, overwrite=overwrite, before=before)

    def write(self, result, summary_extra: dict | None = None, writer=None) -> Path:
        """Write ``result`` (a CoupledResult) and put it in place; returns the folder
        (``writer``: write_files's)."""
        return self.publish(lambda staging: write_files(result, staging, summary_extra, writer))

    def publish(self, fill) -> Path:
        """``fill(folder)`` writes the files into a fresh hidden folder, which then takes the
        destination's place (module docstring); returns the destination."""
        staging = Path(tempfile.mkdtemp(prefix=f"{STAGING_PREFIX}{self.path.name}-", dir=self.path.parent))
        new = staging.stat().st_ino  # which folder is the new result, whichever name it has now
        held = _hold(staging)  # tells `recover` the folder is in use; released when this process ends
        try:
            _make_public(staging)
            fill(staging)
            old = self._swap(staging)
        except BaseException:
            if _inode(self.path) == new:  # interrupted after the exchange: staging is the previous result
                self._finish(staging)
            else:
                shutil.rmtree(staging, ignore_errors=True)
            raise
        finally:
            os.close(held)
        if old is not None:
            self._finish(old)
        return self.path

    def _finish(self, old: Path) -> None:
        kept = self._carry_over(old)
        if kept:
            self.notes.append(f"{', '.join(sorted(kept))} appeared in {self.path} as the result was put in "
                              f"place; kept in {old}")
        else:
            shutil.rmtree(old, ignore_errors=True)

    def _swap(self, staging: Path) -> Path | None:
        """Put ``staging`` at the destination; returns the folder now holding the previous
        result (to carry over and delete), or None. Raises before anything moved."""
        path = self.path
        if not (path.exists() or path.is_symlink()):
            try:
                os.rename(staging, path)
                return None
            except OSError:  # the folder appeared during the run
                if not (path.exists() or path.is_symlink()):
                    raise
        if path.is_symlink() or not path.is_dir():
            raise DestinationError(f"--out {str(path)!r} became a file or a link during the run; nothing was "
                                   "replaced")
        added = set(os.listdir(path)) - (self.before or frozenset())
        clash = added & set(os.listdir(staging))
        if clash and not self.overwrite:
            raise DestinationError(
                f"--out {str(path)!r}: {', '.join(sorted(clash))} appeared there during the run and the result "
                "would replace it; nothing was replaced: move it away and run again (or --overwrite)")
        if _exchange(staging, path):
            return staging  # now the previous result
        old = path.parent / f"{OLD_PREFIX}{os.urandom(4).hex()}.{path.name}"  # (not uuid: it imports platform, ~2 ms a start)
        os.rename(path, old)
        try:
            os.rename(staging, path)
        except BaseException:
            os.rename(old, path)  # put the previous result back
            raise
        return old

    def _carry_over(self, old: Path) -> set:
        """Move the files put into the folder during the run from the previous result into
        the new one; returns those left behind (the new result has a file of that name,
        which only ``overwrite`` lets win)."""
        kept = set()
        for name in set(os.listdir(old)) - (self.before or frozenset()):
            target = self.path / name
            if target.exists() or target.is_symlink():
                if not self.overwrite:
                    kept.add(name)
                continue
            try:
                os.rename(old / name, target)
            except OSError:
                kept.add(name)
        return kept


def _hold(folder: Path) -> int:
    """An open descriptor of ``folder`` holding an exclusive flock on it (close it to release)."""
    fd = os.open(folder, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        pass  # a file system without flock: `recover` then sees the folder as left over, which it only reports
    return fd


def _in_use(folder: Path) -> bool:
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        return False
    except OSError:
        return True
    finally:
        os.close(fd)  # closing releases a lock taken here


def _inode(path: Path) -> int | None:
    try:
        return path.stat().st_ino
    except OSError:
        return None


def _exchange(a: Path, b: Path) -> bool:
    """Swap two folders in one atomic rename (Linux renameat2 RENAME_EXCHANGE); False where
    the system or the file system has no such rename (nothing moved then)."""
    global _RENAMEAT2
    if _RENAMEAT2 is None:
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            fn = libc.renameat2
            fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
            fn.restype = ctypes.c_int
            _RENAMEAT2 = (fn, ctypes)
        except (OSError, AttributeError):  # not glibc >= 2.28 (or not Linux)
            _RENAMEAT2 = False
    if not _RENAMEAT2:
        return False
    fn, ctypes = _RENAMEAT2
    at_fdcwd = -100
    if fn(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), RENAME_EXCHANGE) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.EINVAL, errno.ENOSYS, errno.ENOTSUP, errno.EOPNOTSUPP):
        return False  # e.g. a file system without the exchange: the two-rename route
    raise OSError(code, os.strerror(code), str(b))


_RENAMEAT2 = None  # (renameat2, ctypes) once looked up, False where there is none


def project_matplotlib() -> None:
    """Import matplotlib with its own default settings, whatever the working folder holds.

    matplotlib reads ``./matplotlibrc`` first when it is imported: a file there changed the
    plots or broke them (``text.usetex: True`` without LaTeX is a traceback at the first
    label), and a FIFO of that name would block the import. The working folder is
    untrusted (docs/circuit.md), so matplotlib is imported from an empty private folder and
    its settings are then reset to the package's defaults (which also drops a user-wide
    matplotlibrc). Called by the command line before it draws."""
    if "matplotlib" not in sys.modules:
        try:
            here = os.getcwd()
        except OSError:  # the working folder was removed: nothing there to read
            here = None
        with tempfile.TemporaryDirectory(prefix="switchsim-mpl-") as empty:
            if here is not None:
                os.chdir(empty)
            try:
                import matplotlib  # noqa: F401
            finally:
                if here is not None:
                    os.chdir(here)
    import matplotlib

    matplotlib.rcdefaults()


def save_result(result, out_dir, *, overwrite: bool = False, scene_path: str | None = None) -> Path:
    """``CoupledResult.save``: the result folder checked and written as the command line does."""
    folder = ResultFolder.check(str(out_dir), scene_identity(result.scene, scene_path), overwrite=overwrite)
    return folder.write(result)


def write_files(result, folder: Path, summary_extra: dict | None = None, writer=None) -> None:
    """Write all of a result's files into ``folder``, summary.json last: the waveforms (CSV,
    parquet, the interactive waveforms.html), openings.csv, the mechanics tables (history.csv
    thinned to ``[output] history_resolution``) and PNG plots, as the scene's [output] asks.
    The one writer of result folders: ``switchsim run`` and ``CoupledResult.save``.

    writer: a ``coupling.app.table_writer.TableWriter`` (``switchsim run``'s own process):
    waveforms.parquet, waveforms.csv and history.csv go to it, the rest is written here
    meanwhile; a table it did not write is written here, and an error here stops it."""
    from coupling.core.results import event_columns

    opts = result.scene.output
    summary = result.summary
    sent = []  # (function, path, args) the writer has
    writers = {"write_csv": write_csv, "write_parquet": write_parquet}  # (by name: the writer's protocol)
    history = None  # summary["history"], entered after waveforms_html (the summary's order as before)

    def large(name, path, *args):
        if writer is not None and writer.submit(name, path, *args):
            sent.append((writers[name], path, args))
        else:
            writers[name](path, *args)

    try:
        waves = result.waveform_columns
        if waves is not None:
            if opts.parquet:  # first: with pyarrow loaded, the large CSVs take write_csv's Arrow route
                large("write_parquet", folder / "waveforms.parquet", waves)
            if opts.csv:
                large("write_csv", folder / "waveforms.csv", waves)
        m = result.mechanics
        if m is not None and opts.history:
            t = m.t
            interval = opts.history_interval(float(t[-1] - t[0]) if len(t) else 0.0)
            kept = thin_history(m, interval)
            codes = history_codes()
            path = folder / "history.csv"
            stream = writer.history if writer is not None else None  # its rows sent during the run
            rest = stream.finish(m, kept, interval) if stream is not None else None
            if rest is not None and writer.submit("write_csv_pieces", path, stream.stream,
                                                  m.select(rest).history_columns, codes, len(stream.pieces)):
                sent.append((lambda where: write_csv(where, m.select(kept).history_columns, codes), path, ()))
            else:
                large("write_csv", path, m.select(kept).history_columns, codes)
            history = {"file": "history.csv", "resolution": interval,
                       "rows": int(len(kept)), "solver_records": int(len(t))}
        if waves is not None:
            if getattr(opts, "html", True):
                from coupling.app.waveview import write_waveform_html

                html = write_waveform_html(result, folder / "waveforms.html")
                summary["waveforms_html"] = "waveforms.html" if html == "written" else html
            if result.scene.circuit is not None:
                write_csv(folder / "openings.csv", result.opening_columns)
                for name in result.contact_results:  # each contact of several: its own table
                    write_csv(folder / f"openings_{name}.csv", result.contact_opening_columns(name))
        if history is not None:
            summary["history"] = history
        if m is not None:
            write_csv(folder / "contacts.csv", m.contact_columns)
            write_csv(folder / "phases.csv", m.phase_columns)
            write_csv(folder / "events.csv", event_columns(m.events))
        if sent:
            done = writer.collect()
            for function, path, args in sent:
                if done.get(str(path), "not answered") is not None:
                    function(path, *args)  # written here: the helper's failure costs time, not the file
    except BaseException:
        if sent:
            writer.close()  # nothing more written into a folder the caller now removes
        raise
    if opts.plots:
        from coupling.app.plots import save_plots

        save_plots(result, folder)
    summary.update(summary_extra or {})
    _write_text(folder / "summary.json", json.dumps(_jsonable(summary), indent=2))


def history_codes() -> dict:
    """history.csv's columns written as names: the first two contact rows' regimes."""
    from coupling.core.results import REGIME_NAMES

    return {"regime_0": REGIME_NAMES, "regime_1": REGIME_NAMES}


def thin_history(mres, resolution: float) -> np.ndarray:
    """Indices of the records history.csv keeps: the first and last, those on either side
    of every event and regime change, and of the rest the first in each interval of
    ``resolution`` seconds (0: every record). At most t_end / resolution + 4 x (events +
    regime changes) + 2 rows, however many steps the solver took."""
    t = np.asarray(mres.t)
    n = len(t)
    if n <= 2:
        return np.arange(n)
    times = np.array([e["time"] for e in mres.events], dtype=float)
    return kept_records(t, np.asarray(mres.regimes), times, resolution, 0, n)


def kept_records(t: np.ndarray, regimes: np.ndarray, event_times: np.ndarray, resolution: float,
                 start: int, stop: int) -> np.ndarray:
    """Indices in [start, stop) of the records ``thin_history`` keeps (its rule), from the
    records' times t (s) and regimes and the events' times (s). With ``stop`` = len(t), the
    whole history's (its last record kept); with ``stop`` < len(t), the records so far of a
    run that goes on (coupling.app.history_stream), whose decisions for [start, stop) the
    records and events after them cannot change: a record's bin follows from the record
    before, a change of regime from the record after, and an event after the records so far
    keeps none of them. A resolution of 0 keeps every record."""
    if resolution <= 0.0:
        return np.arange(start, stop)
    n = len(t)
    whole = stop == n
    keep = np.zeros(stop - start, bool)
    if start == 0:
        keep[0] = True
    if whole:
        keep[-1] = True
    lo = max(start - 1, 0)
    bins = np.floor((t[lo:stop] - t[0]) / resolution)
    keep[np.flatnonzero(np.diff(bins) > 0) + lo + 1 - start] = True
    last = min(stop, n - 1)  # (a change between record k and k + 1, k < last)
    change = np.flatnonzero(np.any(regimes[lo + 1:last + 1] != regimes[lo:last],
                                   axis=tuple(range(1, regimes.ndim)))) + lo
    marks = [change, change + 1]
    if len(event_times):
        k = np.searchsorted(t, event_times)
        if whole:
            k = np.clip(k, 0, n - 1)
        marks += [k, np.maximum(k - 1, 0)]
    for k in marks:  # either side of every change of a regime and every event
        k = k[(k >= start) & (k < stop)]
        keep[k - start] = True
    return np.flatnonzero(keep) + start


def write_csv(path: Path, columns: dict, codes: dict | None = None) -> None:
    """A CSV file of ``columns`` (name -> array or list, equal lengths), as pandas'
    ``to_csv(index=False)`` writes it: floats in their shortest exact form, NaN and None
    blank, booleans True/False; a column named in ``codes`` holds indices into its names.
    Written from the arrays: the command line needs no pandas to write its tables.

    A large table of numbers (floats, integers, codes) is written through Arrow's kernels
    (coupling.app.arrow_text), the same bytes at about a fifth of the cost, where pyarrow
    is loaded already (the default coupled run writes waveforms.parquet first) or the
    table is large enough to pay for importing it (``ARROW_IMPORT_MIN_CELLS``).
    Otherwise the lines are joined here, not by the csv module, when no field needs
    quoting (numbers never do; the names and text cells are checked): csv.writer's
    per-field quoting scan cost ~30 ms of a default run's history.csv (2 900 rows x 61
    columns) for the same bytes. Otherwise, and for a single column (where csv writes an
    empty field as ""), csv.writer writes the file."""
    with open(path, "wb") as fh:
        _write_table(fh, columns, codes, header=True)


def csv_rows(columns: dict, codes: dict | None = None) -> bytes:
    """The lines ``write_csv`` writes after its header line, for the same columns: a table
    written in pieces (history.csv while the run goes on) is its header line and its pieces'
    rows, the bytes of the whole table written at once."""
    buffer = io.BytesIO()
    _write_table(buffer, columns, codes, header=False)
    return buffer.getvalue()


def write_csv_pieces(path: Path, rest: dict, codes: dict | None, pieces: list) -> None:
    """A CSV file of a table whose earlier rows are ``pieces`` (``csv_rows`` of each, in
    order) and whose last rows are the columns ``rest`` (their names the table's): the bytes
    ``write_csv`` writes for the whole table."""
    with open(path, "wb") as fh:
        _write_table(fh, {name: [] for name in rest}, None, header=True)  # (its header line as write_csv's)
        fh.writelines(pieces)
        _write_table(fh, rest, codes, header=False)


def _write_table(fh, columns: dict, codes: dict | None, header: bool) -> None:
    """write_csv into the binary file ``fh``, its header line only where ``header``."""
    codes = codes or {}
    names = list(columns)
    plain = len(names) > 1 and not _NEEDS_QUOTES.search("".join(names))
    if plain and _write_numbers(fh, names, columns, codes, header):
        return
    cells = []
    for name in names:
        col, numeric = _cells(columns[name], codes.get(name))
        if plain and not numeric:
            col = [c if type(c) is str else str(c) for c in col]  # as csv.writer: str() of the rest
            plain = not _NEEDS_QUOTES.search("".join(col))
        cells.append(col)
    # (text in the encoding open() would give a text file: the locale's)
    text = io.TextIOWrapper(fh, newline="", write_through=True)
    try:
        if not plain:
            import csv  # (here: the default scene's and the plunger's tables never come this way)

            writer = csv.writer(text, lineterminator="\n")
            if header:
                writer.writerow(names)
            writer.writerows(zip(*cells))
            return
        if header:
            text.write(",".join(names) + "\n")
        rows = zip(*cells)
        # in pieces of 200 lines: the whole text is never held (peak RSS as with csv.writer)
        while chunk := list(itertools.islice(rows, 200)):
            text.write("\n".join(map(",".join, chunk)) + "\n")
    finally:
        text.flush()
        text.detach()


# write_csv's Arrow route from these sizes on, in cells (rows x columns), where it saves
# more than it costs: a cell costs ~0.35 us by the Python route, ~0.11 us by Arrow's (the
# default scene's history.csv and waveforms.csv, CPU time); its first use in a process
# costs ~8 ms (pyarrow._compute and pyarrow.csv imported, the layout checked, the kernels'
# first calls), importing pyarrow ~40 ms more
ARROW_MIN_CELLS = 2_000  # the route in use already
ARROW_FIRST_MIN_CELLS = 30_000  # pyarrow loaded (waveforms.parquet is written first)
ARROW_IMPORT_MIN_CELLS = 200_000  # pyarrow not loaded


def _write_numbers(fh, names: list, columns: dict, codes: dict, header: bool) -> bool:
    """write_csv's Arrow route: writes the table into the binary file ``fh`` (its header line
    where ``header``) and returns True where every column is a
    1-D numpy array of floats or integers in the machine's byte order (codes: integers
    within their names, which need no quoting), all of one length, the names and codes
    ASCII (the bytes then do not depend on the locale's encoding), and the table is large
    enough (the constants above)."""
    arrays, labels = [columns[name] for name in names], []
    if not all(isinstance(a, np.ndarray) and a.ndim == 1 and a.dtype.kind in "iuf" and a.dtype.isnative
               for a in arrays):
        return False
    n = len(arrays[0])
    if any(len(a) != n for a in arrays) or not "".join(names).isascii():
        return False
    from coupling.app import arrow_text

    least = (ARROW_MIN_CELLS if arrow_text.ready() else
             ARROW_FIRST_MIN_CELLS if "pyarrow" in sys.modules else ARROW_IMPORT_MIN_CELLS)
    if n * len(arrays) < least:
        return False
    for name, a in zip(names, arrays):
        label = codes.get(name)
        if label is not None:
            label = tuple(label)
            if (a.dtype.kind == "f" or a.min() < 0 or a.max() >= len(label)
                    or not all(type(x) is str and x.isascii() and not _NEEDS_QUOTES.search(x) for x in label)):
                return False
        labels.append(label)
    if not arrow_text.available():
        return False
    if header:
        fh.write((",".join(names) + "\n").encode())
    arrow_text.write_rows(fh, arrays, labels)
    return True


# what makes csv.writer (QUOTE_MINIMAL, "," and '"', "\n" line ends) quote a field
_NEEDS_QUOTES = re.compile('[,"\r\n]')


def _cells(values, names=None) -> tuple[list, bool]:
    """One column's CSV cells (see write_csv), and whether they are all numbers (or codes'
    names), which never need quoting; otherwise the cells are text or other objects."""
    if names is not None:
        return [names[v] for v in np.asarray(values).tolist()], not _NEEDS_QUOTES.search("".join(names))
    if isinstance(values, np.ndarray) and values.dtype.kind == "f":
        return _float_cells(values.astype(float)), True
    if isinstance(values, np.ndarray) and values.dtype.kind in "iub":
        return list(map(str, values.tolist())), True
    values = values.tolist() if isinstance(values, np.ndarray) else values
    return ["" if v is None or (isinstance(v, float) and math.isnan(v)) else
            (float.__repr__(v) if isinstance(v, float) else v) for v in values], False


def _float_cells(v: np.ndarray) -> list:
    """The cells of a float64 column: float.__repr__ of each value (its shortest exact form),
    NaN blank. A value repeated (compared bit for bit: -0.0 is not 0.0) is formatted once: a
    column that never changes (a planar run's out-of-plane states, a single contact's
    switched-off second row: a third of a relay's history.csv) or the zeros of a force in
    flight cost a list entry, not a conversion. (numpy's astype(str) gives the same text,
    checked on 2e5 random bit patterns, but at 1.5 times the cost.)"""
    n = len(v)
    out = None
    if n:
        bits = v.view(np.int64)
        if np.all(bits == bits[0]):
            out = [float.__repr__(float(v[0]))] * n
        else:
            zero = bits == 0
            if np.count_nonzero(zero) > n // 8:
                out = ["0.0"] * n
                rest = np.flatnonzero(~zero)
                for k, cell in zip(rest.tolist(), map(float.__repr__, v[rest].tolist())):
                    out[k] = cell
    if out is None:
        out = list(map(float.__repr__, v.tolist()))
    for k in np.flatnonzero(np.isnan(v)).tolist():
        out[k] = ""
    return out


def write_parquet(path: Path, columns: dict) -> None:
    """A Parquet file of ``columns`` (name -> numpy array) through pyarrow, without pandas.

    Numeric columns become Arrow arrays over their own memory: ``pa.array`` on a numpy
    array imports pandas to ask whether it is a pandas object (0.17 s, more than the rest
    of the file); NaN stays NaN (not null), as pa.array would keep it. The file is written
    by the writer ``pyarrow.parquet.write_table`` uses, with its defaults, imported from
    ``pyarrow._parquet``: importing ``pyarrow.parquet`` also imports pyarrow.fs and ssl
    (~20 ms); the bytes are the same (tests/coupling/test_output_arrow.py). Where that
    writer is not there or takes other arguments, ``pyarrow.parquet`` writes the file."""
    import pyarrow as pa

    def arrow(values):
        values = np.ascontiguousarray(values)
        if values.ndim == 1 and values.dtype.kind in "iuf" and values.dtype.isnative:
            return pa.Array.from_buffers(pa.from_numpy_dtype(values.dtype), len(values), [None, pa.py_buffer(values)])
        return pa.array(values)  # booleans (bit-packed in Arrow), strings: pyarrow's own conversion

    table = pa.Table.from_arrays([arrow(v) for v in columns.values()], names=list(columns))
    try:
        from pyarrow._parquet import ParquetWriter

        writer = ParquetWriter(str(path), table.schema, **PARQUET_DEFAULTS)
    except (ImportError, TypeError):
        import pyarrow.parquet as pq

        pq.write_table(table, path)
        return
    try:
        writer.write_table(table)
    finally:
        writer.close()


# pyarrow.parquet.write_table's defaults for its writer (pyarrow 26; the test compares the bytes)
PARQUET_DEFAULTS = {"version": "2.6", "compression": "snappy", "use_dictionary": True, "write_statistics": True,
                    "writer_engine_version": "V2", "data_page_version": "1.0", "use_compliant_nested_type": True,
                    "store_schema": True}


def _write_text(path: Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def _make_public(folder: Path) -> None:
    """mkdtemp makes a private (0700) folder; a result folder gets the usual permissions."""
    mask = os.umask(0)
    os.umask(mask)
    os.chmod(folder, 0o777 & ~mask)


def _jsonable(value):
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        value = float(value)
        return value if np.isfinite(value) else None
    return value
