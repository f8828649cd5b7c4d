"""`switchsim life`: the worn geometry against the closed-form cap, the wear bookkeeping, the
end criteria, resume after an interrupt, bad input, and several designs on Dask.

The sampled scene is the built-in relay_cycle (one make and one break, ~0.6 s a run)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from coupling import builtin_scene
from coupling.app import life
from coupling.app.cli import main
from coupling.app.life import ContactGeometry, LifeError, LifeStudy, life_study, prepare, worn_document
from coupling.core.scene import scene_from_dict
from coupling.laws.duty import cap_volume


@pytest.fixture(scope="module")
def relay():
    return prepare(builtin_scene("relay_cycle"))[0]


def _cap_by_slices(height: float, radius: float) -> float:
    return quad(lambda z: math.pi * (radius * radius - z * z), radius - height, radius)[0]


def test_a_known_volume_gives_the_closed_form_cap_and_the_scene_keys(relay):
    """Take 20 % of the rivet's cap and 10 % of the fixed one's: the new height solves the cap
    of the kept base c, pi h (3 c^2 + h^2) / 6 = V - dV (a cubic, by numpy's roots here), the
    new sphere radius is (c^2 + h^2) / (2 h); the scene keys follow: [[rivet]] radius, its
    offset moving the apex up by the height lost, block.radius, initial.height grown by both
    heights lost, duty.cap_height, and duty.conductor_radius kept."""
    geom = ContactGeometry.of(relay)
    assert (geom.moving_height, geom.moving_radius, geom.gap) == (1.5e-3, 1.5e-3, 5e-4)  # a hemisphere, 0.5 mm gap
    dvm = 0.2 * _cap_by_slices(geom.moving_height, geom.moving_radius)
    dvf = 0.1 * _cap_by_slices(geom.fixed_height, geom.fixed_radius)
    worn = geom.worn(dvm, dvf)
    scene = scene_from_dict(worn_document(relay.raw, worn, geom), name="worn")
    expected = {}
    for side, h0, r0, dv in (("moving", geom.moving_height, geom.moving_radius, dvm),
                             ("fixed", geom.fixed_height, geom.fixed_radius, dvf)):
        c2 = h0 * (2 * r0 - h0)
        target = _cap_by_slices(h0, r0) - dv
        roots = np.roots([math.pi / 6, 0.0, math.pi * c2 / 2, -target])
        h = float(min(r.real for r in roots if abs(r.imag) < 1e-12 * h0 and r.real > 0))
        expected[side] = (h, (c2 + h * h) / (2 * h))
        assert _cap_by_slices(h, (c2 + h * h) / (2 * h)) == pytest.approx(target, rel=1e-9)
    (hm, rm), (hf, rf) = expected["moving"], expected["fixed"]
    rivet = scene.mech.rivets[0]
    assert rivet.radius == pytest.approx(rm, rel=1e-9)
    assert scene.mech.block.radius == pytest.approx(rf, rel=1e-9)
    base = relay.mech.rivets[0]
    # the apex (centre - radius, on the underside) moved towards the blade by the height lost
    assert rivet.offset - rivet.radius == pytest.approx(base.offset - base.radius + (1.5e-3 - hm), abs=1e-15)
    assert scene.mech.initial.height == pytest.approx(5e-4 + (1.5e-3 - hm) + (1.5e-3 - hf), rel=1e-9)
    assert scene.duty.cap_height == pytest.approx((hm, hf), rel=1e-9)
    assert scene.duty.conductor_radius == 1.5e-3
    assert float(cap_volume(hm, rm)) == pytest.approx(float(cap_volume(1.5e-3, 1.5e-3)) - dvm, rel=1e-9)
    with pytest.raises(ValueError, match=r"worn through"):
        geom.worn(1.01 * _cap_by_slices(geom.moving_height, geom.moving_radius), 0.0)


@pytest.fixture(scope="module")
def whole(relay, tmp_path_factory):
    """6 operations sampled every 2 (three runs), uninterrupted."""
    out = tmp_path_factory.mktemp("whole")
    report = life_study(relay, LifeStudy(6, 2), out)
    return report, out


def test_the_worn_volume_is_each_samples_erosion_times_the_operations_it_stands_for(relay, whole):
    report, out = whole
    rows = report.rows
    assert [r["operation"] for r in rows] == [0, 2, 4] and report.end == "operations"
    assert report.operations_done == 6
    worn = [0.0, 0.0]
    geom = ContactGeometry.of(relay)
    for row in rows:
        assert row["moving_worn_volume"] == pytest.approx(worn[0], rel=1e-12, abs=1e-30)
        shape = geom.worn(*worn)
        assert row["gap"] == pytest.approx(shape["gap"], rel=1e-12) and row["gap"] > 5e-4 - 1e-18
        worn = [worn[0] + row["operations"] * row["moving_eroded_volume"],
                worn[1] + row["operations"] * row["fixed_eroded_volume"]]
        # one operation's loss: the library's coefficient x its stage energies (Ag on Ag, 1e-13 m^3/J)
        assert row["moving_eroded_volume"] == pytest.approx(1e-13 * row["moving_anodic_energy"]
                                                            + 1e-13 * row["moving_cathodic_energy"], rel=1e-12)
    assert report.worn == pytest.approx(tuple(worn), rel=1e-12)
    # the end criteria's defaults: the gap within +-50 %, half the first held force, 10 x its R_c
    limits = dict(report.limits)
    assert limits.pop("stop_on_weld") == "likely"
    assert limits == pytest.approx({"gap_low": 2.5e-4, "gap_high": 7.5e-4, "min_force": 0.5 * rows[0]["held_force"],
                                    "max_resistance": 10 * rows[0]["contact_resistance"]}, rel=1e-12)
    from coupling.app.quantities import quantity
    from coupling.app.sweep import flatten_summary

    numbers = [k for k, v in flatten_summary({"life": report.summary()}).items()
               if isinstance(v, (int, float)) and not isinstance(v, bool)]
    assert len(numbers) >= 15 and [k for k in numbers if quantity(k) is None] == []
    import pandas as pd

    table = pd.read_parquet(out / "life.parquet")
    assert list(table.operation) == [0, 2, 4] and list(table.columns) == list(life.LIFE_COLUMNS)
    assert (out / "life.png").is_file() and (out / "life.csv").is_file()
    from plot_checks import assert_every_axis_has_a_unit

    assert assert_every_axis_has_a_unit(life.plot_life(rows), "plot_life")


def test_resume_after_an_interrupt_loses_no_sampled_operation(relay, whole, tmp_path, monkeypatch):
    """Ctrl-C during the third run: the two samples before it are on disk; --resume runs the
    third only and the study is the uninterrupted one's (the same runs in the same process:
    equal to round-off)."""
    calls = []
    real = life.run_sample

    def interrupted(scene):
        calls.append(scene.name)
        if len(calls) == 3:
            raise KeyboardInterrupt
        return real(scene)

    monkeypatch.setattr(life, "run_sample", interrupted)
    with pytest.raises(KeyboardInterrupt):
        life_study(relay, LifeStudy(6, 2), tmp_path)
    import pandas as pd

    assert list(pd.read_csv(tmp_path / "life.csv").operation) == [0, 2]
    with pytest.raises(LifeError, match=r"already holds a life study: pass --resume"):
        life_study(relay, LifeStudy(6, 2), tmp_path)
    with pytest.raises(LifeError, match=r"holds a different life study"):
        life_study(relay, LifeStudy(8, 2), tmp_path, resume=True)
    monkeypatch.setattr(life, "run_sample", real)
    resumed = life_study(relay, LifeStudy(6, 2), tmp_path, resume=True)
    assert resumed.new_samples == 1 and resumed.end == "operations"
    expected = whole[0].rows
    assert [r["operation"] for r in resumed.rows] == [r["operation"] for r in expected]
    for got, want in zip(resumed.rows, expected):
        for key in life.LIFE_COLUMNS:
            if key == "wall_time":
                continue
            if isinstance(want[key], float):
                assert got[key] == pytest.approx(want[key], rel=1e-12, abs=1e-300), key
            else:
                assert got[key] == want[key], key
    done = life_study(relay, LifeStudy(6, 2), tmp_path, resume=True)  # nothing left to do
    assert done.new_samples == 0 and len(done.rows) == 3


@pytest.mark.parametrize("changes, end, done", [
    ({"duty.life": {"min_force": 5.0}}, "force", 1),  # the relay holds at 1.6 N
    ({"duty.life": {"max_resistance": 1e-5}}, "resistance", 1),  # it holds at 0.25 mOhm
    ({"duty.life": {"stop_on_weld": "possible"}}, "weld", 1),  # its first bounce's pool: "possible"
    ({"duty.erosion_coefficient": 1e-6}, "worn_through", 10),  # 7e-9 m^3 per operation: the cap holds 7e-9
    ({"duty.erosion_coefficient": 1e-9, "duty.life": {"gap_range": [4e-4, 5.01e-4]}}, "gap", 10),
])
def test_a_study_ends_at_its_first_end_criterion(relay, tmp_path, changes, end, done):
    report = life_study(relay.update(changes), LifeStudy(100, 10), tmp_path)
    assert report.end == end and report.operations_done == done and len(report.rows) == 1
    assert report.summary()["end"] == end


def _err(capsys) -> str:
    return capsys.readouterr().err.strip()


def test_bad_input_is_one_line_naming_the_key_and_nothing_runs(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["life", "--operations", "0", "--out", str(out)]) == 2
    line = _err(capsys)
    assert "--operations" in line and "= 0" in line and "\n" not in line
    assert main(["life", "--operations", "10", "--every", "0", "--out", str(out)]) == 2
    assert "--every" in _err(capsys)
    scene = tmp_path / "bad.toml"
    scene.write_text(_toml_with({"duty": {"erosion_coefficient": -1e-13}}))
    assert main(["life", str(scene), "--operations", "10", "--out", str(out)]) == 2
    line = _err(capsys)
    assert "duty.erosion_coefficient[0] = -1e-13" in line and "\n" not in line
    drop = tmp_path / "drop.toml"
    from coupling.core.scene import builtin_scene_text

    drop.write_text(builtin_scene_text("free_drop"))
    assert main(["life", str(drop), "--operations", "10", "--out", str(out)]) == 2
    assert "a life study wears one [[rivet]] on a held bar" in _err(capsys)
    assert not out.exists()


def _toml_with(extra: dict) -> str:
    from coupling.core.scene import builtin_scene_text

    lines = [builtin_scene_text("relay_cycle")]
    for section, table in extra.items():
        lines.append(f"[{section}]")
        lines += [f"{k} = {v!r}" for k, v in table.items()]
    return "\n".join(lines) + "\n"


def test_the_command_runs_a_study_and_says_where(tmp_path, capsys):
    out = tmp_path / "life"
    assert main(["life", "--operations", "1", "--out", str(out), "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "1 of 1 operations, end: 1 operations" in text and str(out) in text
    assert {p.name for p in out.iterdir()} >= {"life.json", "checkpoint.json", "life.csv", "life.parquet", "life.png"}


def test_several_designs_on_dask(tmp_path):
    """Two designs of a cases sweep, each a life study (2 operations, one sample): a row per
    design with its outcome, its tables in OUT/life/<run_id>/; half the load current erodes
    less (the arc energy falls with the current); a resume has nothing left to do."""
    pytest.importorskip("distributed")
    from coupling.app.sweep import read_results

    (tmp_path / "relay.toml").write_text(_toml_with({}))
    sweep = tmp_path / "designs.toml"
    sweep.write_text('[sweep]\nscene = "relay.toml"\ndesign = "cases"\n'
                     '[[sweep.cases]]\nname = "r10"\n"circuit.load_resistance" = 10.0\n'
                     '[[sweep.cases]]\nname = "r20"\n"circuit.load_resistance" = 20.0\n')
    out = tmp_path / "out"
    report = life.life_sweep(sweep, LifeStudy(2, 2), out, workers=1, progress=False)
    assert report.done == 2 and report.failed == 0
    df = read_results(out).set_index("run_id")
    assert list(df.loc[["r10", "r20"], "life.end"]) == ["operations", "operations"]
    assert list(df.loc[["r10", "r20"], "life.operations_done"]) == [2, 2]
    assert df.loc["r20", "life.moving_worn_volume"] < df.loc["r10", "life.moving_worn_volume"]
    assert (out / "life" / "r10" / "life.csv").is_file() and (out / "life" / "r20" / "life.png").is_file()
    again = life.life_sweep(sweep, LifeStudy(2, 2), out, workers=1, progress=False, resume=True)
    assert again.done == 0 and again.skipped == 2
