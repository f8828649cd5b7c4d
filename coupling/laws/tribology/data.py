"""The tribometer CSV form: reading it and validating it, with errors that name file, column, line and value.

Form (docs/tribology.md): one row per measured point, columns
`load_N, current_A, friction_N, resistance_ohm` (normal load in N, DC current in A,
friction force in N, contact resistance in ohm) and an optional `run` (repeat id, any
label). Lines whose first non-blank character is `#` are comments; blank lines are
skipped. The sign of the current is ignored by the fits (|I|).
"""

from __future__ import annotations

import csv
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Sequence

import numpy as np

from mech.validation import check_file, suggest

if TYPE_CHECKING:  # pandas (0.2-0.3 s) is imported where a table is read or checked
    import pandas as pd

NUMERIC_COLUMNS = ("load_N", "current_A", "friction_N", "resistance_ohm")
OPTIONAL_COLUMNS = ("run",)
COLUMNS = NUMERIC_COLUMNS + OPTIONAL_COLUMNS
# A per-current friction fit has one mu per current level plus gamma, and needs one
# more point than parameters to estimate the scatter.
EXTRA_POINTS_NEEDED = 2


def minimum_rows(n_current_levels: int) -> int:
    """Rows a fit needs: one mu per current level, gamma, and one for the scatter."""
    return n_current_levels + EXTRA_POINTS_NEEDED


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


def _check_columns(names: list[str], where: str, quoted: bool = True) -> None:
    """Column names: no tribometer column twice, none unknown (each with the did-you-mean);
    ``quoted`` False names an unknown column by its place, not its text (the file may be
    anything, and what is not a tribometer header is not repeated)."""
    duplicated = sorted({c for c in names if names.count(c) > 1 and c in COLUMNS})
    if duplicated:
        raise ValueError(f"{where}: duplicated column(s) {duplicated}")
    unknown = [(k, c) for k, c in enumerate(names, start=1) if c not in COLUMNS]
    if unknown:
        hints = [(repr(c) if quoted else f"column {k}") + suggest(c, COLUMNS) for k, c in unknown]
        raise ValueError(f"{where}: unknown column(s) {', '.join(hints)}; allowed: {', '.join(COLUMNS)}")


def _check_header(names: list[str], path: Path, line: int) -> None:
    """The header line's column names; they are quoted only when the line has the shape of
    a CSV header."""
    shaped = len(names) >= len(NUMERIC_COLUMNS) - 1 and all(_NAME.fullmatch(n) for n in names)
    _check_columns(names, f"{path}: header line {line}", quoted=shaped)


def read_tribometer_csv(path) -> pd.DataFrame:
    """Read and validate a tribometer CSV; returns a DataFrame of the columns above.

    path: str or Path. Raises ValueError naming the file, column, line and value for
    missing or unknown columns, non-numeric or missing (NaN) values, loads that are
    not > 0, negative or zero friction forces and resistances, non-finite currents,
    and too few points for a fit; FileNotFoundError for a missing file, ValueError for a
    folder or a device (mech.validation.check_file). A header that
    is not a tribometer header is not repeated in the message (the path may name any
    file). UTF-8 with or without a byte-order mark. The comment lines are kept in
    `df.attrs["header"]` and the path in `df.attrs["source"]`.
    """
    import pandas as pd

    path = check_file("tribometer CSV", path)
    try:
        scan = _scan(path)
    except OSError as err:
        raise ValueError(f"{path}: cannot read ({err.strerror or type(err).__name__})") from None
    if not scan.ascii or scan.nul:
        _decode(path.read_bytes(), path)  # raises with line and column if the file is not UTF-8 text
    header = [c.decode("utf-8", "replace").strip().lstrip("#").strip() for c in scan.comments]
    comment_only = scan.hashes == sum(c.count(b"#") for c in scan.comments)
    first, header_line, quoted = scan.first, scan.first_line, scan.quoted
    if first is None:
        raise ValueError(f"{path}: no header line and no data (expected columns {', '.join(NUMERIC_COLUMNS)})")
    names = [cell.strip() for cell in next(csv.reader([first]))]
    _check_header(names, path, header_line)
    df = _fast_frame(path, names) if comment_only and not quoted else None
    if df is None:
        # the exact reading: quoted cells, '#' inside data lines, or a malformed file (the error says where)
        _, rows, line_numbers = _data_lines(_decode(path.read_bytes(), path))
        for cells, number in zip(rows[1:], line_numbers[1:]):
            if len(cells) != len(names):
                raise ValueError(f"{path}: line {number} has {len(cells)} fields, the header line "
                                 f"{line_numbers[0]} has {len(names)}")
        raw = pd.DataFrame(rows[1:], columns=names) if len(rows) > 1 else pd.DataFrame(columns=names)
        labels: Sequence[str] | Callable[[int], str] = [f"line {n}" for n in line_numbers[1:]]
    else:
        raw = df
        labels = lambda k: f"line {lines_of_rows(path, [k])[0]}"  # noqa: E731
    out = validate_tribometer_frame(raw, source=str(path), row_labels=labels)
    out.attrs["header"] = tuple(header)
    out.attrs["source"] = str(path)
    out.attrs["csv"] = True  # rows are the file's data lines in order (outliers are reported by line)
    return out


