"""Bad scene files through the real command: one line in the user's words, exit 2, never a
traceback, nothing run. Audit reproductions, then generated (hypothesis) bad documents."""

from __future__ import annotations

import json
import math
import tempfile
import textwrap
from pathlib import Path

import pytest
from cli_checks import assert_one_line_error, run_cli
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from coupling.core import scene as cs


# --- audit reproductions ---------------------------------------------------------------

def test_undecodable_scene_names_file_line_and_column(tmp_path):
    scene = tmp_path / "latin1.toml"
    scene.write_bytes("[bar]\nlength = 0.3\n# r\u00e9glage du contact\n".encode("latin-1"))
    line = assert_one_line_error(*run_cli(["run", str(scene), "--out", str(tmp_path / "o")]))
    assert str(scene) in line and "line 3, column 4" in line and "0xe9" in line and "UTF-8" in line
    assert "codec" not in line


def test_a_folder_as_scene_is_called_a_folder(tmp_path):
    line = assert_one_line_error(*run_cli(["run", str(tmp_path), "--out", str(tmp_path / "o")]))
    assert "is a folder" in line and "not found" not in line


def test_dev_null_as_scene_is_not_a_regular_file(tmp_path):
    line = assert_one_line_error(*run_cli(["run", "/dev/null", "--out", str(tmp_path / "o")]))
    assert "not a regular file" in line and "not found" not in line


def test_a_missing_scene_is_not_found(tmp_path):
    line = assert_one_line_error(*run_cli(["run", str(tmp_path / "nope.toml"), "--out", str(tmp_path / "o")]))
    assert "not found" in line


@pytest.mark.parametrize("text", ["", "\n\n", "# only a comment\n"])
def test_an_empty_scene_is_an_error_not_a_silent_default_run(tmp_path, text):
    scene = tmp_path / "empty.toml"
    scene.write_text(text)
    line = assert_one_line_error(*run_cli(["run", str(scene), "--out", str(tmp_path / "o")]))
    assert "empty" in line


@pytest.mark.parametrize("value, words", [
    ("2.5", ["bar.modes = 2.5", "whole number"]),
    ("41", ["bar.modes = 41", "[0, 40]"]),
    ("{ axial = 2.5 }", ["bar.modes.axial = 2.5"]),
])
def test_bar_modes_errors_name_the_key_the_user_wrote(tmp_path, value, words):
    scene = tmp_path / "modes.toml"
    scene.write_text(f"[bar]\nmodes = {value}\n")
    line = assert_one_line_error(*run_cli(["run", str(scene), "--out", str(tmp_path / "o")]))
    assert line.startswith(f"switchsim: error: {scene}: ")
    for word in words:
        assert word in line
    assert "axial_modes" not in line


def test_a_family_count_beside_bar_modes_is_refused_not_overridden():
    """bar.modes stands for both families' counts; a field of it set beside it
    (Scene.set("bar.axial_modes", 3) on a scene with modes = "auto") was silently
    overridden by modes: the run went on at the auto count. One line naming both keys."""
    from coupling.core.scene import builtin_scene

    with pytest.raises(ValueError) as err:
        builtin_scene("default").set("bar.axial_modes", 3)
    line = str(err.value)
    assert "bar.axial_modes = 3 beside bar.modes = 'auto'" in line and "\n" not in line
    assert builtin_scene("default").set("bar.modes", {"axial": 3, "bending": 17}).mech.bar.axial_modes == 3


def test_a_byte_order_mark_is_accepted(tmp_path):
    """Some Windows editors start UTF-8 files with a BOM: the scene is read as written."""
    from coupling.core.scene import load_scene

    scene = tmp_path / "bom.toml"
    scene.write_bytes(b"\xef\xbb\xbf" + "[bar]\nmodes = 1\n".encode())
    assert load_scene(scene).mech.bar.axial_modes == 1


