"""Scenes: the default scene, every kind of bad input rejected before anything runs with
an error naming the field and what is allowed, round trips, and the summary's format."""

from __future__ import annotations

import dataclasses
import json
import math
import tomllib

import pytest

import mech
from mech import load_scene, scene_from_dict, scene_to_dict
from mech.scene import DEFAULT_SCENE_TOML


def test_default_scene_is_the_documented_steel_link():
    scene = mech.default_scene()
    bar = scene.bar
    assert (bar.length, bar.diameter, bar.tip_radius) == (0.3, 0.01, 0.005)
    # issue 9: the mode count is chosen from the scene (tests/mech/test_mech_mode_count.py)
    assert (bar.axial_modes, bar.bending_modes) == ("auto", "auto")
    assert bar.mass == pytest.approx(7850.0 * math.pi * 0.01**2 / 4 * 0.3, rel=1e-14)
    assert scene.initial.velocity == (0.2, 0.1, -1.0)  # out of plane: a 3D scene
    assert (scene.friction.mu, scene.friction.gamma) == (0.3, 0.7)
    assert (scene.solver.rtol, scene.solver.t_end) == (1e-6, 0.05)
    assert scene == scene_from_dict(tomllib.loads(DEFAULT_SCENE_TOML))


BAD = [
    # (document, words the message must contain)
    ({"bar": {"length": 0.0}}, ["bar.length", "> 0"]),
    ({"bar": {"length": -0.3}}, ["bar.length", "> 0"]),
    ({"bar": {"diameter": 0.0}}, ["bar.diameter", "> 0"]),
    ({"bar": {"tip_radius": -0.005}}, ["bar.tip_radius", "> 0"]),
    ({"bar": {"density": 0.0}}, ["bar.density", "[1.0, 100000.0]"]),
    ({"block": {"youngs_modulus": 0.0}}, ["block.youngs_modulus", "> 0"]),
    ({"bar": {"poisson_ratio": 0.5}}, ["bar.poisson_ratio", "(-1.0, 0.5)"]),
    ({"bar": {"poisson_ratio": -1.0}}, ["bar.poisson_ratio", "(-1.0, 0.5)"]),
    ({"block": {"poisson_ratio": 0.7}}, ["block.poisson_ratio", "(-1.0, 0.5)"]),
    ({"bar": {"length": math.nan}}, ["bar.length", "finite"]),
    ({"initial": {"velocity": [0.0, math.nan, -1.0]}}, ["initial.velocity[1]", "finite"]),
    ({"solver": {"rtol": math.inf}}, ["solver.rtol", "finite"]),
    ({"bar": {"length": "long"}}, ["bar.length", "number"]),
    ({"initial": {"height": -1e-3}}, ["initial.height", "inside the block", ">= 0"]),
    ({"friction": {"gamma": 1.0}}, ["friction.gamma", "[0.0, 1.0)"]),
    ({"friction": {"gamma": -0.1}}, ["friction.gamma", "[0.0, 1.0)"]),
    ({"friction": {"mu": -0.1}}, ["friction.mu", ">= 0"]),
    ({"contact": {"damping": 1e7, "restitution": 0.8}}, ["damping", "restitution", "not both"]),
    ({"contact": {"restitution": 1.5}}, ["contact.restitution", "(0.0, 1.0]"]),
    ({"contact": {"law": "hertz"}}, ["contact.law", "hunt_crossley"]),
    ({"contact": {"law": "paper", "calibration": "formula"}}, ["calibration", "exact"]),
    ({"bar": {"tip_radius": 0.004}}, ["bar.tip_radius", ">= 0.005", "half the diameter"]),
    ({"bar": {"tip_radius": 0.2}}, ["bar.tip_radius", "length/2"]),
    ({"bar": {"modes": 41}}, ["bar.modes", "[0, 40]"]),
    ({"bar": {"modes": 2.5}}, ["bar.modes = 2.5", "whole number"]),
    ({"bar": {"modes": {"axial": 2, "bend": 1}}}, ["modes", "'bend'", "axial, bending"]),
    ({"bar": {"width": 0.01}}, ["bar.width", "bar.thickness"]),
    ({"initial": {"angle_deg": 95.0}}, ["initial.angle_deg", "[-90.0, 90.0]"]),
    ({"initial": {"velocity": [1.0, 2.0]}}, ["initial.velocity", "3 numbers"]),
    ({"solver": {"rtol": 1.0}}, ["solver.rtol", "1e-05]"]),
    ({"solver": {"model": "2d"}}, ["solver.model", "'planar'", "'3d'"]),
    ({"solver": {"max_steps": 0}}, ["solver.max_steps", "[1, 100000000]"]),
    ({"friction": {"max_ratio": "big"}}, ["max_ratio", "inf"]),
    ({"environment": {"gravity": -9.81}}, ["environment.gravity", ">= 0"]),
    ({"bar": 3}, ["[bar]", "table"]),
]


