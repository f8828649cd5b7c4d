"""The one ngspice of the process: finding libngspice, its session with fixed callbacks, transient control.

ngspice keeps global state, so a process holds exactly one session (``get_session()``);
it is cleared between runs, and parallel runs need separate processes. Only this
module talks to the shared library.
"""

from __future__ import annotations

import bisect
import contextlib
import locale
import math
import os
import re
import shutil
import sys
import tempfile
import threading
import time
import weakref
from pathlib import Path
from typing import Callable, Mapping

import numpy as np
from greenlet import getcurrent, greenlet

from . import compiled_callbacks
from ._callbacks_ffi import ffi as cffi_callbacks
from ._ngspice_ffi import ffi
from .arc import ARC_CELLS
from .channels import ConstantChannel, TableChannel
from .contact import LANDING_TOLERANCE
from .deck_guard import check_deck
from .errors import (
    ConvergenceError,
    LibraryNotFoundError,
    NetlistError,
    NgspiceError,
    SessionBusyError,
    SimulationAborted,
    SimulationTimeout,
    TimestepTooSmallError,
)

LIBRARY_ENV = "NGSPICE_LIBRARY_PATH"

# Where distributions put the library when ldconfig does not know it (e.g. containers
# without an ld.so.cache); checked after the ldconfig lookup.
_FALLBACK_PATHS = (
    "/usr/lib/x86_64-linux-gnu/libngspice.so.0",
    "/lib/x86_64-linux-gnu/libngspice.so.0",
    "/usr/lib/aarch64-linux-gnu/libngspice.so.0",
    "/usr/lib64/libngspice.so.0",
    "/usr/lib/libngspice.so.0",
    "/usr/local/lib/libngspice.so.0",
    "/usr/local/lib/libngspice.so",
    "/opt/homebrew/lib/libngspice.dylib",
    "/usr/local/lib/libngspice.dylib",
)

# ngSpice_Command keeps every command in ngspice's history; a stepping run
# sends three per macro step, so the history is released periodically (a NULL command).
_COMMANDS_BEFORE_HISTORY_RELEASE = 5000
# Rejected steps the compiled sync callback logs before Python moves them into its list
# (a full log: that redo goes to Python, which empties it)
REJECTIONS_LOGGED = 1024
_VALUES_ALL = ffi.typeof("pvecvaluesall")  # (SendData's point: a cast to a type object, not a name parsed)
_IDLE = ARC_CELLS.index("idle")  # (an ArcState's cells: 1.0 out over the last step and after it)


def find_library() -> str:
    """Path of the ngspice shared library.

    Order: the environment variable ``NGSPICE_LIBRARY_PATH``; ``libngspice.so.0`` (what
    Debian's ``libngspice0`` installs, without the -dev symlink ``libngspice.so``) or
    ``libngspice.so`` as the dynamic loader finds it (its own search: LD_LIBRARY_PATH,
    the ld.so cache, the system's folders), the file it mapped read back from
    /proc/self/maps; where that finds none (or there is no /proc), ``ldconfig -p`` for
    the same names; a few usual install paths.
    """
    override = os.environ.get(LIBRARY_ENV)
    if override:
        if not Path(override).is_file():
            raise LibraryNotFoundError(f"{LIBRARY_ENV}={override!r} does not name an existing file")
        return override
    for name in ("libngspice.so.0", "libngspice.so"):
        found = _loader_lookup(name)
        if found:
            return found
    for name in ("libngspice.so.0", "libngspice.so"):
        found = _ldconfig_lookup(name)
        if found:
            return found
    for candidate in _FALLBACK_PATHS:
        if Path(candidate).is_file():
            return candidate
    raise LibraryNotFoundError(
        "ngspice shared library not found: install it (Debian/Ubuntu: apt-get install libngspice0) "
        f"or set {LIBRARY_ENV} to the path of libngspice.so.0"
    )


_LOADED_BY_NAME: list = []  # the library the loader opened by its name (held: the session opens the same)


def _loader_lookup(name: str) -> str | None:
    """The file the dynamic loader opens for the library ``name``, or None (not found, or
    no /proc/self/maps to say which file it is). Cheaper than running ``ldconfig -p``
    (its fork and exec, ~4-10 ms of a coupled run's start, and subprocess's import)."""
    before = _mapped_ngspice()
    if before is None:
        return None
    try:
        library = ffi.dlopen(name)
    except OSError:
        return None
    after = _mapped_ngspice()
    if not after:
        return None
    new = after - before or after
    if len(new) != 1:  # (two ngspice libraries in one process: which is which is not known here)
        return None
    _LOADED_BY_NAME.append(library)
    path = next(iter(new))
    return path if Path(path).is_file() else None


def _mapped_ngspice() -> set[str] | None:
    """The files named libngspice* mapped into this process (/proc/self/maps), None without it."""
    try:
        with open("/proc/self/maps", encoding="utf-8", errors="replace") as maps:
            found = set()
            for line in maps:
                fields = line.rstrip("\n").split(maxsplit=5)
                if len(fields) == 6 and os.path.basename(fields[5]).startswith("libngspice"):
                    found.add(fields[5])
            return found
    except OSError:
        return None


def _ldconfig_lookup(name: str) -> str | None:
    import subprocess  # (only here: a run finds its library through the loader)

    exe = shutil.which("ldconfig") or next(
        (p for p in ("/sbin/ldconfig", "/usr/sbin/ldconfig") if Path(p).is_file()), None
    )
    if exe is None:
        return None
    try:
        listing = subprocess.run([exe, "-p"], capture_output=True, text=True, timeout=10).stdout
    except (OSError, subprocess.SubprocessError):
        return None
    for line in listing.splitlines():
        entry = line.strip()
        if entry.startswith(name + " ") and "=>" in entry:
            path = entry.rsplit("=>", 1)[1].strip()
            if Path(path).is_file():
                return path
    return None


#: Environment variables pointed at the empty start-up folder while ngspice initializes
#: (a build that looks for ~/.spiceinit through $HOME then finds the empty one).
_START_ENV = ("HOME", "USERPROFILE")


@contextlib.contextmanager
def isolated_start():
    """Working directory and home of the process while ngspice initializes: a fresh, private,
    empty folder holding an empty ``.spiceinit``.

    ngspice's shared library, in ``ngSpice_Init``, sources ``./.spiceinit`` if it exists
    and otherwise ``<home>/.spiceinit`` (home from the password database, not $HOME, in
    ngspice 39), and those files may hold any command (``shell ...``). With the empty
    ``.spiceinit`` in the working directory ngspice reads that one and never looks in the
    real working directory or the home folder; $HOME (and %USERPROFILE%) point at the
    same folder for builds that use them. The system's ``spinit`` (from the ngspice
    installation, SPICE_LIB_DIR / SPICE_SCRIPTS) is still read: it belongs to the
    installation, not to a shared folder; a relative SPICE_SCRIPTS resolves in the empty
    folder. The working directory and environment are restored afterwards.
    """
    try:
        previous_cwd = os.getcwd()
    except OSError:  # the working directory was deleted
        previous_cwd = None
    saved = {name: os.environ.get(name) for name in _START_ENV}
    with tempfile.TemporaryDirectory(prefix="switchsim-ngspice-") as folder:
        Path(folder, ".spiceinit").write_text("* switchsim: empty ngspice start-up file\n")
        try:
            for name in _START_ENV:
                os.environ[name] = folder
            os.chdir(folder)
            yield folder
        finally:
            os.chdir(previous_cwd if previous_cwd is not None else tempfile.gettempdir())
            for name, value in saved.items():
                if value is None:
                    os.environ.pop(name, None)
                else:
                    os.environ[name] = value


