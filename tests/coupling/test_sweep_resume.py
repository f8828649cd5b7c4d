"""An interrupted sweep loses nothing and redoes nothing: Ctrl-C, a killed client, a killed worker.

Each test runs `switchsim sweep` in a subprocess on a small sweep of tiny mechanics-only
scenes (one worker; ~0.2 s a run, so the interruption lands mid-sweep), interrupts it
once some rows are on disk, resumes it, and checks the results dataset: every run
exactly once, the rows written before the interruption untouched (same session, same
values), the rest written by the resume.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

pytest.importorskip("distributed")
psutil = pytest.importorskip("psutil")

from coupling.app.sweep import finished_run_ids, read_results  # noqa: E402
from dask_cli_cluster import dask_cli_cluster  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
RUNS = 10

SCENE = """
[bar]
length = 0.1
diameter = 0.006
tip_radius = 0.003
modes = 8
[initial]
height = 0.0001
angle_deg = 30.0
velocity = [0.0, 0.0, -1.0]
[solver]
t_end = 0.016
"""  # ~0.25 s a run in-process: at 4 ms (50 ms a run) a Ctrl-C after two rows sometimes
# reached the client only after all ten were written, and the test could not interrupt


def _write(tmp_path: Path) -> Path:
    (tmp_path / "tiny.toml").write_text(SCENE)
    angles = ", ".join(f"{a:.1f}" for a in [20.0 + 3.0 * k for k in range(RUNS)])
    path = tmp_path / "sw.toml"
    path.write_text(textwrap.dedent(f"""
        [sweep]
        scene = "tiny.toml"
        design = "grid"
        [sweep.grid]
        "initial.angle_deg" = [{angles}]
    """))
    return path


@pytest.fixture(scope="module")
def scheduler(tmp_path_factory):
    """One Dask cluster shared by the sweeps of this module through --scheduler, started as a
    user starts one (`dask scheduler`, one `dask worker`): the worker imports once. (The
    local cluster, `--workers`, is tested in test_sweep_cluster.py.)"""
    with dask_cli_cluster(tmp_path_factory.mktemp("dask"), workers=1) as (address, _, _):
        yield address


def _start(sweep: Path, out: Path, *extra: str) -> subprocess.Popen:
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    return subprocess.Popen([sys.executable, "-m", "coupling.app.cli", "sweep", str(sweep), "--out", str(out),
                             "--quiet", *extra],
                            env=env, start_new_session=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))  # see tests/conftest.py


def _wait_rows(out: Path, proc: subprocess.Popen, at_least: int, timeout: float = 120.0) -> int:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        n = len(finished_run_ids(out)) if (out / "results").is_dir() else 0
        if n >= at_least:
            return n
        if proc.poll() is not None:
            raise AssertionError(f"the sweep ended before {at_least} rows: {proc.stderr.read().decode()[-2000:]}")
        time.sleep(0.05)
    raise AssertionError(f"fewer than {at_least} rows after {timeout} s")


def _reap(proc: subprocess.Popen, children: list) -> None:
    """Wait for the client; end what it started if it left anything behind (by pid)."""
    try:
        proc.wait(timeout=60)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()
    for child in children:
        try:
            child.kill()
        except psutil.NoSuchProcess:
            pass


def _children(proc: subprocess.Popen) -> list:
    try:
        return psutil.Process(proc.pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return []


def _check_complete(out: Path, before) -> None:
    df = read_results(out)
    assert sorted(df.run_id) == [f"run{k:04d}" for k in range(RUNS)]  # each run exactly once
    assert (df.status == "ok").all()
    # rows written before the interruption are still there, from the first session, unchanged
    kept = df.set_index("run_id").loc[before.run_id]
    assert list(kept.session) == list(before.session)
    assert list(kept["restitution.kinematic"]) == list(before["restitution.kinematic"])
    assert df.session.nunique() == 2


def _resume(sweep: Path, out: Path, *extra: str) -> None:
    proc = _start(sweep, out, "--resume", *extra)
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 0, err.decode()[-2000:]


@pytest.mark.parametrize("how", ["ctrl_c", "killed_client"])
def test_interrupted_sweep_resumes_without_losing_or_redoing_runs(tmp_path, how, scheduler):
    sweep, out = _write(tmp_path), tmp_path / "out"
    proc = _start(sweep, out, "--scheduler", scheduler)
    _wait_rows(out, proc, 2)
    children = _children(proc)
    if how == "ctrl_c":
        os.killpg(proc.pid, signal.SIGINT)  # a terminal's Ctrl-C reaches the whole process group
        proc.wait(timeout=60)
        assert proc.returncode == 130, proc.stderr.read().decode()[-2000:]
    else:
        proc.send_signal(signal.SIGKILL)
    _reap(proc, children)
    before = read_results(out)
    assert 2 <= len(before) < RUNS  # really interrupted
    assert before.run_id.is_unique
    _resume(sweep, out, "--scheduler", scheduler)
    _check_complete(out, before)


def test_a_killed_worker_loses_no_run_and_resume_then_has_nothing_to_do(tmp_path, scheduler):
    from distributed import Client

    with Client(scheduler, timeout="30s") as client:
        pids = list(client.run(os.getpid).values())
    sweep, out = _write(tmp_path), tmp_path / "out"
    proc = _start(sweep, out, "--scheduler", scheduler)
    assert _wait_rows(out, proc, 2) < RUNS and proc.poll() is None  # the sweep is still running
    psutil.Process(pids[0]).kill()  # the nanny starts a new worker; Dask reruns the run that was on it
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 0, err.decode()[-2000:]
    df = read_results(out)
    assert sorted(df.run_id) == [f"run{k:04d}" for k in range(RUNS)] and (df.status == "ok").all()
    _resume(sweep, out, "--scheduler", scheduler)  # nothing to redo: no new rows
    again = read_results(out)
    assert len(again) == RUNS and again.session.nunique() == 1
