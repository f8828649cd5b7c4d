"""The tribometer CSV form: reading it and validating it, with errors that name file, column, line and value.

Form (docs/tribology.md): one row per measured point, columns
`load_N, current_A, friction_N, resistance_ohm` (normal load in N, DC current in A,
friction force in N, contact resistance in ohm) and an optional `run` (repeat id, any
label). Lines whose first non-blank character is `#` are comments; blank lines are
skipped. The sign of the current is ignored by the fits (|I|).
"""

from __future__ import annotations

import csv
import difflib
import io
import re
from pathlib import Path
from typing import Callable, Sequence

import numpy as np
import pandas as pd

NUMERIC_COLUMNS = ("load_N", "current_A", "friction_N", "resistance_ohm")
OPTIONAL_COLUMNS = ("run",)
# A per-current friction fit has one mu per current level plus gamma, and needs one
# more point than parameters to estimate the scatter.
EXTRA_POINTS_NEEDED = 2


def minimum_rows(n_current_levels: int) -> int:
    """Rows a fit needs: one mu per current level, gamma, and one for the scatter."""
    return n_current_levels + EXTRA_POINTS_NEEDED


_COMMENT = re.compile(r"^[ \t]*#[^\n]*(?:\n|$)", re.M)
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]{0,40}")


def _decode(data: bytes, path: Path) -> str:
    """UTF-8 text (an Excel "CSV UTF-8" export starts with a byte-order mark: dropped)."""
    if b"\x00" in data[:65536]:
        raise ValueError(f"{path}: not a text file (NUL bytes): expected a tribometer CSV")
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        start = err.start
        line = data[:start].count(b"\n") + 1
        column = start - (data.rfind(b"\n", 0, start) + 1) + 1
        raise ValueError(f"{path}: line {line}, column {column}: byte 0x{data[start]:02x} is not UTF-8 text; "
                         "save the file as CSV UTF-8 (or plain ASCII)") from None


def _data_lines(text: str) -> tuple[list[str], list[list[str]], list[int]]:
    """Comment lines, split data lines (header first) and their line numbers: the exact,
    line-by-line reading, used for small files and to locate an error."""
    header: list[str] = []
    rows: list[list[str]] = []
    line_numbers: list[int] = []
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            header.append(stripped.lstrip("#").strip())
            continue
        rows.append([cell.strip() for cell in next(csv.reader([line]))])
        line_numbers.append(number)
    return header, rows, line_numbers


def _check_header(names: list[str], path: Path, line: int) -> None:
    """Column names, without repeating a header that is not a tribometer header (the file
    may be anything: a name is quoted only when the line has the shape of a CSV header)."""
    shaped = len(names) >= len(NUMERIC_COLUMNS) - 1 and all(_NAME.fullmatch(n) for n in names)
    allowed = NUMERIC_COLUMNS + OPTIONAL_COLUMNS
    duplicated = sorted({c for c in names if names.count(c) > 1 and c in allowed})
    if duplicated:
        raise ValueError(f"{path}: duplicated column(s) {duplicated}")
    unknown = [(k, c) for k, c in enumerate(names, start=1) if c not in allowed]
    if unknown:
        hints = []
        for k, c in unknown:
            close = difflib.get_close_matches(c, allowed, n=1)
            label = f"{c!r}" if shaped else f"column {k}"
            hints.append(label + (f" (did you mean {close[0]!r}?)" if close else ""))
        raise ValueError(f"{path}: header line {line}: unknown column(s) {', '.join(hints)}; "
                         f"allowed: {', '.join(allowed)}")