# Lines ngspice prints on success (some on stderr), or that are
# progress chatter; never part of an error message.
_CHATTER = re.compile(
    r"condition met|pause requested|simulation interrupted|^Note:|Trying gmin|Further gmin increment"
    r"|One successful|Supplies reduced|^Doing analysis|^Reference value|No compatibility mode"
    r"|can't find the initialization file|^Circuit:|^No\. of Data Rows"
)
_ERROR_LINE = re.compile(r"error|abort|fail|too small|trouble with|singular|iteration limit|can't find", re.I)


def stop_margin(target: float) -> float:
    """s: how far before a pause's target (s) a point counts as reaching it: a step aimed at
    the target can end a rounding short of it, and a step from there would be a sliver."""
    return max(1e-12 * abs(target), 1e-300)


class NgspiceSession:
    """libngspice's shared-library session (circuit/ngspice_api.py declares the calls).

    - stdout/stderr lines are captured per command instead of being printed or logged
      (ngspice prints "condition met", "Note: ..." and warnings on success);
    - the background-thread and status callbacks return an int, as ngspice expects;
    - the EXTERNAL voltage source gets its value from a function of time set with
      ``set_channels`` (by source name); the GetSyncData callback (installed once: ngspice cannot
      uninstall it) shortens steps to land exactly on the next macro time, and aborts
      the run on a callback failure or a wall-clock timeout;
    - the EXTERNAL voltage sources' callback is compiled C (circuit/callbacks.c, built at
      first use by circuit/compiled_callbacks.py) when its library is there: it answers a
      repeated time, a ConstantChannel and a TableChannel without Python and calls the
      other channels' Python functions through one trampoline (``_on_c_evaluate``); without
      the library (a failed build, or SWITCHSIM_PYTHON_CALLBACKS=1) the Python callback
      ``_on_vsrc`` does it all. The route is chosen at each ``load``; both give the same bits;
    - on both routes an arc's gap channel is held (its last value, no call) while the arc
      cannot read it: idle (out over the last step and after it), its contact's
      conductance the constant 0 for the macro step, no breakdown voltage (``_gate_gaps``);
    - the EXTERNAL current sources (the arcs' states, arc.py) read their ArcState's
      ``value``: in C from its ``cell`` (the compiled callback), else ``_on_isrc``;
    - GetSyncData is compiled too (``sw_sync``, ``_on_sync``'s rules), calling ``_on_sync``
      (through ``_on_sync_from_c``) for a failure, a deadline passed, a full log of
      rejected steps and, with arcs, a point after an accepted one that is not the arcs'
      plain case (``ArcState.cells``); the fields it reads are mirrored into its state
      when Python changes them (``_mirror_steps``), the landings kept one list, the
      rejections moved into ``rejections`` before Python reads or adds to it;
    - a transient is one ``run`` in its own greenlet: ``transient`` switches into it, and the
      SendData callback (after each accepted point is stored) switches back at the pause's
      target, with ngspice suspended inside its time loop (no command per pause). SendData
      is given once, at ngspice's init: the compiled ``sw_data`` when the library is there
      then, which calls ``_on_data`` only for the point that pauses (every point on the
      Python route).

    The library is reached through cffi's out-of-line ABI module (no C parser at a
    start), not through PySpice's NgSpiceShared, which parses its header at each start;
    PySpice builds the netlists. One ngspice per process: a PySpice simulator
    (``circuit.simulator()``) would load the same library a second time and replace these
    callbacks, so a process that runs switchsim's circuits does not use PySpice's own.

    Use ``get_session()``; do not instantiate directly.
    """

    def __init__(self, library_path: str):
        self._lines: list[str] = []
        self._exit_status: tuple[int, bool, bool] | None = None
        # The input channels: each EXTERNAL voltage source of the loaded circuit gets its
        # value from a Python function of time; ngspice passes the instance's own name
        # string, so each source is found by its name once and by the pointer after that
        # (the char * cdata itself as the key: cffi hashes and compares a pointer by its
        # address, a third of the cost of int(ffi.cast(...)) at ~75k callbacks a run).
        self._channels: dict[str, Channel] = {}
        self._by_pointer: dict[object, Channel] = {}
        self._target = math.inf
        self._max_step = math.inf  # s: the step bound of the current pause (transient's max_step)
        self._deadline = math.inf
        # The compiled callbacks (circuit/callbacks.c) when the loaded circuit uses them
        # (compiled_callbacks.load(), chosen at each load), their state and channel cells
        self._compiled = None
        self._clib = None
        self._cstate = None
        self._c_cells = None
        self._c_channels: list[CompiledChannel] = []  # by their index in the cells
        self._c_arc_cells: list = []  # the arcs' value cells the compiled isrc callback reads
        self._c_landings_seen = 0  # the compiled landings' head when _landings last followed it
        self._failure_value: BaseException | None = None
        self._failure = None
        # The loaded circuit's transient runs in its own greenlet ("run", one ngspice
        # command for the whole analysis); at a pause it switches back to the caller of
        # transient() from ngspice's per-point data callback and is resumed from there.
        self._run: greenlet | None = None
        self._caller: greenlet | None = None
        self._pause_value = math.inf  # (``_pause_at``)
        self._accepting = -math.inf  # s: time of the point ngspice is accepting (sync callback, loc 1)
        # while ngspice is paused inside SendData: its vecvaluesall (the pausing point's value of
        # every vector), and which of them each tuple of names asks for (one run's vectors)
        self._paused = None
        self._point_plans: dict[tuple[str, ...], list[int] | None] = {}
        self._run_thread: threading.Thread | None = None  # the thread whose greenlet self._run is
        self._landings: list[float] = []  # s: the breakpoints set for the current pause, ascending
        self._arcs: dict[str, object] = {}  # the ArcState of each arc, by its EXTERNAL current source
        self._arc_by_pointer: dict[object, object] = {}
        self._arc_from = math.nan  # accepted time the arc's step bounds below apply from
        self._arc_step = math.inf
        self._arc_land = math.inf
        self._rejections: list[tuple[float, bool]] = []  # (``rejections``)
        # the compiled sync callback's arc rules (sw_arc_rule[]) and its rejections' log
        self._c_rules = None
        self._c_rules_size = 0
        self._c_rule_cells: list = []
        self._c_gate_cells: list = []  # the arcs' cells the gap channels' C cells point to (_gate_gaps)
        self._arcs_stale = True  # the arcs or the channels changed since the gates and rules were written
        self._c_rejections = None
        self._commands_sent = 0
        self._encoded: dict[str, bytes] = {}
        self.owner: weakref.ref | None = None
        self.lock = threading.Lock()
        # ngspice reads and prints numbers with the C library's locale: a decimal comma
        # (LC_NUMERIC of de_DE, say) would misread every netlist value
        locale.setlocale(locale.LC_NUMERIC, "C")
        self._ngspice_shared = ffi.dlopen(library_path)
        self._self_c = ffi.new_handle(self)
        # the callbacks live as long as the session (ngspice keeps their addresses);
        # onerror: an exception escaping a callback (e.g. KeyboardInterrupt) is kept and
        # re-raised after ngspice stops, instead of being printed and lost by cffi.
        self._send_char_c = ffi.callback("int(char *, int, void *)", self._send_char)
        self._send_stat_c = ffi.callback("int(char *, int, void *)", self._send_stat)
        self._exit_c = ffi.callback("int(int, bool, bool, int, void *)", self._exit)
        self._background_c = ffi.callback("int(bool, int, void *)", self._background_thread_running)
        self._vsrc_c = ffi.callback(
            "int(double *, double, char *, int, void *)", self._on_vsrc, onerror=self._on_callback_error
        )
        self._isrc_c = ffi.callback(
            "int(double *, double, char *, int, void *)", self._on_isrc, onerror=self._on_callback_error
        )
        self._sync_c = ffi.callback(
            "int(double, double *, double, int, int, int, void *)", self._on_sync, onerror=self._on_callback_error
        )
        self._data_c = ffi.callback("int(void *, int, int, void *)", self._on_data, onerror=self._on_callback_error)
        self._init_data_c = ffi.callback("int(void *, int, void *)", self._on_init_data)
        self._ident_c = ffi.new("int *", 0)
        # SendData is given once, here: the compiled one (callbacks.c's sw_data) when the
        # library is there, which calls _on_data only at a pause (or on the Python route)
        data = ffi.cast("void *", self._data_c)
        self._data_library = compiled_callbacks.load()
        if self._data_library is not None:
            self._c_data = cffi_callbacks.callback("sw_data_fn", self._on_data, onerror=self._on_callback_error)
            self._data_library.sw_install_data(self._c_data)
            data = ffi.cast("void *", int(cffi_callbacks.cast("uintptr_t", self._data_library.sw_data)))
        with isolated_start():
            rc = self._ngspice_shared.ngSpice_Init(
                self._send_char_c, self._send_stat_c, self._exit_c, data,
                ffi.cast("void *", self._init_data_c), self._background_c, self._self_c)
        if rc:
            raise NgspiceError(f"ngSpice_Init returned {rc}", _message(self._lines))
        rc = self._ngspice_shared.ngSpice_Init_Sync(
            self._vsrc_c, self._isrc_c, self._sync_c, self._ident_c, self._self_c
        )
        if rc:
            raise NgspiceError(f"ngSpice_Init_Sync returned {rc}")
        self.library = library_path
        # no pager: a long listing would wait for a key press that never comes
        self.command("set nomoremode")

    @property
    def _pause_at(self) -> float:
        """s: the accepted point at or after this time pauses the run (the compiled SendData
        sees it too)."""
        return self._pause_value

    @_pause_at.setter
    def _pause_at(self, t: float) -> None:
        self._pause_value = t
        if self._cstate is not None:
            self._cstate.pause_at = t

    @property
    def _failure(self) -> BaseException | None:
        """The exception a callback met (re-raised after ngspice stopped), or None; the
        compiled callbacks see whether there is one."""
        return self._failure_value

    @_failure.setter
    def _failure(self, failure: BaseException | None) -> None:
        self._failure_value = failure
        if self._cstate is not None:
            self._cstate.failed = failure is not None

    # -- ngspice's output and status callbacks --

    def _send_char(self, message_c, ngspice_id, user_data):
        # A bound method, so the instance comes with it instead of through the handle (4
        # lines a macro step). Lines arrive as "stdout ..." / "stderr ..."; kept whole,
        # parsed only on failure.
        self._lines.append(ffi.string(message_c).decode("utf-8", "replace").rstrip())
        return 0

    @staticmethod
    def _send_stat(message_c, ngspice_id, user_data):
        return 0

    @staticmethod
    def _background_thread_running(is_running, ngspice_id, user_data):
        return 0

    @staticmethod
    def _exit(exit_status, immediate_unloading, quit_exit, ngspice_id, user_data):
        self = ffi.from_handle(user_data)
        self._exit_status = (int(exit_status), bool(immediate_unloading), bool(quit_exit))
        return int(exit_status)

    # -- our callbacks --

    @staticmethod
    def _on_init_data(info, ngspice_id, user_data):
        return 0

    def _on_data(self, values, count, ngspice_id, user_data):
        # Each accepted point, after ngspice stored it: the pause (back to transient()'s caller).
        # (the properties' fields read directly: on the Python route this runs at every point)
        accepting = self._accepting if self._compiled is None else self._cstate.accepting
        if accepting >= self._pause_value and self._failure_value is None:
            self._pause_at = math.inf
            # (valid while ngspice waits in this call: ``last_values`` reads the point from it)
            self._paused = values
            try:
                self._caller.switch()
            finally:
                self._paused = None
        return 0

    def _on_vsrc(self, out, t, name, ident, user):
        # Called at every Newton iteration and on rejected trial points: the value must
        # depend on t only. Repeated calls at the same t skip the Python function, and so
        # does an arc's gap while the arc cannot read it (_gate_gaps; callbacks.c's sw_held).
        channel = self._by_pointer.get(name)
        if channel is None:
            channel = self._learn(name)
        if t == channel.last_t or self._failure is not None:
            out[0] = channel.last_value
            return 0
        gate = channel.gate
        if gate is not None and gate[0][_IDLE] != 0.0 and gate[1].zero:  # (not counted: no evaluation)
            channel.last_t = t
            out[0] = channel.last_value
            return 0
        channel.calls += 1
        value = self._value(channel, t)
        if value is None:
            out[0] = channel.last_value
            return 0
        channel.last_t = t
        channel.last_value = value
        out[0] = value
        return 0

    def _value(self, channel: "Channel", t: float) -> float | None:
        """The value of ``channel``'s function at t (s), checked finite and >= 0; None with
        the failure kept (re-raised after ngspice has stopped) otherwise. Both source
        callbacks' route: the Python one and the compiled one's trampoline."""
        try:
            value = float(channel.function(t))
        except BaseException as exc:  # re-raised after ngspice has stopped
            self._failure = exc
            return None
        if not (0.0 <= value < math.inf):
            self._failure = channel.error(t, value)
            return None
        return value

    # -- the compiled callbacks (circuit/callbacks.c) --

    def _choose_callbacks(self) -> None:
        """The source callbacks of the next circuit: the compiled ones when their library
        is there (built at first use), else (a failed build, or FORCE_PYTHON in the
        environment) the Python ones. Chosen at each load, with no circuit loaded."""
        library = compiled_callbacks.load()
        if library is self._compiled:
            return
        if self._cstate is not None:  # (the compiled SendData calls Python at every point then)
            self._cstate.python_data = library is None
        vsrc, isrc, sync = self._vsrc_c, self._isrc_c, self._sync_c
        if library is not None:
            if self._cstate is None or library is not self._clib:
                self._start_compiled(library)
            vsrc = ffi.cast("GetVSRCData *", int(cffi_callbacks.cast("uintptr_t", library.sw_vsrc)))
            isrc = ffi.cast("GetISRCData *", int(cffi_callbacks.cast("uintptr_t", library.sw_isrc)))
            sync = ffi.cast("GetSyncData *", int(cffi_callbacks.cast("uintptr_t", library.sw_sync)))
        # (ngspice keeps the last callbacks given; a NULL user pointer leaves its own unchanged)
        rc = self._ngspice_shared.ngSpice_Init_Sync(vsrc, isrc, sync, self._ident_c, ffi.NULL)
        if rc:
            raise NgspiceError(f"ngSpice_Init_Sync returned {rc}")
        self._compiled = library

    def _start_compiled(self, library) -> None:
        """The compiled callbacks' state: Python's trampolines and the channel cells."""
        if self._clib is not None and self._clib is not library:
            # (another library's: its SendData, if ngspice has it, must not read the state freed below)
            self._clib.sw_install(cffi_callbacks.NULL)
        state = cffi_callbacks.new("sw_state *")
        # kept as long as the session (the library holds their addresses)
        self._c_evaluate = cffi_callbacks.callback("sw_evaluate_fn", self._on_c_evaluate, error=1,
                                                   onerror=self._on_callback_error)
        self._c_learn = cffi_callbacks.callback("sw_learn_fn", self._on_c_learn, error=-1,
                                                onerror=self._on_callback_error)
        self._c_learn_arc = cffi_callbacks.callback("sw_learn_fn", self._on_c_learn_arc, error=0,
                                                    onerror=self._on_callback_error)
        self._c_sync = cffi_callbacks.callback("sw_sync_fn", self._on_sync_from_c, onerror=self._on_callback_error)
        state.evaluate = self._c_evaluate
        state.learn = self._c_learn
        state.learn_arc = self._c_learn_arc
        state.sync_python = self._c_sync
        state.landing_tolerance = LANDING_TOLERANCE
        self._c_landings = cffi_callbacks.new("double[]", 16)
        state.landings, state.landings_size = self._c_landings, 16
        self._c_arcs = cffi_callbacks.new("sw_arc[]", 4)
        state.arcs, state.arcs_size = self._c_arcs, 4
        self._c_cells = cffi_callbacks.new("sw_channel[]", 8)
        state.channels = self._c_cells
        self._c_rejections = cffi_callbacks.new("double[]", 2 * REJECTIONS_LOGGED)
        state.rejections, state.rejections_size = self._c_rejections, REJECTIONS_LOGGED
        state.failed = self._failure is not None
        state.pause_at = self._pause_at
        state.python_data = False
        library.sw_install(state)
        self._cstate, self._clib = state, library
        self._c_rules, self._c_rules_size, self._arcs_stale = None, 0, True
        state.accepting = self._accepting
        self._set_arc_bounds(self._arc_from, self._arc_step, self._arc_land)
        self._mirror_steps()

    def _mirror_steps(self) -> None:
        """The step control's fields that only Python writes into the compiled sync callback's
        state (before ngspice steps again after Python changed any: a pause's start, the
        arcs, a breakpoint, a clear; a pause's end leaves them, as ngspice takes no step then);
        the accepting time and the arcs' step bounds, which both write, are copied where
        Python sets them (``_set_arc_bounds``, ``_on_sync_from_c``). The arcs' ties to the
        input channels are written afresh after either changed, on both routes."""
        if self._arcs_stale:
            self._gate_gaps()
            if self._cstate is not None:
                self._c_arc_rules()
            self._arcs_stale = False
        state = self._cstate
        if state is None:
            return
        self._landings_from_c()
        state.target, state.max_step, state.deadline = self._target, self._max_step, self._deadline
        landings = self._landings
        if landings:  # (most pauses have none)
            if len(landings) > state.landings_size:
                self._c_landings = cffi_callbacks.new("double[]", 2 * len(landings))
                state.landings, state.landings_size = self._c_landings, 2 * len(landings)
            for k, t in enumerate(landings):
                state.landings[k] = t
        state.landings_head, state.landings_used = 0, len(landings)
        self._c_landings_seen = 0

    def _landings_from_c(self) -> None:
        """The landings the compiled sync callback passed, dropped from ``_landings`` too: one
        list, popped in order by whichever callback answers (as the Python callback alone would)."""
        state = self._cstate
        if state is not None and self._compiled is not None:
            passed = state.landings_head - self._c_landings_seen
            if passed:
                del self._landings[:passed]
                self._c_landings_seen = state.landings_head

    def _rejections_from_c(self) -> None:
        """The rejected steps the compiled sync callback logged, appended to ``_rejections``
        (in order: Python logs only after this)."""
        state = self._cstate
        if state is not None and state.rejections_used:
            log = self._c_rejections
            self._rejections.extend((log[2 * k], log[2 * k + 1] != 0.0) for k in range(state.rejections_used))
            state.rejections_used = 0

    @property
    def rejections(self) -> list[tuple[float, bool]]:
        """Every step ngspice rejected since the circuit was loaded: (the accepted time it
        retries from, s; True if Newton failed, else its truncation-error test), from the
        sync callback's redo flag. ngspice cuts a step that failed to converge to exactly
        1/8 (dctran.c); a truncation-error rejection proposes its own estimate instead."""
        self._rejections_from_c()
        return self._rejections

    def _set_arc_bounds(self, start: float, step: float, land: float) -> None:
        """The arcs' step bounds (from the accepted time ``start``: the next step at most
        ``step``, landing on ``land``), in the compiled state too."""
        self._arc_from, self._arc_step, self._arc_land = start, step, land
        if self._cstate is not None:
            self._cstate.arc_from, self._cstate.arc_step, self._cstate.arc_land = start, step, land

    def _c_arc_rules(self) -> None:
        """The compiled sync callback's view of the arcs: each ArcState's cells and the
        input channel whose last value is its contact's conductance (-1: none, Python reads
        it from ngspice)."""
        state = self._cstate
        arcs = list(self._arcs.values())
        if len(arcs) > self._c_rules_size:
            self._c_rules_size = 2 * len(arcs)
            self._c_rules = cffi_callbacks.new("sw_arc_rule[]", self._c_rules_size)
            state.arc_rules = self._c_rules
        self._c_rule_cells = []
        for k, arc in enumerate(arcs):
            cells = cffi_callbacks.from_buffer("double[]", arc.cells)
            self._c_rule_cells.append(cells)  # (held while C reads through it)
            channel = self._channels.get(arc.conductance_source.lower()) if arc.conductance_source else None
            self._c_rules[k].cells = cells
            self._c_rules[k].conductance = channel.index if isinstance(channel, CompiledChannel) else -1
        state.arc_rules_used = len(arcs)
        state.has_arcs = bool(arcs)

    def _gate_gaps(self) -> None:
        """Each arc's gap channel tied to the arc's state and its contact's conductance
        channel (``Channel.gate``; in C, the channel cell's ``gate_arc`` and
        ``gate_conductance``): both source callbacks answer the gap with its last value,
        without evaluating it, at a new time when the arc is idle (``ArcState.idle``: out
        over the step to its last accepted point and after it) and the conductance channel
        is the constant 0 for the macro step. The arc then reads the gap nowhere: V(arc_on)
        is 0 in the point Newton starts from and in every iterate, so its path's current
        and derivatives are the same doubles whatever the gap; it cannot arm while its
        contact stays open; and an arc without a breakdown voltage reads the gap at
        accepted points only to test one (an arc with one is never held). So ngspice's
        solution is the same bits; only the gap node holds its value instead of following
        the contact. (Out only from the last point on is not enough: Newton starts from
        that point's solution, arc lit, and the linearised path reads the new gap.) The
        default relay's gap was called from Python at ~4 900 new times a run, ~1 050
        with this."""
        self._c_gate_cells = []
        for channel in self._channels.values():
            self._set_gate(channel, None)
        for arc in self._arcs.values():
            if arc.arc.breakdown_voltage is not None or not arc.gap_source or not arc.conductance_source:
                continue
            gap = self._channels.get(arc.gap_source.lower())
            conductance = self._channels.get(arc.conductance_source.lower())
            if gap is not None and conductance is not None:
                self._set_gate(gap, (arc.cells, conductance))

    def _set_gate(self, channel: "Channel", gate) -> None:
        """``channel.gate`` (None, or an arc's cells and its conductance channel), in its C
        cell too with the compiled callbacks."""
        channel.gate = gate
        if isinstance(channel, CompiledChannel):
            cell = channel.cell
            if gate is None or not isinstance(gate[1], CompiledChannel):
                cell.gate_arc, cell.gate_conductance = cffi_callbacks.NULL, -1
            else:
                cells = cffi_callbacks.from_buffer("double[]", gate[0])
                self._c_gate_cells.append(cells)  # (held while C reads through it)
                cell.gate_arc, cell.gate_conductance = cells, gate[1].index

    def _on_sync_from_c(self, ckttime, pdelta, olddelta, redostep, ident, loc, user):
        # The compiled sync callback's calls that need Python (a failure, a deadline passed,
        # a full rejections' buffer, an arc's point that is not plain): Python's own rules on
        # the compiled state's arc bounds and rejections, then what they changed back into it
        # (the accepting time, the arcs' bounds).
        self._landings_from_c()
        self._rejections_from_c()
        state = self._cstate
        self._arc_from, self._arc_step, self._arc_land = state.arc_from, state.arc_step, state.arc_land
        result = self._on_sync(ckttime, pdelta, olddelta, redostep, ident, loc, user)
        state.accepting = self._accepting
        state.arc_from, state.arc_step, state.arc_land = self._arc_from, self._arc_step, self._arc_land
        # (Python pops only from the front of the same list)
        state.landings_head = self._c_landings_seen = state.landings_used - len(self._landings)
        return result

    def _new_channel(self, name: str, function, make_error=None) -> "Channel":
        """A channel of the loaded circuit: a C cell of its own with the compiled callbacks."""
        if self._compiled is None:
            return Channel(name, function, make_error)
        index = len(self._c_channels)
        if index == len(self._c_cells):  # more room: the cells move (C finds them by index)
            cells = cffi_callbacks.new("sw_channel[]", 2 * index)
            cffi_callbacks.memmove(cells, self._c_cells, index * cffi_callbacks.sizeof("sw_channel"))
            for k, channel in enumerate(self._c_channels):
                channel.cell = cells + k
            self._c_cells = self._cstate.channels = cells
        cell = self._c_cells + index
        cell.name = cffi_callbacks.NULL
        cell.kind = compiled_callbacks.PYTHON
        cell.gate_arc, cell.gate_conductance = cffi_callbacks.NULL, -1  # (a cell of an earlier circuit's)
        channel = CompiledChannel(name, function, make_error, cell, index)
        self._c_channels.append(channel)
        self._cstate.channels_used = index + 1
        return channel

    def _set_function(self, channel: "Channel", function) -> None:
        """The function behind ``channel`` for the next macro step, its last value forgotten:
        evaluated in C if it is a ConstantChannel or a TableChannel and the compiled callbacks
        are in use."""
        channel.zero = isinstance(function, ConstantChannel) and function.value == 0.0
        if self._compiled is None:
            channel.function = function.function if isinstance(function, (ConstantChannel, TableChannel)) else function
            channel.last_t = math.nan
            return
        cell = channel.cell
        cell.last_t = math.nan  # (CompiledChannel.last_t's field, without the property's call)
        if isinstance(function, ConstantChannel):
            cell.kind = compiled_callbacks.CONSTANT
            cell.constant = function.value
            channel.function, channel.keep = function.function, None
        elif isinstance(function, TableChannel):
            compiled_callbacks.fill_table(cell, function)
            channel.function, channel.keep = function.function, function  # (its arrays live while C reads them)
        else:
            cell.kind = compiled_callbacks.PYTHON
            channel.function, channel.keep = function, None

    def _forget_c_arcs(self) -> None:
        """The compiled isrc callback learns the arcs afresh (a new circuit or new arcs)."""
        if self._cstate is not None:
            self._cstate.arcs_used = 0
        self._c_arc_cells = []

    def _on_c_evaluate(self, index, t, out):
        # The compiled vsrc callback's trampoline: a Python channel's new time (the repeats
        # and the checks before it are in C), or a C channel's value that is not finite and
        # >= 0 (its Python function gives the same value and the error). 1: failed.
        value = self._value(self._c_channels[index], t)
        if value is None:
            return 1
        out[0] = value
        return 0

    def _on_c_learn(self, name):
        # The compiled vsrc callback meets a source for the first time: its channel's index.
        channel = self._channel_named(cffi_callbacks.string(name).decode("ascii", "replace").lower())
        channel.cell.name = name
        return channel.index

    def _on_c_learn_arc(self, name):
        # The compiled isrc callback meets a source for the first time: 1 and its arc's value
        # cell bound to the name pointer, or 0 (not an arc's: 0 A, asked again next time).
        arc = self._arcs.get(cffi_callbacks.string(name).decode("ascii", "replace").lower())
        if arc is None:
            return 0
        state = self._cstate
        used = state.arcs_used
        if used == state.arcs_size:  # more room: the slots move (C scans them afresh)
            arcs = cffi_callbacks.new("sw_arc[]", 2 * used)
            cffi_callbacks.memmove(arcs, self._c_arcs, used * cffi_callbacks.sizeof("sw_arc"))
            self._c_arcs, state.arcs, state.arcs_size = arcs, arcs, 2 * used
        cell = cffi_callbacks.from_buffer("double[]", arc.cell)
        self._c_arc_cells.append(cell)  # (held while C reads through it)
        state.arcs[used].name = name
        state.arcs[used].value = cell
        state.arcs_used = used + 1
        return 1

    def _learn(self, name) -> "Channel":
        """The channel of an EXTERNAL voltage source seen for the first time (by its name)."""
        channel = self._by_pointer[name] = self._channel_named(ffi.string(name).decode("ascii", "replace").lower())
        return channel

    def _channel_named(self, text: str) -> "Channel":
        """The input channel of the EXTERNAL source named ``text`` (lower case), for both
        source callbacks' routes; for a source that has none (the deck admits none), a
        channel of 0 and an error, reported after the run."""
        channel = self._channels.get(text)
        if channel is None:
            channel = self._new_channel(text, _zero)
            if self._failure is None:
                self._failure = NgspiceError(f"EXTERNAL source {text!r} has no input channel")
        return channel

    def _on_callback_error(self, exc_type, exc_value, traceback):
        if self._failure is None:
            self._failure = exc_value if exc_value is not None else exc_type()
        return None

    def _on_isrc(self, out, t, name, ident, user):
        # The EXTERNAL current sources are the arcs' states (arc.py): constant over a
        # step, ArcState changes them only between accepted points.
        arc = self._arc_by_pointer.get(name)
        if arc is None:
            arc = self._arcs.get(ffi.string(name).decode("ascii", "replace").lower())
            if arc is None:
                out[0] = 0.0
                return 0
            self._arc_by_pointer[name] = arc
        out[0] = arc.value
        return 0

    def _on_sync(self, ckttime, pdelta, olddelta, redostep, ident, loc, user):
        if redostep:
            self._rejections.append((ckttime, pdelta[0] == 0.125 * olddelta))
        elif loc:
            self._accepting = ckttime
        if self._failure is None and time.monotonic() > self._deadline:
            self._failure = SimulationTimeout("wall-clock limit reached (SimulationOptions.wall_timeout)")
        if self._failure is not None:
            # A zero step on a redo makes ngspice abort at once with 'Timestep too
            # small': the only way to stop a synchronous run from a callback.
            pdelta[0] = 0.0
            return 1
        target = self._target
        if pdelta[0] > self._max_step:
            pdelta[0] = self._max_step
        if self._arcs:
            if loc == 0:
                # loc 0: after a point was accepted (and stored), before the next step.
                # A contact's source was last evaluated at that point (if it is EXTERNAL).
                step = land = math.inf
                for arc in self._arcs.values():
                    channel = self._channels.get(arc.conductance_source.lower()) if arc.conductance_source else None
                    known = channel.last_value if channel is not None and channel.last_t == ckttime else None
                    arc_step, arc_land = arc.accepted(ckttime, known, self._read_last)
                    step, land = min(step, arc_step), min(land, arc_land)
                self._arc_step, self._arc_land = step, land
                self._arc_from = ckttime
            if ckttime == self._arc_from:  # the step (or its retry) from that accepted point
                if pdelta[0] > self._arc_step:
                    pdelta[0] = self._arc_step
                if self._arc_land < target:
                    target = self._arc_land
        landings = self._landings
        while landings and landings[0] <= ckttime + stop_margin(landings[0]):
            landings.pop(0)
        if landings and landings[0] < target:
            # ngspice cuts its step at our next breakpoint (a make/break): that is where
            # this step lands, and the rule below aims at it instead of the target beyond
            target = landings[0]
        remaining = target - ckttime
        # Within transient()'s stop margin of the target the pause is reached: a step aimed
        # at the target from there would be a sliver (an arc's landing an ulp before a
        # macro step's end took a 1e-19 s step, and the next rejection, below ngspice's
        # smallest step, aborted the run with "timestep too small").
        if remaining > stop_margin(target):
            delta = pdelta[0]
            if delta >= remaining * (1.0 - LANDING_TOLERANCE):  # equal up to rounding: land, no extra point
                pdelta[0] = remaining
            elif remaining < 2.0 * delta:
                # Two equal steps instead of a full one and a sliver: ngspice grows its
                # step by at most 2x per point, so a sliver before the target would cost
                # several points after it. Shortening is always safe; lengthening could
                # jump over a breakpoint we do not know of.
                pdelta[0] = 0.5 * remaining
        return 0

    def _read_last(self, names):
        return self.last_values(names)[1]

    # -- commands --

    def _check_alive(self) -> None:
        if self._exit_status is not None:
            status, immediate, quit_ = self._exit_status
            raise NgspiceError(
                f"ngspice has exited (status {status}, unload={immediate}, quit={quit_}); "
                "it cannot be restarted inside this process"
            )

    def command(self, text: str) -> list[str]:
        """Run one ngspice command; returns the lines it printed ("stdout ..."/"stderr ...").
        SessionBusyError while a transient is paused (an open Stepper's run): ngspice is
        inside it, and a command would run inside its time loop."""
        self._check_alive()
        run = self._run
        if run is not None and not run.dead and getcurrent() is not run:
            raise SessionBusyError(f"ngspice is paused inside a transient (an open Stepper's run): close it "
                                   f"before the command {text!r}")
        if self._commands_sent >= _COMMANDS_BEFORE_HISTORY_RELEASE:
            self._ngspice_shared.ngSpice_Command(ffi.NULL)
            self._commands_sent = 0
        self._commands_sent += 1
        self._lines = []
        rc = self._ngspice_shared.ngSpice_Command(text.encode("ascii"))
        lines = self._lines
        self._lines = []
        if rc:
            raise NgspiceError(f"ngspice rejected the command {text!r} (return code {rc})", "\n".join(lines))
        return lines

    def clear(self) -> None:
        """Forget every plot and circuit of earlier runs (a run left paused is stopped first)."""
        self._abandon_run()
        for cmd in ("destroy all", "remcirc"):
            self.command(cmd)
        self._reset_callback_state()

    def _reset_callback_state(self) -> None:
        self._rejections = []
        if self._cstate is not None:
            self._cstate.rejections_used = 0
        self._channels = {}
        self._by_pointer = {}
        self._c_channels = []
        if self._cstate is not None:
            self._cstate.channels_used = 0
        self._forget_c_arcs()
        self._mirror_steps()
        self._target = math.inf
        self._deadline = math.inf
        self._failure = None
        self._arcs = {}
        self._arc_by_pointer = {}
        self._set_arc_bounds(math.nan, math.inf, math.inf)
        self._arcs_stale = True

    def load(self, lines: list[str]) -> None:
        """Load a deck (title line first, ``.end`` last); raises NetlistError with ngspice's message.

        The deck passes ``deck_guard.check_deck`` first (its title is replaced by
        switchsim's own): no line that could run an ngspice command or read a file gets
        through, whoever built the deck (NetlistInputError)."""
        lines = check_deck(list(lines))
        if _pyspice_holds_ngspice():
            raise SessionBusyError(
                "PySpice's own simulator has started ngspice in this process and replaced switchsim's "
                "callbacks (one ngspice per process): run PySpice's simulations in a separate process")
        self.clear()
        self._check_alive()
        self._choose_callbacks()
        keep = [ffi.new("char[]", line.encode("utf-8")) for line in lines] + [ffi.NULL]
        self._lines = []
        rc = self._ngspice_shared.ngSpice_Circ(ffi.new("char *[]", keep))
        printed = self._lines
        self._lines = []
        errors = [line for line in printed if re.search(r"error", line, re.I)]
        if rc or errors:
            raise NetlistError("ngspice could not parse the netlist", _message(printed))

    def set_channels(self, functions: Mapping[str, Callable[[float], float]],
                     errors: Mapping[str, Callable[[float, float], Exception]] | None = None) -> None:
        """The function of time (s) behind each EXTERNAL voltage source of the loaded circuit,
        by source name; ``errors`` (by source name) makes the error for a value that is not
        finite and >= 0 (default: a ValueError naming the source). Channels keep their
        call counts across calls; their last values are forgotten (a new step)."""
        channels = self._channels
        for source, function in functions.items():
            key = source.lower()
            channel = channels.get(key)
            if channel is None:
                channel = channels[key] = self._new_channel(key, function, (errors or {}).get(source))
                self._arcs_stale = True  # (an arc's conductance or gap channel may be this one)
            self._set_function(channel, function)

    @property
    def channel_calls(self) -> dict[str, int]:
        """Evaluations of each input channel so far (source name -> calls): its function
        called (or, in C, its constant or table evaluated) at a new time; a repeated time
        and a held gap (``_gate_gaps``) are answered without one."""
        return {name: channel.calls for name, channel in self._channels.items()}

    def set_arcs(self, arcs: Mapping[str, object]) -> None:
        """The ``ArcState`` of each arc of the loaded circuit, by the EXTERNAL current source
        that carries its state (empty: no arc)."""
        self._arcs = {name.lower(): arc for name, arc in arcs.items()}
        self._arc_by_pointer = {}
        self._forget_c_arcs()
        self._set_arc_bounds(math.nan, math.inf, math.inf)
        self._arcs_stale = True
        self._mirror_steps()

    def set_breakpoint(self, t: float) -> None:
        """A transient breakpoint: ngspice lands on t and restarts with a small first-order step."""
        self._lines = []
        ok = self._ngspice_shared.ngSpice_SetBkpt(float(t))
        printed = self._lines
        self._lines = []
        if not ok:
            raise NgspiceError(f"ngspice refused a breakpoint at t = {t!r} s", _message(printed))
        self._landings_from_c()
        bisect.insort(self._landings, float(t))
        self._mirror_steps()

    def transient(self, target: float | None, first: bool, wall_timeout: float | None, t_end: float,
                  end_tolerance: float = 0.0, max_step: float = math.inf) -> None:
        """Start (``first``) or resume the loaded transient and pause exactly at ``target`` (s).

        ``target=None`` runs to ``t_end``, the end time of the ``.tran`` line, where the
        run ends (no pause). Raises the ngspice error, or the exception a callback raised, after
        ngspice has stopped; KeyboardInterrupt if Ctrl-C paused ngspice (ngspice installs
        its own SIGINT handler while it runs, which pauses instead of raising).
        ``end_tolerance``: how early (s) ngspice may end a run to ``t_end``
        (``SimulationOptions.end_tolerance``). ``max_step``: s, no step of this run or pause
        longer (below the deck's own TMAX; the sync callback shortens longer ones).
        """
        self._deadline = math.inf if wall_timeout is None else time.monotonic() + wall_timeout
        self._target = math.inf if target is None else float(target)
        self._max_step = float(max_step)
        # (ngspice ends a run within max(1e-9 * t_end, end_tolerance) of t_end)
        threshold = t_end - max(1e-9 * t_end, end_tolerance) if target is None else target - stop_margin(target)
        try:
            if first:
                self._abandon_run()
                self._point_plans = {}  # (a new run: its vectors may be others)
                self._run = greenlet(self._run_body)
                self._run_thread = threading.current_thread()
                self._accepting = -math.inf  # (the last run's last point)
                if self._cstate is not None:
                    self._cstate.accepting = -math.inf
            elif self._run is not None and not self._resumable():
                self._run = None
                raise SimulationAborted("the thread that started this transient has ended: it cannot be resumed")
            elif self._run is None:
                # ngspice ended the run at the last pause, within CKTminBreak of t_end (a
                # macro step landed there): nothing is left to run
                if self.last_time() >= threshold:
                    return
                raise SimulationAborted(f"ngspice's transient ended at t = {self.last_time()!r} s, "
                                        f"before {threshold!r} s")
            self._pause_at = math.inf if target is None else threshold
            self._mirror_steps()
            self._caller = getcurrent()
            printed = self._run.switch()
            if not self._run.dead:
                return  # paused at a point at or after the threshold (_on_data)
            self._run = None
            self._raise_if_failed(printed)
            # ngspice ends a run once within CKTminBreak (5e-5 TMAX) of t_end: after
            # rejected steps near the end its last point can be that early (measured
            # 0.88 ns before t_end with TMAX = 30 us).
            self._check_reached(printed, threshold)
        finally:
            # (Python's fields only: the compiled state keeps this pause's until the next
            # transient, set_breakpoint or clear mirrors them, as ngspice takes no step
            # while paused or after its run ended, and an abandoned run, resumed with its
            # failure set, aborts without reading them; ~1 us a macro step)
            self._target = math.inf
            self._max_step = math.inf
            self._deadline = math.inf
            self._landings = []

    def _run_body(self) -> list[str]:
        """The whole transient of the loaded circuit: one "run" (its greenlet pauses inside)."""
        return self.command("run")

    def _resumable(self) -> bool:
        """True if the paused transient can be resumed from this thread: a greenlet lives in
        the thread that made it. SessionBusyError while that thread is alive; False once it
        has ended (its transient can never run on)."""
        thread = self._run_thread
        if thread is None or thread is threading.current_thread():
            return True
        if thread.is_alive():
            raise SessionBusyError("ngspice is paused inside a transient started by another thread: advance or "
                                   "close that Stepper from the thread that started it")
        return False

    def _abandon_run(self) -> None:
        """A transient left paused (a run failed or closed early) is stopped: resumed with a
        failure set, which makes the sync callback abort it at its next step. One left by a
        thread that has ended is only forgotten."""
        run = self._run
        if run is None or run.dead:
            self._run = None
            return
        resumable = self._resumable()  # (SessionBusyError while its own thread may still resume it)
        self._run = None
        if not resumable:
            return
        self._failure = SimulationAborted("the run was abandoned")
        self._pause_at = math.inf
        self._caller = getcurrent()
        try:
            run.switch()
        except Exception:  # noqa: BLE001 - the abort's own error
            pass
        finally:
            self._failure = None

    def _check_reached(self, printed: list[str], threshold: float) -> None:
        """The run ended (its `run` command returned): it must have got to ``threshold``;
        ended earlier, it was paused by Ctrl-C (ngspice's own SIGINT handler:
        KeyboardInterrupt) or stopped (SimulationAborted with ngspice's message)."""
        if self.last_time() >= threshold:
            return
        if any("interrupted" in line for line in printed):
            raise KeyboardInterrupt(f"ngspice paused by an interrupt at t = {self.last_time()!r} s")
        raise SimulationAborted(f"ngspice stopped at t = {self.last_time()!r} s before {threshold!r} s",
                                _message(printed))

    def _raise_if_failed(self, printed: list[str]) -> None:
        failure, self._failure = self._failure, None
        aborted = any("aborted" in line or "Error:" in line for line in printed)
        if failure is not None:
            if isinstance(failure, SimulationTimeout):
                raise SimulationTimeout(str(failure), _message(printed)) from None
            raise failure
        if aborted or self._exit_status is not None:
            self._check_alive()
            message = _message(printed)
            if re.search(r"Transient op failed|gmin stepping failed|source stepping failed|"
                         r"iteration limit|Transient solution failed", message):
                raise ConvergenceError("no convergence at the operating point", message)
            if "Timestep too small" in message:
                raise TimestepTooSmallError("transient aborted: timestep too small", message)
            raise SimulationAborted("transient aborted", message)

    # -- results --

    def _encode(self, name: str) -> bytes:
        encoded = self._encoded[name] = name.encode("ascii")
        return encoded

    def vector_info(self, name: str):
        encoded = self._encoded.get(name)
        if encoded is None:
            encoded = self._encode(name)
        info = self._ngspice_shared.ngGet_Vec_Info(encoded)
        return None if info == ffi.NULL else info

    def last_values(self, names: tuple[str, ...]) -> tuple[int, list[float]]:
        """Number of points and the last value of each named vector: while the run is paused,
        from the pausing point SendData gave (ngspice copies each vector's last value there;
        ten look-ups of ngGet_Vec_Info cost a coil relay's macro step ~13 us), else one
        look-up each."""
        paused = self._paused
        if paused is not None:
            point = ffi.cast(_VALUES_ALL, paused)
            vectors = point.vecsa
            plan = self._point_plans.get(names, False)
            # (the plan holds each vector's vecvalues cell, which ngspice fills at every point
            # of a plot: valid while SendData's array of cells is the one it was made from)
            if plan is False or (plan is not None and plan[0] != vectors):
                plan = self._point_plans[names] = self._point_plan(point, names)
            if plan is not None:
                return point.vecindex + 1, [cell.creal for cell in plan[1]]
        values = []
        length = 0
        encoded, look_up = self._encoded, self._ngspice_shared.ngGet_Vec_Info
        for name in names:
            key = encoded.get(name)
            info = look_up(key if key is not None else self._encode(name))
            if info == ffi.NULL or info.v_length == 0:
                raise KeyError(f"ngspice has no data for {name!r}")
            length = info.v_length
            data = info.v_realdata
            values.append(float(data[length - 1]) if data != ffi.NULL else float(info.v_compdata[length - 1].cx_real))
        return int(length), values

    @staticmethod
    def _point_plan(point, names: tuple[str, ...]) -> tuple | None:
        """(SendData's array of vecvalues cells in ``point``, the cell of each of ``names``):
        where ngspice copies each vector's last value at every point (sharedspice's
        sh_ExecutePerLoop, into the cells a plot's start allocated; their pointers read once,
        not at every macro step: ~0.1 us a vector), or None if any is not there as a real
        vector (read by look-up)."""
        where = {}
        vectors = point.vecsa
        for k in range(point.veccount):
            vector = vectors[k]
            if not vector.is_complex:
                where.setdefault(ffi.string(vector.name).decode("ascii", "replace").lower(), vector)
        plan = [where.get(name.lower()) for name in names]
        return None if None in plan else (vectors, plan)

    def _span(self, name: str, start: int, stop: int | None):
        """(vector_info, start, stop) of the points [start, stop) of a vector of the current
        plot, the bounds clipped to its length; KeyError naming a vector it does not hold."""
        # (vector_info's look-up in one line, not a call: a coupled macro step reads two or
        # three columns through ``floats``)
        info = self._ngspice_shared.ngGet_Vec_Info(self._encoded.get(name) or self._encode(name))
        if info == ffi.NULL:
            raise KeyError(f"ngspice has no vector {name!r} in the current plot")
        n = info.v_length
        stop = n if stop is None else min(stop, n)
        return info, max(0, min(start, stop)), stop

    def vector(self, name: str, start: int = 0, stop: int | None = None) -> np.ndarray:
        """Copy of a real vector of the current plot (node name, 'xxx#branch', 'time')."""
        info, start, stop = self._span(name, start, stop)
        n = info.v_length
        if info.v_realdata != ffi.NULL:
            data = np.frombuffer(ffi.buffer(info.v_realdata, n * 8), dtype=np.float64)
            return data[start:stop].copy()
        pairs = np.frombuffer(ffi.buffer(info.v_compdata, n * 16), dtype=np.float64)
        return pairs[2 * start : 2 * stop : 2].copy()

    def floats(self, name: str, start: int = 0, stop: int | None = None) -> list[float]:
        """``vector(name, start, stop)`` as a list of floats (the same doubles), read by cffi
        without a numpy array between."""
        info, start, stop = self._span(name, start, stop)
        if info.v_realdata != ffi.NULL:
            return ffi.unpack(info.v_realdata + start, stop - start)
        return self.vector(name, start, stop).tolist()

    def length(self) -> int:
        info = self.vector_info("time")
        return 0 if info is None else int(info.v_length)

    def last_value(self, name: str) -> float:
        info = self.vector_info(name)
        if info is None or info.v_length == 0:
            raise KeyError(f"ngspice has no data for {name!r}")
        if info.v_realdata != ffi.NULL:
            return float(info.v_realdata[info.v_length - 1])
        return float(info.v_compdata[info.v_length - 1].cx_real)

    def last_time(self) -> float:
        info = self.vector_info("time")
        if info is None or info.v_length == 0:
            return -math.inf
        return float(info.v_realdata[info.v_length - 1])

    # -- ownership: one user at a time --

    @contextlib.contextmanager
    def exclusive(self):
        """Hold the session's thread lock without waiting: a second thread gets an error, never a hang."""
        if not self.lock.acquire(blocking=False):
            raise SessionBusyError("ngspice is in use by another thread of this process")
        try:
            yield self
        finally:
            self.lock.release()

    def claim(self, owner: object) -> None:
        current = self.owner() if self.owner is not None else None
        if current is not None and current is not owner:
            raise SessionBusyError(
                "this process's ngspice is in use by an open Stepper; close it first "
                "(one ngspice per process: run parallel simulations in separate processes)"
            )
        self.owner = weakref.ref(owner)

    def release(self, owner: object) -> None:
        if self.owner is not None and self.owner() is owner:
            self.owner = None

    @property
    def exited(self) -> bool:
        """True once ngspice has ended its session ("cannot recover"): no circuit can run in
        this process any more (a sweep worker is then restarted)."""
        return self._exit_status is not None


