"""The compiled ngspice callbacks (circuit/callbacks.c, circuit/compiled_callbacks.py): their
build, its fallback, and the declarations Python reads the library with.

The behaviour of the callbacks themselves -- both routes giving the same waveforms to the
bit -- is tested in test_compiled_callbacks_runs.py.
"""

from __future__ import annotations

import math

import pytest

from circuit import compiled_callbacks
from circuit._callbacks_ffi import ffi
from circuit.arc import ARC_CELLS


@pytest.fixture
def fresh(monkeypatch):
    """No library loaded yet in this process (as at a start), the Python route not forced."""
    monkeypatch.setattr(compiled_callbacks, "_LOADED", {})
    monkeypatch.delenv(compiled_callbacks.FORCE_PYTHON, raising=False)


def test_the_library_builds_into_its_folder_and_loads(tmp_path, fresh):
    library = compiled_callbacks.load(tmp_path)
    assert library is not None
    folder = compiled_callbacks.library_folder(tmp_path)
    assert (folder / compiled_callbacks.LIBRARY).is_file()
    assert compiled_callbacks.load(tmp_path) is library  # loaded once per process


def test_the_declarations_match_the_compiled_structures(tmp_path, fresh):
    """A field declared at another offset than the compiler put it would be read wrong, silently."""
    library = compiled_callbacks.load(tmp_path)
    out = ffi.new("long[]", 128)
    count = library.sw_layout(out, 128)
    expected = [ffi.sizeof(struct) for struct in compiled_callbacks.STRUCTS]
    expected += [ffi.offsetof(struct, field) for struct, field in compiled_callbacks.LAYOUT]
    expected += list(range(len(ARC_CELLS)))  # (the C indices of the ArcState's cells, in their order)
    assert count < 128 and list(out[0:count]) == expected


