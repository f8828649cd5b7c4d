"""Result folders under the audit's cases: a file put into the folder during a run, a kill in
the middle of the replacement, `switchsim fit --out` over an earlier fit and Ctrl-C while it
draws, `switchsim plot` of a damaged summary.json, and the working folder's matplotlibrc
and tomllib.py.

Runs are a rigid bar dropped on one tip (mechanics only, a few ms of compute); a kill is a
child process that SIGKILLs itself at the chosen point of the replacement.
"""

from __future__ import annotations

import json
import os
import shutil
import struct
import subprocess
import sys
import textwrap
from pathlib import Path
from unittest import mock

import pytest

import coupling.core.master
from coupling.app.cli import main
from coupling.laws.tribology import illustrative_data_path

ROOT = Path(__file__).resolve().parents[2]
DROP = textwrap.dedent("""
    [bar]
    modes = 0
    [initial]
    height = 0.0002
    angle_deg = 90.0
    velocity = [0.0, 0.0, -0.5]
    [solver]
    t_end = {t_end}
    [output]
    plots = false
    """)
# (an empty PYTHONPATH entry would put the working folder on the path itself)
ENV = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH")) if p)}


def scene(tmp_path: Path, t_end: float = 0.001) -> Path:
    path = tmp_path / "drop.toml"
    path.write_text(DROP.format(t_end=t_end))
    return path


def t_end_of(folder: Path) -> float:
    """The last time of the result's history: tells the first run (1 ms) from the second (2 ms)."""
    return float((folder / "history.csv").read_text().strip().splitlines()[-1].split(",")[0])


def during_the_run(action):
    """The simulation, then ``action()`` before the result is written: what a user does while it runs."""
    real = coupling.core.master.run

    def run(*args, **kwargs):
        result = real(*args, **kwargs)
        action()
        return result

    return mock.patch.object(coupling.core.master, "run", run)


# --- a file put into the result folder during the run ------------------------------------

@pytest.mark.parametrize("existing", [True, False], ids=["over a previous result", "into a new folder"])
def test_a_file_put_into_the_folder_during_the_run_survives(tmp_path, capsys, existing):
    path, out = scene(tmp_path), tmp_path / "out"
    if existing:
        assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
        path.write_text(DROP.format(t_end=0.002))
    with during_the_run(lambda: (out.mkdir(exist_ok=True), (out / "notes.txt").write_text("my notes"))):
        assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    assert (out / "notes.txt").read_text() == "my notes"
    assert json.loads((out / "summary.json").read_text())["status"] == "ok"
    assert t_end_of(out) == pytest.approx(0.002 if existing else 0.001)  # the new result, whole
    assert not [p.name for p in tmp_path.iterdir() if p.name.startswith(".switchsim")]


