"""`switchsim sweep` input under the audit's cases, each one line (exit 2) before anything
runs, never a traceback or a hang: the sweep file a folder, /dev/zero, a FIFO, too large, not
UTF-8 or nested too deep; a design above the size limit (refused before it is built); an
unknown `waveforms` column; `--out` an existing file; a damaged sweep.json; `--scheduler`
with nothing listening; a folder in use by another sweep. These run in this process and
start no cluster (except where a scheduler is needed, none is)."""

from __future__ import annotations

import os
import resource
import socket
import textwrap
import time
import tomllib
from pathlib import Path

import pytest

pytest.importorskip("distributed")

from cli_checks import assert_one_line_error  # noqa: E402

from coupling.app.cli import main  # noqa: E402
from coupling.app.sweep import (  # noqa: E402
    COUPLED_COLUMNS, MAX_RUNS, MAX_SWEEP_FILE_BYTES, SCHEDULER_TIMEOUT, RowWriter, Sweep, _FolderLock, load_sweep,
)
from coupling.core.scene import scene_from_dict  # noqa: E402

TINY = """
[bar]
length = 0.1
diameter = 0.006
tip_radius = 0.003
modes = 0
[initial]
height = 0.0001
angle_deg = 90.0
velocity = [0.0, 0.0, -1.0]
[solver]
t_end = 0.0004
"""
COUPLED = TINY + '[tribology]\nsource = "illustrative"\n[circuit]\ntemplate = "resistive"\n'


def sweep_cli(capsys, *argv: str) -> str:
    rc = main(["sweep", *argv])
    return assert_one_line_error(rc, capsys.readouterr().err)


def write_sweep(folder: Path, body: str, scene: str = TINY) -> Path:
    (folder / "tiny.toml").write_text(scene)
    path = folder / "sw.toml"
    path.write_text('[sweep]\nscene = "tiny.toml"\n' + textwrap.dedent(body))
    return path


# --- the sweep file, checked as any input file -------------------------------------------------

def test_a_folder_as_sweep_file(tmp_path, capsys):
    line = sweep_cli(capsys, str(tmp_path), "--out", str(tmp_path / "o"))
    assert "sweep file" in line and "is a folder" in line


def test_dev_zero_as_sweep_file_is_refused_unread(tmp_path, capsys):
    """/dev/zero was read until memory ran out."""
    line = sweep_cli(capsys, "/dev/zero", "--out", str(tmp_path / "o"))
    assert "'/dev/zero' is not a regular file" in line


def test_a_fifo_as_sweep_file_is_refused_unopened(tmp_path, capsys):
    """Opening a FIFO blocks until a writer comes: a hang. It is never opened."""
    os.mkfifo(tmp_path / "pipe.toml")
    line = sweep_cli(capsys, str(tmp_path / "pipe.toml"), "--out", str(tmp_path / "o"))
    assert "pipe.toml' is not a regular file" in line


def test_a_sweep_file_above_the_size_limit(tmp_path, capsys):
    path = tmp_path / "big.toml"
    with open(path, "wb") as fh:  # sparse: no disk written
        fh.truncate(MAX_SWEEP_FILE_BYTES + 1)
    line = sweep_cli(capsys, str(path), "--out", str(tmp_path / "o"))
    assert f"is {MAX_SWEEP_FILE_BYTES + 1} bytes, more than the {MAX_SWEEP_FILE_BYTES}" in line


def test_a_sweep_file_that_is_not_utf8_names_line_and_column(tmp_path, capsys):
    path = tmp_path / "lat.toml"
    path.write_bytes('[sweep]\n# r\u00e9glage\ndesign = "grid"\n'.encode("latin-1"))
    line = sweep_cli(capsys, str(path), "--out", str(tmp_path / "o"))
    assert "line 2, column 4: byte 0xe9 is not UTF-8 text" in line


