"""Numeric CSV rows through Arrow's compute kernels: the bytes of write_csv's Python route
(``float.__repr__`` of each float, ``str`` of each integer) at a fraction of its cost.

Arrow's float-to-string cast writes the shortest digits that read back to the same double,
the digits ``float.__repr__`` writes, about five times faster; only their layout differs.
``repr`` writes a decimal exponent e in -4 <= e <= 15 in positional form, always with a
fraction ("1.0", "-0.0"), else "d.ddde-05" (two exponent digits at least); Arrow writes
-6 <= e <= 9 positionally, without a fraction for whole numbers ("1", "-0"), else with as
few exponent digits as needed ("1.5e-7"). Which of the two cases a value falls in follows
from the value alone: its shortest digits have an exponent >= k exactly when |x| >= the
double nearest 10**k (a shorter decimal on the other side of 10**k would read back on that
side). So each value is classed by comparisons, and four classes are rewritten with string
kernels (splices and joins; a regular expression cost ten times as much a string):

- whole numbers below 1e9: Arrow's "123" gets ".0";
- 1e-9 <= |x| < 1e-6 (exponents -9..-7): "1.5e-7" becomes "1.5e-07";
- 1e-6 <= |x| < 1e-4 (exponents -6, -5): Arrow's "0.0000123" becomes "1.23e-05";
- 1e9 <= |x| < 1e17 (where the two differ both ways): ``float.__repr__`` itself, rare in SI
  quantities of a switch.

The rest (|x| < 1e-9, 1e-4 <= |x| < 1e9 not whole, |x| >= 1e17, inf) is the same text in
both. NaN is null, written blank. Whether this pyarrow lays floats out as described is
checked once per process (``available``), against ``float.__repr__`` on values of every
class and their boundaries; where it does not, write_csv keeps its Python route.

Arrow is driven through ``pyarrow._compute`` (the module ``pyarrow.compute`` re-exports
``call_function`` from): importing ``pyarrow.compute`` builds a Python wrapper for every
kernel, ~20 ms. Arrays and scalars are built from buffers: ``pa.array`` and ``pa.scalar``
on Python objects import pandas (~0.17 s) to ask whether they are pandas objects. The
kernels allocate from the system's malloc, not pyarrow's default pool (mimalloc), which
kept the memory of every piece: the default scene's peak RSS grew 38 MB instead of 14.
"""

from __future__ import annotations

import io

import numpy as np

# cells formatted at once (850 rows of a relay's history.csv): in pieces this size the
# default scene's history.csv and waveforms.csv took the least time and raised the
# process's peak RSS by 14 MB (66 MB in one piece of 2**20 cells)
CHUNK_CELLS = 1 << 16
# class edges (module docstring): the doubles nearest these powers of ten
_EDGES = np.array([1e-9, 1e-6, 1e-5, 1e-4, 1e9, 1e17])
_WHOLE_BELOW = 1e9  # Arrow writes whole numbers below 1e10 positionally; 1e9.. goes to repr

_ARROW = None  # pyarrow and the kernels' options once checked (_load); False: not usable here


def available(*, again: bool = False) -> bool:
    """Whether pyarrow is importable and lays floats out as the module docstring says,
    checked once per process (``again``: anew) against ``float.__repr__``: ``float_text``
    and ``write_rows`` on ``probe_values()``; a pyarrow that formats otherwise leaves
    write_csv on its Python route."""
    global _ARROW
    if _ARROW is None or again:
        try:
            _ARROW = _load()
            _ARROW = _ARROW if _probe() else False
        except Exception:  # no pyarrow, or one whose kernels fail here: the Python route
            _ARROW = False
    return bool(_ARROW)


def ready() -> bool:
    """Whether ``available`` was asked in this process and said yes (the route's first-use
    costs are paid)."""
    return bool(_ARROW)


