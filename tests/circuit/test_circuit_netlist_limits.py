"""Netlists that would crash ngspice or never finish reading: refused with one named line.

- A recursive '.func' (direct, mutual, or through a '.param') makes ngspice expand it until
  its stack overflows: a segmentation fault that ends the whole process (in a sweep, the
  worker), even when the function is never used. A circular '.param' ends ngspice's session.
- An include fan-out (each file including the next ten times) reads 10^depth files: the
  files read, their lines and their bytes are bounded.

The crash cases run in a child process: before the check they killed it (exit -11).
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from circuit import NetlistCircuit, SimulationOptions, run_transient
from circuit.errors import NetlistInputError
from circuit.netlist_check import MAX_INCLUDED_FILES, MAX_TOTAL_LINES, read_netlist

ROOT = Path(__file__).resolve().parents[2]
HEAD = "relay\nV1 s 0 12\nR1 s a 1\nXCONTACT a b\nVLOAD b c 0\nRl c 0 11\n"

RECURSIVE = {
    "direct": ".func f(x) {f(x)+1}\nRx c 0 {f(2)}",
    "mutual": ".func f(x) {g(x)+1}\n.func g(x) {f(x)*2}\nRx c 0 {f(2)}",
    "never used": ".func f(x) {1 + f(x - 1)}",
    "behavioural source": ".func f(x) {f(x)+1}\nB1 c 0 V={f(time)}",
    "through a parameter": ".func f(x) {x + pq}\n.param pq={f(1)}\nRx c 0 {pq}",
    "circular parameters": ".param pa={pb+1}\n.param pb={pa+1}\nRx c 0 {pa}",
    "one line": ".param pa={pb+1} pb = {2*pa}\nRx c 0 {pa}",
    "subcircuit parameters": ".subckt ld p n params: w={l} l={w*2}\nR9 p n {l}\n.ends\nX1 c 0 ld",
}
# the same shapes without a cycle: ngspice runs them (a function may call another, a
# parameter may use an earlier one, a subcircuit's local parameter may use a global one)
ACYCLIC = {
    "function of functions": (".func f(x) {x*2}\n.func g(y) {f(y)+f(1)}\nRx c 0 {g(2)}", 4.0 + 2.0),
    "spaced form": (".func f (x) = {x*3}\nRx c 0 {f(2)}", 6.0),
    "parameter chain": (".param a=1 b={a*2} c = {b + a}\nRx c 0 {c}", 3.0),
    "local shadows": (".param w=5\n.subckt ld p n params: w=1 l={w*2}\nR9 p n {l}\n.ends\nX1 c 0 ld", 2.0),
}

CHILD = textwrap.dedent("""
    import json, sys
    from circuit import NetlistCircuit, SimulationOptions, run_transient
    from circuit.errors import NetlistInputError
    out = {}
    for name, path in json.loads(sys.argv[1]).items():
        try:
            run_transient(NetlistCircuit.from_file(path), 1000.0, 2e-6, options=SimulationOptions(max_step=1e-6))
            out[name] = "ran"
        except NetlistInputError as err:
            out[name] = str(err)
    print(json.dumps(out))
