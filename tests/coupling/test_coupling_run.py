"""Runs end to end: the command, its files, what each kind of scene builds, failures."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import numpy as np
import pandas as pd
import pytest

from coupling import builtin_scene, run
from coupling.app.cli import main
from coupling.core.scene import scene_from_dict

SUMMARY_KEYS = {"contacts", "restitution", "energy", "solver", "bounce"}
BOUNCE_KEYS = {"first_make", "last_make", "bounces", "total_bounce_time", "peak_contact_voltage", "arc_energy"}
WAVE_COLUMNS = {"time", "contact_voltage", "contact_current", "contact_resistance", "normal_force", "mu"}


def test_default_scene_runs_end_to_end_through_the_command(tmp_path, capsys):
    scene = tmp_path / "short_default.toml"
    from coupling.core.scene import builtin_scene_text

    scene.write_text(builtin_scene_text("relay_force").replace("t_end = 0.005", "t_end = 0.003"))
    assert main(["run", str(scene), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    out = tmp_path / "out"
    summary = json.loads((out / "summary.json").read_text())
    assert SUMMARY_KEYS <= set(summary) and BOUNCE_KEYS <= set(summary["bounce"])
    assert summary["status"] == "ok"
    for c in summary["contacts"]:
        assert {"tip", "t_start", "t_end", "peak_force", "impulse"} <= set(c)
    assert set(summary["energy"]) >= {"initial", "kinetic", "elastic", "potential_change", "normal_dissipation",
                                      "friction_dissipation", "residual"}
    assert set(summary["solver"]) >= {"steps", "rhs_evals", "events", "wall_time"}
    waves_csv = pd.read_csv(out / "waveforms.csv")
    waves_pq = pd.read_parquet(out / "waveforms.parquet")
    assert WAVE_COLUMNS <= set(waves_csv.columns)
    pd.testing.assert_frame_equal(waves_csv, waves_pq, check_exact=False, rtol=1e-12)
    # PNGs only on request, drawn afterwards from the folder's own tables
    pngs = ("waveforms.png", "waveforms_whole_run.png", "normal_force.png", "tip_heights.png", "energy.png")
    assert not any((out / name).exists() for name in pngs)
    assert main(["plot", str(out)]) == 0
    for name in pngs:
        assert (out / name).stat().st_size > 10_000
    b = summary["bounce"]
    # the bounce summary agrees with the mechanics' contact intervals
    starts = sorted(c["t_start"] for c in summary["contacts"])
    assert b["first_make"] == pytest.approx(starts[0]) and b["bounces"] == len(starts) - 1
    # arcs burn at U_min + E d + R i during the open intervals: the peak is at least U_min
    assert b["peak_contact_voltage"] >= 12.0 and b["arc_energy"] > 0.0


def test_mechanics_only_scene_starts_no_ngspice(tmp_path):
    """Leave out what the scene does not need: no circuit, no ngspice (checked in a fresh process)."""
    scene = tmp_path / "mech.toml"
    scene.write_text(textwrap.dedent("""
        [bar]
        modes = 0
        [initial]
        height = 0.001
        angle_deg = 90.0
        velocity = [0.0, 0.0, -0.5]
        [solver]
        t_end = 0.004
        """))
    code = textwrap.dedent(f"""
        import sys
        from coupling.app.cli import main
        rc = main(["run", {str(scene)!r}, "--out", {str(tmp_path / 'out')!r}, "--quiet"])
        import circuit.ngspice as ng
        print(rc, ng._SESSION is None)
        """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    rc, no_ngspice = out.stdout.splitlines()[-1].split()  # after the result lines (--quiet keeps them)
    assert rc == "0" and no_ngspice == "True"
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["kind"] == "mechanics" and "bounce" not in summary
    assert summary["solver"]["model"] == "planar" and summary["solver"]["modes"] == 0
    assert not (tmp_path / "out" / "waveforms.csv").exists()


def test_circuit_only_scene_reproduces_the_one_shot_pwl_reference():
    """A prescribed schedule runs no mechanics and gives the circuit package's own result."""
    from circuit import run_pwl_reference

    # both routes at a tight RELTOL: this compares them, through a ~1.7 kV opening spike
    doc = {"circuit": {"template": "inductive", "load_resistance": 24.0, "load_inductance": 10e-3,
                       "voltage": 24.0, "arc": True, "reltol": 1e-6,
                       "schedule": {"make": [1e-4, 4e-4, 7e-4], "break": [3e-4, 6e-4, 1.5e-3],
                                    "closed_resistance": 0.01}},
           "solver": {"t_end": 2e-3}}
    scene = scene_from_dict(doc)
    res = run(scene)
    assert res.mechanics is None and scene.kind == "circuit"
    ref = run_pwl_reference(scene.circuit.circuit, scene.circuit.schedule, scene.t_end, options=scene.circuit.options)
    t = np.linspace(5e-5, 1.9e-3, 800)
    for col in ("load_current", "contact_voltage"):
        scale = np.max(np.abs(ref[col]))
        np.testing.assert_allclose(np.interp(t, res.waveforms.time, res.waveforms[col]),
                                   np.interp(t, ref.time, ref[col]), atol=2e-3 * scale)
    b = res.bounce
    assert b["first_make"] == pytest.approx(1e-4) and b["last_make"] == pytest.approx(7e-4) and b["bounces"] == 2
    # an inductive load carries ~1 A at the final break: the arc takes it (arc energy > 0)
    assert b["arc_energy"] > 0.0