def _load() -> dict:
    import pyarrow as pa

    try:
        from pyarrow._compute import (CastOptions, JoinOptions, ReplaceSliceOptions, ReplaceSubstringOptions,
                                      call_function)
    except ImportError:  # a pyarrow laid out otherwise: the public module (its wrappers cost ~20 ms)
        from pyarrow.compute import (CastOptions, JoinOptions, ReplaceSliceOptions, ReplaceSubstringOptions,
                                     call_function)
    import pyarrow.csv

    pool = pa.system_memory_pool()

    def call(name, args, options=None):
        return call_function(name, args, options, pool)

    return {"pa": pa, "call": call, "pool": pool, "to_text": CastOptions(pa.string()), "csv": pyarrow.csv,
            "csv_options": pyarrow.csv.WriteOptions(include_header=False, quoting_style="none"),
            "join": JoinOptions("replace", ""), "splice": ReplaceSliceOptions,
            "dot_e": ReplaceSubstringOptions(".e", "e")}


def probe_values() -> np.ndarray:
    """Values of every class of the module docstring, on and beside its edges, both signs,
    and the special ones (zeros, subnormals, the largest double, inf, NaN)."""
    values = [0.0, 5e-324, 2.2250738585072014e-308, 1.7976931348623157e308, 1e-300, 1e300, float("inf"),
              float("nan"), 123456789.0, 999999999.0, 1e22, 0.1, 1 / 3]
    for k in range(-12, 20):
        edge = float(f"1e{k}")
        values += [edge, float(np.nextafter(edge, 0.0)), float(np.nextafter(edge, np.inf)), float(f"3e{k}"),
                   float(f"1.2345678901234567e{k}"), float(f"9.999999999999999e{k}"), float(f"2.5e{k}")]
    values = np.array(values)
    return np.concatenate([values, -values])


def _probe() -> bool:
    values = probe_values()
    ints = np.array([0, -1, 7, np.iinfo(np.int64).max, np.iinfo(np.int64).min])
    floats = float_text(values)
    expected = ["" if v != v else float.__repr__(v) for v in values.tolist()]
    sink = io.BytesIO()
    write_rows(sink, [values, values[::-1].copy(), np.arange(len(values)) % 3], [None, None, ("a", "b", "c")])
    lines = [f"{a},{b},{'abc'[k % 3]}\n" for k, (a, b) in enumerate(zip(expected, expected[::-1]))]
    return ([("" if s is None else s) for s in floats.to_pylist()] == expected
            and _int_text(ints).to_pylist() == [str(i) for i in ints.tolist()]
            and sink.getvalue() == "".join(lines).encode())


def _strings(texts: list[str]):
    """A pyarrow string array of ``texts``, built from its buffers (see the module docstring)."""
    pa = _ARROW["pa"]
    data = [t.encode() for t in texts]
    offsets = np.zeros(len(data) + 1, np.int32)
    np.cumsum([len(b) for b in data], out=offsets[1:])
    return pa.Array.from_buffers(pa.string(), len(data), [None, pa.py_buffer(offsets), pa.py_buffer(b"".join(data))])


def _indices(idx: np.ndarray):
    pa = _ARROW["pa"]
    idx = np.ascontiguousarray(idx, np.int64)
    return pa.Array.from_buffers(pa.int64(), len(idx), [None, pa.py_buffer(idx)])


def _numbers(values: np.ndarray, valid=None):
    pa = _ARROW["pa"]
    values = np.ascontiguousarray(values)
    return pa.Array.from_buffers(pa.from_numpy_dtype(values.dtype), len(values), [valid, pa.py_buffer(values)])


def _int_text(values: np.ndarray):
    return _ARROW["call"]("cast", [_numbers(values)], _ARROW["to_text"])


