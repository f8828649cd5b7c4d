"""Sweeps on real Dask clusters, under the audit's cases:

- the local cluster admits no other process (TLS with credentials made for it alone);
- a run that makes ngspice end its session ("cannot recover") no longer fails the good
  runs after it on the same worker: the worker is restarted; `--resume` reruns failed runs;
- two invocations on one folder at once: the second is refused (no run written twice);
- the docs' Python example, saved as a script, runs as written; without its
  `if __name__ == "__main__":` guard it stops at once, saying so, and blocks nothing;
- a study on a cluster started with `dask scheduler` / `dask worker` (two worker processes
  on loopback), one of them killed mid-study: no row lost, none twice.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

pytest.importorskip("distributed")

from coupling.app.sweep import finished_run_ids, local_cluster, read_results  # noqa: E402
from dask_cli_cluster import ENV, ROOT, dask_cli_cluster, stop  # noqa: E402

# A rigid bar dropped on one tip closing a netlist circuit (coupled, ~0.1 s a run).
BASE = textwrap.dedent("""
    [bar]
    modes = 0
    [initial]
    height = 0.0002
    angle_deg = 90.0
    velocity = [0.0, 0.0, -0.5]
    [solver]
    t_end = 0.001
    [tribology]
    source = "illustrative"
    [circuit]
    template = "netlist"
    netlist = "good.cir"
    [output]
    plots = false
    """)
GOOD = "relay\nV1 s 0 12\nR1 s a 1\nXCONTACT a b\nVLOAD b c 0\nRl c 0 11\n"
# passes the netlist checks; ngspice cannot parse the expression and ends its session for
# the whole process ("cannot recover"): every later circuit in that process fails
POISON = GOOD + "Rx c 0 {1+}\n"


def cli(*args: str, cwd: Path | None = None, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "coupling", *args], cwd=cwd, env=ENV, capture_output=True,
                          text=True, timeout=timeout)


def netlist_sweep(folder: Path, netlists: list[str]) -> Path:
    (folder / "base.toml").write_text(BASE)
    (folder / "good.cir").write_text(GOOD)
    (folder / "poison.cir").write_text(POISON)
    text = '[sweep]\nscene = "base.toml"\ndesign = "cases"\n'
    for k, name in enumerate(netlists):
        text += f'[[sweep.cases]]\nname = "r{k}"\n"circuit.netlist" = "{name}.cir"\n'
    (folder / "sw.toml").write_text(text)
    return folder / "sw.toml"


# --- the local cluster --------------------------------------------------------------------

FOREIGN = textwrap.dedent("""
    import json, sys
    from distributed import Client
    from distributed.security import Security
    out = {}
    for address in json.loads(sys.argv[1]):
        for label, form, security in (("as given", address, None),
                                      ("plain tcp", address.replace("tls://", "tcp://"), None),
                                      ("other credentials", address, Security.temporary())):
            try:
                with Client(form, timeout=2, security=security) as client:
                    out[f"{address} {label}"] = client.run(lambda: "code ran")
            except Exception as err:
                out[f"{address} {label}"] = f"refused: {type(err).__name__}"
    print(json.dumps(out))
""")


def test_a_foreign_process_cannot_reach_the_local_cluster():
    """Another process on the machine connected to the scheduler's TCP port and ran code in
    the workers. Now every listener (scheduler, worker, nanny) takes TLS connections with
    this cluster's credentials only: no connection as given, as plain TCP, or with
    credentials of its own; the cluster's own client runs code (the control)."""
    from distributed import Client

    with local_cluster(1) as cluster, Client(cluster) as client:
        assert client.run(lambda: "code ran") != {}
        info = client.scheduler_info()["workers"]
        addresses = [cluster.scheduler_address, *info, *(w["nanny"] for w in info.values())]
        assert all(a.startswith("tls://127.0.0.1:") for a in addresses), addresses  # loopback only
        child = subprocess.run([sys.executable, "-c", FOREIGN, json.dumps(addresses)], env=ENV, capture_output=True,
                               text=True, timeout=300)
        outcomes = json.loads(child.stdout)
        assert len(outcomes) == 3 * len(addresses)
        assert all(isinstance(v, str) and v.startswith("refused") for v in outcomes.values()), outcomes


def test_a_run_that_ends_ngspice_fails_alone_and_resume_reruns_it(tmp_path):
    """One worker, five runs, the second poisons ngspice: before, the three after it failed
    with 'ngspice has exited'; now the worker is restarted and they are ok. `--resume` then
    reruns the failed run alone (its netlist fixed meanwhile) and replaces its row."""
    sweep = netlist_sweep(tmp_path, ["good", "poison", "good", "good", "good"])
    out = tmp_path / "out"
    done = cli("sweep", str(sweep), "--out", str(out), "--workers", "1")
    assert done.returncode == 1, done.stderr  # one run failed
    df = read_results(out).set_index("run_id").sort_index()
    assert list(df.status) == ["ok", "failed", "ok", "ok", "ok"], df.error.to_dict()
    assert "could not parse" in df.error["r1"]
    assert "run r1 ended ngspice in its worker; worker restarted (OK)" in done.stderr
    first_session = df.session["r0"]

    (tmp_path / "poison.cir").write_text(GOOD)  # the user fixes the netlist; the sweep is the same
    again = cli("sweep", str(sweep), "--out", str(out), "--workers", "1", "--resume")
    assert again.returncode == 0, again.stderr
    assert "rerunning 1 failed run(s)" in again.stderr
    df = read_results(out).set_index("run_id").sort_index()
    assert list(df.index) == ["r0", "r1", "r2", "r3", "r4"] and (df.status == "ok").all()  # one row each
    assert (df.session.drop("r1") == first_session).all() and df.session["r1"] != first_session
    # the rerun computes what the good netlist gives: the same contact as the other runs
    assert df["bounce.first_make"]["r1"] == df["bounce.first_make"]["r0"]


