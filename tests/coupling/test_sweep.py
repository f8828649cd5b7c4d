"""Design sweeps: the designs, validation of sweep files, rows of a run, the results dataset.

These run in this process (no Dask); the interruption tests (Ctrl-C, killed worker,
killed client) are in test_sweep_resume.py.
"""

from __future__ import annotations

import math
import textwrap
import tomllib

import numpy as np
import pandas as pd
import pytest

from coupling.core.scene import scene_from_dict
from coupling.app.sweep import Sweep, RowWriter, apply_changes, flatten_summary, load_sweep, read_results, \
    run_sweep_inline

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
[contact]
law = "hunt_crossley"
restitution = 0.8
[solver]
t_end = 0.0004
"""


def tiny():
    return scene_from_dict(tomllib.loads(TINY), name="tiny")


def test_grid_is_every_combination_with_stable_ids():
    sw = Sweep.grid(tiny(), {"contact.restitution": [0.5, 0.9], "initial.height": [1e-4, 2e-4, 3e-4]})
    assert len(sw.runs) == 6 and sw.parameters == ["contact.restitution", "initial.height"]
    combos = {(r.params["contact.restitution"], r.params["initial.height"]) for r in sw.runs}
    assert combos == {(e, h) for e in (0.5, 0.9) for h in (1e-4, 2e-4, 3e-4)}
    assert [r.run_id for r in sw.runs] == [f"run{k:04d}" for k in range(6)]
    # the same sweep built again has the same ids and fingerprint (what --resume relies on)
    again = Sweep.grid(tiny(), {"contact.restitution": [0.5, 0.9], "initial.height": [1e-4, 2e-4, 3e-4]})
    assert again.fingerprint() == sw.fingerprint()
    other = Sweep.grid(tiny(), {"contact.restitution": [0.5, 0.8], "initial.height": [1e-4, 2e-4, 3e-4]})
    assert other.fingerprint() != sw.fingerprint()


def test_lhs_design_is_seeded_and_stratified_and_log_ranges_stay_inside():
    ranges = {"initial.angle_deg": [10.0, 80.0], "contact.restitution": {"low": 0.1, "high": 0.9, "log": True}}
    a = Sweep.sample(tiny(), ranges, samples=10, seed=3, method="lhs")
    b = Sweep.sample(tiny(), ranges, samples=10, seed=3, method="lhs")
    assert [r.params for r in a.runs] == [r.params for r in b.runs]
    angles = np.array([r.params["initial.angle_deg"] for r in a.runs])
    # Latin hypercube: exactly one sample in each tenth of the range
    assert sorted(np.floor((angles - 10.0) / 7.0).astype(int)) == list(range(10))
    e = np.array([r.params["contact.restitution"] for r in a.runs])
    assert np.all((e >= 0.1) & (e <= 0.9))
    # log-uniform: one sample per tenth of log(e)
    assert sorted(np.floor(np.log(e / 0.1) / (np.log(9.0) / 10)).astype(int)) == list(range(10))
    r = Sweep.sample(tiny(), ranges, samples=10, seed=3, method="random")
    assert [x.params for x in r.runs] != [x.params for x in a.runs]


def test_dotted_keys_create_nested_tables_without_touching_the_base():
    base = {"circuit": {"voltage": 24.0}}
    doc = apply_changes(base, {"circuit.snubber.resistance": 47.0, "circuit.snubber.capacitance": 1e-7})
    assert doc["circuit"]["snubber"] == {"resistance": 47.0, "capacitance": 1e-7}
    assert base == {"circuit": {"voltage": 24.0}}


@pytest.mark.parametrize("body, needle", [
    ('design = "grid"\n[sweep.grid]\n"initial.angel_deg" = [10.0]', "angel_deg"),
    ('design = "grid"\n[sweep.grid]\n"contact.restitution" = [0.5, 1.5]', "restitution"),
    ('design = "grid"\n[sweep.grid]\n"contact.restitution" = 0.5', "non-empty list"),
    ('design = "grid"\n[sweep.grid]\nrestitution = [0.5]', "section.key"),
    ('design = "grd"', "grid"),
    ('design = "lhs"\nsamples = 4\n[sweep.ranges]\n"initial.angle_deg" = [80.0, 10.0]', "low < high"),
    ('design = "lhs"\n[sweep.ranges]\n"initial.angle_deg" = [10.0, 80.0]', "samples"),
    ('design = "cases"\n[[sweep.cases]]\nname = "a b"\n"initial.angle_deg" = 10.0', "name"),
    ('design = "cases"\n[[sweep.cases]]\nname = "a"\n[[sweep.cases]]\nname = "a"', "used twice"),
    ('design = "grid"\nwaveform = true\n[sweep.grid]\n"initial.angle_deg" = [10.0]', "sweep.waveform"),
])
def test_bad_sweep_files_name_the_key_before_anything_runs(tmp_path, body, needle):
    (tmp_path / "tiny.toml").write_text(TINY)
    path = tmp_path / "sw.toml"
    path.write_text('[sweep]\nscene = "tiny.toml"\n' + body + "\n")
    with pytest.raises(ValueError, match=needle):
        load_sweep(path)


def test_sweep_file_with_named_cases_and_common_values(tmp_path):
    (tmp_path / "tiny.toml").write_text(TINY)
    path = tmp_path / "sw.toml"
    path.write_text(textwrap.dedent("""
        [sweep]
        scene = "tiny.toml"
        design = "cases"
        set = { "solver.t_end" = 0.0003 }
        [[sweep.cases]]
        name = "soft"
        contact.restitution = 0.3
        [[sweep.cases]]
        name = "hard"
        contact.restitution = 0.95
    """))
    sw = load_sweep(path)
    assert [r.run_id for r in sw.runs] == ["soft", "hard"]
    assert sw.scene(sw.runs[1]).t_end == 0.0003
    assert sw.scene(sw.runs[1]).mech.contact.restitution == 0.95


def test_rows_carry_parameters_and_summary_scalars_and_follow_the_physics():
    """A rigid bar dropped flat-end-down (90 deg) onto the block rebounds with the restitution
    the Hunt-Crossley law is calibrated to: the row's kinematic restitution follows e."""
    sw = Sweep.grid(tiny(), {"contact.restitution": [0.4, 0.8]})
    rows = run_sweep_inline(sw)
    assert [r["status"] for r in rows] == ["ok", "ok"]
    for row in rows:
        assert row["restitution.kinematic"] == pytest.approx(row["contact.restitution"], abs=0.03)
        assert row["wall_time"] > 0 and row["error"] is None
        assert isinstance(row["energy.relative_residual"], float)