def float_text(values: np.ndarray):
    """Each float64 as ``float.__repr__`` writes it (the module docstring), NaN null: a
    pyarrow string array."""
    A = _ARROW
    call, join, splice = A["call"], A["join"], A["splice"]
    v = np.ascontiguousarray(values, np.float64)
    n = len(v)
    nan = np.isnan(v)
    valid = A["pa"].py_buffer(np.packbits(~nan, bitorder="little")) if nan.any() else None
    text = call("cast", [_numbers(v, valid)], A["to_text"])
    size = np.abs(v)
    cls = np.searchsorted(_EDGES, size, side="right")  # NaN sorts last: class 6, left as it is
    with np.errstate(invalid="ignore"):
        whole = (v == np.trunc(v)) & (size < _WHOLE_BELOW)
    sep = _strings([".0", "", "e-06", "e-05"])
    pieces, order, count = [text], np.arange(n, dtype=np.int64), n

    def put(idx, piece):  # these rows' text is `piece`, in their order
        nonlocal count
        order[idx] = np.arange(count, count + len(idx))
        count += len(idx)
        pieces.append(piece)

    def part(idx):
        return call("take", [text, _indices(idx)])

    if len(idx := np.flatnonzero(whole)):
        put(idx, call("binary_join_element_wise", [part(idx), sep[0], sep[1]], join))
    if len(idx := np.flatnonzero(cls == 1)):  # "1.5e-7": a 0 before the exponent's one digit
        put(idx, call("binary_replace_slice", [part(idx)], splice(-1, -1, "0")))
    for k, tail in ((2, sep[2]), (3, sep[3])):  # "0.00000123" / "0.0000123" of |x|: its digits, a point after the first
        if len(idx := np.flatnonzero(cls == k)):
            digits = call("binary_replace_slice", [call("cast", [_numbers(size[idx])], A["to_text"])],
                          splice(0, 9 - k, ""))
            body = call("binary_replace_slice", [digits], splice(1, 1, "."))
            body = call("binary_join_element_wise", [_signs(v[idx] < 0), body, tail, sep[1]], join)
            put(idx, call("replace_substring", [body], A["dot_e"]))  # one digit: "1.e-05" -> "1e-05"
    if len(idx := np.flatnonzero(cls == 5)):
        put(idx, _strings(list(map(float.__repr__, v[idx].tolist()))))
    if len(pieces) == 1:
        return text
    return call("take", [A["pa"].concat_arrays(pieces, A["pool"]), _indices(order)])


def _signs(negative: np.ndarray):
    """A string array of "-" where ``negative``, "" elsewhere, from its buffers."""
    pa = _ARROW["pa"]
    offsets = np.zeros(len(negative) + 1, np.int32)
    np.cumsum(negative, out=offsets[1:])
    return pa.Array.from_buffers(pa.string(), len(negative), [None, pa.py_buffer(offsets),
                                                             pa.py_buffer(b"-" * int(offsets[-1]))])


def write_rows(fh, columns: list, codes: list) -> None:
    """Write the rows of ``columns`` (equal-length 1-D numpy arrays of floats or integers)
    to the binary file ``fh``: cells joined with ",", lines ended by "\\n"; a column with
    names in ``codes`` (a tuple, or None) holds indices into them (0 <= index < len).
    Arrow's CSV writer lays the cells out (without quoting: no cell needs any); it joins
    the lines in a third of the time of a row-wise join kernel. Call only where
    ``available()``."""
    A = _ARROW
    call, pa = A["call"], A["pa"]
    names = [None if c is None else _strings(list(c)) for c in codes]
    n = len(columns[0])
    step = max(1, CHUNK_CELLS // len(columns))
    for start in range(0, n, step):
        rows = slice(start, min(n, start + step))
        m = rows.stop - rows.start
        parts, floats, where = [], [], []
        for col, label in zip(columns, names):
            v = col[rows]
            if label is not None:
                parts.append(call("take", [label, _indices(v)]))
            elif v.dtype.kind != "f":
                parts.append(_int_text(v))
            else:
                v = np.ascontiguousarray(v, np.float64)
                bits = v.view(np.int64)
                if np.all(bits == bits[0]):  # a constant column (a third of a relay's history): one cell
                    cell = _strings(["" if v[0] != v[0] else float.__repr__(float(v[0]))])
                    parts.append(call("take", [cell, _indices(np.zeros(m, np.int64))]))
                else:
                    where.append(len(parts))
                    floats.append(v)
                    parts.append(None)
        if floats:  # all the chunk's floats in one pass: a kernel call costs microseconds per column
            text = float_text(np.concatenate(floats))
            for k, at in enumerate(where):
                parts[at] = text.slice(k * m, m)
        table = pa.Table.from_arrays(parts, names=[str(k) for k in range(len(parts))])
        sink = pa.BufferOutputStream(A["pool"])
        A["csv"].write_csv(table, sink, A["csv_options"], A["pool"])
        fh.write(memoryview(sink.getvalue()))