def _zero(t: float) -> float:
    return 0.0


class Channel:
    """One input channel: the function of time behind an EXTERNAL voltage source, its last
    value (ngspice asks again at the same time during Newton iterations) and its calls;
    ``zero``: the function is the constant 0 for this macro step; ``gate``: an arc's gap
    channel's (the arc's cells, its contact's conductance channel), see
    ``NgspiceSession._gate_gaps``."""

    __slots__ = ("name", "function", "make_error", "last_t", "last_value", "calls", "zero", "gate")

    def __init__(self, name: str, function: Callable[[float], float],
                 make_error: Callable[[float, float], Exception] | None = None):
        self.name = name
        self.function = function
        self.make_error = make_error
        self.last_t = math.nan
        self.last_value = 0.0
        self.calls = 0
        self.zero = False
        self.gate = None

    def error(self, t: float, value: float) -> Exception:
        if self.make_error is not None:
            return self.make_error(t, value)
        return ValueError(f"input {self.name} at t = {t!r} s is {value!r}; it must be finite and >= 0")


class CompiledChannel(Channel):
    """An input channel of the compiled callbacks: its last time, value and calls live in
    its C cell (``cell``, index ``index`` of the session's cells), where the C callback
    keeps them; ``keep`` holds what the cell points to (a TableChannel's arrays)."""

    __slots__ = ("cell", "index", "keep")

    def __init__(self, name: str, function: Callable[[float], float],
                 make_error: Callable[[float, float], Exception] | None, cell, index: int):
        self.cell, self.index, self.keep = cell, index, None
        super().__init__(name, function, make_error)

    @property
    def last_t(self) -> float:
        return self.cell.last_t

    @last_t.setter
    def last_t(self, t: float) -> None:
        self.cell.last_t = t

    @property
    def last_value(self) -> float:
        return self.cell.last_value

    @last_value.setter
    def last_value(self, value: float) -> None:
        self.cell.last_value = value

    @property
    def calls(self) -> int:
        return int(self.cell.calls)

    @calls.setter
    def calls(self, calls: int) -> None:
        self.cell.calls = calls