def test_two_invocations_on_one_folder_at_once_write_each_run_once(tmp_path):
    """Two `--resume` at once gave 16 rows for 8 runs; now the second is refused in one line."""
    sweep = netlist_sweep(tmp_path, ["good"] * 8)
    out = tmp_path / "out"
    def start():
        return subprocess.Popen([sys.executable, "-m", "coupling", "sweep", str(sweep), "--out", str(out),
                                 "--workers", "1", "--resume", "--quiet"], env=ENV, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)

    # the second starts once the first holds the folder (started together, a loaded machine
    # let the first finish before the second looked: both exited 0)
    procs = [start()]
    deadline = time.monotonic() + 120
    while not (out / ".sweep.lock").exists() and procs[0].poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    procs.append(start())
    results = [(p.wait(timeout=300), p.stderr.read()) for p in procs]
    codes = sorted(code for code, _ in results)
    assert codes == [0, 2], results
    refused = next(err for code, err in results if code == 2)
    assert re.fullmatch(r"switchsim: error: \S+ is in use by another sweep \(process \d+\): wait for it to "
                        r"finish, or use another --out\n", refused), refused
    df = read_results(out)
    assert sorted(df.run_id) == [f"r{k}" for k in range(8)] and (df.status == "ok").all()


# --- the docs' Python example -------------------------------------------------------------

def docs_example() -> str:
    text = (ROOT / "docs" / "sweeps.md").read_text()
    section = text[text.index("## Python"):]
    start = section.index("```python\n") + len("```python\n")
    return section[start:section.index("\n```", start)] + "\n"


def test_the_docs_python_example_runs_as_a_script_and_without_its_guard_blocks_nothing(tmp_path):
    (tmp_path / "examples").mkdir()
    shutil.copy(ROOT / "examples" / "snubber_design.toml", tmp_path / "examples")
    example = docs_example()
    assert 'if __name__ == "__main__":' in example
    unguarded = example.replace('if __name__ == "__main__":  # needed in a script: every worker process imports '
                                'it again\n    main()', "main()")
    assert unguarded != example
    (tmp_path / "unguarded.py").write_text(unguarded)
    tick = time.monotonic()
    done = subprocess.run([sys.executable, "unguarded.py"], cwd=tmp_path, env=ENV, capture_output=True, text=True,
                          timeout=300)
    assert time.monotonic() - tick < 120  # stops at once, never hangs
    assert done.returncode != 0
    assert "the local Dask cluster did not start" in done.stderr
    assert 'put the sweep under `if __name__ == "__main__":`' in done.stderr
    assert not finished_run_ids(tmp_path / "out")

    (tmp_path / "example.py").write_text(example)  # as written, into the same out/: no --resume needed
    done = subprocess.run([sys.executable, "example.py"], cwd=tmp_path, env=ENV, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    df = read_results(tmp_path / "out").sort_values("circuit.snubber.capacitance")
    assert list(df.status) == ["ok"] * 3
    # a larger snubber capacitor lowers the peak opening voltage (examples/snubber_design.py's test
    # bounds it by E + I_min sqrt(L / C))
    peaks = list(df["bounce.peak_contact_voltage"])
    assert peaks[0] > peaks[1] > peaks[2], peaks
    assert "bounce.peak_contact_voltage" in done.stdout


# --- a cluster started with Dask's own commands -----------------------------------------------

ANGLES = 12
DROP = textwrap.dedent("""
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
    """)  # ~0.25 s a run


def test_a_study_on_a_dask_cli_cluster_loses_no_row_when_a_worker_is_killed(tmp_path):
    (tmp_path / "drop.toml").write_text(DROP)
    angles = ", ".join(f"{20.0 + 3.0 * k:.1f}" for k in range(ANGLES))
    (tmp_path / "sw.toml").write_text(f'[sweep]\nscene = "drop.toml"\ndesign = "grid"\n'
                                      f'[sweep.grid]\n"initial.angle_deg" = [{angles}]\n')
    out = tmp_path / "out"
    with dask_cli_cluster(tmp_path / "dask", workers=2) as (address, scheduler_file, workers):
        proc = subprocess.Popen([sys.executable, "-m", "coupling", "sweep", str(tmp_path / "sw.toml"), "--out",
                                 str(out), "--scheduler", address, "--quiet"], env=ENV, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        end = time.monotonic() + 180
        while len(finished_run_ids(out)) < 2 if (out / "results").is_dir() else True:
            assert time.monotonic() < end and proc.poll() is None, proc.stderr.read() if proc.poll() else "slow"
            time.sleep(0.05)
        assert len(finished_run_ids(out)) < ANGLES  # mid-study
        stop(workers[0])  # the whole `dask worker` (nanny and worker): its runs go to the other one
        _, err = proc.communicate(timeout=300)
        assert proc.returncode == 0, err
    df = read_results(out)
    assert sorted(df.run_id) == [f"run{k:04d}" for k in range(ANGLES)] and (df.status == "ok").all()
    assert df.session.nunique() == 1