@pytest.mark.parametrize("doc, words", BAD, ids=[str(d) for d, _ in BAD])
def test_bad_input_is_rejected_with_the_field_and_the_allowed_range(doc, words):
    with pytest.raises(ValueError) as info:
        scene_from_dict(doc)
    message = str(info.value)
    for word in words:
        assert word in message, (word, message)


@pytest.mark.parametrize("doc, unknown, suggestion", [
    ({"bar": {"lenght": 0.3}}, "'lenght'", "'length'"),
    ({"friction": {"gama": 0.7}}, "'gama'", "'gamma'"),
    ({"initial": {"velocity": [0, 0, -1], "hieght": 0.01}}, "'hieght'", "'height'"),
    ({"barr": {"length": 0.3}}, "[barr]", "'bar'"),
    ({"frictoin": {}}, "[frictoin]", "'friction'"),
])
def test_unknown_keys_and_sections_are_errors_with_a_suggestion(doc, unknown, suggestion):
    with pytest.raises(ValueError) as info:
        scene_from_dict(doc)
    message = str(info.value)
    assert "unknown" in message and unknown in message and f"did you mean {suggestion}" in message
    assert "allowed" in message


def test_other_packages_sections_pass_only_when_declared():
    doc = {"bar": {"length": 0.3}, "circuit": {"voltage": 24.0}}
    with pytest.raises(ValueError, match=r"unknown section \[circuit\]"):
        scene_from_dict(doc)
    assert scene_from_dict(doc, extra_sections=("circuit",)).bar.length == 0.3


def test_scene_round_trips_through_its_dict_form():
    scene = scene_from_dict({
        "bar": {"width": 0.012, "thickness": 0.004, "tip_radius": 0.007, "modes": {"axial": 2, "bending": 4},
                "bending": "paper_shear", "modal_damping": 0.01},
        "contact": {"law": "flores", "damping": 3e9},
        "friction": {"mu": 0.31, "gamma": 0.7, "max_ratio": "inf", "model": "regularized"},
        "initial": {"height": 0.002, "angle_deg": -45.0, "azimuth_deg": 20.0, "velocity": [0.1, 0.2, -0.5]},
        "solver": {"rtol": 1e-7, "t_end": 0.01, "model": "3d", "max_step": 1e-6},
        "environment": {"gravity": 0.0},
    })
    assert scene.bar.diameter is None and scene.contact.restitution is None
    assert math.isinf(scene.friction.max_ratio)
    assert scene_from_dict(scene_to_dict(scene)) == scene
    default = mech.default_scene()
    assert scene_from_dict(scene_to_dict(default)) == default


def test_a_callable_mu_cannot_be_written_to_a_scene_file():
    scene = dataclasses.replace(mech.default_scene(), friction=mech.Friction(mu=lambda current: 0.3 + 0.01 * current))
    with pytest.raises(ValueError, match="friction.mu"):
        scene_to_dict(scene)


def test_load_scene_reads_toml_and_names_the_file_in_errors(tmp_path):
    path = tmp_path / "drop.toml"
    path.write_text('[bar]\nlength = 0.25\nmodes = 0\n[initial]\nheight = 0.01\nangle_deg = 90.0\n'
                    'velocity = [0.0, 0.0, -0.5]\n')
    scene = load_scene(path)
    assert scene.bar.length == 0.25 and scene.bar.axial_modes == 0
    bad = tmp_path / "bad.toml"
    bad.write_text("[bar]\nlenght = 0.25\n")
    with pytest.raises(ValueError, match="bad.toml"):
        load_scene(bad)
    broken = tmp_path / "broken.toml"
    broken.write_text("[bar\nlength = 0.25\n")
    with pytest.raises(ValueError, match="not valid TOML"):
        load_scene(broken)
    with pytest.raises(FileNotFoundError, match="missing.toml"):
        load_scene(tmp_path / "missing.toml")


def test_summary_has_the_issues_fields_and_is_json(tmp_path):
    base = mech.default_scene()
    scene = dataclasses.replace(base, solver=dataclasses.replace(base.solver, t_end=1.4e-3))
    res = mech.simulate(scene)
    out = res.save(tmp_path / "run")
    summary = json.loads((out / "summary.json").read_text())
    assert len(summary["contacts"]) == 2
    for c in summary["contacts"]:
        assert {"tip", "t_start", "t_end", "peak_force", "impulse"} <= set(c)
    assert set(summary["restitution"]) == {"kinematic", "energetic"}
    assert {"initial", "kinetic", "elastic", "potential_change", "normal_dissipation",
            "friction_dissipation", "residual"} <= set(summary["energy"])
    assert {"steps", "rhs_evals", "events", "wall_time"} <= set(summary["solver"])
    for name in ("history.csv", "contacts.csv", "phases.csv", "events.csv"):
        assert (out / name).stat().st_size > 0