_COMMENT_BYTES = re.compile(rb"^[ \t]*#[^\n]*", re.M)


@dataclass
class _Scan:
    """What one streaming pass over the file's bytes tells: text or not, the comment lines,
    how many '#' it holds, whether any cell is quoted, the header line and its number."""

    ascii: bool = True
    nul: bool = False
    comments: list = field(default_factory=list)
    hashes: int = 0
    quoted: bool = False
    first: str | None = None
    first_line: int = 0
    lines: int = 0


def _scan(path: Path, block_size: int = 1 << 20) -> _Scan:
    scan = _Scan()
    carry = b""
    with open(path, "rb") as handle:
        start = True
        while True:
            block = handle.read(block_size)
            if start:
                block = block[3:] if block.startswith(b"\xef\xbb\xbf") else block
                start = False
            if not block:
                if carry:
                    _scan_lines(scan, carry)
                break
            scan.ascii = scan.ascii and block.isascii()
            scan.nul = scan.nul or b"\x00" in block
            buf = carry + block
            cut = buf.rfind(b"\n")
            if cut < 0:
                carry = buf
                continue
            _scan_lines(scan, buf[: cut + 1])
            carry = buf[cut + 1 :]
    return scan


def _scan_lines(scan: _Scan, chunk: bytes) -> None:
    hashes = chunk.count(b"#")
    scan.hashes += hashes
    scan.quoted = scan.quoted or b'"' in chunk
    if hashes:
        scan.comments += [m.group(0) for m in _COMMENT_BYTES.finditer(chunk)]
    if scan.first is None:
        for number, line in enumerate(chunk.split(b"\n"), start=scan.lines + 1):
            text = line.strip()
            if text and not text.startswith(b"#"):
                scan.first = line.decode("utf-8", "replace").rstrip("\r")
                scan.first_line = number
                break
    scan.lines += chunk.count(b"\n")


def lines_of_rows(path, rows: Sequence[int]) -> list[int]:
    """File line numbers of data rows (0-based, in the order given), counting comment and
    blank lines; one pass over the file."""
    wanted = sorted(set(int(k) + 1 for k in rows))
    found: dict[int, int] = {}
    count = -1
    i = 0
    with open(path, encoding="utf-8-sig", errors="replace") as handle:
        for number, line in enumerate(handle, start=1):
            if i >= len(wanted):
                break
            stripped = line.strip()
            if not stripped or stripped.startswith("#"):
                continue
            count += 1
            if count == wanted[i]:
                found[count] = number
                i += 1
    return [found.get(int(k) + 1, -1) for k in rows]


