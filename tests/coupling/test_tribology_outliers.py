"""Dubious tribometer input: outliers are flagged by the stated rule, bad files and destinations get one-line errors."""

from __future__ import annotations

import json

import numpy as np
import pytest

from coupling.app.cli import main
from coupling.laws.tribology import TribometerFit, default_fit, fit_tribometer, illustrative_data_path, read_tribometer_csv
from coupling.laws.tribology.fits import GROSS_FACTOR, fit_friction, fit_resistance

SHIPPED = illustrative_data_path().read_text()
HEADER_AT = SHIPPED.splitlines().index("load_N,current_A,friction_N,resistance_ohm,run")


def with_cell(tmp_path, row: int, column: int, value: str, name="data.csv"):
    """The shipped CSV with data row `row` (0-based), column `column` replaced; returns (path, line number)."""
    lines = SHIPPED.splitlines()
    k = HEADER_AT + 1 + row
    cells = lines[k].split(",")
    cells[column] = value
    lines[k] = ",".join(cells)
    path = tmp_path / name
    path.write_text("\n".join(lines) + "\n")
    return path, k + 1


def test_shipped_data_has_no_outliers_and_the_cell_fit_equals_the_row_fit():
    fit = default_fit()
    assert fit.friction.n_outliers == 0 and fit.resistance.n_outliers == 0
    # the fit on (load, current) cells reproduces the row-by-row residual sum of squares
    df = read_tribometer_csv(illustrative_data_path())
    chosen = fit.resistance.selection.chosen
    from coupling.laws.tribology.fits import ln_resistance

    lm, cm = chosen.name.split("+")
    x = np.array([p.value for p in chosen.parameters])
    r = np.log(df["resistance_ohm"].to_numpy()) - ln_resistance(lm, cm, x, df["load_N"].to_numpy(),
                                                                  np.abs(df["current_A"].to_numpy()))
    assert chosen.rss_log == pytest.approx(float(r @ r), rel=1e-10)


@pytest.mark.parametrize("column, value, name", [(0, "1e308", "load_N"), (2, "1e-320", "friction_N")])
def test_a_gross_value_is_flagged_with_its_line_and_gamma_is_unaffected(tmp_path, column, value, name):
    path, line = with_cell(tmp_path, 10, column, value)
    fit = fit_tribometer(read_tribometer_csv(path))
    out = fit.friction.outliers
    assert [(o.where, o.column) for o in out] == [(f"line {line}", name)] and "gross" in out[0].reason
    # gamma as without the row (the illustrative truth is 0.7)
    assert abs(fit.gamma - default_fit().gamma) < 0.01 and fit.gamma < 0.8
    assert fit.data_range.load_range_N == (3.0, 8.0)


def test_a_ten_fold_resistance_is_flagged_by_the_residual_rule(tmp_path):
    df = read_tribometer_csv(illustrative_data_path())
    value = float(df["resistance_ohm"].iloc[20]) * 10.0
    path, line = with_cell(tmp_path, 20, 3, repr(value))
    fit = fit_tribometer(read_tribometer_csv(path))
    assert [o.where for o in fit.resistance.outliers] == [f"line {line}"]
    assert "studentized" in fit.resistance.outliers[0].reason and fit.friction.n_outliers == 0
    # without the rule the fit is pulled: the plain fit's scatter is several times larger
    plain = fit_resistance(read_tribometer_csv(path)).selection.chosen.resid_std_log
    assert plain > 3 * fit.resistance.selection.chosen.resid_std_log


def test_cli_reports_outliers_and_the_fit_file_round_trips(tmp_path, capsys):
    path, line = with_cell(tmp_path, 3, 0, "1e308")
    assert main(["fit", str(path), "--out", str(tmp_path / "out")]) == 0
    text = capsys.readouterr().out
    assert f"OUTLIERS left out of the friction fit: 1 row(s): line {line}" in text
    saved = json.loads((tmp_path / "out" / "fit.json").read_text())
    assert saved["friction"]["outliers"][0]["where"] == f"line {line}"
    again = TribometerFit.from_json(tmp_path / "out" / "fit.json")
    assert again.friction.n_outliers == 1 and again.gamma == pytest.approx(saved["laws"]["mu"]["gamma"])


def test_too_many_gross_rows_is_an_error(tmp_path):
    lines = SHIPPED.splitlines()
    for k in range(HEADER_AT + 1, HEADER_AT + 1 + 20):
        cells = lines[k].split(",")
        cells[2] = f"{float(cells[2]) * GROSS_FACTOR * 10:g}"
        lines[k] = ",".join(cells)
    path = tmp_path / "bad.csv"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match="20 of 72 rows hold gross values"):
        fit_tribometer(read_tribometer_csv(path))


def test_bom_and_undecodable_csv(tmp_path):
    bom = tmp_path / "excel.csv"
    bom.write_bytes(b"\xef\xbb\xbf" + SHIPPED.encode())
    assert list(read_tribometer_csv(bom).columns)[:4] == ["load_N", "current_A", "friction_N", "resistance_ohm"]
    bad = tmp_path / "latin1.csv"
    bad.write_bytes(SHIPPED.encode().replace(b"3,0,", b"3\xb5,0,", 1))
    with pytest.raises(ValueError, match=r"latin1.csv: line \d+, column 2: byte 0xb5 is not UTF-8"):
        read_tribometer_csv(bad)


def write_fit(tmp_path, change=None):
    doc = default_fit().to_dict()
    if change:
        change(doc)
    path = tmp_path / "fit.json"
    path.write_text(json.dumps(doc))
    return path


def test_fit_json_errors_are_one_line(tmp_path):
    assert TribometerFit.from_json(write_fit(tmp_path)).gamma == default_fit().gamma
    (tmp_path / "list.json").write_text("[1, 2]")
    with pytest.raises(ValueError, match="expected a JSON object, got a JSON list"):
        TribometerFit.from_json(tmp_path / "list.json")
    with pytest.raises(ValueError, match="is a folder"):
        TribometerFit.from_json(tmp_path)
    (tmp_path / "junk.json").write_bytes(b"\x80\x81")
    with pytest.raises(ValueError, match="not UTF-8"):
        TribometerFit.from_json(tmp_path / "junk.json")


def test_edited_laws_block_is_refused(tmp_path):
    def edit(doc):
        doc["laws"]["mu"]["gamma"] = 0.5

    with pytest.raises(ValueError, match="'laws' block differs"):
        TribometerFit.from_json(write_fit(tmp_path, edit))


@pytest.mark.parametrize("args, needle", [
    (["fit", "{tmp}", "--out", "{tmp}/o"], "is a folder"),
    (["fit", "{data}", "--out", "{tmp}/afile"], "exists and is not a folder"),
    (["fit", "{data}", "--out", ""], "give a folder name"),
])
def test_fit_command_bad_paths_are_one_line_errors(tmp_path, capsys, args, needle):
    (tmp_path / "afile").write_text("x")
    args = [a.format(tmp=tmp_path, data=illustrative_data_path()) for a in args]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert needle in err and "Traceback" not in err and err.count("\n") == 1


def test_plain_fits_still_take_every_row():
    df = read_tribometer_csv(illustrative_data_path())
    assert fit_friction(df).mu_selection.chosen.n_points == len(df)
