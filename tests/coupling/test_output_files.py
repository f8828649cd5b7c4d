"""The result folder's tables as written by coupling.app.output: the CSV cells are the float64
values exactly (shortest repr, as numpy's own repr of the value), the file is what
csv.writer writes for the same cells (quoting included), and waveforms.parquet holds the
same values as waveforms.csv."""

from __future__ import annotations

import csv
import io
import math

import numpy as np
import pyarrow.parquet as pq
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from coupling.app.output import _cells, write_csv, write_parquet

SPECIAL = np.array([0.0, -0.0, 5e-324, -5e-324, 2.2250738585072014e-308, 2.225073858507201e-308, 1.7976931348623157e308,
                    -1.7976931348623157e308, 1e-4, 9.999999999999999e-05, 1e16, 9999999999999998.0, 1e-300, 1e300,
                    0.1, 1 / 3, float("inf"), -float("inf"), float("nan"), 1e22, 123456789.0, -1.5e-7])


def random_floats(n: int, seed: int) -> np.ndarray:
    """float64 from every part of the range: random bit patterns (subnormals, huge and tiny
    exponents, NaN payloads), normal samples, integers and the special values above."""
    rng = np.random.default_rng(seed)
    bits = rng.integers(0, 2**64, size=n, dtype=np.uint64).view(np.float64)
    return np.concatenate([SPECIAL, bits, rng.standard_normal(n) * 10.0 ** rng.integers(-12, 12, n),
                           rng.integers(-10**6, 10**6, n).astype(float)])


def read_back(path, columns: int) -> list[list[str]]:
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    assert all(len(r) == columns for r in rows)
    return rows


def csv_module_text(columns: dict, codes: dict | None = None) -> str:
    """The file as csv.writer writes the same cells (the writer before the joined lines)."""
    buf = io.StringIO(newline="")
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(list(columns))
    writer.writerows(zip(*[_cells(v, (codes or {}).get(k))[0] for k, v in columns.items()]))
    return buf.getvalue()


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_csv_floats_round_trip_exactly_and_are_numpys_repr(tmp_path, seed):
    x = random_floats(3000, seed)
    path = tmp_path / "t.csv"
    write_csv(path, {"a": x, "b": x[::-1].copy()})
    rows = read_back(path, 2)
    assert rows[0] == ["a", "b"]
    cells = [r[0] for r in rows[1:]]
    assert len(cells) == len(x)
    for value, cell in zip(x.tolist(), cells):
        if math.isnan(value):
            assert cell == ""  # NaN is blank, as pandas writes it
            continue
        assert cell == repr(value) == str(np.float64(value))  # shortest exact form, numpy's own repr
        back = float(cell)
        assert np.array([back]).view(np.uint64)[0] == np.array([value]).view(np.uint64)[0]  # bit for bit, -0.0 too


MOSTLY_ZERO = np.zeros(64)
MOSTLY_ZERO[[3, 9, 10, 40]] = [-0.0, 5e-324, 1.5, float("nan")]


@pytest.mark.parametrize("column", [
    np.zeros(50), np.full(50, -0.0), np.full(50, float("nan")), np.full(50, 0.1), np.full(1, 2.5),
    MOSTLY_ZERO, np.where(np.arange(60) % 3 == 0, -0.0, 0.0), np.where(np.arange(60) % 2 == 0, 0.0, 1e-300),
], ids=["zeros", "negative zeros", "nan", "constant", "one row", "mostly zeros", "zeros and negative zeros",
        "half zeros"])
def test_repeated_values_are_written_as_each_value_alone(tmp_path, column):
    """A column that repeats a value (formatted once: a constant column, or the zeros of a
    force in flight) is written as each of its values alone: -0.0 stays -0.0 beside 0.0
    (the values are compared bit for bit), NaN stays blank."""
    path = tmp_path / "t.csv"
    write_csv(path, {"a": column, "b": column[::-1].copy()})
    rows = read_back(path, 2)
    for k, (value, row) in enumerate(zip(column.tolist(), rows[1:])):
        assert row[0] == ("" if math.isnan(value) else repr(value))
        back = column[::-1][k]
        assert row[1] == ("" if math.isnan(back) else repr(float(back)))


def test_float32_and_integer_and_boolean_columns(tmp_path):
    path = tmp_path / "t.csv"
    f32 = np.array([0.1, -2.5, np.nan], dtype=np.float32)
    write_csv(path, {"f": f32, "i": np.array([-3, 0, 2**62]), "u": np.array([0, 1, 2], np.uint8),
                     "b": np.array([True, False, True])})
    rows = read_back(path, 4)
    assert rows[1:] == [[repr(float(f32[0])), "-3", "0", "True"], ["-2.5", "0", "1", "False"],
                        ["", str(2**62), "2", "True"]]