def test_a_failing_run_is_a_row_with_its_error_and_the_others_still_run():
    sw = Sweep.grid(tiny(), {"solver.max_steps": [2, 100000]})
    rows = run_sweep_inline(sw)
    assert rows[0]["status"] == "failed" and "step" in rows[0]["error"].lower()
    assert rows[1]["status"] == "ok" and rows[1]["error"] is None


def test_flatten_summary_keeps_scalars_with_dotted_keys():
    flat = flatten_summary({"bounce": {"first_make": 1e-3, "bounces": 2, "final_state": "open"},
                            "contacts": [{"tip": 0}], "flags": ["a", "b"], "run": {"circuit": {"steps": 5}}})
    assert flat == {"bounce.first_make": 1e-3, "bounce.bounces": 2, "bounce.final_state": "open",
                    "flags": "a; b", "run.circuit.steps": 5}


def test_batches_with_different_columns_read_back_as_one_dataset(tmp_path):
    """A failed run's batch lacks the summary columns and may hold only nulls in a numeric one;
    the dataset is still one table, nulls where a batch had no value."""
    writer = RowWriter(tmp_path / "results", "s1", every=math.inf, size=10)
    writer.add({"run_id": "a", "x": 1.0, "bounce.bounces": 2, "status": "ok", "error": None})
    writer.flush()
    writer.add({"run_id": "b", "x": 2.0, "status": "failed", "error": "boom"})
    writer.flush()
    writer.add({"run_id": "c", "x": 3.0, "bounce.bounces": 1.5, "status": "ok", "error": None})
    writer.flush()
    df = read_results(tmp_path).sort_values("run_id").reset_index(drop=True)
    assert list(df.run_id) == ["a", "b", "c"]
    assert df["bounce.bounces"].iloc[0] == 2 and pd.isna(df["bounce.bounces"].iloc[1])
    assert df["bounce.bounces"].iloc[2] == 1.5
    assert list(df.error.fillna("")) == ["", "boom", ""]