def test_deeply_nested_values_in_a_sweep_file(tmp_path, capsys):
    path = tmp_path / "deep.toml"
    path.write_text("[sweep]\nset = " + "[" * 5000 + "]" * 5000 + "\n")
    line = sweep_cli(capsys, str(path), "--out", str(tmp_path / "o"))
    assert "nested too deeply" in line


# --- the design's size -------------------------------------------------------------------------

def test_a_grid_above_the_limit_is_refused_before_it_is_built(tmp_path, capsys):
    """A 1e10-run grid died at 5.6 GB, a 1e6 one hung for minutes: the product of the list
    lengths is refused first, in well under a second and a few MB (the address-space cap
    below fails the test if the design is built)."""
    keys = "\n".join(f'"initial.v{k}" = [{", ".join(["1.0"] * 10)}]' for k in range(10))
    path = write_sweep(tmp_path, f'design = "grid"\n[sweep.grid]\n{keys}\n')
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    used = int(Path("/proc/self/statm").read_text().split()[0]) * resource.getpagesize()
    resource.setrlimit(resource.RLIMIT_AS, (used + 2_000_000_000, hard))
    try:
        tick = time.monotonic()
        line = sweep_cli(capsys, str(path), "--out", str(tmp_path / "o"))
        assert time.monotonic() - tick < 5
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
    assert f"10 x 10 x 10 x 10 x 10 x 10 x 10 x 10 x 10 x 10 values make 10000000000 runs, more than the " \
           f"{MAX_RUNS}" in line and "split the study" in line
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("design", ["random", "lhs"])
def test_samples_above_the_limit_are_refused_before_they_are_drawn(tmp_path, capsys, design):
    path = write_sweep(tmp_path, f'design = "{design}"\nsamples = 1000000\n'
                                 '[sweep.ranges]\n"initial.angle_deg" = [10.0, 80.0]\n')
    line = sweep_cli(capsys, str(path), "--out", str(tmp_path / "o"))
    assert f"sweep samples make 1000000 runs, more than the {MAX_RUNS}" in line


def test_the_limit_itself_is_allowed():
    base = scene_from_dict(tomllib.loads(TINY), name="tiny")
    assert len(Sweep.grid(base, {"contact.restitution": [0.5] * MAX_RUNS}).runs) == MAX_RUNS
    with pytest.raises(ValueError, match=f"make {MAX_RUNS + 1} runs"):
        Sweep.grid(base, {"contact.restitution": [0.5] * (MAX_RUNS + 1)})
    with pytest.raises(ValueError, match=f"make {MAX_RUNS + 1} runs"):
        Sweep.cases(base, [{"contact.restitution": 0.5}] * (MAX_RUNS + 1))


# --- waveforms columns ---------------------------------------------------------------------------

def test_an_unknown_waveforms_column_is_named_with_a_did_you_mean(tmp_path, capsys):
    """It was accepted silently and the waveform files then lacked it."""
    path = write_sweep(tmp_path, 'design = "grid"\nwaveforms = ["contact_voltag"]\n'
                                 '[sweep.grid]\n"circuit.load_resistance" = [5.0, 10.0]\n', scene=COUPLED)
    line = sweep_cli(capsys, str(path), "--out", str(tmp_path / "o"))
    assert "sweep waveforms: unknown column 'contact_voltag' (did you mean 'contact_voltage'?)" in line
    assert "normal_force" in line  # the columns the runs record are listed


def test_the_coupled_columns_named_for_waveforms_are_those_a_run_records():
    """COUPLED_COLUMNS lists by hand what the master adds to a coupled run's waveforms: a
    real run has exactly these besides the circuit's (so no valid column is refused)."""
    from circuit import COLUMNS
    from coupling import run

    result = run(scene_from_dict(tomllib.loads(COUPLED), name="tiny"))
    assert set(result.waveforms.columns) == set(COLUMNS) | set(COUPLED_COLUMNS)


