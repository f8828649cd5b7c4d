"""A second process that writes a run's large tables while the command's own process
writes the rest.

``switchsim run`` forks it once its scene is built, before the co-simulation. While the run
goes on (one core) it imports pyarrow and readies the Arrow route of
``coupling.app.output.write_csv`` (~40 ms that no longer wait for the run's end); after the
run it writes waveforms.parquet, waveforms.csv and history.csv into the result's staging
folder while the command's process writes waveforms.html, the small tables and, last,
summary.json. The files are the same bytes as those written in one process: the same
functions write them (tests/coupling/test_table_writer.py).

What it is sent (one pickled message a table: the function's name, the path, its
arguments) is written into an in-memory file the two processes share (``memfd_create``,
made before the fork, grown as tables come and emptied when all are answered), and only
where it lies goes through a pipe: the command never waits for the helper to take a table
(a pipe holds 64 KiB, history.csv's columns are a few MiB), the helper needs no thread to
read it, and neither process maps it (a cap on the address space, ``ulimit -v``, sees
nothing of it). Its answers (the path, None or the error's text, and the seconds it took)
come back through a second pipe, each when its table is on disk.

A table the helper did not write (it failed or died, or there was no memory to hand it
over) is written by the command itself: the helper can cost time, never a file. It ignores
the user's Ctrl-C, which is the command's to handle: an interrupted run's partial result
still gets its tables through it. It ends at the end of its input (the command's process
ended, for any reason) or when the command closes it, at once: by then everything it was
sent is written, or given up with a folder that is being removed.

Only where ``os.fork`` is there (Linux) and the process may use two CPUs (``wanted``);
elsewhere, and inside a caller's process (tests, ``CoupledResult.save``, sweeps),
everything is written in one process as before.
"""

from __future__ import annotations

import os
import pickle
import signal
import struct
import sys
import time
from pathlib import Path

from coupling.app import usable_cpus

_LENGTH = struct.Struct("<Q")  # each answer: its pickle's length, then the pickle
_WHERE = struct.Struct("<QQ")  # each table: where its pickle lies in the shared file (offset, length)


def wanted(scene, cpus: int | None = None) -> bool:
    """Whether a run of ``scene`` is worth a helper: a co-simulation (a circuit: the run
    outlasts the helper's start) that writes at least one of the large tables, on a machine
    that lets this process use two CPUs or more (``cpus``; None: as the system says). On one
    CPU the helper would take its time from the run: the pair costs more CPU time than one
    process (the fork, pyarrow's import, the tables' copies: ~20-30 ms a relay run,
    docs/benchmarks.md), which only a second CPU hides."""
    if cpus is None:
        cpus = usable_cpus()
    opts = scene.output
    return cpus >= 2 and scene.circuit is not None and (opts.parquet or opts.csv or opts.history)


class TableWriter:
    """The parent's end of the helper (module docstring). ``start()`` forks it; ``submit``
    sends a table, ``collect`` waits for every table sent, ``close`` ends the helper."""

    # what it may be asked to write (coupling.app.output's functions of these names);
    # write_csv_pieces: a table whose rows came before in pieces (``send_piece``)
    WRITERS = ("write_csv", "write_parquet", "write_csv_pieces")

    def __init__(self, pid: int, shared: int, jobs: int, replies: int):
        self.pid = pid
        self._shared = shared  # fd: the in-memory file the tables are put into
        self._used = 0  # bytes of it holding tables not yet answered
        self._jobs = jobs  # fd: where each table lies
        self._replies = os.fdopen(replies, "rb")
        self._pending: list[str] = []
        self._broken = False
        self.seconds: dict[str, float] = {}  # path -> the helper's time writing it (benchmarks)
        # a coupling.app.history_stream.HistoryStream sending history.csv's rows while the run
        # goes on (write_files asks it for the rest), or None
        self.history = None

    @classmethod
    def start(cls) -> "TableWriter | None":
        """Fork the helper; None where fork is not there or fails (then one process writes)."""
        if not (hasattr(os, "fork") and hasattr(os, "memfd_create") and sys.platform.startswith("linux")):
            return None
        fds = []
        try:
            fds.append(shared := os.memfd_create("switchsim-tables", os.MFD_CLOEXEC))
            fds.extend(jobs := os.pipe())
            fds.extend(replies := os.pipe())
            pid = os.fork()
        except OSError:
            for fd in fds:
                os.close(fd)
            return None
        (jobs_r, jobs_w), (replies_r, replies_w) = jobs, replies
        if pid == 0:  # the helper: never returns into the command's code
            code = 1
            try:
                os.close(jobs_w)
                os.close(replies_r)
                _serve(shared, jobs_r, replies_w)
                code = 0
            finally:
                os._exit(code)  # no atexit handlers, no flush of the parent's buffers
        os.close(jobs_r)
        os.close(replies_w)
        return cls(pid, shared, jobs_w, replies_r)

    def submit(self, function: str, path: Path, *args) -> bool:
        """Send one table (``function`` of coupling.app.output called with ``path, *args``);
        False if the helper is gone or the table does not fit (the caller then writes it)."""
        if function not in self.WRITERS:
            raise ValueError(f"function = {function!r}: allowed values are {', '.join(self.WRITERS)}")
        if not self._put((function, str(path), args)):
            return False
        self._pending.append(str(path))
        return True

    def send_piece(self, stream: int, columns: dict, codes: dict | None = None) -> bool:
        """Send rows of a table written in pieces (coupling.app.history_stream): the helper
        turns them into text at once, while the run goes on, and keeps it for the
        ``write_csv_pieces`` table of the same ``stream`` (a number), which writes the pieces
        in the order sent. No answer comes for a piece: a piece that failed fails that table
        (the command then writes it whole). False if the helper is gone or the piece does
        not fit."""
        return self._put(("csv_piece", "", (stream, columns, codes)))

    def _put(self, message: tuple) -> bool:
        """Put one message into the shared file and say where through the pipe."""
        if self._broken:
            return False
        data = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
        start = self._used
        try:
            os.ftruncate(self._shared, start + len(data))
            if os.pwrite(self._shared, data, start) != len(data):
                return False
        except OSError:  # (no memory for it)
            return False
        try:
            _write_all(self._jobs, _WHERE.pack(start, len(data)))
        except OSError:  # (BrokenPipeError: it died)
            self._broken = True
            return False
        self._used = start + len(data)
        return True

    def collect(self) -> dict:
        """Wait for every table sent: path -> None (written) or why it was not (its error's
        text, or that the helper ended before answering)."""
        done = {}
        pending, self._pending = self._pending, []
        for path in pending:
            reply = None if self._broken else _read(self._replies)
            if reply is None:
                self._broken = True
                done[path] = "the table writer ended before writing it"
                continue
            written, error, seconds = reply
            done[written] = error
            self.seconds[written] = seconds
        self._used = 0  # every table answered: the shared file's memory is given back
        try:
            os.ftruncate(self._shared, 0)
        except OSError:
            pass
        return done

    def close(self, wait: bool = True) -> None:
        """End the helper now. It holds nothing of its own: every table sent was collected,
        or is being given up with its folder (``write_files``), and one still importing
        pyarrow after a run that wrote no tables need not finish. ``wait``: until it has
        ended (its memory's teardown takes ~5 ms); otherwise a process about to end itself
        leaves it to the system (its parent's end makes init reap it)."""
        if self.pid:
            try:
                os.kill(self.pid, signal.SIGKILL)
            except OSError:
                pass
        self._broken = True
        if self._jobs >= 0:
            os.close(self._jobs)
            self._jobs = -1
            self._replies.close()
            os.close(self._shared)
        if self.pid:
            try:
                os.waitpid(self.pid, 0 if wait else os.WNOHANG)
            except ChildProcessError:
                pass
            self.pid = 0


