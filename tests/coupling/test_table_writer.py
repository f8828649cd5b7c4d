"""The large tables' helper process of `switchsim run` (coupling.app.table_writer): the files
it writes are the bytes one process writes, a table it could not write is written by the
command itself, and the command line's own process uses it for a co-simulation.

Each case runs in a fresh interpreter: the helper is forked, and a fork of the test
process (its threads, its ngspice) is not what the command line forks."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

if not sys.platform.startswith("linux"):
    pytest.skip("the helper is forked on Linux only", allow_module_level=True)


def python(script: str, *args: str) -> dict:
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    done = subprocess.run([sys.executable, "-c", textwrap.dedent(script), *args], env=env, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


# Tables of every kind write_csv and write_parquet meet: floats of every formatting class
# (arrow_text's probe values), NaN, a constant column, integers, a coded column, enough
# rows for the Arrow route; and a small table of text.
TABLES = """
    import json, os, sys
    from pathlib import Path
    import numpy as np
    from coupling.app import arrow_text
    from coupling.app.output import write_csv, write_parquet
    from coupling.app.table_writer import TableWriter

    rng = np.random.default_rng(5)
    probe = arrow_text.probe_values()
    n = 40 * len(probe)
    floats = np.concatenate([probe] * 40)
    wave = {"time": np.linspace(0.0, 1e-3, n), "v": floats, "i": rng.standard_normal(n) * 1e-3,
            "flat": np.full(n, 0.25), "count": np.arange(n) - 7}
    history = {"time": np.linspace(0.0, 1.0, n), "x": floats[::-1].copy(),
               "strided": np.repeat(rng.standard_normal(n), 2)[::2], "regime_0": np.arange(n) % 3}
    codes = {"regime_0": ("flight", "stick", "slip")}
    text = {"name": ["a", "b,c", 'd"e'], "value": [1.0, float("nan"), 3.5]}
    jobs = [("write_parquet", "waveforms.parquet", (wave,)), ("write_csv", "waveforms.csv", (wave,)),
            ("write_csv", "history.csv", (history, codes)), ("write_csv", "text.csv", (text,))]
    here, there = Path(sys.argv[1]), Path(sys.argv[2])
"""


def test_the_helper_writes_the_bytes_one_process_writes(tmp_path):
    (tmp_path / "here").mkdir()
    (tmp_path / "there").mkdir()
    seen = python(TABLES + """
    writer = TableWriter.start()
    sent = [writer.submit(f, there / name, *args) for f, name, args in jobs]
    answers = writer.collect()
    helper = writer.pid
    writer.close()
    arrow_here = "pyarrow" in sys.modules  # the helper imported it, not this process
    for f, name, args in jobs:
        {"write_csv": write_csv, "write_parquet": write_parquet}[f](here / name, *args)
    same = {name: (here / name).read_bytes() == (there / name).read_bytes() for _, name, _ in jobs}
    print(json.dumps(dict(sent=sent, answers=answers, helper=helper, me=os.getpid(), arrow_here=arrow_here,
                          same=same)))
    """, str(tmp_path / "here"), str(tmp_path / "there"))
    assert seen["sent"] == [True] * 4
    assert seen["answers"] == {str(tmp_path / "there" / name): None for name in seen["same"]}
    assert seen["helper"] not in (0, seen["me"]) and not seen["arrow_here"]
    assert all(seen["same"].values()), seen["same"]


def test_a_table_the_helper_cannot_write_is_answered_with_its_error(tmp_path):
    seen = python(TABLES + """
    writer = TableWriter.start()
    assert writer.submit("write_csv", there / "missing" / "t.csv", wave)
    assert writer.submit("write_csv", there / "t.csv", wave)
    answers = writer.collect()
    writer.close()
    print(json.dumps(answers))
    """, str(tmp_path), str(tmp_path))
    assert seen[str(tmp_path / "t.csv")] is None
    assert seen[str(tmp_path / "missing" / "t.csv")].startswith("FileNotFoundError")


@pytest.mark.parametrize("when", ["before", "after"])
def test_a_helper_that_dies_costs_no_file(tmp_path, when):
    """Killed before the tables are sent (submit says so) or after (collect says so): the
    command writes every table itself, the same bytes."""
    (tmp_path / "here").mkdir()
    (tmp_path / "there").mkdir()
    seen = python(TABLES + """
    import signal
    from coupling.app.output import write_files

    class Result:  # what write_files reads of a run's result, its tables only
        def __init__(self):
            from coupling.core.scene import builtin_scene
            self.scene = builtin_scene("relay_force").set("output.html", False)
            self.summary, self.waveform_columns, self.mechanics = {}, wave, None
            self.opening_columns, self.contact_results = text, ()

    writer = TableWriter.start()
    if sys.argv[3] == "before":
        os.kill(writer.pid, signal.SIGKILL)
        os.waitpid(writer.pid, 0)
        writer.pid = 0
    else:  # the tables taken, then the helper gone before it answered
        submit = writer.submit
        def submit_then_die(*args):
            ok = submit(*args)
            if writer.pid:
                os.kill(writer.pid, signal.SIGKILL)
                os.waitpid(writer.pid, 0)
                writer.pid = 0
            return ok
        writer.submit = submit_then_die
    write_files(Result(), there, writer=writer)
    writer.close()
    write_files(Result(), here)
    names = sorted(p.name for p in here.iterdir())
    same = {name: (here / name).read_bytes() == (there / name).read_bytes() for name in names}
    print(json.dumps(dict(names=names, there=sorted(p.name for p in there.iterdir()), same=same)))
    """, str(tmp_path / "here"), str(tmp_path / "there"), when)
    assert seen["names"] == seen["there"] and "waveforms.csv" in seen["names"]
    assert "waveforms.parquet" in seen["names"] and "summary.json" in seen["names"]
    assert all(same for name, same in seen["same"].items() if name != "summary.json"), seen["same"]


ONE_SHOT = """
    import json, sys
    import coupling.app.table_writer as tw
    used = {}
    start, collect = tw.TableWriter.start, tw.TableWriter.collect
    def started(cls):
        writer = start()
        used["started"] = writer is not None
        return writer
    def collected(self):
        answers = collect(self)
        used.setdefault("answers", {}).update({k.rsplit("/", 1)[-1]: v for k, v in answers.items()})
        return answers
    tw.TableWriter.start = classmethod(started)
    tw.TableWriter.collect = collected
    import coupling.app.history_stream as hs
    hs.PIECE_ROWS = int(sys.argv[3])  # (pieces of a short run's history)
    send_piece = tw.TableWriter.send_piece
    def sent_piece(self, *args):
        used["pieces"] = used.get("pieces", 0) + 1
        return send_piece(self, *args)
    tw.TableWriter.send_piece = sent_piece
    from coupling.app.cli import main
    sys.argv = ["switchsim", "run", sys.argv[1], "--out", sys.argv[2], "--quiet"]
    code = main()
    print(json.dumps(dict(used, code=code)))