""")


def test_recursive_functions_and_circular_parameters_are_refused_before_ngspice(tmp_path):
    paths = {}
    for k, (name, body) in enumerate(RECURSIVE.items()):
        paths[name] = str(tmp_path / f"net{k}.cir")
        Path(paths[name]).write_text(HEAD + body + "\n")
    child = subprocess.run([sys.executable, "-c", CHILD, json.dumps(paths)], capture_output=True, text=True,
                           timeout=300, cwd=ROOT)
    assert child.returncode == 0, f"the child died (exit {child.returncode}): {child.stderr[-2000:]}"
    for (name, message), k in zip(json.loads(child.stdout).items(), range(len(RECURSIVE))):
        assert message != "ran", name
        assert f"netlist net{k}.cir line 7:" in message and "depends on itself" in message, (name, message)
        assert "\n" not in message


def test_the_cycle_names_every_line_it_runs_through(tmp_path):
    path = tmp_path / "net.cir"
    path.write_text(HEAD + ".func f(x) {g(x)+1}\n.param p0=1\n.func g(x) {h(x)}\n.func h(x) {f(x)}\n")
    with pytest.raises(NetlistInputError, match=r"net\.cir line 7: .* \(through the definitions at net\.cir line 9, "
                                                r"net\.cir line 10\)"):
        read_netlist(path)


@pytest.mark.parametrize("name", list(ACYCLIC))
def test_definitions_without_a_cycle_still_run(name):
    """R_x takes the value the definitions compute: with the contact closed (1 GS) the load
    current is 12 V over R1 + (Rl || R_x) (the subcircuit X1 puts its R9 = R_x at node c)."""
    body, r_x = ACYCLIC[name]
    circuit = NetlistCircuit(HEAD + body + "\n")
    df = run_transient(circuit, 1e9, 2e-6, options=SimulationOptions(max_step=1e-6))
    expected = 12.0 / (1.0 + 11.0 * r_x / (11.0 + r_x))
    # a resistive divider: one linear solve, exact to ngspice's tolerances (reltol 1e-3)
    assert df.load_current.iloc[-1] == pytest.approx(expected, rel=1e-3)


def _fan_out(folder: Path, depth: int) -> Path:
    """f0 includes f1 ten times, f1 includes f2 ten times, ...: 10^depth leaves."""
    for k in range(depth):
        (folder / f"f{k}.inc").write_text(f".include f{k + 1}.inc\n" * 10)
    (folder / f"f{depth}.inc").write_text("")
    net = folder / "net.cir"
    net.write_text(HEAD + ".include f0.inc\n")
    return net


def test_an_include_fan_out_is_refused_within_seconds(tmp_path):
    net = _fan_out(tmp_path, 7)  # 10^7 leaves: read unbounded (> 120 s) before the limit
    code = f"from circuit.netlist_check import read_netlist\nread_netlist({str(net)!r})"
    tick = time.monotonic()
    child = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, cwd=ROOT)
    assert time.monotonic() - tick < 30
    assert child.returncode == 1 and f"more than {MAX_INCLUDED_FILES} files" in child.stderr


def test_a_small_fan_out_reads_and_a_larger_one_is_refused(tmp_path):
    small = tmp_path / "small"
    small.mkdir()
    lines = read_netlist(_fan_out(small, 2))  # 1 + 10 + 100 files read, below the limit
    assert len(lines) == 6
    large = tmp_path / "large"
    large.mkdir()
    with pytest.raises(NetlistInputError, match=f"reads more than {MAX_INCLUDED_FILES} files"):
        read_netlist(_fan_out(large, 3))  # 1111 files


def test_included_lines_are_bounded_in_all(tmp_path):
    """A file below every per-file limit, included again and again, passes the line limit
    (each inclusion counts) and is refused with one line naming the limit."""
    per_file = 200_000
    (tmp_path / "many.inc").write_text("".join(f"* comment {k}\n" for k in range(per_file)))
    ok = tmp_path / "ok.cir"
    ok.write_text(HEAD + ".include many.inc\n" * (MAX_TOTAL_LINES // per_file - 1))
    assert len(read_netlist(ok)) == 6
    net = tmp_path / "net.cir"
    net.write_text(HEAD + ".include many.inc\n" * (MAX_TOTAL_LINES // per_file + 1))
    with pytest.raises(NetlistInputError, match=f"exceed {MAX_TOTAL_LINES} lines") as err:
        read_netlist(net)
    assert "net.cir line" in str(err.value) and "\n" not in str(err.value)


def test_a_fifo_include_is_refused_without_opening_it(tmp_path):
    import os

    os.mkfifo(tmp_path / "pipe.inc")
    net = tmp_path / "net.cir"
    net.write_text(HEAD + ".include pipe.inc\n")
    with pytest.raises(NetlistInputError, match="not a regular file"):
        read_netlist(net)