def _fast_frame(path: Path, names: list[str]) -> pd.DataFrame | None:
    """The table through pandas' C reader (large files, read in chunks), or None when a
    row does not parse cleanly: wrong field count or a non-numeric or empty cell (the
    exact reading then says where)."""
    import pandas as pd

    dtypes = {c: np.float64 for c in NUMERIC_COLUMNS if c in names}
    options = dict(skipinitialspace=True, skip_blank_lines=True, comment="#", encoding="utf-8-sig", engine="c")
    df = None
    if "run" in names:
        # numeric run ids (the usual case) as numbers: a third of the memory of labels
        try:
            df = pd.read_csv(path, dtype={**dtypes, "run": np.float64}, **options)
        except (ValueError, pd.errors.ParserError, UnicodeDecodeError):
            df = None
        if df is not None:
            run = df["run"].to_numpy()
            if np.all(np.isfinite(run)) and np.all(run == np.round(run)) and np.all(np.abs(run) < 2**53):
                df["run"] = run.astype(np.int64)
        else:
            dtypes["run"] = "category"
    if df is None:
        try:
            df = pd.read_csv(path, dtype=dtypes, **options)
        except (ValueError, pd.errors.ParserError, UnicodeDecodeError):
            return None
    if [str(c).strip() for c in df.columns] != names:
        return None
    df.columns = names
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
    import pandas as pd

    columns = [str(c) for c in df.columns]
    _check_columns(columns, source)
    missing = [c for c in NUMERIC_COLUMNS if c not in columns]
    if missing:
        raise ValueError(
            f"{source}: missing column(s) {', '.join(missing)}; "
            f"required: {', '.join(NUMERIC_COLUMNS)} (units in the names), optional: run"
        )
    if row_labels is None:
        label = lambda k: f"row {df.index[k]}"  # noqa: E731
    elif callable(row_labels):
        label = row_labels
    else:
        label = row_labels.__getitem__
    columns_out: dict[str, object] = {}
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
        columns_out[column] = numbers
    if "run" in columns:
        columns_out["run"] = df["run"].array
    # no copy of the columns (a 1,000,000-row table is 32 MB per copy); pandas copies on write
    out = pd.DataFrame(columns_out, index=pd.RangeIndex(len(df)), copy=False)
    for column, rule, bad in (
        ("load_N", "must be > 0 N (a point at zero load has no contact to measure)", out["load_N"] <= 0.0),
        ("friction_N", "must be > 0 N (the fits are in log space; a negative force is a sign error)", out["friction_N"] <= 0.0),
        ("resistance_ohm", "must be > 0 ohm", out["resistance_ohm"] <= 0.0),
    ):
        if bad.any():
            k = int(np.flatnonzero(bad.to_numpy())[0])
            raise ValueError(f"{source}: column {column}, {label(k)}: value {float(out[column].iloc[k])!r} {rule}")
    # hashing, not sorting, the rows: linear time and little memory for large tables
    level_of_row, levels = pd.factorize(np.abs(out["current_A"].to_numpy()))
    levels = np.asarray(levels, float)
    needed = minimum_rows(len(levels))
    if len(out) < needed:
        raise ValueError(
            f"{source}: {len(out)} data row(s) are too few for a fit: at least {needed} are needed "
            f"({len(levels)} current level(s) -> one mu each, plus gamma, plus one to estimate the scatter)"
        )
    loads = np.sort(pd.unique(out["load_N"].to_numpy()))
    if len(loads) < 2:
        raise ValueError(
            f"{source}: all points are at load {loads[0]} N; at least 2 different loads are needed "
            "to fit gamma and the load dependence of the resistance"
        )
    load = out["load_N"].to_numpy()
    lowest = np.full(len(levels), np.inf)
    highest = np.full(len(levels), -np.inf)
    np.minimum.at(lowest, level_of_row, load)
    np.maximum.at(highest, level_of_row, load)
    if not np.any(highest > lowest):
        raise ValueError(
            f"{source}: every current level has a single load, so gamma cannot be told apart from mu(I): "
            "at least one current level needs points at 2 or more different loads"
        )
    return out