@pytest.mark.parametrize("value", ["-1", "2.5", "true", "\"many\""])
def test_history_max_rows_is_validated(tmp_path, value):
    scene = tmp_path / "rows.toml"
    scene.write_text(f"[bar]\nmodes = 0\n[output]\nhistory_max_rows = {value}\n")
    line = assert_one_line_error(*run_cli(["run", str(scene), "--out", str(tmp_path / "o")]))
    assert "output.history_max_rows" in line and "whole number in [0, 10000000]" in line


def test_history_resolution_is_validated(tmp_path):
    scene = tmp_path / "res.toml"
    scene.write_text("[bar]\nmodes = 0\n[output]\nhistory_resolution = -1e-5\n")
    line = assert_one_line_error(*run_cli(["run", str(scene), "--out", str(tmp_path / "o")]))
    assert "output.history_resolution = -1e-05" in line and ">= 0" in line


@pytest.mark.parametrize("value", ["[" * 5000 + "]" * 5000, "{a = " * 2000 + "1" + "}" * 2000],
                         ids=["5000 nested arrays", "2000 nested inline tables"])
def test_deeply_nested_values_are_one_line_not_a_recursion_traceback(tmp_path, value):
    """tomllib parses nested arrays and inline tables recursively: past Python's stack this
    was a RecursionError traceback; the Python API says the same line."""
    from coupling.core.scene import load_scene

    scene = tmp_path / "deep.toml"
    scene.write_text(f"[bar]\nlength = {value}\n")
    line = assert_one_line_error(*run_cli(["run", str(scene), "--out", str(tmp_path / "o")]))
    assert line == f"switchsim: error: {scene}: arrays or inline tables nested too deeply (a scene needs a few levels)"
    with pytest.raises(ValueError, match="nested too deeply"):
        load_scene(scene)


# --- generated bad documents -------------------------------------------------------------

def toml_str(s: str) -> str:
    """A TOML basic string (JSON's escapes, plus DEL, which TOML forbids raw)."""
    return json.dumps(s, ensure_ascii=False).replace("\x7f", "\\u007f")


def toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return toml_str(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{toml_str(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(v)


def toml_text(doc: dict) -> str:
    out = []
    for section, table in doc.items():
        out.append(f"[{toml_str(section)}]")
        out += [f"{toml_str(k)} = {toml_value(v)}" for k, v in table.items()]
    return "\n".join(out) + "\n"


# Keys that take a finite number, with values outside their range.
OUT_OF_RANGE = {  # below and above each key's range (docs/scene_keys.md, "Bounds")
    ("bar", "length"): [0.0, -0.3, 11.0, 1e300], ("bar", "diameter"): [0.0, -0.01, 1e300],
    ("bar", "tip_radius"): [-0.005, 0.2, 1e300],
    ("bar", "youngs_modulus"): [0.0, -210e9, 1e300], ("bar", "poisson_ratio"): [0.5, -1.0, 0.7],
    ("bar", "density"): [0.0, -7850.0, 1e-3, 1e300], ("bar", "modal_damping"): [-0.1, 1.0],
    ("block", "youngs_modulus"): [0.0, -1.0, 1e300], ("block", "poisson_ratio"): [0.5, 2.0],
    ("initial", "height"): [-1e-3, 1e300], ("initial", "angle_deg"): [90.5, -180.0],
    ("contact", "restitution"): [0.0, 1.5], ("contact", "reference_speed"): [0.0, -1.0, 1e300],
    ("contact", "stiffness"): [0.0, -1e10, 1e300],
    ("friction", "mu"): [-0.3, 1e300], ("friction", "gamma"): [1.0, -0.1],
    ("friction", "regularization_speed"): [0.0, -1e-4, 1e300],
    ("solver", "rtol"): [0.0, 1e-4, 0.1, 1.0], ("solver", "t_end"): [0.0, -1.0, 1001.0, 1e300],
    ("solver", "max_step"): [0.0, -1e-6, 1e300], ("solver", "stick_velocity_tol"): [0.0, 1e300],
    ("solver", "energy_tolerance"): [0.0, -1e-3, 0.01, 1e300], ("environment", "gravity"): [-9.81, 1e300],
    ("solver", "max_steps"): [0, 10**9], ("solver", "history_rows"): [10, 10**8],
    ("output", "history_resolution"): [-1e-5, 1e300], ("output", "history_max_rows"): [-1, 10**8],
}
NUMERIC_KEYS = sorted(OUT_OF_RANGE) + [("initial", "azimuth_deg")]
CHOICE_KEYS = [("bar", "bending"), ("contact", "law"), ("contact", "calibration"), ("friction", "model"),
               ("solver", "model")]
BOOL_KEYS = [("output", "csv"), ("output", "plots"), ("output", "history"), ("initial", "resting")]
# every section a scene accepts (Hypothesis draws string constants of the code under test,
# such as "rivet", among its texts)
KNOWN_SECTIONS = set(cs.MECH_SECTIONS) | set(cs.COUPLING_SECTIONS)

not_a_number = st.one_of(
    st.sampled_from([math.nan, math.inf, -math.inf]),
    st.text(max_size=8), st.booleans(), st.lists(st.floats(-1, 1), max_size=3),
    st.dictionaries(st.text(min_size=1, max_size=4), st.integers(), max_size=2),
)


@st.composite
def bad_entry(draw) -> tuple[str, str, object]:
    kind = draw(st.sampled_from(["range", "type", "choice", "bool", "vector", "unknown_key"]))
    if kind == "range":
        section, key = draw(st.sampled_from(sorted(OUT_OF_RANGE)))
        return section, key, draw(st.sampled_from(OUT_OF_RANGE[(section, key)]))
    if kind == "type":
        section, key = draw(st.sampled_from(NUMERIC_KEYS))
        return section, key, draw(not_a_number)
    if kind == "choice":
        section, key = draw(st.sampled_from(CHOICE_KEYS))
        return section, key, draw(st.one_of(st.text(max_size=12).filter(
            lambda s: s not in {"euler_bernoulli", "paper_shear", "paper", "hunt_crossley", "lankarani_nikravesh",
                                "flores", "exact", "formula", "regularized", "auto", "planar", "3d"}),
            st.integers(), st.floats(allow_nan=False)))
    if kind == "bool":
        section, key = draw(st.sampled_from(BOOL_KEYS))
        return section, key, draw(st.one_of(st.integers(), st.text(max_size=5), st.floats(allow_nan=False)))
    if kind == "vector":
        key = draw(st.sampled_from(["velocity", "angular_velocity"]))
        value = draw(st.one_of(st.lists(st.floats(-1, 1), max_size=2), st.lists(st.floats(-1, 1), min_size=4,
                                                                                  max_size=5),
                               st.lists(not_a_number, min_size=3, max_size=3).filter(
                                   lambda v: any(not isinstance(x, float) or not math.isfinite(x) for x in v)),
                               st.text(max_size=4).filter(lambda s: len(s) != 3), st.floats()))
        return "initial", key, value
    section = draw(st.sampled_from(["bar", "block", "initial", "contact", "friction", "solver", "environment",
                                    "output"]))
    key = draw(st.text(st.characters(codec="utf-8", exclude_categories=("Cs",)), min_size=1, max_size=12)
               .filter(lambda k: not known_key(section, k)))
    return section, key, 1.0


def known_key(section: str, key: str) -> bool:
    import dataclasses

    from coupling.core.scene import OutputOptions
    from mech.scene import ENVIRONMENT_KEYS, SECTIONS

    if section == "environment":
        return key in ENVIRONMENT_KEYS
    cls = OutputOptions if section == "output" else SECTIONS[section]
    return key in {f.name for f in dataclasses.fields(cls)} or (section == "bar" and key == "modes")


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(entries=st.lists(bad_entry(), min_size=1, max_size=3),
       good=st.dictionaries(st.sampled_from(["height", "angle_deg"]), st.floats(0.0, 10.0), max_size=2))
def test_generated_bad_values_get_one_named_line_and_exit_2(entries, good):
    doc: dict = {"initial": dict(good)}
    for section, key, value in entries:
        doc.setdefault(section, {})[key] = value
    with tempfile.TemporaryDirectory() as tmp:
        scene = Path(tmp) / "bad.toml"
        scene.write_text(toml_text(doc), encoding="utf-8")
        line = assert_one_line_error(*run_cli(["run", str(scene), "--out", str(Path(tmp) / "o")]))
    # the message names a key the user wrote (or the section holding it)
    named = [f"{s}.{k}" for s, k, _ in entries] + [repr(k) for _, k, _ in entries] + [s for s, _, _ in entries]
    assert any(n in line for n in named), (doc, line)


@settings(max_examples=40, deadline=None)
@given(name=st.text(st.characters(codec="utf-8", exclude_categories=("Cs",)), min_size=1, max_size=10)
       .filter(lambda s: s not in KNOWN_SECTIONS))
def test_generated_unknown_sections_get_one_line_and_exit_2(name):
    with tempfile.TemporaryDirectory() as tmp:
        scene = Path(tmp) / "bad.toml"
        scene.write_text(toml_text({name: {"x": 1}, "bar": {"modes": 0}}), encoding="utf-8")
        line = assert_one_line_error(*run_cli(["run", str(scene), "--out", str(Path(tmp) / "o")]))
    assert "unknown section" in line


@settings(max_examples=40, deadline=None)
@given(head=st.binary(max_size=40), tail=st.binary(max_size=40),
       encoding=st.sampled_from(["raw", "utf-16", "utf-32", "latin-1", "cp1252"]))
def test_generated_odd_encodings_get_one_line_and_exit_2(head, tail, encoding):
    """Bytes that are not UTF-8: a scene saved as UTF-16/32, Latin-1 or Windows-1252 with
    accented comments, or raw binary with an invalid byte somewhere."""
    text = "[bar]\nmodes = 0\n# contact r\u00e9gl\u00e9 \u00e0 0,3 mm\n"
    data = head + b"\xff" + tail if encoding == "raw" else text.encode(encoding)
    with tempfile.TemporaryDirectory() as tmp:
        scene = Path(tmp) / "odd.toml"
        scene.write_bytes(data)
        line = assert_one_line_error(*run_cli(["run", str(scene), "--out", str(Path(tmp) / "o")]))
    assert "not UTF-8" in line and "line " in line and "column " in line


@settings(max_examples=40, deadline=None)
@given(text=st.text(st.characters(codec="utf-8", exclude_categories=("Cs",)), max_size=60))
def test_generated_text_is_never_a_traceback(text):
    """Any text at all: a valid scene (then it would run: the run is replaced here, and a
    document that validates is skipped) or one line and exit 2."""
    from coupling.core.scene import load_scene

    with tempfile.TemporaryDirectory() as tmp:
        scene = Path(tmp) / "any.toml"
        scene.write_text(text, encoding="utf-8")
        try:
            load_scene(scene)
        except (ValueError, FileNotFoundError):
            assert_one_line_error(*run_cli(["run", str(scene), "--out", str(Path(tmp) / "o")]))
        # a document that validates is a valid scene: nothing to assert about errors


def test_the_toml_writer_used_here_round_trips():
    import tomllib

    doc = {"bar": {"length": -0.3, "bending": "x\u00e9\n\"\x7f", "v": [1.0, math.inf], "t": {"a": 1}}}
    back = tomllib.loads(toml_text(doc))
    assert back["bar"]["length"] == -0.3 and back["bar"]["bending"] == "x\u00e9\n\"\x7f"
    assert back["bar"]["v"] == [1.0, math.inf] and back["bar"]["t"] == {"a": 1}
    assert textwrap.dedent(toml_text({"s": {}})).strip() == '["s"]'