def test_batches_whose_text_column_is_missing_in_every_row_read_as_one_table(tmp_path):
    """A 1000-run study stopped when one batch's rows all lacked a text column (settle_note:
    a float column of NaN there) and another's had it (strings): no schema unified them."""
    from coupling.app.sweep import RowWriter, read_results

    writer = RowWriter(tmp_path / "results", "s1", size=2)
    # batch 1: no settle_note in either row (a failed run's row holds NaN there): pandas
    # makes the column float
    writer.add({"run_id": "run0", "status": "failed", "bounce.bounces": 3, "bounce.settle_note": float("nan")})
    writer.add({"run_id": "run1", "status": "ok", "bounce.bounces": 4, "bounce.settle_note": None})
    writer.add({"run_id": "run2", "status": "ok", "bounce.bounces": 5, "bounce.settle_note": "not settled"})
    writer.add({"run_id": "run3", "status": "ok", "bounce.bounces": 6, "bounce.settle_note": None})
    writer.flush()
    df = read_results(tmp_path).sort_values("run_id")
    assert list(df.run_id) == ["run0", "run1", "run2", "run3"]
    assert list(df["bounce.bounces"]) == [3, 4, 5, 6]
    assert df["bounce.settle_note"].tolist()[2] == "not settled" and df["bounce.settle_note"].isna().tolist() == [
        True, True, False, True]


def test_a_long_study_leaves_few_batch_files_and_every_row_once(tmp_path):
    """The writer merges every `merge` files of one size into one, and so up: 100 batches
    with merge = 4 leave at most 3 files per level (4 levels here), each row read once,
    columns that differ between batches (a failed run's row lacks the summary) unified."""
    writer = RowWriter(tmp_path / "results", "s1", every=math.inf, size=1, merge=4)
    for k in range(100):
        row = {"run_id": f"run{k:03d}", "status": "ok" if k % 7 else "failed", "x": float(k)}
        if k % 7:
            row["bounce.bounces"] = k
        writer.add(row)
    writer.flush()
    files = sorted((tmp_path / "results").glob("part-*.parquet"))
    # 100 in base 4 is 1210: one file of 64 batches, two of 16, one of 4, none single
    assert len(files) == 1 + 2 + 1
    df = read_results(tmp_path)
    assert list(df.run_id) == [f"run{k:03d}" for k in range(100)]  # in the order written
    assert df.x.tolist() == [float(k) for k in range(100)]
    assert df["bounce.bounces"].isna().tolist() == [k % 7 == 0 for k in range(100)]


def test_a_merge_stopped_before_its_deletes_reads_each_row_once(tmp_path):
    """A merge writes the merged file, then deletes the batches it holds: stopped between the
    two (a kill), both are on disk, and the rows are still read, and counted, once."""
    import shutil

    from coupling.app.sweep import finished_run_ids

    folder = tmp_path / "results"
    writer = RowWriter(folder, "s1", every=math.inf, size=1, merge=4)
    for k in range(3):
        writer.add({"run_id": f"run{k}", "status": "ok", "x": float(k)})
    kept = sorted(folder.glob("part-*.parquet"))
    shutil.copytree(folder, tmp_path / "copy")
    writer.add({"run_id": "run3", "status": "ok", "x": 3.0})  # the fourth batch: merged, the three deleted
    assert [f.name for f in folder.glob("part-*.parquet")] == ["part-s1-00000to00003.parquet"]
    for f in kept:  # as if the deletes had not happened
        shutil.copy(tmp_path / "copy" / f.name, folder / f.name)
    assert len(list(folder.glob("part-*.parquet"))) == 4
    assert sorted(read_results(tmp_path).run_id) == ["run0", "run1", "run2", "run3"]
    assert finished_run_ids(tmp_path) == {"run0", "run1", "run2", "run3"}