def test_a_file_put_there_under_a_result_files_name_makes_the_run_refuse(tmp_path, capsys):
    """A new folder made during the run with a file the result also writes: the result does
    not replace it (without --overwrite); the run says so and exits 1."""
    path, out = scene(tmp_path), tmp_path / "out"
    with during_the_run(lambda: (out.mkdir(), (out / "events.csv").write_text("mine"))):
        assert main(["run", str(path), "--out", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert "events.csv appeared there during the run" in err and "nothing was replaced" in err
    assert [p.name for p in out.iterdir()] == ["events.csv"] and (out / "events.csv").read_text() == "mine"
    with during_the_run(lambda: (out / "events.csv").write_text("mine again")):
        assert main(["run", str(path), "--out", str(out), "--quiet", "--overwrite"]) == 0
    assert (out / "events.csv").read_text() != "mine again"  # --overwrite: the result's own file


# --- a kill in the middle of the replacement ------------------------------------------------

KILL = textwrap.dedent("""
    import os, signal, sys
    from pathlib import Path
    import coupling.app.output as output
    out = Path(sys.argv[2]).absolute()
    if sys.argv[1] == "no-exchange" and hasattr(output, "_exchange"):
        output._exchange = lambda a, b: False  # a file system without RENAME_EXCHANGE
    real = os.rename
    def rename(src, dst, *a, **k):
        real(src, dst, *a, **k)
        if Path(src).absolute() == out:  # the previous result just moved aside
            os.kill(os.getpid(), signal.SIGKILL)
    output.os.rename = rename
    from coupling.app.cli import main
    sys.exit(main(sys.argv[3:]))
""")


def kill_child(mode: str, out: Path, *argv: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", KILL, mode, str(out), *argv], env=ENV, capture_output=True,
                          text=True, timeout=300)


def test_the_replacement_never_leaves_the_folder_missing(tmp_path):
    """The default route exchanges the two folders in one rename: a kill armed to strike
    when the previous result is moved aside never strikes, and the new result is in place."""
    path, out = scene(tmp_path), tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    path.write_text(DROP.format(t_end=0.002))
    child = kill_child("exchange", out, "run", str(path), "--out", str(out), "--quiet")
    assert child.returncode == 0, child.stderr
    assert t_end_of(out) == pytest.approx(0.002)


@pytest.mark.parametrize("command", ["run", "plot"])
def test_a_kill_between_the_two_renames_is_undone_by_the_next_run_or_plot(tmp_path, capsys, command):
    path, out = scene(tmp_path), tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    path.write_text(DROP.format(t_end=0.002))
    child = kill_child("no-exchange", out, "run", str(path), "--out", str(out), "--quiet")
    assert child.returncode == -9
    assert not out.exists()  # the state the kill leaves: the previous result only under a hidden name
    capsys.readouterr()
    if command == "run":
        assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
        assert t_end_of(out) == pytest.approx(0.002)
    else:
        with mock.patch("coupling.app.plots.save_plots", return_value=[]):  # drawing is not the point
            assert main(["plot", str(out)]) == 0
        assert t_end_of(out) == pytest.approx(0.001)  # the previous result, back whole
    err = capsys.readouterr().err
    assert f"restored {out}: a replacement of it was interrupted" in err
    # the killed run's unfinished folder (its new result, never put in place) is named, not deleted
    left = [p.name for p in tmp_path.iterdir() if p.name.startswith(".switchsim")]
    assert len(left) == 1 and left[0].startswith(".switchsim-out-") and f"{left[0]} beside {out}: left by a run" in err


# --- switchsim fit --out ------------------------------------------------------------------

def data_copy(tmp_path: Path, name: str) -> Path:
    path = tmp_path / name
    shutil.copyfile(illustrative_data_path(), path)
    return path


def test_fit_does_not_replace_another_fit_without_overwrite(tmp_path, capsys):
    a, b, out = data_copy(tmp_path, "a.csv"), data_copy(tmp_path, "b.csv"), tmp_path / "fit"
    assert main(["fit", str(a), "--out", str(out)]) == 0
    first = (out / "fit.json").read_bytes()
    capsys.readouterr()
    assert main(["fit", str(b), "--out", str(out)]) == 2
    line = capsys.readouterr().err.strip()
    assert line.count("\n") == 0 and "holds files that are not a fit of this data file" in line and "--overwrite" in line
    assert (out / "fit.json").read_bytes() == first
    assert main(["fit", str(a), "--out", str(out)]) == 0  # the same data: a fit of it is replaced, as a run's result
    assert main(["fit", str(b), "--out", str(out), "--overwrite"]) == 0
    assert json.loads((out / "fit.json").read_text())["source"] == str(b)


def test_ctrl_c_while_fit_draws_leaves_the_folder_as_it_was(tmp_path, capsys):
    import coupling.app.fit_plots as fit_plots

    data, out = data_copy(tmp_path, "a.csv"), tmp_path / "fit"
    real = fit_plots.save_plots

    def interrupted(fit, df, folder):
        real(fit, df, folder)  # the figures are written, then Ctrl-C before fit.json
        raise KeyboardInterrupt

    with mock.patch.object(fit_plots, "save_plots", interrupted):
        assert main(["fit", str(data), "--out", str(out)]) == 130
    assert not out.exists()
    assert main(["fit", str(data), "--out", str(out)]) == 0
    kept = {p.name: p.read_bytes() for p in out.iterdir()}
    with mock.patch.object(fit_plots, "save_plots", interrupted):
        assert main(["fit", str(data), "--out", str(out)]) == 130
    assert {p.name: p.read_bytes() for p in out.iterdir()} == kept  # the earlier fit, whole
    assert not [p.name for p in tmp_path.iterdir() if p.name.startswith(".switchsim")]


# --- switchsim plot of a damaged result ---------------------------------------------------

@pytest.mark.parametrize("damage, words", [
    (lambda text: text[: len(text) // 2], "not valid JSON"),
    (lambda text: "", "not valid JSON: Expecting value"),
    (lambda text: "[1, 2]", "a JSON list, not an object"),
])
def test_plot_of_a_damaged_summary_names_the_file(tmp_path, capsys, damage, words):
    path, out = scene(tmp_path), tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    summary = out / "summary.json"
    summary.write_text(damage(summary.read_text()))
    capsys.readouterr()
    assert main(["plot", str(out)]) == 2
    line = capsys.readouterr().err.strip()
    assert line.count("\n") == 0 and line.startswith(f"switchsim: error: {summary}: ") and words in line


def test_plot_of_a_damaged_table_is_one_line(tmp_path, capsys):
    path, out = scene(tmp_path), tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    (out / "history.csv").write_bytes(b"\x00\xff" * 10)
    capsys.readouterr()
    assert main(["plot", str(out)]) == 2
    line = capsys.readouterr().err.strip()
    assert line.count("\n") == 0 and "the result's files cannot be read back" in line and str(out) in line


# --- the working folder ---------------------------------------------------------------------

def png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


def plot_in(cwd: Path, out: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "coupling", "plot", str(out)], cwd=cwd, env=ENV,
                          capture_output=True, text=True, timeout=300)


def test_a_matplotlibrc_in_the_working_folder_changes_no_plot(tmp_path):
    """usetex without LaTeX was a traceback at the first label; a dpi there changed every
    PNG's size; a FIFO named matplotlibrc would block the import. The plots drawn in such a
    folder are those drawn in an empty one, pixel for pixel in size."""
    path, out = scene(tmp_path), tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 0
    clean = tmp_path / "clean"
    clean.mkdir()
    done = plot_in(clean, out)
    assert done.returncode == 0, done.stderr
    sizes = {p.name: png_size(p) for p in out.glob("*.png")}
    assert sizes
    for p in out.glob("*.png"):
        p.unlink()
    hostile = tmp_path / "hostile"
    hostile.mkdir()
    (hostile / "matplotlibrc").write_text("text.usetex: True\nsavefig.dpi: 17\nfigure.dpi: 17\n")
    done = plot_in(hostile, out)
    assert done.returncode == 0, done.stderr
    assert {p.name: png_size(p) for p in out.glob("*.png")} == sizes
    fifo = tmp_path / "fifo"
    fifo.mkdir()
    os.mkfifo(fifo / "matplotlibrc")
    done = plot_in(fifo, out)  # blocks in open() before the fix: the timeout fails the test
    assert done.returncode == 0, done.stderr


@pytest.mark.parametrize("module", ["coupling", "coupling.app.cli"])
def test_python_m_coupling_runs_no_module_from_the_working_folder(tmp_path, module):
    """`python -m` puts the working folder first on sys.path: a tomllib.py (or argparse.py)
    there was imported, and run, in place of the library's."""
    marker = tmp_path / "PWNED"
    for name in ("tomllib", "argparse", "json"):
        (tmp_path / f"{name}.py").write_text(f"open({str(marker)!r}, 'a').write({name!r})\n")
    (tmp_path / "bad.toml").write_text("[bar]\nlength = -1.0\n")
    done = subprocess.run([sys.executable, "-m", module, "run", "bad.toml", "--out", "o"], cwd=tmp_path, env=ENV,
                          capture_output=True, text=True, timeout=300)
    assert not marker.exists(), marker.read_text()
    assert done.returncode == 2 and done.stderr.startswith("switchsim: error: bad.toml: bar.length = -1"), \
        done.stderr


def test_safe_path_keeps_the_users_first_entry(tmp_path):
    """With PYTHONSAFEPATH (-P) `python -m` puts nothing on sys.path: its first entry is then
    the user's own (PYTHONPATH's first), which may be the working folder itself (a checkout
    run from inside it), and must stay: dropping it ran the installed copy instead."""
    env = {**ENV, "PYTHONSAFEPATH": "1",
           "PYTHONPATH": os.pathsep.join((str(tmp_path), ENV["PYTHONPATH"]))}
    code = ("import sys; before = list(sys.path); from coupling.__main__ import drop_working_folder; "
            "drop_working_folder(); print(sys.path == before, sys.path[0])")
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0, done.stderr
    kept, first = done.stdout.split()
    assert kept == "True" and os.path.realpath(first) == os.path.realpath(tmp_path)
