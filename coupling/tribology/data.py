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
from pathlib import Path
from typing import Sequence

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


def read_tribometer_csv(path) -> pd.DataFrame:
    """Read and validate a tribometer CSV; returns a DataFrame of the columns above.

    path: str or Path. Raises ValueError naming the file, column, line and value for
    missing or unknown columns, non-numeric or missing (NaN) values, loads that are
    not > 0, negative or zero friction forces and resistances, non-finite currents,
    and too few points for a fit. The comment lines are kept in
    `df.attrs["header"]` and the path in `df.attrs["source"]`.
    """
    path = Path(path)
    try:
        text = path.read_text()
    except FileNotFoundError:
        raise FileNotFoundError(f"{path}: no such tribometer CSV file") from None
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
    if not rows:
        raise ValueError(f"{path}: no header line and no data (expected columns {', '.join(NUMERIC_COLUMNS)})")
    names = rows[0]
    for cells, number in zip(rows[1:], line_numbers[1:]):
        if len(cells) != len(names):
            raise ValueError(
                f"{path}: line {number} has {len(cells)} fields, the header line {line_numbers[0]} has "
                f"{len(names)} ({', '.join(names)})"
            )
    raw = pd.DataFrame(rows[1:], columns=names) if len(rows) > 1 else pd.DataFrame(columns=names)
    df = validate_tribometer_frame(raw, source=str(path), row_labels=[f"line {n}" for n in line_numbers[1:]])
    df.attrs["header"] = tuple(header)
    df.attrs["source"] = str(path)
    return df


def validate_tribometer_frame(df: pd.DataFrame, source: str = "DataFrame", row_labels: Sequence[str] | None = None) -> pd.DataFrame:
    """Check a tribometer table and return a clean copy with float columns.

    source names the data in the messages; row_labels (one per row) say where a bad
    value sits (default: "row <index>"). Accepts string or numeric columns.
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
        row_labels = [f"row {i}" for i in df.index]
    out = pd.DataFrame(index=pd.RangeIndex(len(df)))
    for column in NUMERIC_COLUMNS:
        values = df[column].to_numpy()
        numbers = pd.to_numeric(pd.Series(values), errors="coerce").to_numpy(dtype=float)
        for k, (raw, x) in enumerate(zip(values, numbers)):
            if np.isnan(x):
                text = "" if raw is None else str(raw).strip()
                if text == "" or text.lower() in ("nan", "na", "none") or (isinstance(raw, float) and np.isnan(raw)):
                    raise ValueError(f"{source}: column {column}, {row_labels[k]}: missing value (NaN: {text!r})")
                raise ValueError(f"{source}: column {column}, {row_labels[k]}: non-numeric value {text!r}")
            if not np.isfinite(x):
                raise ValueError(f"{source}: column {column}, {row_labels[k]}: value {x} is not finite")
        out[column] = numbers
    for column, rule, bad in (
        ("load_N", "must be > 0 N (a point at zero load has no contact to measure)", out["load_N"] <= 0.0),
        ("friction_N", "must be > 0 N (the fits are in log space; a negative force is a sign error)", out["friction_N"] <= 0.0),
        ("resistance_ohm", "must be > 0 ohm", out["resistance_ohm"] <= 0.0),
    ):
        if bad.any():
            k = int(np.flatnonzero(bad.to_numpy())[0])
            raise ValueError(f"{source}: column {column}, {row_labels[k]}: value {float(out[column].iloc[k])!r} {rule}")
    if "run" in columns:
        out["run"] = df["run"].to_numpy()
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
