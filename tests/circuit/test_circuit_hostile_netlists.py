"""Property tests: generated hostile netlists are refused with one named line, never a traceback, never a command run.

Netlists are random mixes of ordinary lines and hostile ones (control blocks, shell and
other ngspice commands, '*#' lines, script titles, includes of files holding control
blocks), with random case, indentation and '+' continuation splits. The property: the
netlist is refused (NetlistInputError, one line, naming the netlist or include file)
exactly when it holds a hostile line; an accepted one runs in ngspice; no marker file
ever appears.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from circuit import NetlistCircuit, SimulationOptions, run_transient
from circuit.errors import NetlistInputError

GOOD = ["Cp a b 10p", "Rx2 c 0 1meg", ".param rr=11\nRx c 0 {{rr*100}}", ".model dm D(is=1e-14)\nD1 0 c dm",
        ".subckt ld p n\nR9 p n 100\n.ends\nX1 c 0 ld", "Lx c d 1u\nRd d 0 1k"]
HOSTILE = [".control", ".endc", "shell touch {pwned}", "*#shell touch {pwned}", "*# shell touch {pwned}",
           ".include evil.inc", ".inc evil.inc", ".lib evil.lib sec", "*ng_script", ".exec", ".title *ng_script",
           "source {pwned}", "pre_set x=1", ".csparam a=1", "write {pwned} v(a)", "codemodel {pwned}",
           ".controlx", ".option reltol=1", ".tran 1u 1m", "Aa 1 2 m"]
EVIL = ".control\nshell touch {pwned}\n.endc\n"


def mutate(line: str, data) -> str:
    case = data.draw(st.sampled_from(["same", "upper", "lower", "title"]))
    line = {"same": line, "upper": line.upper(), "lower": line.lower(), "title": line.title()}[case]
    return data.draw(st.sampled_from(["", " ", "\t", "  "])) + line + data.draw(st.sampled_from(["", " ", "\t", "\r"]))


def split(line: str, data) -> list[str]:
    """Split a line at a space into a line and a '+' continuation (ngspice joins them)."""
    indent = line[: len(line) - len(line.lstrip())]
    parts = line.strip().split(" ")
    if len(parts) < 3 or not data.draw(st.booleans()):
        return [line]
    k = data.draw(st.integers(2, len(parts) - 1))
    return [indent + " ".join(parts[:k]), "+ " + " ".join(parts[k:])]


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_hostile_netlists_are_refused_and_run_nothing(data):
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        pwned = folder / "PWNED"
        (folder / "evil.inc").write_text(EVIL.format(pwned=pwned))
        (folder / "evil.lib").write_text(".lib sec\n" + EVIL.format(pwned=pwned) + ".endl\n")
        title = data.draw(st.sampled_from(["relay", "* a title", "*ng_script", " *NG_SCRIPT"]))
        picks = data.draw(st.lists(st.sampled_from(GOOD + HOSTILE), max_size=6, unique=True))
        hostile = title.strip().lower().lstrip("*").strip().startswith("ng_script") or any(p in HOSTILE for p in picks)
        body = ["V1 s 0 12", "R1 s a 1", "XCONTACT a b", "VLOAD b c 0", "Rl c 0 11"]
        for line in picks:
            at = data.draw(st.integers(0, len(body)))
            body[at:at] = line.format(pwned=pwned).split("\n")
        lines = [title]
        for line in body:
            lines += split(mutate(line, data), data)
        path = folder / "net.cir"
        path.write_text("\n".join(lines) + "\n")
        try:
            circuit = NetlistCircuit.from_file(path)
        except NetlistInputError as err:
            message = str(err)
            assert "\n" not in message and ("net.cir" in message or "evil" in message)
            assert str(pwned) not in message
            assert hostile or "element" in message  # a good line may only fail for a name clash
        else:
            assert not hostile, lines
            df = run_transient(circuit, 1000.0, 2e-6, options=SimulationOptions(max_step=1e-6))
            assert len(df) > 1
        assert not pwned.exists()
