"""Shared scene folders through the CLI: no command runs, no content of a non-input file is echoed (docs/circuit.md)."""

from __future__ import annotations

from pathlib import Path

import pytest
from cli_checks import FAR

from coupling.app.cli import main



def scene(folder: Path, text: str) -> Path:
    path = folder / "scene.toml"
    path.write_text(FAR + text)
    return path


def run_cli(capsys, *args) -> tuple[int, str]:
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out + captured.err


def test_netlist_scene_including_a_control_block_runs_nothing(tmp_path, capsys):
    pwned = tmp_path / "PWNED"
    (tmp_path / "evil.cir").write_text(f".control\nshell touch {pwned}\n.endc\n")
    (tmp_path / "relay.cir").write_text("relay\nV1 s 0 24\nXCONTACT s b\nVLOAD b c 0\nR1 c 0 12\n.include evil.cir\n")
    path = scene(tmp_path, '[tribology]\nsource = "illustrative"\n[circuit]\ntemplate = "netlist"\n'
                           'netlist = "relay.cir"\n')
    code, text = run_cli(capsys, "run", str(path), "--out", str(tmp_path / "out"), "--quiet")
    assert code == 2
    assert "evil.cir line 1" in text and ".control" in text and "Traceback" not in text
    assert not pwned.exists()


def test_tribology_data_naming_a_system_file_echoes_none_of_it(tmp_path, capsys):
    passwd = Path("/etc/passwd")
    if not passwd.is_file():
        pytest.skip("no /etc/passwd")
    path = scene(tmp_path, '[tribology]\ndata = "/etc/passwd"\n')
    code, text = run_cli(capsys, "run", str(path), "--out", str(tmp_path / "out"), "--quiet")
    assert code == 2 and "/etc/passwd" in text
    first = passwd.read_text(errors="replace").splitlines()[0]
    assert first not in text and first.split(":")[0] + ":" not in text


def test_fit_of_a_system_file_echoes_none_of_it(tmp_path, capsys):
    code, text = run_cli(capsys, "fit", "/etc/passwd", "--out", str(tmp_path / "out"))
    assert code == 2 and "root:" not in text and "header line 1" in text


def test_netlist_that_ngspice_rejects_is_an_input_error_not_a_traceback(tmp_path, capsys):
    (tmp_path / "relay.cir").write_text("relay\nV1 s 0 24\nXCONTACT s b\nVLOAD b c 0\nR1 c 0 12\nR2 c 0 abc\n")
    path = scene(tmp_path, '[tribology]\nsource = "illustrative"\n[circuit]\ntemplate = "netlist"\n'
                           'netlist = "relay.cir"\n')
    code, text = run_cli(capsys, "run", str(path), "--out", str(tmp_path / "out"), "--quiet")
    assert code == 2 and "ngspice could not parse the netlist" in text and "Traceback" not in text


def test_tribology_fit_naming_a_system_file_echoes_none_of_it(tmp_path, capsys):
    path = scene(tmp_path, '[tribology]\nfit = "/etc/passwd"\n')
    code, text = run_cli(capsys, "run", str(path), "--out", str(tmp_path / "out"), "--quiet")
    assert code == 2 and "not a readable tribometer fit" in text and "root:" not in text
