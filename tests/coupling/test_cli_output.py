"""`switchsim run`'s result folder: checked before the run, written whole or not at all,
replaced whole, partial results for failures and Ctrl-C, the default --out, --quiet."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from cli_checks import DROP

import coupling.core.master
from coupling.app.cli import main
from coupling.core.scene import load_scene

ROOT = Path(__file__).resolve().parents[2]


# The same bar closing a resistive circuit (coupled, ngspice), no plots.
COUPLED = DROP.replace("[output]", textwrap.dedent("""
    [tribology]
    source = "illustrative"
    [circuit]
    template = "resistive"
    voltage = 24.0
    load_resistance = 12.0
    [output]"""))


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def no_run(*_args, **_kwargs):
    raise AssertionError("the simulation started although the destination is unusable")


def one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert "Traceback" not in err[0]
    return err[0]


def staging_left(parent: Path) -> list[str]:
    return [p.name for p in parent.iterdir() if p.name.startswith(".switchsim-")]


# --- the destination is checked before anything runs ------------------------------------

@pytest.mark.parametrize("out, words", [
    ("", ["--out ''", "result folder"]),
    ("/dev/null", ["/dev/null", "not a folder"]),
    ("/proc/switchsim_result", ["cannot create a folder", "/proc"]),
])
def test_unusable_destinations_are_refused_before_the_run(tmp_path, capsys, monkeypatch, out, words):
    scene = write(tmp_path, "drop.toml", DROP)
    monkeypatch.setattr(coupling.core.master, "run", no_run)
    assert main(["run", str(scene), "--out", out]) == 2
    line = one_error_line(capsys)
    for word in words:
        assert word in line


def test_an_existing_file_as_destination_is_refused_and_left_alone(tmp_path, capsys, monkeypatch):
    scene = write(tmp_path, "drop.toml", DROP)
    target = write(tmp_path, "notes.txt", "mine")
    monkeypatch.setattr(coupling.core.master, "run", no_run)
    assert main(["run", str(scene), "--out", str(target)]) == 2
    assert "is a file" in one_error_line(capsys)
    assert target.read_text() == "mine"


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_a_read_only_folder_is_refused(tmp_path, capsys, monkeypatch):
    scene = write(tmp_path, "drop.toml", DROP)
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    monkeypatch.setattr(coupling.core.master, "run", no_run)
    try:
        assert main(["run", str(scene), "--out", str(locked / "out")]) == 2
    finally:
        locked.chmod(0o755)
    assert "cannot create a folder" in one_error_line(capsys)


def test_a_folder_of_other_files_needs_overwrite_and_is_then_replaced_whole(tmp_path, capsys):
    scene = write(tmp_path, "drop.toml", DROP)
    out = tmp_path / "out"
    out.mkdir()
    (out / "thesis.tex").write_text("precious")
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 2
    assert "--overwrite" in one_error_line(capsys)
    assert (out / "thesis.tex").read_text() == "precious"
    assert main(["run", str(scene), "--out", str(out), "--quiet", "--overwrite"]) == 0
    assert not (out / "thesis.tex").exists() and (out / "summary.json").exists()
    assert staging_left(tmp_path) == []


def test_overwrite_never_deletes_a_folder_with_sub_folders(tmp_path, capsys, monkeypatch):
    scene = write(tmp_path, "drop.toml", DROP)
    out = tmp_path / "project"
    (out / "src").mkdir(parents=True)
    monkeypatch.setattr(coupling.core.master, "run", no_run)
    assert main(["run", str(scene), "--out", str(out), "--overwrite"]) == 2
    assert "sub-folders" in one_error_line(capsys)
    assert (out / "src").is_dir()


def test_the_current_folder_is_never_a_destination(tmp_path, capsys, monkeypatch):
    scene = write(tmp_path, "drop.toml", DROP)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(coupling.core.master, "run", no_run)
    assert main(["run", str(scene), "--out", ".", "--overwrite"]) == 2
    assert "current folder" in one_error_line(capsys)
    assert (tmp_path / "drop.toml").exists()


# --- written whole, replaced whole ----------------------------------------------------

def test_a_link_to_a_folder_gets_the_result_in_the_folder_it_names(tmp_path):
    scene = write(tmp_path, "drop.toml", DROP)
    target = tmp_path / "results_disk"
    target.mkdir()
    link = tmp_path / "out"
    link.symlink_to(target)
    assert main(["run", str(scene), "--out", str(link), "--quiet"]) == 0
    assert link.is_symlink() and (target / "summary.json").exists()
    assert staging_left(tmp_path) == []


def test_a_coupled_then_a_mechanics_run_of_the_same_scene_leaves_no_stale_waveforms(tmp_path):
    """The audit's case: the second run's summary beside the first run's waveforms."""
    scene = write(tmp_path, "relay.toml", COUPLED)
    out = tmp_path / "out"
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 0
    assert (out / "waveforms.csv").exists()
    scene.write_text(DROP)  # the same scene file, now mechanics only: replaces its result
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["kind"] == "mechanics" and summary["status"] == "ok"
    assert not (out / "waveforms.csv").exists() and not (out / "waveforms.parquet").exists()
    assert staging_left(tmp_path) == []


