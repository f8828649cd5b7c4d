"""No scene may take the machine's memory: the audit's three scenes end in one line under a
memory cap, running out of memory is a failed run with its partial result on every route
(command line, coupling.run, sweep rows), and the work and memory a scene asks for are
estimated and refused, naming the key, before anything runs."""

from __future__ import annotations

import contextlib
import io
import json
import os
import resource
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import tomllib

import coupling
from coupling import run, scene_from_dict
from coupling.app.cli import main
from coupling.core.master import CoupledRunError
from coupling.core.scene import MACRO_STEPS_MAX, builtin_scene_text, memory_estimate
from mech.recorder import CHUNK, MEMORY_LIMIT, Recorder, history_memory

ROOT = Path(__file__).resolve().parents[2]
CAP = 3 * 2**30  # bytes of address space for the child: a default run needs ~1.6 GiB (numba, ngspice)

AUDIT_SCENES = {
    # a free drop of a bar lighter than air: 72 MHz axial modes, 2.5e7 steps (23 GB before)
    "light.toml": "[bar]\ndensity = 1e-3\n",
    # a mechanics run to 1e300 s (grew 25 MB/s to a 4.25 GiB allocation traceback)
    "long.toml": "[solver]\nt_end = 1e300\n",
    # the relay with a 5.4 MN armature force (12 GB before)
    "crush.toml": builtin_scene_text("relay_force").replace("value = [0.0, 5.4]", "value = [0.0, 5.4e6]"),
}


def capped(argv, cwd: Path, timeout: float = 300.0) -> subprocess.CompletedProcess:
    """``python -m coupling.app.cli argv`` in a child whose address space is capped at CAP."""
    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (CAP, CAP))

    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-m", "coupling.app.cli", *argv], cwd=cwd, env=env, text=True,
                          capture_output=True, preexec_fn=limit, timeout=timeout)


@pytest.mark.slow
@pytest.mark.parametrize("name", list(AUDIT_SCENES))
def test_the_audit_scenes_end_in_one_line_under_a_memory_cap(tmp_path, name):
    """Each ends by itself with one line and exit 1 (stopped, what it computed written) or
    2 (refused before it runs): never a traceback, never killed (the timeout is a hang's)."""
    (tmp_path / name).write_text(AUDIT_SCENES[name])
    proc = capped(["run", name, "--out", "out", "--quiet"], tmp_path)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode in (1, 2), proc.stderr
    assert "Traceback" not in proc.stderr and len(lines) == 1, proc.stderr
    if proc.returncode == 2:
        assert "allowed range" in lines[0] and not (tmp_path / "out").exists()
    else:  # the crushed relay: stopped where its rivet sank past its cap, the partial result kept
        assert "deeper than its cap" in lines[0]
        summary = json.loads((tmp_path / "out" / "summary.json").read_text())
        assert summary["status"] == "failed" and summary["stopped_at"] >= 0.0


class OutOfMemory:
    """The recorder's buffers cannot grow past ``rows`` rows: MemoryError, as numpy raises it."""

    def __init__(self, rows: int):
        self.rows = rows

    def __enter__(self):
        self.grow = Recorder.grow
        rows, grow = self.rows, self.grow

        def limited(rec, cap):
            if cap > rows:
                raise MemoryError(f"Unable to allocate {cap * 8 / 2**20:.3g} MiB for an array")
            grow(rec, cap)

        Recorder.grow = limited
        return self

    def __exit__(self, *exc):
        Recorder.grow = self.grow


MECH = "[bar]\nmodes = 3\n[solver]\nt_end = 0.05\n"  # the default drop, ~6 000 steps


def test_out_of_memory_on_the_command_line_is_one_line_exit_1_and_the_partial_result(tmp_path):
    scene = tmp_path / "drop.toml"
    scene.write_text(MECH)
    err = io.StringIO()
    with OutOfMemory(4096), contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        rc = main(["run", str(scene), "--out", str(tmp_path / "out"), "--quiet"])
    lines = err.getvalue().strip().splitlines()
    assert rc == 1 and len(lines) == 1 and "out of memory" in lines[0] and "Traceback" not in err.getvalue()
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["solver"]["steps"] >= 4000


