"""write_csv's Arrow route (coupling.app.arrow_text) and the lean Parquet writer: every
float reads back to the same double, in CPython's own text (float.__repr__, David Gay's
shortest digits, an implementation independent of Arrow's double-conversion), a column of
whole floats stays a float column for pandas, the file is the Python route's byte for
byte, and a pyarrow that lays floats out otherwise is caught and left alone."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq
import pytest

from coupling.app import arrow_text, output

ROOT = Path(__file__).resolve().parents[2]


def hard_floats(seed: int, n: int = 20_000) -> np.ndarray:
    """Every class arrow_text rewrites and its edges: random bit patterns (subnormals, NaN
    payloads, both extreme exponents), decimals of 1 to 17 digits at exponents -12..19 (the
    layouts' boundaries), whole floats, powers of ten and their neighbours, -0.0, inf."""
    rng = np.random.default_rng(seed)
    bits = rng.integers(0, 2**64, n, dtype=np.uint64).view(np.float64)
    digits = rng.integers(1, 18, n)
    mantissa = rng.integers(1, 10**17, n, dtype=np.int64) // 10 ** (17 - digits)
    decimals = np.array([float(f"{m}e{e}") for m, e in zip(mantissa.tolist(), rng.integers(-30, 20, n).tolist())])
    whole = np.concatenate([rng.integers(-10**6, 10**6, n).astype(float), 2.0 ** np.arange(64), 10.0 ** np.arange(23)])
    tens = np.array([float(f"1e{k}") for k in range(-325, 309)])
    tens = np.concatenate([tens, np.nextafter(tens, 0.0), np.nextafter(tens, np.inf)])
    special = np.array([0.0, -0.0, 5e-324, 2.2250738585072014e-308, 2.225073858507201e-308, 1.7976931348623157e308,
                        np.inf, np.nan, 1e-5, 9.999999999999999e-06, 1e-4, 1e16, 9999999999999998.0, 1e9, 1e17])
    values = np.concatenate([bits, decimals, whole, tens, special])
    return np.concatenate([values, -values])


def same_bits(a: float, b: float) -> bool:
    return np.array([a]).view(np.uint64)[0] == np.array([b]).view(np.uint64)[0]


@pytest.mark.parametrize("seed", [0, 1])
def test_every_float_is_written_as_float_repr_and_reads_back_to_the_same_double(seed):
    assert arrow_text.available()
    values = hard_floats(seed)
    cells = arrow_text.float_text(values).to_pylist()
    for value, cell in zip(values.tolist(), cells):
        if value != value:
            assert cell is None  # NaN: null, written blank
            continue
        assert cell == float.__repr__(value), value
        assert same_bits(float(cell), value)  # -0.0 too


def big_table(rows: int = 3000) -> tuple[dict, dict]:
    """Every kind of column the Arrow route takes: floats of every class (NaN, inf among
    them), whole floats, constant columns (0.0, -0.0, NaN, a value), integers, codes."""
    values = hard_floats(3)[:rows]
    with np.errstate(invalid="ignore", over="ignore"):
        single = values.astype(np.float32)
    rng = np.random.default_rng(4)
    columns = {"time": np.arange(rows) * 1e-6, "x": values, "y": values[::-1].copy(),
               "whole": rng.integers(-50, 50, rows).astype(float), "zero": np.zeros(rows), "minus_zero": np.full(rows, -0.0),
               "blank": np.full(rows, np.nan), "level": np.full(rows, 2.5e-7), "f32": single,
               "step": np.arange(rows), "u": rng.integers(0, 255, rows).astype(np.uint8),
               "regime": rng.integers(0, 3, rows)}
    return columns, {"regime": ("free", "slip", "stick")}


def python_route(monkeypatch, path: Path, columns: dict, codes: dict | None = None) -> bytes:
    with monkeypatch.context() as m:
        for name in ("ARROW_MIN_CELLS", "ARROW_FIRST_MIN_CELLS", "ARROW_IMPORT_MIN_CELLS"):
            m.setattr(output, name, 10**12)
        output.write_csv(path, columns, codes)
    return path.read_bytes()


def arrow_route(monkeypatch, path: Path, columns: dict, codes: dict | None = None) -> bytes:
    """write_csv, asserting that it took the Arrow route."""
    taken = []
    inner = arrow_text.write_rows
    monkeypatch.setattr(arrow_text, "write_rows", lambda *a: taken.append(1) or inner(*a))
    output.write_csv(path, columns, codes)
    monkeypatch.setattr(arrow_text, "write_rows", inner)
    assert taken, "the Arrow route was not taken"
    return path.read_bytes()


@pytest.mark.parametrize("chunk", [arrow_text.CHUNK_CELLS, 1000])
def test_the_arrow_route_writes_the_python_routes_bytes(tmp_path, monkeypatch, chunk):
    """In one piece and in pieces of a few rows (1000 cells: 83 rows of 12 columns)."""
    monkeypatch.setattr(arrow_text, "CHUNK_CELLS", chunk)
    columns, codes = big_table()
    assert arrow_route(monkeypatch, tmp_path / "a.csv", columns, codes) == \
        python_route(monkeypatch, tmp_path / "p.csv", columns, codes)


def test_float_columns_read_back_as_floats_and_exactly_in_pandas(tmp_path, monkeypatch):
    """A column of whole floats stays float64 (Arrow alone writes 1.0 as "1", an integer
    column for pandas); every value reads back bit for bit (pandas' round-trip parser)."""
    columns, codes = big_table()
    arrow_route(monkeypatch, tmp_path / "a.csv", columns, codes)
    frame = pd.read_csv(tmp_path / "a.csv")
    # pandas 3 reads round trip by default (and deprecates the option); pandas 2 on request
    exact = pd.read_csv(tmp_path / "a.csv", **({} if int(pd.__version__.split(".")[0]) >= 3
                                               else {"float_precision": "round_trip"}))
    assert list(frame.columns) == list(columns)
    for name, values in columns.items():
        if name in codes:
            assert frame[name].tolist() == [codes[name][k] for k in values]
        elif values.dtype.kind == "f":
            assert frame[name].dtype == np.float64, name
            back = exact[name].to_numpy()
            wanted = values.astype(float)
            assert np.array_equal(np.isnan(back), np.isnan(wanted))
            ok = ~np.isnan(wanted)
            assert np.array_equal(back[ok].view(np.uint64), wanted[ok].view(np.uint64)), name
        else:
            assert frame[name].dtype == np.int64 and frame[name].tolist() == values.tolist()


def test_a_pyarrow_laying_floats_out_otherwise_is_refused(tmp_path, monkeypatch):
    """Arrow's cast alone (1.0 as "1", 1e-05 as "0.00001", 1.5e-07 as "1.5e-7") fails the
    once-per-process check: write_csv then writes the same bytes by its Python route."""
    columns, codes = big_table()
    expected = python_route(monkeypatch, tmp_path / "p.csv", columns, codes)

    def cast_only(values):
        return pc.cast(pa.array(np.asarray(values, np.float64), from_pandas=True), pa.string())  # NaN: null

    monkeypatch.setattr(arrow_text, "float_text", cast_only)
    try:
        assert not arrow_text.available(again=True)
        output.write_csv(tmp_path / "c.csv", columns, codes)
    finally:
        monkeypatch.undo()
        assert arrow_text.available(again=True)
    assert (tmp_path / "c.csv").read_bytes() == expected
    assert pd.read_csv(tmp_path / "c.csv")["whole"].dtype == np.float64


@pytest.mark.parametrize("columns", [
    {"a": np.arange(3000.0), "b": [1.0] * 3000},  # a list: not an array
    {"a": np.arange(3000.0), "b": np.arange(3000) % 2 == 0},  # booleans: True/False
    {"a": np.arange(3000.0), "b": np.arange(2999.0)},  # lengths differ: zip stops at the shortest
    {"a": np.arange(3000.0), "\u00e4": np.arange(3000.0)},  # a name not ASCII: the locale's encoding
    {"a": np.arange(3000.0), "b": np.arange(3000).astype(">i8")},  # not the machine's byte order
], ids=["list", "booleans", "lengths", "name", "byte order"])
def test_tables_the_arrow_route_does_not_take_are_written_as_before(tmp_path, monkeypatch, columns):
    expected = python_route(monkeypatch, tmp_path / "p.csv", columns)
    monkeypatch.setattr(arrow_text, "write_rows", None)  # a call would fail
    output.write_csv(tmp_path / "a.csv", columns)
    assert (tmp_path / "a.csv").read_bytes() == expected


def test_codes_beyond_their_names_fail_as_before(tmp_path, monkeypatch):
    monkeypatch.setattr(arrow_text, "write_rows", None)
    with pytest.raises(IndexError):  # the Python route indexes the names
        output.write_csv(tmp_path / "a.csv", {"a": np.arange(3000.0), "b": np.full(3000, 7)}, {"b": ("x", "y")})


def test_parquet_is_the_file_pyarrow_parquet_writes(tmp_path, monkeypatch):
    """The writer taken from pyarrow._parquet with write_table's defaults gives its bytes;
    where that writer refuses the arguments (another pyarrow), pyarrow.parquet writes."""
    values = hard_floats(5)[:4000]
    columns = {"t": np.arange(len(values)) * 1e-6, "v": values, "n": np.arange(len(values)),
               "on": np.arange(len(values)) % 3 == 0}
    output.write_parquet(tmp_path / "lean.parquet", columns)
    table = pa.Table.from_arrays([pa.array(v) for v in columns.values()], names=list(columns))
    pq.write_table(table, tmp_path / "public.parquet")
    assert (tmp_path / "lean.parquet").read_bytes() == (tmp_path / "public.parquet").read_bytes()

    # a pyarrow whose writer takes other arguments: simulated by one it does not know
    monkeypatch.setitem(output.PARQUET_DEFAULTS, "a_keyword_of_another_pyarrow", True)
    output.write_parquet(tmp_path / "fallback.parquet", columns)
    assert (tmp_path / "fallback.parquet").read_bytes() == (tmp_path / "public.parquet").read_bytes()


def test_the_outputs_import_neither_pandas_nor_pyarrow_parquet_nor_compute(tmp_path):
    """pandas (~0.17 s), pyarrow.parquet (pyarrow.fs, ssl: ~20 ms) and pyarrow.compute (a
    wrapper per kernel: ~20 ms) are not needed to write a large CSV and the Parquet file."""
    code = textwrap.dedent(f"""
        import json, sys
        import numpy as np
        from pathlib import Path
        from coupling.app import arrow_text, output
        columns = {{"t": np.arange(12000) * 1e-6, "x": np.sin(np.arange(12000.0)), "n": np.arange(12000)}}
        output.write_parquet(Path({str(tmp_path)!r}) / "w.parquet", columns)
        output.write_csv(Path({str(tmp_path)!r}) / "w.csv", columns)
        print(json.dumps([arrow_text.ready(), sorted(sys.modules)]))  # ready: the Arrow route wrote
    """)
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    took_arrow, modules = json.loads(done.stdout.strip().splitlines()[-1])
    assert took_arrow
    assert not {"pandas", "pyarrow.parquet", "pyarrow.compute", "pyarrow.fs"} & set(modules)
    assert pd.read_csv(tmp_path / "w.csv")["x"].tolist() == np.sin(np.arange(12000.0)).tolist()


def test_rows_are_written_through_a_binary_file():
    """write_rows writes bytes: "," between cells, "\\n" after each line, NaN blank."""
    assert arrow_text.available()
    sink = io.BytesIO()
    arrow_text.write_rows(sink, [np.array([1.0, np.nan, -2.5e-7]), np.array([3, -4, 5])], [None, None])
    assert sink.getvalue() == b"1.0,3\n,-4\n-2.5e-07,5\n"