"""


@pytest.mark.parametrize("piece_rows", [64, 100_000])
def test_the_command_lines_own_process_writes_the_large_tables_through_the_helper(tmp_path, piece_rows):
    """The same folder as CoupledResult.save's (one process), every table but the summary's
    timings byte for byte; the helper wrote waveforms.parquet, waveforms.csv, history.csv,
    history.csv's rows in pieces sent while the run went on (coupling.app.history_stream) or,
    with pieces longer than the run's history, whole after it."""
    from coupling.core.scene import builtin_scene_text

    path = tmp_path / "s.toml"
    path.write_text(builtin_scene_text("relay_force").replace("t_end = 0.005", "t_end = 0.001"))
    seen = python(ONE_SHOT, str(path), str(tmp_path / "cli"), str(piece_rows))
    if len(os.sched_getaffinity(0)) < 2:
        pytest.skip("one CPU: the command writes in one process")
    assert seen["code"] == 0 and seen["started"]
    assert seen["answers"] == {"waveforms.parquet": None, "waveforms.csv": None, "history.csv": None}
    assert (seen.get("pieces", 0) >= 2) == (piece_rows == 64)

    from coupling import run

    from coupling.core.scene import load_scene

    run(load_scene(str(path))).save(tmp_path / "api")
    names = sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert names == sorted(p.name for p in (tmp_path / "api").iterdir())
    for name in names:
        if name != "summary.json":
            assert (tmp_path / "cli" / name).read_bytes() == (tmp_path / "api" / name).read_bytes(), name
    cli, api = (json.loads((tmp_path / d / "summary.json").read_text()) for d in ("cli", "api"))
    assert list(cli) == list(api) + ["scene_file"]  # (the command line names its scene file)
    assert cli["history"] == api["history"] and cli["status"] == api["status"]


def test_only_a_co_simulation_that_writes_large_tables_gets_the_helper(tmp_path):
    from cli_checks import DROP

    from coupling.app.table_writer import wanted
    from coupling.core.scene import builtin_scene, load_scene

    relay = builtin_scene("relay_force")
    assert wanted(relay, cpus=2) and not wanted(relay, cpus=1)  # (on one CPU it would slow the run)
    assert not wanted(relay.set("output.csv", False).set("output.parquet", False).set("output.history", False),
                      cpus=2)
    assert wanted(relay.set("output.csv", False).set("output.parquet", False), cpus=2)
    (tmp_path / "drop.toml").write_text(DROP)
    drop = load_scene(str(tmp_path / "drop.toml"))  # the mechanics alone: over before the helper is ready
    assert drop.circuit is None and not wanted(drop, cpus=2)