def _message(printed: list[str]) -> str:
    """ngspice's own error lines, in order, without chatter and repeats."""
    kept: list[str] = []
    for line in printed:
        text = line.split(" ", 1)[1] if line.startswith(("stdout ", "stderr ")) else line
        text = text.strip()
        if not text or _CHATTER.search(text):
            continue
        if line.startswith("stderr ") or _ERROR_LINE.search(text):
            if not kept or kept[-1] != text:
                kept.append(text)
    return "\n".join(kept[-40:])


def _pyspice_holds_ngspice() -> bool:
    """True if PySpice's own NgSpiceShared (never imported by switchsim) has started ngspice
    in this process: it loads the same library and installs its own callbacks."""
    pyspice = sys.modules.get("PySpice.Spice.NgSpice.Shared")
    return pyspice is not None and bool(pyspice.NgSpiceShared._instances)


_SESSION: NgspiceSession | None = None
_SESSION_LOCK = threading.Lock()


def get_session() -> NgspiceSession:
    """The process's ngspice session, created on first use."""
    global _SESSION
    with _SESSION_LOCK:
        if _SESSION is None:
            if _pyspice_holds_ngspice():
                raise SessionBusyError(
                    "PySpice's own NgSpiceShared already holds ngspice in this process "
                    "(only one ngspice can exist per process): create switchsim's session first"
                )
            _SESSION = NgspiceSession(find_library())
        return _SESSION
