"""A Dask cluster started the way a user starts one: `dask scheduler` and `dask worker`
processes on loopback (plain TCP: such a cluster's security is its owner's), for the sweep
tests that run `switchsim sweep --scheduler`."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DASK = str(Path(sys.executable).with_name("dask"))
# the worker settings docs/sweeps.md asks of an existing cluster, and the project on the path
ENV = {**os.environ, "DASK_DISTRIBUTED__WORKER__PROFILE__ENABLED": "False",
       "PYTHONPATH": os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH")) if p)}


def start_worker(scheduler_file: Path, log: Path) -> subprocess.Popen:
    """One `dask worker` process (a nanny and its one worker process, one thread)."""
    return subprocess.Popen([DASK, "worker", "--scheduler-file", str(scheduler_file), "--nworkers", "1",
                             "--nthreads", "1", "--no-dashboard", "--host", "127.0.0.1"],
                            env=ENV, stdout=subprocess.DEVNULL, stderr=open(log, "ab"), start_new_session=True)


def wait_for_workers(address: str, n: int, timeout: float = 120.0) -> None:
    from distributed import Client

    with Client(address, timeout="30s") as client:
        client.wait_for_workers(n, timeout=timeout)


@contextlib.contextmanager
def dask_cli_cluster(folder: Path, workers: int = 2):
    """Yields (scheduler address, scheduler file, worker processes); everything started here
    is ended here, by process group."""
    folder.mkdir(parents=True, exist_ok=True)
    scheduler_file = folder / "scheduler.json"
    log = folder / "dask.log"
    procs = [subprocess.Popen([DASK, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                               "--scheduler-file", str(scheduler_file)],
                              env=ENV, stdout=subprocess.DEVNULL, stderr=open(log, "ab"), start_new_session=True)]
    try:
        end = time.monotonic() + 60
        while not scheduler_file.is_file() or not scheduler_file.read_text().strip():
            if time.monotonic() > end or procs[0].poll() is not None:
                raise RuntimeError(f"dask scheduler did not start: {log.read_text()[-2000:]}")
            time.sleep(0.1)
        address = json.loads(scheduler_file.read_text())["address"]
        worker_procs = [start_worker(scheduler_file, log) for _ in range(workers)]
        procs += worker_procs
        wait_for_workers(address, workers)
        yield address, scheduler_file, worker_procs
    finally:
        for proc in reversed(procs):
            stop(proc)


def stop(proc: subprocess.Popen) -> None:
    """End a process started here and its children (its own process group)."""
    if proc.poll() is None:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGTERM)
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    with contextlib.suppress(ProcessLookupError):
        os.killpg(proc.pid, signal.SIGKILL)  # anything of the group left behind
