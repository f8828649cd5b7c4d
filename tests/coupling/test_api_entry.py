"""The Python API's entry points say what to pass instead, at the entry: `run(None)`,
`run("scene.toml")` and `load_scene(None)` ended in AttributeError or TypeError deep inside,
and `run(scene, check="yes")` was accepted (a truthy string ran the accuracy check)."""

from __future__ import annotations

from pathlib import Path

import pytest

from coupling import default_scene, load_scene, run, scene_from_dict

TINY = {"bar": {"length": 0.1, "diameter": 0.006, "tip_radius": 0.003, "modes": 0},
        "initial": {"height": 1e-4, "angle_deg": 90.0, "velocity": [0.0, 0.0, -1.0]},
        "solver": {"t_end": 2e-4}}


@pytest.mark.parametrize("value, words", [
    (None, "run() takes a Scene, got NoneType None: load_scene('scene.toml'), default_scene() or"),
    ("scene.toml", "run() takes a Scene, got str 'scene.toml': load_scene('scene.toml') first"),
    (Path("my.toml"), "load_scene('my.toml') first"),
    (TINY, "got dict"),
])
def test_run_of_something_else_than_a_scene_says_how_to_get_one(value, words):
    with pytest.raises(TypeError) as err:
        run(value)
    assert words in str(err.value)


@pytest.mark.parametrize("keyword, value", [("check", "yes"), ("check", 1), ("progress", "no"), ("progress", None)])
def test_run_flags_must_be_booleans(keyword, value):
    scene = scene_from_dict(TINY, name="tiny")
    with pytest.raises(TypeError, match=rf"run\({keyword}={value!r}\): pass True or False"):
        run(scene, **{keyword: value})


@pytest.mark.parametrize("value, words", [
    (None, "load_scene() takes the path of a scene TOML file (str or pathlib.Path), got NoneType None; "
           "the built-in scene is default_scene()"),
    (3, "got int 3"),
])
def test_load_scene_of_something_else_than_a_path_says_what_it_takes(value, words):
    with pytest.raises(TypeError) as err:
        load_scene(value)
    assert words in str(err.value)


def test_load_scene_of_a_scene_says_to_run_it():
    with pytest.raises(TypeError, match="already a Scene: pass it to run()"):
        load_scene(default_scene())


def test_the_entry_points_still_take_what_they_document(tmp_path):
    """A path as str or Path loads; a Scene with boolean flags runs: the bar dropped flat at
    v0 = 1 m/s from h = 0.1 mm touches after (sqrt(v0^2 + 2 g h) - v0) / g (the contacts
    table rounds times to 1 us, hence the tolerance)."""
    path = tmp_path / "tiny.toml"
    path.write_text("[bar]\nlength = 0.1\ndiameter = 0.006\ntip_radius = 0.003\nmodes = 0\n"
                    "[initial]\nheight = 1e-4\nangle_deg = 90.0\nvelocity = [0.0, 0.0, -1.0]\n"
                    "[solver]\nt_end = 2e-4\n")
    assert load_scene(str(path)).raw == load_scene(path).raw == TINY
    result = run(load_scene(path), progress=False, check=False)
    g, v0, h = 9.81, 1.0, 1e-4
    assert result.status == "ok"
    assert result.mechanics.contacts.t_start.iloc[0] == pytest.approx((((v0**2 + 2 * g * h) ** 0.5) - v0) / g,
                                                                        abs=1e-6)