def test_a_result_of_another_scene_is_not_replaced_without_overwrite(tmp_path, capsys):
    a = write(tmp_path, "a.toml", DROP)
    b = write(tmp_path, "b.toml", DROP.replace("angle_deg = 90.0", "angle_deg = 60.0"))
    out = tmp_path / "out"
    assert main(["run", str(a), "--out", str(out), "--quiet"]) == 0
    capsys.readouterr()
    assert main(["run", str(b), "--out", str(out), "--quiet"]) == 2
    assert "not a switchsim result of this scene" in one_error_line(capsys)
    assert json.loads((out / "summary.json").read_text())["scene_file"] == str(a.resolve())


def test_an_error_while_writing_leaves_the_previous_result_untouched(tmp_path, monkeypatch, capsys):
    """summary.json and the tables go into a hidden folder first: a failure halfway leaves
    the previous result as it was and no half-written folder behind."""
    scene = write(tmp_path, "drop.toml", DROP)
    out = tmp_path / "out"
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}

    def broken_history(*_args, **_kwargs):
        raise OSError(28, "No space left on device")

    import coupling.app.output as output

    monkeypatch.setattr(output, "write_csv", broken_history)
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 1
    assert "No space left on device" in capsys.readouterr().err
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert staging_left(tmp_path) == []