def test_a_known_column_and_probes_pass(tmp_path):
    path = write_sweep(tmp_path, 'design = "grid"\nwaveforms = ["mu", "v(load)"]\n'
                                 '[sweep.grid]\n"circuit.load_resistance" = [5.0]\n',
                       scene=COUPLED + 'probes = ["v(load)"]\n')
    assert load_sweep(path).waveforms == ("time", "mu", "v(load)")


# --- the output folder ---------------------------------------------------------------------------

def test_out_an_existing_file(tmp_path, capsys):
    path = write_sweep(tmp_path, 'design = "grid"\n[sweep.grid]\n"contact.restitution" = [0.5]\n')
    (tmp_path / "afile").write_text("mine")
    line = sweep_cli(capsys, str(path), "--out", str(tmp_path / "afile"))
    assert "is a file; give a folder name" in line
    assert (tmp_path / "afile").read_text() == "mine"


def test_a_damaged_sweep_json_is_named(tmp_path, capsys):
    path = write_sweep(tmp_path, 'design = "grid"\n[sweep.grid]\n"contact.restitution" = [0.5]\n')
    out = tmp_path / "o"
    RowWriter(out / "results", "s1", size=1).add({"run_id": "run0000", "status": "ok"})  # a row: a sweep began
    (out / "sweep.json").write_text('{"fingerprint": ')
    line = sweep_cli(capsys, str(path), "--out", str(out), "--resume")
    assert f"{out / 'sweep.json'}: damaged, not the record of a sweep" in line


def test_scheduler_with_nothing_listening_is_one_line_within_seconds(tmp_path, capsys):
    path = write_sweep(tmp_path, 'design = "grid"\n[sweep.grid]\n"contact.restitution" = [0.5]\n')
    with socket.socket() as sock:  # a free port: bound, never listening
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
        tick = time.monotonic()
        line = sweep_cli(capsys, str(path), "--out", str(tmp_path / "o"), "--scheduler", f"tcp://127.0.0.1:{port}")
        assert time.monotonic() - tick < SCHEDULER_TIMEOUT + 5
    assert f"--scheduler 'tcp://127.0.0.1:{port}': no Dask scheduler answered within 5 s" in line


def test_a_port_that_takes_connections_and_says_nothing_is_one_line_within_seconds(tmp_path, capsys):
    """Dask's connect timeout ends at the TCP connection: a listener that never speaks held
    the Client's start for as long as it stayed open."""
    path = write_sweep(tmp_path, 'design = "grid"\n[sweep.grid]\n"contact.restitution" = [0.5]\n')
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        sock.listen(4)  # the kernel accepts; nobody answers
        port = sock.getsockname()[1]
        tick = time.monotonic()
        line = sweep_cli(capsys, str(path), "--out", str(tmp_path / "o"), "--scheduler", f"tcp://127.0.0.1:{port}")
        assert time.monotonic() - tick < SCHEDULER_TIMEOUT + 5
    assert "no Dask scheduler answered within 5 s (the port takes connections but no Dask scheduler speaks" in line


def test_a_scheduler_address_that_is_no_address(tmp_path, capsys):
    path = write_sweep(tmp_path, 'design = "grid"\n[sweep.grid]\n"contact.restitution" = [0.5]\n')
    line = sweep_cli(capsys, str(path), "--out", str(tmp_path / "o"), "--scheduler", "localhost")
    assert "--scheduler 'localhost': not a Dask scheduler address" in line


def test_a_folder_in_use_by_another_sweep_is_refused(tmp_path, capsys):
    """flock is per open file: a lock held here stands for another process's (the subprocess
    case is in test_sweep_cluster.py)."""
    path = write_sweep(tmp_path, 'design = "grid"\n[sweep.grid]\n"contact.restitution" = [0.5]\n')
    out = tmp_path / "o"
    out.mkdir()
    with _FolderLock(out):
        line = sweep_cli(capsys, str(path), "--out", str(out), "--resume")
    assert line == (f"switchsim: error: {out} is in use by another sweep (process {os.getpid()}): wait for it to "
                    "finish, or use another --out")
    assert not (out / "sweep.json").exists()
