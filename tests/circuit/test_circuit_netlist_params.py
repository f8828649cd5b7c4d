"""A netlist's .param values set from outside (circuit.params): the top-level
definitions take the new numbers, in included files too, before the netlist's checks run;
a subcircuit's own parameters and names the netlist does not define are refused."""

from __future__ import annotations

import pytest

from circuit import NetlistCircuit

MAIN = """params
.include parts.inc
.param RF = 1k  CF={RF*1n}
.subckt LOAD a b params: RS=5
.param RIN=3
R1 a b {RS+RIN}
.ends
V1 a 0 10
XCONTACT a b
X1 b c LOAD
VLOAD c d 0
R2 d 0 {RF}
C1 d 0 {CF}
"""


def _params(tmp_path, **params):
    (tmp_path / "main.cir").write_text(MAIN)
    (tmp_path / "parts.inc").write_text(".param RL=2k\n")
    return NetlistCircuit.from_file(tmp_path / "main.cir", params=params)


def _param_lines(circuit) -> list[str]:
    """The deck's .param lines, spaced alike ("name = value")."""
    return [" ".join(line.replace("=", " = ").split()) for line in circuit.netlist().splitlines()
            if line.lower().startswith(".param")]


def test_top_level_definitions_take_the_new_values(tmp_path):
    lines = _param_lines(_params(tmp_path, rf=4700.0, RL=3300.0))
    # the expression CF follows RF; the subcircuit's own RIN is left alone
    assert lines == [".param RL = 3300.0", ".param RF = 4700.0 CF = {RF*1n}", ".param RIN = 3"]
    assert _param_lines(_params(tmp_path)) == [".param RL = 2k", ".param RF = 1k CF = {RF*1n}", ".param RIN = 3"]


@pytest.mark.parametrize("params, fragments", [
    ({"RS": 1.0}, ["circuit.params.RS = 1.0", "no '.param RS' at its top level", "CF, RF, RL"]),
    ({"RIN": 1.0}, ["no '.param RIN' at its top level"]),  # a subcircuit's own
    ({"RX": 1.0}, ["no '.param RX'", "did you mean"]),
    ({"RF": "1k"}, ["circuit.params.RF = '1k'", "finite number"]),
    ({"RF": float("nan")}, ["finite number"]),
    ({"RF": 1e40}, ["|value| <= 1e+30"]),
    ({"RF": 1.0, "rf": 2.0}, ["given twice"]),
    ({"R-F": 1.0}, ["not a parameter name"]),
])
def test_bad_params_are_one_line(tmp_path, params, fragments):
    with pytest.raises(ValueError) as err:
        _params(tmp_path, **params)
    msg = str(err.value)
    assert "\n" not in msg
    for fragment in fragments:
        assert fragment in msg, msg
