"""The command line's own process (``python -m coupling``, the `switchsim` script) ends at once
after `switchsim run` (coupling.app.cli.entry: os._exit, no interpreter teardown): what it
printed still arrives whole through pipes, its exit code is the command's, and its result
folder is complete."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
ENV = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")


def switchsim(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "coupling", *args], cwd=cwd, env=ENV, capture_output=True,
                          text=True, timeout=300)


def test_a_run_ends_with_its_output_and_its_result_whole(tmp_path):
    from coupling.core.scene import builtin_scene_text

    scene = tmp_path / "s.toml"
    scene.write_text(builtin_scene_text("relay_force").replace("t_end = 0.005", "t_end = 0.001"))
    done = switchsim("run", str(scene), "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    # the last line, written just before the process ends, arrived through the pipe
    assert done.stderr.rstrip().splitlines()[-1] == f"switchsim: status ok; wrote {tmp_path / 'out'}"
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["status"] == "ok"
    for name in ("waveforms.csv", "history.csv", "waveforms.parquet"):
        assert (tmp_path / "out" / name).stat().st_size > 0


def test_a_run_with_bad_input_exits_with_its_code_and_says_why(tmp_path):
    scene = tmp_path / "bad.toml"
    scene.write_text("[solver]\nt_end = -1.0\n")
    done = switchsim("run", str(scene), "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert done.returncode == 2
    assert "t_end" in done.stderr and not (tmp_path / "out").exists()


def test_another_command_prints_all_it_has_to_say(tmp_path):
    """`switchsim scene` writes a whole scene to stdout (through a pipe: block-buffered)."""
    from coupling.core.scene import builtin_scene_text

    done = switchsim("scene", "default", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout == builtin_scene_text("default")