def test_the_generated_module_holds_the_declarations(tmp_path):
    """Fails when DECLARATIONS was edited without `python -m circuit.compiled_callbacks`."""
    pytest.importorskip("pycparser")
    import importlib.util

    path = compiled_callbacks.write_module(tmp_path / "regenerated.py")
    spec = importlib.util.spec_from_file_location("regenerated", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    for struct in compiled_callbacks.STRUCTS:
        assert module.ffi.sizeof(struct) == ffi.sizeof(struct)
        fresh = [(name, f.offset, module.ffi.getctype(f.type)) for name, f in module.ffi.typeof(struct).fields]
        kept = [(name, f.offset, ffi.getctype(f.type)) for name, f in ffi.typeof(struct).fields]
        assert fresh == kept, struct


def test_a_failed_build_falls_back_to_the_python_callbacks_and_says_why_once(tmp_path, fresh, monkeypatch, capsys):
    monkeypatch.setenv("CC", "/bin/false")
    assert compiled_callbacks.load(tmp_path) is None
    said = capsys.readouterr().err
    assert "using the Python ngspice callbacks: their C build failed" in said
    folder = compiled_callbacks.library_folder(tmp_path)
    assert folder.with_name(folder.name + ".failed").is_file()
    assert compiled_callbacks.load(tmp_path) is None
    assert capsys.readouterr().err == ""  # said once per process
    monkeypatch.setattr(compiled_callbacks, "_LOADED", {})  # (another process)
    assert compiled_callbacks.load(tmp_path) is None
    assert "failed before" in capsys.readouterr().err


def test_a_missing_compiler_falls_back(tmp_path, fresh, monkeypatch, capsys):
    monkeypatch.setenv("CC", str(tmp_path / "no-such-cc"))
    assert compiled_callbacks.load(tmp_path) is None
    assert "no C compiler" in capsys.readouterr().err


def test_the_python_route_can_be_forced(tmp_path, fresh, monkeypatch):
    monkeypatch.setenv(compiled_callbacks.FORCE_PYTHON, "1")
    assert compiled_callbacks.load(tmp_path) is None
    assert not compiled_callbacks.library_folder(tmp_path).exists()  # nothing built


class StepControl:
    """A compiled step callback of its own (a library built in a folder of its own has its own
    state), driven point by point as ngspice drives it: one input channel (the contact's
    conductance) and the arcs' rules; ``python`` records the calls it hands to Python."""

    def __init__(self, library, arcs=(), rejections=4):
        self.library, self.python = library, []
        self.state = state = ffi.new("sw_state *")
        self.channel = ffi.new("sw_channel[]", 1)
        self.channel[0].kind = compiled_callbacks.PYTHON
        self.rules = ffi.new("sw_arc_rule[]", max(len(arcs), 1))
        self.cells = [ffi.from_buffer("double[]", arc.cells) for arc in arcs]
        for k, cells in enumerate(self.cells):
            self.rules[k].cells, self.rules[k].conductance = cells, 0
        self.log = ffi.new("double[]", 2 * rejections)
        self.fallback = ffi.callback("sw_sync_fn", self._python)
        state.sync_python = self.fallback
        state.channels, state.channels_used = self.channel, 1
        state.arc_rules, state.arc_rules_used, state.has_arcs = self.rules, len(arcs), bool(arcs)
        state.rejections, state.rejections_size = self.log, rejections
        state.target = state.max_step = state.deadline = math.inf
        state.arc_from, state.arc_step, state.arc_land = math.nan, math.inf, math.inf
        state.accepting = -math.inf
        library.sw_install(state)

    def _python(self, ckttime, pdelta, olddelta, redostep, ident, location, user):
        self.python.append((ckttime, redostep, location))
        return 0

    def sync(self, t: float, delta: float = 1e-7, olddelta: float = 1e-7, redo: bool = False, location: int = 0):
        """One GetSyncData call at t (the conductance channel's last value already at t)."""
        pdelta = ffi.new("double *", delta)
        self.library.sw_sync(t, pdelta, olddelta, int(redo), 0, location, ffi.NULL)
        return pdelta[0]


def never_read(names):
    raise AssertionError(f"read {names}: a plain point needs no vector")


def test_the_compiled_arc_rules_answer_as_arcstate_where_only_its_filter_moves(tmp_path, fresh):
    """A contact that makes, stays closed, breaks with the arc lit and stays open: the compiled
    step callback answers the points where only the arc's filtered closed indicator moves
    (the level, the step bounds and the landing on its crossing of 1/2 bit for bit those of
    ArcState.accepted on a twin driven by Python) and hands the others to Python: the first
    point, the make, the arming, the break, the arc burning on the open contact (its current
    read) and its extinction."""
    from circuit.arc import ArcModel, ArcState

    model = ArcModel(min_voltage=12.0, min_current=0.4, formation_time=1e-6)
    compiled, twin = ArcState(model, "i", "a", "b", "g"), ArcState(model, "i", "a", "b", "g")
    for arc in (compiled, twin):
        arc.start(False)
    control = StepControl(compiled_callbacks.load(tmp_path), [compiled])
    current = lambda names: [0.1] * len(names)  # A: below I_min, the arc goes out once unarmed
    dt, answered, landings, lit = 0.13e-6, [], [], []
    times = [dt * k for k in range(1, 120)]
    for t in times:
        g = 1.0 if 30 * dt <= t < 80 * dt else 0.0  # made at the 30th point, broken at the 80th
        control.channel[0].last_t, control.channel[0].last_value = t, g
        before = len(control.python)
        control.sync(t)
        step, land = twin.accepted(t, g, current)
        if twin.burning and not lit:
            lit.append(t)
        if len(control.python) > before:  # Python's turn: as the session answers it
            assert compiled.accepted(t, g, current) == (step, land)
        else:
            answered.append(t)
            assert (control.state.arc_from, control.state.arc_step, control.state.arc_land) == (t, step, land)
            if math.isfinite(land):
                landings.append(t)
        assert compiled.cells.tobytes() == twin.cells.tobytes(), t
    handed = [t for t, _, _ in control.python]
    armed = lit[0]  # formation_time after the make (switched right after the point before it)
    assert times[29] + 0.5 * model.formation_time < armed < times[29] + model.formation_time + dt
    assert handed[:3] == [times[0], times[29], armed]  # the first point, the make, the arming
    burning = [t for t in handed if t >= times[79]]  # the break, its armed window, the extinction
    assert burning[0] == times[79] and len(burning) < 12
    assert len(answered) == len(times) - 3 - len(burning)
    assert landings and all(times[29] < t < armed for t in landings)  # closed, not armed yet: land on 1/2


def test_the_compiled_step_callback_logs_rejected_steps_and_hands_a_full_log_to_python(tmp_path, fresh):
    control = StepControl(compiled_callbacks.load(tmp_path), rejections=2)
    control.sync(1e-6, delta=1e-8, olddelta=8e-8, redo=True, location=1)  # Newton failed: the step cut to 1/8
    control.sync(2e-6, delta=3e-8, olddelta=8e-8, redo=True, location=1)  # the truncation error's estimate
    assert control.state.rejections_used == 2 and list(control.log) == [1e-6, 1.0, 2e-6, 0.0]
    assert control.python == []
    control.sync(3e-6, redo=True, location=1)
    assert control.python == [(3e-6, 1, 1)] and control.state.rejections_used == 2  # (Python empties it)
    assert control.state.accepting == -math.inf  # a redo accepts nothing
    control.sync(4e-6, location=1)
    assert control.state.accepting == 4e-6 and control.state.rejections_used == 2


def test_the_compiled_senddata_hands_python_only_the_point_that_pauses(tmp_path, fresh):
    """SendData (sw_data): Python's _on_data pauses the run at the first accepted point at or
    after the pause time, and does nothing once the run failed; the compiled one calls it
    exactly there, and at every point before a state is installed or on the Python route."""
    library = compiled_callbacks.load(tmp_path)
    called = []
    data = ffi.callback("sw_data_fn", lambda values, count, ident, user: called.append(count) or 0)
    library.sw_install_data(data)
    library.sw_install(ffi.NULL)
    library.sw_data(ffi.NULL, 1, 0, ffi.NULL)  # no state yet: Python's
    state = ffi.new("sw_state *")
    state.pause_at, state.accepting = 2e-6, 1e-6
    library.sw_install(state)
    library.sw_data(ffi.NULL, 2, 0, ffi.NULL)  # before the pause: nothing to do
    state.accepting = 2e-6
    library.sw_data(ffi.NULL, 3, 0, ffi.NULL)  # the point that pauses
    state.failed = 1
    library.sw_data(ffi.NULL, 4, 0, ffi.NULL)  # failed: no pause
    state.failed, state.python_data, state.accepting = 0, 1, 1e-6
    library.sw_data(ffi.NULL, 5, 0, ffi.NULL)  # the Python route: every point
    assert called == [1, 3, 5]
