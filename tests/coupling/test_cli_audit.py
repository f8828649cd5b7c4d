"""Issue 10, sections 5 and 6, through the command line: each reproduction of the audit gets
exit 2 and one line naming the file and the key as the user wrote them (never a traceback,
nothing run), or, where the input is good (a byte-order mark, a fit with an outlier), runs
and reports what it did. Reproductions already covered elsewhere: bar.modes, undecodable
scenes, a folder or /dev/null as the scene, an empty scene (test_cli_input.py); fit on a
folder, fit --out an existing file, a gross load (test_tribology_outliers.py)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from cli_checks import FAR, assert_one_line_error, run_cli
from fit_compare import assert_same_fit

from coupling.app.cli import main
from coupling.core.scene import load_scene
from coupling.laws.tribology import default_fit, illustrative_data_path

REPO = Path(__file__).resolve().parents[2]
COUPLED = FAR + '[tribology]\nsource = "illustrative"\n'
NETLIST = "relay\nV1 s 0 24\nXCONTACT s b\nVLOAD b c 0\nR1 c 0 12\n{extra}\n"
SHIPPED = illustrative_data_path().read_text()
HEADER_AT = SHIPPED.splitlines().index("load_N,current_A,friction_N,resistance_ohm,run")


def with_cell(row: int, column: int, value: str) -> tuple[str, int]:
    """The shipped CSV with one cell replaced, and that cell's line number."""
    lines = SHIPPED.splitlines()
    k = HEADER_AT + 1 + row
    cells = lines[k].split(",")
    cells[column] = value
    lines[k] = ",".join(cells)
    return "\n".join(lines) + "\n", k + 1


def run_scene(folder: Path, text: str, files: dict | None = None) -> str:
    """`switchsim run scene.toml` on a scene and its files: the one error line."""
    for name, content in (files or {}).items():
        (folder / name).write_bytes(content if isinstance(content, bytes) else content.encode())
    scene = folder / "scene.toml"
    scene.write_text(text)
    line = assert_one_line_error(*run_cli(["run", str(scene), "--out", str(folder / "out")]))
    assert line.startswith(f"switchsim: error: {scene}: "), line  # the scene file first
    assert not (folder / "out").exists()
    return line


LATIN1_CSV = SHIPPED.encode().replace(b"3,0,", b"3\xb5,0,", 1)
LATIN1_LINE = SHIPPED.encode()[:SHIPPED.encode().index(b"3,0,")].count(b"\n") + 1


# --- section 5: errors in the user's words -------------------------------------------------

@pytest.mark.parametrize("circuit, words, internal", [
    ("voltage = -1.0", ["circuit.voltage = -1 V is out of range: allowed 0 < value"], "DCSource"),
    ("load_resistance = 0.0", ["circuit.load_resistance = 0 ohm is out of range"], "ResistiveLoad"),
    ("source_resistance = -1.0", ["circuit.source_resistance = -1 ohm"], "DCSource"),
    ("arc = {min_voltag = 10.0}", ["circuit.arc: unknown key 'min_voltag' (did you mean 'min_voltage'?)",
                                   "allowed keys: ayrton_c, ayrton_d, breakdown_gradient, breakdown_voltage"], "unexpected keyword"),
    ("reltol = 0.5", ["circuit.reltol = 0.5 is out of range"], "SimulationOptions"),
])
def test_circuit_errors_name_the_scene_key(tmp_path, circuit, words, internal):
    line = run_scene(tmp_path, COUPLED + f"[circuit]\n{circuit}\n")
    for word in words:
        assert word in line
    assert internal not in line and "TypeError" not in line


@pytest.mark.parametrize("command", ["run", "fit"])
def test_an_undecodable_csv_names_file_line_and_column(tmp_path, command):
    if command == "run":
        line = run_scene(tmp_path, COUPLED.replace('source = "illustrative"', 'data = "lat.csv"') + "[circuit]\n",
                         {"lat.csv": LATIN1_CSV})
    else:
        (tmp_path / "lat.csv").write_bytes(LATIN1_CSV)
        line = assert_one_line_error(*run_cli(["fit", str(tmp_path / "lat.csv"), "--out", str(tmp_path / "o")]))
    assert f"lat.csv: line {LATIN1_LINE}, column 2: byte 0xb5 is not UTF-8" in line and "codec" not in line


@pytest.mark.parametrize("key", ["tribology.data", "tribology.fit", "circuit.netlist"])
@pytest.mark.parametrize("target, words", [("adir", "is a folder, not a file"),
                                           ("/dev/null", "is not a regular file")])
def test_a_folder_or_device_named_by_a_scene_is_called_so(tmp_path, key, target, words):
    (tmp_path / "adir").mkdir()
    if key == "circuit.netlist":
        text = COUPLED + f'[circuit]\ntemplate = "netlist"\nnetlist = "{target}"\n'
    else:
        text = COUPLED.replace('source = "illustrative"', f'{key.split(".")[1]} = "{target}"') + "[circuit]\n"
    line = run_scene(tmp_path, text)
    assert f"{key} = '{target}'" in line and words in line and "not found" not in line


def test_fit_of_a_device_is_not_a_regular_file(tmp_path):
    line = assert_one_line_error(*run_cli(["fit", "/dev/null", "--out", str(tmp_path / "o")]))
    assert "tribometer CSV: '/dev/null' is not a regular file" in line