def test_summary_is_the_last_file_written(tmp_path, monkeypatch):
    import coupling.app.output as output

    scene = write(tmp_path, "drop.toml", DROP)
    order = []
    real = output._write_text

    def spy(path, text):
        order.append(sorted(p.name for p in path.parent.iterdir()))
        real(path, text)

    monkeypatch.setattr(output, "_write_text", spy)
    assert main(["run", str(scene), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    written_before_summary = set(order[-1])
    final = {p.name for p in (tmp_path / "out").iterdir()}
    # every table is already there when the final summary is written
    assert final - {"summary.json"} <= written_before_summary


# --- failures and interruptions keep what was computed ---------------------------------

def test_a_mechanics_failure_inside_a_coupled_run_writes_the_partial_result_at_its_time(tmp_path, capsys):
    """The audit's case: max_steps = 10 reported 'failed at t = 0.0 s' and wrote nothing."""
    scene = write(tmp_path, "few.toml", COUPLED.replace("t_end = 0.001", "t_end = 0.001\nmax_steps = 10"))
    out = tmp_path / "out"
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["message"]
    t_fail = summary["stopped_at"]
    history = pd.read_csv(out / "history.csv")
    # the mechanics' own failure time: where its records end, not the macro step's start
    assert t_fail > 0.0 and t_fail == pytest.approx(history.time.iloc[-1], rel=1e-12)
    assert f"t = {t_fail!r} s" in err


def test_a_mechanics_only_failure_states_its_time_the_same_way(tmp_path):
    scene = write(tmp_path, "few.toml", DROP.replace("t_end = 0.001", "t_end = 0.001\nmax_steps = 10"))
    out = tmp_path / "out"
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 1
    summary = json.loads((out / "summary.json").read_text())
    t_fail = summary["stopped_at"]
    assert t_fail > 0.0 and t_fail == pytest.approx(pd.read_csv(out / "history.csv").time.iloc[-1], rel=1e-12)


def test_a_netlist_line_that_cannot_be_parsed_is_bad_input_before_anything_runs(tmp_path, capsys):
    # (was: a failed result written at t = 0; a netlist ngspice refuses is bad input, like
    # one switchsim's own check refuses: exit 2, one line, no result folder)
    (tmp_path / "relay.cir").write_text("* relay\nV1 supply 0 24\nR1 supply a 12\nXCONTACT a 0\n"
                                        "garbage line here %%%\n")
    text = COUPLED.replace('template = "resistive"\nvoltage = 24.0\nload_resistance = 12.0',
                           'template = "netlist"\nnetlist = "relay.cir"')
    scene = write(tmp_path, "relay.toml", text)
    out = tmp_path / "out"
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "could not parse" in err[0]
    assert not out.exists()


# A tilted flexible bar bouncing elastically (e = 1): it never comes to rest, so the solver
# integrates every bounce; ~7 s of work per simulated second here, t_end 10 s.
BOUNCING = textwrap.dedent("""
    [bar]
    modes = 10
    [initial]
    angle_deg = 30.0
    height = 0.001
    velocity = [0.0, 0.0, 0.0]
    [contact]
    restitution = 1.0
    [solver]
    t_end = 10.0
    [output]
    plots = false
    """)


def interrupted_time(out: Path) -> float:
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "interrupted"
    t_stop = summary["stopped_at"]
    history = pd.read_csv(out / "history.csv")
    assert history.time.iloc[-1] == pytest.approx(t_stop, rel=1e-9, abs=1e-15)
    return t_stop


@pytest.mark.slow
def test_ctrl_c_in_a_coupled_run_writes_the_partial_result_marked_interrupted_and_exits_130(tmp_path):
    """A real SIGINT to the command, once its run loop reports progress."""
    # The bouncing bar closing the circuit: far longer than the test waits (1 s: 5e5 macro
    # steps, within the 1e6 a run may take; 10 s would be refused before it starts).
    scene = write(tmp_path, "long.toml", BOUNCING.replace("t_end = 10.0", "t_end = 1.0").replace(
        "[output]", COUPLED[COUPLED.index("[tribology]"):COUPLED.index("[output]")] + "[output]"))
    out = tmp_path / "out"
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    # a non-interactive parent leaves SIGINT ignored in its children: restore the default
    proc = subprocess.Popen([sys.executable, "-m", "coupling.app.cli", "run", str(scene), "--out", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        lines = []
        while not any(" t = " in line for line in lines):  # the first progress line: mid-run
            line = proc.stderr.readline()
            assert line, lines
            lines.append(line)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "interrupted at t = " in err
    t_stop = interrupted_time(out)
    assert 0.0 < t_stop < 1.0
    waves = pd.read_csv(out / "waveforms.csv")
    assert waves.time.iloc[-1] <= t_stop * (1 + 1e-12) and waves.time.iloc[-1] > 0.5 * t_stop
    assert staging_left(tmp_path) == []


def test_ctrl_c_in_a_mechanics_run_keeps_the_partial_result(tmp_path, sigint_raises):
    """The same for the mechanics alone (KeyboardInterrupt delivered as SIGINT would, in-process)."""
    import _thread
    import threading

    warm = write(tmp_path, "drop.toml", DROP)
    assert main(["run", str(warm), "--out", str(tmp_path / "warm"), "--quiet"]) == 0  # compiled, loaded
    scene = write(tmp_path, "long.toml", BOUNCING)
    out = tmp_path / "out"
    timer = threading.Timer(2.0, _thread.interrupt_main)  # the run takes > 20 s: well inside it
    timer.start()
    try:
        rc = main(["run", str(scene), "--out", str(out), "--quiet"])
    finally:
        timer.cancel()
    assert rc == 130
    assert 0.0 < interrupted_time(out) < 1.0


@pytest.mark.parametrize("coupled", [False, True])
def test_an_interrupt_after_the_rows_are_kept_reports_where_the_history_ends(tmp_path, monkeypatch, coupled):
    """Ctrl-C lands where Python runs again after a compiled segment: it can come after the
    recorder kept the segment's rows and before the solver took the segment's end as its
    time. The partial result then says it stopped where its history ends, not at the
    segment's start (a fresh clone's run of the test above reported 0.2515 s with history to
    0.2807 s). The interrupt is made to land there: the fifth commit keeps its rows, then
    raises as Ctrl-C would."""
    from mech.recorder import Recorder

    from coupling.core.master import RunInterrupted

    commit, calls = Recorder.commit, []

    def interrupted(rec, rows, regime):
        commit(rec, rows, regime)
        calls.append(rows)
        if len(calls) == 5:
            raise KeyboardInterrupt

    monkeypatch.setattr(Recorder, "commit", interrupted)
    scene = load_scene(write(tmp_path, "long.toml", COUPLED if coupled else BOUNCING))
    with pytest.raises(RunInterrupted) as err:
        coupling.core.master.run(scene)
    partial = err.value.partial
    history = partial.mechanics.history
    assert partial.status == "interrupted" and history.time.iloc[-1] == partial.stopped_at > 0.0


# --- defaults and verbosity --------------------------------------------------------------

def test_run_without_out_writes_to_runs_scene_name(tmp_path, monkeypatch):
    scene = write(tmp_path, "my_relay.toml", DROP)
    monkeypatch.chdir(tmp_path)
    assert main(["run", "my_relay.toml", "--quiet"]) == 0
    summary = json.loads((tmp_path / "runs" / "my_relay" / "summary.json").read_text())
    assert summary["status"] == "ok" and summary["scene_file"] == str(scene.resolve())
    # the same scene again replaces its own result without --overwrite
    assert main(["run", "my_relay.toml", "--quiet"]) == 0


def test_quiet_keeps_the_result_lines_and_drops_the_chatter(tmp_path, capsys):
    scene = write(tmp_path, "drop.toml", DROP)
    assert main(["run", str(scene), "--out", str(tmp_path / "loud")]) == 0
    loud = capsys.readouterr()
    assert main(["run", str(scene), "--out", str(tmp_path / "quiet"), "--quiet"]) == 0
    quiet = capsys.readouterr()
    assert "contact(s), first restitution" in quiet.out and quiet.out == loud.out
    assert "running" in loud.err and "running" not in quiet.err


# --- the history is thinned to its resolution ----------------------------------------

def test_history_keeps_events_and_at_most_one_row_per_resolution_interval(tmp_path):
    from coupling.app.output import thin_history

    scene = write(tmp_path, "drop.toml", DROP.replace("plots = false", "plots = false\nhistory_max_rows = 10"))
    out = tmp_path / "out"
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 0
    history = pd.read_csv(out / "history.csv")
    summary = json.loads((out / "summary.json").read_text())
    assert summary["history"]["rows"] == len(history) < summary["history"]["solver_records"]
    events = pd.read_csv(out / "events.csv")
    phases = pd.read_csv(out / "phases.csv")
    assert len(events) > 0
    for t in events.time:  # every event instant is kept
        assert np.min(np.abs(history.time - t)) <= 1e-12 * max(t, 1.0)
    # one row per 0.1 ms interval (11 over 1 ms), plus two around each event and regime change
    assert len(history) <= 11 + 2 * (len(events) + len(phases)) + 2
    assert summary["history"]["resolution"] == pytest.approx(1e-4)  # 1 ms / 10 rows, above 1e-6 s

    class Stub:
        t = np.linspace(0.0, 1.0, 100_001)
        regimes = np.zeros((len(t), 2), int)
        events = []

    kept = thin_history(Stub, 1e-3)
    assert len(kept) == 1001 and kept[0] == 0 and kept[-1] == 100_000
    assert len(thin_history(Stub, 0.0)) == 100_001


def test_a_coupled_bar_bouncing_through_grazing_contact_ends_keeps_going(tmp_path):
    """The bouncing bar closing the circuit, 80 ms: at 74.9 ms a contact ends at 1 cm/s and a
    redone coupling step stopped a round-off sliver (5e-16 s) before that event; the step
    after it started from the sliver's own step and failed as 'step size too small'."""
    scene = write(tmp_path, "bounce.toml", BOUNCING.replace("t_end = 10.0", "t_end = 0.08").replace(
        "[output]", COUPLED[COUPLED.index("[tribology]"):COUPLED.index("[output]")] + "[output]"))
    out = tmp_path / "out"
    assert main(["run", str(scene), "--out", str(out), "--quiet"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "ok" and len(summary["contacts"]) >= 10
