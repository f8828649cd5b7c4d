"""Property test: tribometer CSVs with random bad values get a one-line named error or a flagged outlier, never a traceback."""

from __future__ import annotations

import tempfile
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from coupling.laws.tribology import fit_tribometer, read_tribometer_csv

COLUMNS = ("load_N", "current_A", "friction_N", "resistance_ohm")
# invalid (an error), non-physical (a gross outlier); unicode and quotes for the reader
INVALID = ["", "nan", "abc", "-1", "0", "inf", "-inf", "1,5", "\"2,5\"", "0x10", "1e", "µ", "NaN", "None"]
GROSS = ["1e308", "1e-320", "1e-300", "1e200"]


def good_rows() -> list[list[str]]:
    rows = []
    for run in (1, 2):
        for current in (0.0, 2.0):
            for load in (3.0, 5.0, 8.0):
                friction = (0.2 + 0.02 * current) * load ** 0.3 * (1.0 + 0.01 * run)
                resistance = 0.02 * load ** (-1 / 3) * (1.0 - 0.05 * current) * (1.0 - 0.01 * run)
                rows.append([f"{load:g}", f"{current:g}", f"{friction:.5f}", f"{resistance:.6f}", str(run)])
    return rows


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_bad_values_give_a_named_error_or_a_flagged_outlier(data):
    rows = good_rows()
    n_bad = data.draw(st.integers(1, 2))
    injected = []
    for _ in range(n_bad):
        row = data.draw(st.integers(0, len(rows) - 1))
        column = data.draw(st.integers(0, 3))
        value = data.draw(st.sampled_from(INVALID + GROSS))
        if column == 1 and value in GROSS + ["-1", "0"]:
            # a current of 0 or -1 A is valid (|I|), and the outlier rule is for the ln columns
            value = "abc"
        rows[row][column] = value
        injected.append((row, COLUMNS[column], value))
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "hostile.csv"
        path.write_text("load_N,current_A,friction_N,resistance_ohm,run\n" + "".join(",".join(r) + "\n" for r in rows))
        try:
            fit = fit_tribometer(read_tribometer_csv(path), mu_models=["constant"],
                                 resistance_candidates=[("power_law", "none")])
        except ValueError as err:
            message = str(err)
            assert "\n" not in message and str(path) in message
            return
    flagged = {o.row for o in fit.friction.outliers + fit.resistance.outliers}
    final = {(r, c): v for r, c, v in injected}  # a later injection may overwrite an earlier one
    for (row, column), value in final.items():
        assert value in GROSS, (row, column, value)
        assert row in flagged, (row, column, value, fit.friction.outliers, fit.resistance.outliers)