def read_tribometer_csv(path) -> pd.DataFrame:
    """Read and validate a tribometer CSV; returns a DataFrame of the columns above.

    path: str or Path. Raises ValueError naming the file, column, line and value for
    missing or unknown columns, non-numeric or missing (NaN) values, loads that are
    not > 0, negative or zero friction forces and resistances, non-finite currents,
    and too few points for a fit; FileNotFoundError for a missing file. A header that
    is not a tribometer header is not repeated in the message (the path may name any
    file). UTF-8 with or without a byte-order mark. The comment lines are kept in
    `df.attrs["header"]` and the path in `df.attrs["source"]`.
    """
    path = Path(path)
    try:
        if path.is_dir():
            raise ValueError(f"{path}: is a folder, not a tribometer CSV file")
        data = path.read_bytes()
    except FileNotFoundError:
        raise FileNotFoundError(f"{path}: no such tribometer CSV file") from None
    except OSError as err:
        raise ValueError(f"{path}: cannot read ({err.strerror or type(err).__name__})") from None
    text = _decode(data, path)
    del data
    comments = [m.group(0) for m in _COMMENT.finditer(text)]
    header = [c.strip().lstrip("#").strip() for c in comments]
    body = _COMMENT.sub("", text) if comments else text
    del text
    first = next((ln for ln in body.splitlines() if ln.strip()), None) if len(body) < 4096 else _first_line(body)
    if first is None:
        raise ValueError(f"{path}: no header line and no data (expected columns {', '.join(NUMERIC_COLUMNS)})")
    names = [cell.strip() for cell in next(csv.reader([first]))]
    header_line = _line_of_data_row(path, 0)
    _check_header(names, path, header_line)
    df = _fast_frame(body, names) if '"' not in body else None
    if df is None:
        # the exact reading: quoted cells, or a malformed file (the error says where)
        _, rows, line_numbers = _data_lines(path.read_bytes().decode("utf-8-sig"))
        for cells, number in zip(rows[1:], line_numbers[1:]):
            if len(cells) != len(names):
                raise ValueError(f"{path}: line {number} has {len(cells)} fields, the header line "
                                 f"{line_numbers[0]} has {len(names)}")
        raw = pd.DataFrame(rows[1:], columns=names) if len(rows) > 1 else pd.DataFrame(columns=names)
        labels: Sequence[str] | Callable[[int], str] = [f"line {n}" for n in line_numbers[1:]]
    else:
        raw = df
        labels = lambda k: f"line {_line_of_data_row(path, k + 1)}"  # noqa: E731
    out = validate_tribometer_frame(raw, source=str(path), row_labels=labels)
    out.attrs["header"] = tuple(header)
    out.attrs["source"] = str(path)
    return out


def _first_line(body: str) -> str | None:
    start = 0
    while start < len(body):
        end = body.find("\n", start)
        end = len(body) if end < 0 else end
        if body[start:end].strip():
            return body[start:end]
        start = end + 1
    return None


def _line_of_data_row(path: Path, k: int) -> int:
    """File line number of data row k (0: the header line), counting comments and blank lines."""
    count = -1
    with open(path, encoding="utf-8-sig", errors="replace") as handle:
        for number, line in enumerate(handle, start=1):
            stripped = line.strip()
            if not stripped or stripped.startswith("#"):
                continue
            count += 1
            if count == k:
                return number
    return -1


def _fast_frame(body: str, names: list[str]) -> pd.DataFrame | None:
    """The table through pandas' C reader (large files), or None when a row does not
    parse cleanly: wrong field count or a non-numeric cell (the exact reading then says where)."""
    dtypes = {c: np.float64 for c in NUMERIC_COLUMNS if c in names}
    if "run" in names:
        dtypes["run"] = "category"
    try:
        df = pd.read_csv(io.StringIO(body), dtype=dtypes, skipinitialspace=True, skip_blank_lines=True,
                         na_filter=True, engine="c")
    except (ValueError, pd.errors.ParserError):
        return None
    if list(df.columns) != names:
        return None
    numeric = [c for c in NUMERIC_COLUMNS if c in names]
    if df[numeric].isna().to_numpy().any():
        return None  # an empty cell, NaN or a short row: located by the exact reading
    return df