def _serve(shared: int, jobs_fd: int, replies_fd: int) -> None:
    """The helper's life: ready the Arrow route, then write each table it is sent."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    from coupling.app import arrow_text, output

    try:  # while the command runs: what the tables' first write would otherwise wait for
        if arrow_text.available():
            import pyarrow._parquet  # noqa: F401 - write_parquet's writer
    except Exception:  # noqa: BLE001 - no pyarrow, or a broken one: write_csv's other route, and the error below
        pass
    writers = {name: getattr(output, name) for name in ("write_csv", "write_parquet")}
    pieces: dict[int, list | str] = {}  # stream -> its pieces' text, or why one failed

    def write_csv_pieces(path, stream, rest, codes, count):
        held = pieces.pop(stream, [])
        if isinstance(held, str):
            raise RuntimeError(f"a piece of its rows failed: {held}")
        if len(held) != count:
            raise RuntimeError(f"{len(held)} pieces of its rows came, not {count}")
        output.write_csv_pieces(path, rest, codes, held)

    writers["write_csv_pieces"] = write_csv_pieces
    with os.fdopen(jobs_fd, "rb") as jobs:
        while len(where := jobs.read(_WHERE.size)) == _WHERE.size:
            start, size = _WHERE.unpack(where)
            function, path, args = pickle.loads(_pread_all(shared, size, start))
            if function == "csv_piece":  # no answer: its text is kept for its table
                stream, columns, codes = args
                held = pieces.setdefault(stream, [])
                if not isinstance(held, str):
                    try:
                        held.append(output.csv_rows(columns, codes))
                    except Exception as err:  # noqa: BLE001 - fails its table, which the command then writes
                        pieces[stream] = f"{type(err).__name__}: {err}"
                del args, columns
                continue
            tick = time.perf_counter()
            try:
                writers[function](Path(path), *args)
                error = None
            except Exception as err:  # noqa: BLE001 - reported; the command writes the table itself
                error = f"{type(err).__name__}: {err}"
            del args  # (the table's arrays freed before the next one comes)
            data = pickle.dumps((path, error, time.perf_counter() - tick), protocol=pickle.HIGHEST_PROTOCOL)
            _write_all(replies_fd, _LENGTH.pack(len(data)) + data)


def _read(stream):
    """The next message of ``stream`` (a buffered binary file), or None at its end."""
    head = stream.read(_LENGTH.size)
    if len(head) < _LENGTH.size:
        return None
    (size,) = _LENGTH.unpack(head)
    data = stream.read(size)
    if len(data) < size:
        return None
    return pickle.loads(data)


def _pread_all(fd: int, size: int, offset: int) -> bytes:
    parts = []
    while size:
        part = os.pread(fd, size, offset)
        if not part:
            raise EOFError("the shared file ends before the table does")
        parts.append(part)
        size -= len(part)
        offset += len(part)
    return b"".join(parts)


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]