def test_a_byte_order_mark_is_read_as_written(tmp_path, capsys):
    """An Excel "CSV UTF-8" export and a scene saved with a BOM: the first column and the
    first section are what they say."""
    (tmp_path / "excel.csv").write_bytes(b"\xef\xbb\xbf" + SHIPPED.encode())
    assert main(["fit", str(tmp_path / "excel.csv"), "--out", str(tmp_path / "fit")]) == 0
    saved = json.loads((tmp_path / "fit" / "fit.json").read_text())
    assert_same_fit(saved["laws"], default_fit().to_dict()["laws"])
    scene = tmp_path / "bom.toml"
    scene.write_bytes(b"\xef\xbb\xbf" + FAR.replace("t_end = 1e-4", "t_end = 1e-5").encode())
    assert main(["run", str(scene), "--out", str(tmp_path / "run"), "--quiet"]) == 0
    assert json.loads((tmp_path / "run" / "summary.json").read_text())["status"] == "ok"
    capsys.readouterr()


# --- section 6: dubious input ----------------------------------------------------------

def test_zero_contact_capacitance_is_refused_before_running(tmp_path):
    line = run_scene(tmp_path, COUPLED + "[circuit]\ncontact_capacitance = 0.0\n")
    assert "circuit.contact_capacitance = 0 F" in line and "snubber" in line


@pytest.mark.parametrize("extra, words", [
    ("R2 supply a", "line 6: resistor line with 3 field(s), it needs at least 4"),
    ("D1 c 0 nomodel", "line 6: the diode names a model that no '.model' line of the netlist defines"),
    ("X9 c 0 nosub", "line 6: the subcircuit instance names a subcircuit that no '.subckt' line"),
])
def test_dubious_netlist_lines_are_named(tmp_path, extra, words):
    line = run_scene(tmp_path, COUPLED + '[circuit]\ntemplate = "netlist"\nnetlist = "net.cir"\n',
                     {"net.cir": NETLIST.format(extra=extra)})
    assert f"netlist net.cir {words}" in line


def test_a_tiny_friction_is_an_outlier_reported_by_fit_and_by_the_scenes_using_it(tmp_path, capsys):
    """One friction of 1e-320 N: the fit leaves it out (gamma as without it), says so, writes
    a fit.json that reads back; a scene using the CSV or that fit.json warns of it."""
    text, line_number = with_cell(10, 2, "1e-320")
    (tmp_path / "data.csv").write_text(text)
    assert main(["fit", str(tmp_path / "data.csv"), "--out", str(tmp_path / "fit")]) == 0
    printed = capsys.readouterr().out
    assert f"OUTLIERS left out of the friction fit: 1 row(s): line {line_number} (friction_N = 1e-320" in printed
    from coupling.core.diagnostics import fit_warnings

    for key, value in (("data", "data.csv"), ("fit", "fit/fit.json")):
        (tmp_path / "scene.toml").write_text(
            COUPLED.replace('source = "illustrative"', f'{key} = "{value}"') + "[circuit]\n")
        scene = load_scene(tmp_path / "scene.toml")
        assert abs(scene.tribology.laws.gamma - default_fit().laws.gamma) < 0.01
        assert [f"line {line_number} (friction_N" in w for w in fit_warnings(scene)] == [True]


@pytest.mark.parametrize("change, words", [
    (lambda doc: doc["laws"]["mu"].update(gamma=0.5), "the 'laws' block differs from the laws the fit found"),
    (lambda doc: [doc], "expected a JSON object, got a JSON list"),
])
def test_an_edited_or_malformed_fit_json_is_refused(tmp_path, change, words):
    doc = default_fit().to_dict()
    doc = change(doc) or doc
    line = run_scene(tmp_path, COUPLED.replace('source = "illustrative"', 'fit = "fit.json"') + "[circuit]\n",
                     {"fit.json": json.dumps(doc)})
    assert "fit.json: not a readable tribometer fit" in line and words in line


# --- the real entry point ----------------------------------------------------------------

def test_python_m_coupling_cli_prints_one_line_and_exits_2(tmp_path):
    """Three audit cases (a circuit value, a netlist line, a CSV byte) in fresh processes."""
    (tmp_path / "c.toml").write_text(COUPLED + "[circuit]\nvoltage = -1.0\n")
    (tmp_path / "n.toml").write_text(COUPLED + '[circuit]\ntemplate = "netlist"\nnetlist = "net.cir"\n')
    (tmp_path / "net.cir").write_text(NETLIST.format(extra="R2 supply a"))
    (tmp_path / "lat.csv").write_bytes(LATIN1_CSV)
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    for args, words in ((["run", "c.toml"], "c.toml: circuit.voltage = -1 V"),
                        (["run", "n.toml"], "n.toml: netlist net.cir line 6: resistor line"),
                        (["fit", "lat.csv"], f"lat.csv: line {LATIN1_LINE}, column 2")):
        done = subprocess.run([sys.executable, "-m", "coupling.app.cli", *args, "--out", "o"], cwd=tmp_path, env=env,
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 2 and done.stdout == "", (args, done.stdout, done.stderr)
        assert done.stderr.startswith("switchsim: error: ") and done.stderr.count("\n") == 1, done.stderr
        assert words in done.stderr and "Traceback" not in done.stderr
        assert not (tmp_path / "o").exists()