def test_planar_scene_uses_the_planar_model_and_zero_modes_the_rigid_bar():
    # pinned to 3 modes per family: the test is about the choice of model, and
    # 3 + 3 + 3 = 9 coordinates is the 3D model's count
    base = builtin_scene("free_drop").set("solver.t_end", 1.2e-3).set("bar.modes", 3)
    planar = base.set("initial.velocity", [0.2, 0.0, -1.0]).set("bar.modes", 0)
    res = run(planar)
    assert res.mechanics.solver["model"] == "planar" and res.mechanics.solver["modes"] == 0
    full = run(base)
    assert full.mechanics.solver["model"] == "3d" and full.mechanics.solver["modes"] == 9


def test_a_failed_run_writes_what_it_has_and_says_why(tmp_path, capsys):
    from coupling.core.scene import builtin_scene_text

    scene = tmp_path / "fails.toml"
    scene.write_text(builtin_scene_text("relay_force").replace("t_end = 0.005", "t_end = 0.003\nmax_steps = 300"))
    rc = main(["run", str(scene), "--out", str(tmp_path / "out"), "--quiet"])
    assert rc == 1
    err = capsys.readouterr().err
    assert "failed" in err and "too many steps" in err
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["status"] == "failed"
    assert (tmp_path / "out" / "history.csv").exists() and (tmp_path / "out" / "waveforms.csv").exists()


def test_bad_scene_file_gives_one_line_error_and_exit_2(tmp_path, capsys):
    scene = tmp_path / "bad.toml"
    scene.write_text("[circuit]\ntemplate = 'resistive'\n[bar]\nlength = -1\n[tribology]\nsource = 'illustrative'\n")
    assert main(["run", str(scene), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bar.length" in err[0] and "must be > 0" in err[0]
    assert not (tmp_path / "out").exists()


def test_no_circuit_step_is_a_pauses_round_off():
    """The circuit's accepted points of the coupled free drop (arcs, make/break landings,
    a pause at every macro step's end): none closer to the one before than the margin a
    pause's target is reached within (1e-12 of the time). Steering the step at a target
    already within it took ulp-sized steps (55 of them below 1e-15 s in the default relay),
    from which ngspice grows its step by at most 2x a point; one rejection there, below
    ngspice's smallest step, aborted a run."""
    result = run(builtin_scene("free_drop"))
    assert result.status == "ok", result.message
    t = np.asarray(result.waveform_columns["time"])
    steps = np.diff(t)
    assert np.all(steps > 1e-12 * t[1:]), (steps.min(), t[1:][np.argmin(steps)])


def test_a_step_through_the_touchdown_is_rejected_not_taken():
    """The free drop with 20 modes per family (mechanics only): in flight the step may grow
    where the far tip's gap allows, and one step of 1.7 ms from 0.92 ms crossed the
    touchdown at 0.995 ms. Its stages left the motion (a singular inertia: the compiled
    division raised, a crash) and its error estimate came out NaN, which compares false
    with 1: the step was accepted and every step after it failed. Rejected now, the drop
    touches down where free fall says, (sqrt(v0^2 + 2 g h) - v0) / g after the release
    (v0, h: the lower tip's speed and height), and its energy audit closes as the auto
    count's run does (1.2e-5 there, 5.6e-6 here: well below 1e-4)."""
    import tomllib

    from coupling.core.scene import builtin_scene_text

    doc = tomllib.loads(builtin_scene_text("free_drop"))
    for section in ("circuit", "tribology", "coupling"):
        doc.pop(section, None)
    doc["bar"]["modes"] = 20
    doc["solver"]["t_end"] = 3e-3
    result = run(scene_from_dict(doc))
    assert result.status == "ok", result.message
    v0 = -doc["initial"]["velocity"][2]
    h, g = doc["initial"]["height"], 9.80665
    touchdown = (np.sqrt(v0 ** 2 + 2.0 * g * h) - v0) / g
    assert result.summary["contacts"][0]["t_start"] == pytest.approx(touchdown, rel=1e-6)
    assert result.summary["energy"]["relative_residual"] < 1e-4
