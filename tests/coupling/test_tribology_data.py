"""The tribometer CSV form: the shipped file, its generator, and one clear error per kind of bad input."""

import numpy as np
import pandas as pd
import pytest

from coupling.laws.tribology import illustrative_data_path, read_tribometer_csv, validate_tribometer_frame
from coupling.laws.tribology.illustrative import illustrative_csv_text

GOOD = "load_N,current_A,friction_N,resistance_ohm,run\n" + "".join(
    f"{f},{i},{0.2 * f**0.3:.4f},{0.02 * f ** (-1 / 3):.6f},1\n" for i in (0, 1) for f in (3, 4, 5)
)


def write(tmp_path, text, name="data.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_shipped_file_is_what_the_seeded_generator_writes():
    assert illustrative_data_path().read_text() == illustrative_csv_text()


def test_shipped_file_says_it_is_illustrative_and_spans_the_paper_design():
    df = read_tribometer_csv(illustrative_data_path())
    assert "ILLUSTRATIVE, NOT MEASURED" in df.attrs["header"][0]
    assert sorted(df["load_N"].unique()) == [3, 4, 5, 6, 7, 8]
    assert sorted(df["current_A"].unique()) == [0, 1, 2, 5]
    assert df.groupby(["load_N", "current_A"]).size().min() >= 3
    ratio = df["friction_N"] / df["load_N"]
    assert 0.04 < ratio.min() and ratio.max() < 0.25  # plausible friction coefficients
    assert 3e-3 < df["resistance_ohm"].min() and df["resistance_ohm"].max() < 50e-3  # mOhm contact


def test_reads_comments_blank_lines_spaces_and_keeps_run(tmp_path):
    text = "# a note\n\n" + GOOD.replace(",", ", ").replace("\n3", "\n# inline comment line\n3", 1)
    df = read_tribometer_csv(write(tmp_path, text))
    assert list(df.columns) == ["load_N", "current_A", "friction_N", "resistance_ohm", "run"]
    assert len(df) == 6 and df["load_N"].dtype == float
    assert df.attrs["header"][0] == "a note"


def test_run_column_is_optional(tmp_path):
    text = "\n".join(line.rsplit(",", 1)[0] for line in GOOD.splitlines()) + "\n"
    df = read_tribometer_csv(write(tmp_path, text))
    assert "run" not in df.columns and len(df) == 6


def drop_field(text, column):
    return "".join(",".join(c for k, c in enumerate(line.split(",")) if k != column) + "\n" for line in text.splitlines())


def replace_cell(text, line, column, value):
    lines = text.splitlines()
    cells = lines[line - 1].split(",")
    cells[column] = value
    lines[line - 1] = ",".join(cells)
    return "\n".join(lines) + "\n"


BAD = {
    "missing column": (drop_field(GOOD, 3), ["missing column", "resistance_ohm"]),
    "unknown column (typo)": (GOOD.replace("friction_N", "fricton_N"), ["unknown column", "'fricton_N'", "did you mean 'friction_N'"]),
    "unit-less name": (GOOD.replace("load_N", "load"), ["unknown column", "'load'", "load_N"]),
    "non-numeric": (replace_cell(GOOD, 3, 2, "0.3x"), ["column friction_N", "line 3", "non-numeric value '0.3x'"]),
    "empty cell": (replace_cell(GOOD, 4, 3, ""), ["column resistance_ohm", "line 4", "missing value"]),
    "NaN": (replace_cell(GOOD, 2, 1, "nan"), ["column current_A", "line 2", "missing value (NaN"]),
    "negative load": (replace_cell(GOOD, 5, 0, "-4"), ["column load_N", "line 5", "-4.0", "must be > 0 N"]),
    "zero load": (replace_cell(GOOD, 5, 0, "0"), ["column load_N", "line 5", "0.0", "must be > 0 N"]),
    "negative resistance": (replace_cell(GOOD, 6, 3, "-0.01"), ["column resistance_ohm", "line 6", "-0.01", "must be > 0 ohm"]),
    "zero resistance": (replace_cell(GOOD, 6, 3, "0"), ["column resistance_ohm", "line 6", "must be > 0 ohm"]),
    "negative friction": (replace_cell(GOOD, 7, 2, "-0.2"), ["column friction_N", "line 7", "-0.2", "must be > 0 N"]),
    "infinite current": (replace_cell(GOOD, 2, 1, "inf"), ["column current_A", "line 2", "not finite"]),
    "too few points": ("load_N,current_A,friction_N,resistance_ohm\n3,0,0.3,0.01\n4,0,0.3,0.01\n5,1,0.3,0.01\n",
                       ["3 data row(s) are too few", "at least 4 are needed", "2 current level(s)"]),
    "single load": ("load_N,current_A,friction_N,resistance_ohm\n" + "3,0,0.3,0.01\n" * 5,
                    ["at least 2 different loads"]),
    "gamma not separable": ("load_N,current_A,friction_N,resistance_ohm\n3,0,.3,.01\n4,1,.3,.01\n5,2,.3,.01\n3,0,.3,.01\n4,1,.3,.01\n5,2,.3,.01\n",
                            ["single load", "gamma cannot be told apart"]),
    "duplicated column": (GOOD.replace(",run", ",load_N"), ["duplicated column", "load_N"]),
    "header only": ("load_N,current_A,friction_N,resistance_ohm\n", ["0 data row(s) are too few"]),
    "empty file": ("# only a comment\n", ["no header line and no data"]),
    "ragged row": (GOOD.replace(",1\n", ",1,7,8\n", 1), ["line 2 has 7 fields", "header line 1 has 5"]),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_csv_gives_a_clear_error_naming_file_column_line_and_value(tmp_path, case):
    text, needles = BAD[case]
    path = write(tmp_path, text, name="bad_input.csv")
    with pytest.raises(ValueError) as err:
        read_tribometer_csv(path)
    message = str(err.value)
    assert message.startswith(str(path))
    assert "\n" not in message
    for needle in needles:
        assert needle in message


def test_missing_file_is_a_file_not_found_error(tmp_path):
    with pytest.raises(FileNotFoundError, match=r"tribometer CSV: file '.*nope\.csv' not found"):
        read_tribometer_csv(tmp_path / "nope.csv")


def test_dataframes_are_validated_too_with_row_labels():
    df = pd.DataFrame({"load_N": [3.0, 4.0, 5.0, 6.0], "current_A": [0, 0, 0, 0],
                       "friction_N": [0.3, 0.3, np.nan, 0.3], "resistance_ohm": [0.01] * 4})
    with pytest.raises(ValueError, match=r"DataFrame: column friction_N, row 2: missing value"):
        validate_tribometer_frame(df)