def validate_tribometer_frame(df: pd.DataFrame, source: str = "DataFrame",
                              row_labels: Sequence[str] | Callable[[int], str] | None = None) -> pd.DataFrame:
    """Check a tribometer table and return a clean copy with float columns.

    source names the data in the messages; row_labels (one per row, or a function of
    the row position) say where a bad value sits (default: "row <index>"). Accepts
    string or numeric columns.
    """
    columns = [str(c) for c in df.columns]
    duplicated = sorted({c for c in columns if columns.count(c) > 1})
    if duplicated:
        raise ValueError(f"{source}: duplicated column(s) {duplicated}")
    unknown = [c for c in columns if c not in NUMERIC_COLUMNS + OPTIONAL_COLUMNS]
    missing = [c for c in NUMERIC_COLUMNS if c not in columns]
    if unknown:
        hints = []
        for c in unknown:
            close = difflib.get_close_matches(c, NUMERIC_COLUMNS + OPTIONAL_COLUMNS, n=1)
            hints.append(f"{c!r}" + (f" (did you mean {close[0]!r}?)" if close else ""))
        raise ValueError(
            f"{source}: unknown column(s) {', '.join(hints)}; "
            f"allowed: {', '.join(NUMERIC_COLUMNS + OPTIONAL_COLUMNS)}"
        )
    if missing:
        raise ValueError(
            f"{source}: missing column(s) {', '.join(missing)}; "
            f"required: {', '.join(NUMERIC_COLUMNS)} (units in the names), optional: run"
        )
    if row_labels is None:
        index = list(df.index)
        label = lambda k: f"row {index[k]}"  # noqa: E731
    elif callable(row_labels):
        label = row_labels
    else:
        label = row_labels.__getitem__
    out = pd.DataFrame(index=pd.RangeIndex(len(df)))
    for column in NUMERIC_COLUMNS:
        series = df[column]
        if pd.api.types.is_float_dtype(series.dtype) or pd.api.types.is_integer_dtype(series.dtype):
            numbers = series.to_numpy(dtype=float)
        else:
            numbers = pd.to_numeric(series, errors="coerce").to_numpy(dtype=float)
        bad = np.flatnonzero(~np.isfinite(numbers))
        if bad.size:
            k = int(bad[0])
            raw, x = series.iloc[k], numbers[k]
            if np.isnan(x):
                text = "" if raw is None else str(raw).strip()
                shown = repr(text) if len(text) <= 24 else f"{text[:20]!r}..."
                if text == "" or text.lower() in ("nan", "na", "none") or (isinstance(raw, float) and np.isnan(raw)):
                    raise ValueError(f"{source}: column {column}, {label(k)}: missing value (NaN: {shown})")
                raise ValueError(f"{source}: column {column}, {label(k)}: non-numeric value {shown}")
            raise ValueError(f"{source}: column {column}, {label(k)}: value {x} is not finite")
        out[column] = numbers
    for column, rule, bad in (
        ("load_N", "must be > 0 N (a point at zero load has no contact to measure)", out["load_N"] <= 0.0),
        ("friction_N", "must be > 0 N (the fits are in log space; a negative force is a sign error)", out["friction_N"] <= 0.0),
        ("resistance_ohm", "must be > 0 ohm", out["resistance_ohm"] <= 0.0),
    ):
        if bad.any():
            k = int(np.flatnonzero(bad.to_numpy())[0])
            raise ValueError(f"{source}: column {column}, {label(k)}: value {float(out[column].iloc[k])!r} {rule}")
    if "run" in columns:
        out["run"] = df["run"].array
    levels = np.unique(np.abs(out["current_A"].to_numpy()))
    needed = minimum_rows(len(levels))
    if len(out) < needed:
        raise ValueError(
            f"{source}: {len(out)} data row(s) are too few for a fit: at least {needed} are needed "
            f"({len(levels)} current level(s) -> one mu each, plus gamma, plus one to estimate the scatter)"
        )
    loads = np.unique(out["load_N"].to_numpy())
    if len(loads) < 2:
        raise ValueError(
            f"{source}: all points are at load {loads[0]} N; at least 2 different loads are needed "
            "to fit gamma and the load dependence of the resistance"
        )
    per_level = out.groupby(np.abs(out["current_A"]))["load_N"].nunique()
    if per_level.max() < 2:
        raise ValueError(
            f"{source}: every current level has a single load, so gamma cannot be told apart from mu(I): "
            "at least one current level needs points at 2 or more different loads"
        )
    return out
