"""`switchsim fit`: the files it writes from the shipped CSV, and its one-line errors."""

import json

from fit_compare import assert_same_fit

from coupling.app.cli import main
from coupling.laws.tribology import TribometerFit, default_fit, illustrative_data_path
from coupling.app.fit import fit_command


def test_fit_command_writes_fit_json_and_figures(tmp_path, capsys):
    out = tmp_path / "fit_out"
    assert fit_command(str(illustrative_data_path()), str(out)) == 0
    printed = capsys.readouterr().out
    assert "ILLUSTRATIVE, NOT MEASURED" in printed and "gamma = 0.69" in printed
    fit = TribometerFit.from_json(out / "fit.json")
    assert_same_fit(fit, default_fit())
    d = json.loads((out / "fit.json").read_text())
    assert d["data_range"]["load_range_N"] == [3.0, 8.0] and d["data_range"]["current_range_A"] == [0.0, 5.0]
    assert d["friction"]["mu_selection"]["criterion"] == "BIC"
    assert len(d["resistance"]["selection"]["candidates"]) == 15
    assert "ILLUSTRATIVE" in d["header"][0]
    for png in ("friction_resistance_vs_load.png", "mu_vs_current.png"):
        data = (out / png).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000


def test_cli_reports_bad_input_on_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("load_N,current_A,friction_N\n3,0,0.3\n")
    assert main(["fit", str(bad), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "missing column(s) resistance_ohm" in err
    assert not (tmp_path / "o").exists()