def test_out_of_memory_in_the_api_and_a_coupled_run_raise_with_the_partial_result():
    with OutOfMemory(4096), pytest.raises(CoupledRunError) as info:
        run(scene_from_dict({"bar": {"modes": 3}, "solver": {"t_end": 0.05}}))
    assert "out of memory" in str(info.value) and info.value.partial.mechanics.t[-1] > 0.0
    # the coupled relay over 10 ms: its mechanics' history cannot grow past 2048 rows (it
    # takes ~7 600, past the recorder's first 4096)
    with OutOfMemory(2048), pytest.raises(CoupledRunError) as info:
        run(coupling.builtin_scene("relay_force").set("solver.t_end", 0.01))
    partial = info.value.partial
    assert "MemoryError" in str(info.value) and "\n" not in str(info.value)
    assert partial is not None and partial.status == "failed" and partial.stopped_at is not None
    waves = partial.waveform_columns
    assert len(waves["time"]) > 0 and len(waves["normal_force"]) == len(waves["time"])


def test_out_of_memory_in_a_sweep_is_a_failed_row_with_the_partial_summary():
    from coupling.app.sweep import execute

    doc = {"base": {"bar": {"modes": 3}, "solver": {"t_end": 0.05}}, "common": {}, "base_dir": ".",
           "base_name": "drop", "waveforms": False}
    with OutOfMemory(4096):
        row = execute(doc, {"run_id": "r0", "name": "r0", "params": {}}, None)
    assert row["status"] == "failed" and "out of memory" in row["error"]
    assert row["solver.steps"] >= 4000  # the partial result's summary, flattened into the row


def test_a_macro_step_that_would_take_millions_of_steps_is_refused_before_it_runs():
    """The audit's case: a 1e-9 s macro step over 5 ms (5e6 steps) started without an estimate."""
    text = builtin_scene_text("relay_force").replace("macro_step = 5e-6", "macro_step = 1e-9")
    with pytest.raises(ValueError) as info:
        scene_from_dict(tomllib.loads(text))
    message = str(info.value)
    assert "coupling.macro_step = 1e-09" in message and "5e+06 macro steps" in message and "\n" not in message
    # at the bound it is allowed
    ok = builtin_scene_text("relay_force").replace("macro_step = 5e-6", f"macro_step = {0.005 / MACRO_STEPS_MAX!r}")
    scene_from_dict(tomllib.loads(ok))


def test_the_memory_estimate_is_the_history_and_the_waveforms_and_refuses_above_the_limit():
    """A held blade with 1 axial and 6 bending modes (planar: 3 + 7 positions, 3 + 7 speeds,
    11 quadratures = 31 states) keeping 100 000 rows: the history's part is
    mech.recorder.history_memory of those; coupled, one macro step's dense output besides."""
    text = textwrap.dedent("""
        [bar]
        length = 0.02
        width = 0.003
        thickness = 0.0003
        tip_radius = 0.0016
        modes = {axial = 1, bending = 6}
        [mount]
        kind = "clamp"
        position = 0.02
        [initial]
        height = 1e-4
        """)
    scene = scene_from_dict(tomllib.loads(text))
    assert memory_estimate(scene) == {"history": history_memory(31, 100_000), "waveforms": 0,
                                      "total": history_memory(31, 100_000)}
    assert history_memory(31, 100_000) == (3 * 100_000 + 2 * CHUNK) * 8 * (21 + 31)
    # ten million rows of the largest state "auto" allows (40 + 40 modes, 3D) would not fit
    with pytest.raises(ValueError) as info:
        scene_from_dict({"solver": {"history_rows": 10_000_000}})
    assert "solver.history_rows = 10000000" in str(info.value) and "GiB" in str(info.value)
    # an ngspice step of 1e-12 s over 5 ms: 5e9 points, refused naming the key
    coupled = builtin_scene_text("relay_force").replace("[circuit]\n", "[circuit]\nmax_step = 1e-12\n")
    with pytest.raises(ValueError) as info:
        scene_from_dict(tomllib.loads(coupled))
    assert "circuit.max_step = 1e-12" in str(info.value)
    assert memory_estimate(coupling.builtin_scene("relay_force"))["total"] < MEMORY_LIMIT  # (auto modes at their cap)