def test_codes_become_their_names(tmp_path):
    path = tmp_path / "t.csv"
    write_csv(path, {"t": np.array([0.0, 1.0, 2.0]), "regime": np.array([0, 2, 1])},
              codes={"regime": ("free", "slip", "stick")})
    assert path.read_text() == "t,regime\n0.0,free\n1.0,stick\n2.0,slip\n"


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.one_of(st.none(), st.text(max_size=6), st.integers(), st.booleans(),
                                    st.floats(allow_nan=True, allow_infinity=True)),
                          st.floats(allow_nan=True), st.text(alphabet=',"\r\n ab', max_size=4)),
                max_size=8),
       st.lists(st.text(alphabet=',"\r\n xy', min_size=1, max_size=4), min_size=3, max_size=3, unique=True))
def test_the_file_is_what_csv_writer_writes_for_the_same_cells(tmp_path_factory, rows, names):
    """Text cells and names that need quoting, None, NaN, mixed objects: the same bytes as csv.writer."""
    columns = {names[0]: [r[0] for r in rows], names[1]: np.array([r[1] for r in rows], dtype=float),
               names[2]: [r[2] for r in rows]}
    path = tmp_path_factory.mktemp("csv") / "t.csv"
    write_csv(path, columns)
    with open(path, newline="") as fh:
        assert fh.read() == csv_module_text(columns)


@pytest.mark.parametrize("columns", [
    {"only": np.array([1.0, np.nan, 2.0])},  # one column: csv.writer writes the blank as ""
    {"only": ["", "a"]},
    {"a": np.array([], dtype=float), "b": []},  # no rows: the header alone
    {"a,b": np.array([1.0]), "c": np.array([2.0])},  # a name that needs quoting
    {"a": ["x\ny", "z"], "b": np.array([1, 2])},
])
def test_edge_tables_are_written_as_csv_writer_writes_them(tmp_path, columns):
    path = tmp_path / "t.csv"
    write_csv(path, columns)
    with open(path, newline="") as fh:
        assert fh.read() == csv_module_text(columns)


def test_parquet_and_csv_hold_the_same_values(tmp_path):
    x = random_floats(500, 7)
    columns = {"time": np.arange(len(x), dtype=float) * 1e-6, "v(a,b)": x, "n": np.arange(len(x))}
    write_csv(tmp_path / "w.csv", columns)
    write_parquet(tmp_path / "w.parquet", columns)
    table = pq.read_table(tmp_path / "w.parquet")
    assert table.column_names == list(columns)
    rows = read_back(tmp_path / "w.csv", 3)
    assert rows[0] == list(columns)
    for j, name in enumerate(columns):
        stored = table.column(name).to_numpy()
        assert stored.dtype == columns[name].dtype
        assert np.array_equal(stored.view(np.uint64 if stored.dtype.kind == "f" else stored.dtype),
                              columns[name].view(np.uint64 if stored.dtype.kind == "f" else stored.dtype))
        from_csv = [r[j] for r in rows[1:]]
        if stored.dtype.kind == "f":
            assert [c == "" for c in from_csv] == np.isnan(stored).tolist()
            ok = ~np.isnan(stored)
            back = np.array([float(c) for c, k in zip(from_csv, ok) if k])
            assert np.array_equal(back.view(np.uint64), stored[ok].view(np.uint64))
        else:
            assert [int(c) for c in from_csv] == stored.tolist()


def test_the_api_and_the_command_line_write_the_same_folder(tmp_path):
    """One writer: result.save and `switchsim run` give the same files, history.csv thinned
    alike (the API wrote every solver record before), and save refuses a folder of other
    files as the command line does."""
    import pytest

    from coupling import builtin_scene, run
    from coupling.app.cli import main
    from coupling.app.output import DestinationError

    from coupling.core.scene import builtin_scene_text

    scene = builtin_scene("relay_force").set("solver.t_end", 1e-3)
    path = tmp_path / "s.toml"
    path.write_text(builtin_scene_text("relay_force").replace("t_end = 0.005", "t_end = 0.001"))
    assert main(["run", str(path), "--out", str(tmp_path / "cli"), "--quiet"]) == 0
    run(scene).save(tmp_path / "api")
    names = sorted(p.name for p in (tmp_path / "cli").iterdir())
    assert names == sorted(p.name for p in (tmp_path / "api").iterdir())
    cli = (tmp_path / "cli" / "history.csv").read_text().splitlines()
    api = (tmp_path / "api" / "history.csv").read_text().splitlines()
    assert len(cli) == len(api) and cli[0] == api[0]
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("keep me")
    with pytest.raises(DestinationError, match="holds files that are not"):
        run(scene).save(tmp_path / "mine")
    assert (tmp_path / "mine" / "notes.txt").read_text() == "keep me"
