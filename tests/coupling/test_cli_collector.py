"""`switchsim run` as its own process turns Python's cyclic collector off while it imports
and builds the scene, freezes what that made, and runs with the collector on; a caller of
the command line (argv given, CoupledResult.save, a sweep) keeps its collector as it was."""

from __future__ import annotations

import gc
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

from cli_checks import DROP

from coupling.app.cli import main

ROOT = Path(__file__).resolve().parents[2]


# The command line's own process (main() reading sys.argv); the run is wrapped to record the
# collector's state when it starts, and a garbage cycle made inside it must be collected.
ONE_SHOT = textwrap.dedent("""
    import gc, json, sys, weakref
    import coupling.core.master as master
    seen = {}
    inner = master.run
    class Cycle:
        pass
    def run(*args, **kw):
        seen["enabled"] = gc.isenabled()
        seen["frozen"] = gc.get_freeze_count()
        a, b = Cycle(), Cycle()
        a.other, b.other = b, a
        gone = weakref.ref(a)
        del a, b
        result = inner(*args, **kw)  # its young collections find the cycle
        gc.collect(1)
        seen["cycle_collected"] = gone() is None
        return result
    master.run = run
    from coupling.app.cli import main
    sys.argv = ["switchsim", "run", sys.argv[1], "--out", sys.argv[2], "--quiet"]
    code = main()
    print(json.dumps(dict(seen, code=code, enabled_after=gc.isenabled())))
""")


def test_the_command_lines_own_process_freezes_the_start_and_runs_with_the_collector_on(tmp_path):
    scene = tmp_path / "drop.toml"
    scene.write_text(DROP)
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    done = subprocess.run([sys.executable, "-c", ONE_SHOT, str(scene), str(tmp_path / "out")], env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    seen = json.loads(done.stdout.strip().splitlines()[-1])
    assert seen["code"] == 0 and (tmp_path / "out" / "summary.json").is_file()
    # numpy, mech and the scene's objects: tens of thousands, frozen before the run
    assert seen["frozen"] > 10_000, seen
    assert seen["enabled"] and seen["cycle_collected"], seen
    assert seen["enabled_after"]


def test_a_caller_of_the_command_line_keeps_its_collector_as_it_was(tmp_path, capsys):
    scene = tmp_path / "drop.toml"
    scene.write_text(DROP)
    frozen = gc.get_freeze_count()
    assert main(["run", str(scene), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    assert gc.isenabled() and gc.get_freeze_count() == frozen


def test_bad_input_in_the_command_lines_own_process_leaves_the_collector_on(tmp_path, capsys):
    from coupling.app.commands import run_command

    scene = tmp_path / "bad.toml"
    scene.write_text(DROP.replace("t_end = 0.001", "t_end = -1.0"))
    frozen = gc.get_freeze_count()
    try:
        run_command(str(scene), str(tmp_path / "out"), quiet=True, one_shot=True)
    except ValueError as err:
        assert "t_end" in str(err)
    else:
        raise AssertionError("a negative t_end was accepted")
    assert gc.isenabled() and gc.get_freeze_count() == frozen  # nothing frozen: the run never started