def test_the_coupled_run_samples_its_contact_in_batches_and_releases_the_dense_output(monkeypatch):
    """The relay sampled every 256 rows of dense output against sampled once at the end (the
    whole run's dense output kept, as before): the same waveforms bit for bit (the same
    rows, the same compiled evaluation), and the mechanics hold at most a batch."""
    from coupling.core import master

    def relay(flush_rows):
        monkeypatch.setattr(master, "DENSE_FLUSH_ROWS", flush_rows)
        sim = master.CoSimulation(coupling.builtin_scene("relay_force"))
        return sim.run(), sim.mech

    batched, mech_batched = relay(256)
    whole, mech_whole = relay(10**9)
    for name, column in whole.waveform_columns.items():
        assert column.tobytes() == batched.waveform_columns[name].tobytes(), name
    assert mech_whole.dense_rows == len(mech_whole.recorder.t[:mech_whole.recorder.n])
    assert 0 < mech_batched.dense_rows < 256 + 4096 and mech_batched.recorder.dense_base > 0


def test_the_state_estimate_counts_a_hysteretic_spring_s_state():
    """The memory estimate's largest state is the model's own, a hysteretic force-travel
    spring's stick force included (the estimate missed it)."""
    from coupling.core.scene import _largest_state
    from mech import ImpactSolver

    loop = dict(travel=[0.0, 2e-4, 4e-4], force=[0.0, 0.5, 0.8], release_force=[0.0, 0.2, 0.4])
    doc = {"bar": dict(length=0.05, diameter=0.005, tip_radius=0.0025, modes=0),
           "mount": dict(kind="pivot", position=0.05),
           "spring": [dict(anchor=[-0.05, 0.0, -1.0], position=0.0, **loop)],
           "initial": dict(height=1e-3), "environment": dict(gravity=0.0), "solver": dict(t_end=1e-3)}
    scene = scene_from_dict(doc, name="loop")
    assert _largest_state(scene.mech) == len(ImpactSolver(scene.mech).y)


def test_a_run_whose_steps_collapse_stops_at_the_memory_a_run_may_take(monkeypatch):
    """The tactile switch's stiff lever at 30 modes per family: its highest mode (56 MHz)
    holds the explicit step near 6 ns, and a coupled macro step keeps all its rows' dense
    output, so the run took the machine's memory (18 GB in a minute) until the system
    killed it, with nothing kept. The recorder now stops at MEMORY_LIMIT (here lowered to
    256 MiB, the same rule at a size a test can reach): a failed run whose message names
    bar.modes, with its partial result: the mechanics up to where it stopped (inside the
    first macro step, which ngspice never reached: the circuit's part is empty)."""
    import mech.recorder

    monkeypatch.setattr(mech.recorder, "MEMORY_LIMIT", 256 * 2**20)
    doc = tomllib.loads((ROOT / "examples" / "tactile_switch.toml").read_text())
    doc["bar"]["modes"] = 30
    scene = scene_from_dict(doc, base_dir=ROOT / "examples")
    with pytest.raises(CoupledRunError) as err:
        run(scene)
    assert "bar.modes" in str(err.value) and "0.25 GiB" in str(err.value)
    partial = err.value.partial
    assert partial is not None and partial.status == "failed"
    assert 0.0 < float(partial.mechanics.t[-1]) < scene.t_end
