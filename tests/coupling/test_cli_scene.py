"""`switchsim scene [NAME]`: a built-in scene's TOML on stdout, the starting point a designer
copies and edits; the file it writes loads as the very scene `switchsim run` runs."""

from __future__ import annotations

import contextlib
import io
from dataclasses import fields

import pytest
from cli_checks import assert_one_line_error, run_cli

from coupling import builtin_scene, load_scene
from coupling.app.cli import main
from coupling.core.scene import BUILTIN_SCENES


@pytest.mark.parametrize("name", BUILTIN_SCENES)
def test_the_printed_scene_loads_as_the_built_in_one(name, tmp_path):
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        rc = main(["scene", name])
    assert rc == 0
    path = tmp_path / f"my_{name}.toml"
    path.write_text(out.getvalue())
    copied, built_in = load_scene(path), builtin_scene(name)
    # the same document, and the same validated sections built from it (the friction law
    # holds a function of the current, equal by what it is built from: the raw document)
    assert copied.raw == built_in.raw
    assert sections(copied.mech) == sections(built_in.mech)
    assert copied.coupling == built_in.coupling and copied.t_end == built_in.t_end


def sections(mech) -> dict:
    """The mechanics scene's sections, the friction law as its parameters (it holds mu(I))."""
    out = {f.name: getattr(mech, f.name) for f in fields(mech) if f.name != "friction"}
    out["friction"] = {f.name: getattr(mech.friction, f.name) for f in fields(mech.friction) if f.name != "mu"}
    return out


def test_without_a_name_it_is_the_default_relay():
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["scene"]) == 0
    assert "[coil]" in out.getvalue() and load_scene_text(out.getvalue()).raw == builtin_scene("default").raw


def load_scene_text(text: str):
    import tomllib

    from coupling import scene_from_dict

    return scene_from_dict(tomllib.loads(text))


def test_an_unknown_name_is_one_line_naming_it_and_the_allowed_ones():
    line = assert_one_line_error(*run_cli(["scene", "relay_fast"]))
    assert "'relay_fast'" in line and all(name in line for name in BUILTIN_SCENES)
