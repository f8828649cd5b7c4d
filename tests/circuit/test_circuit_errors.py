"""Every failure path raises a Python exception carrying ngspice's own message; nothing hangs."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from circuit import (
    ConductanceError,
    ConvergenceError,
    LibraryNotFoundError,
    NetlistCircuit,
    NetlistError,
    SimulationOptions,
    SimulationTimeout,
    Stepper,
    TimestepTooSmallError,
    find_library,
    run_transient,
)

OPTIONS = SimulationOptions(max_step=1e-6)
GOOD = NetlistCircuit("good\nV1 a 0 10\nXCONTACT a b\nVLOAD b c 0\nR1 c 0 10\n")


def still_works():
    df = run_transient(GOOD, 1.0, 20e-6, options=OPTIONS)
    assert df.load_current.iloc[-1] == pytest.approx(10.0 / 11.0, rel=1e-6)


def test_unknown_element_is_a_netlist_error_with_ngspice_message():
    # A transistor without a model is refused before ngspice (netlist_check); a value
    # ngspice cannot read still reaches ngspice, whose message is carried verbatim.
    bad = NetlistCircuit("bad\nV1 a 0 10\nXCONTACT a b\nR2 b 0 abc\nR1 b 0 10\n")
    with pytest.raises(NetlistError) as info:
        run_transient(bad, 1.0, 20e-6, options=OPTIONS)
    assert "Error on line" in info.value.ngspice_message
    assert "r2 b 0 abc" in info.value.ngspice_message
    still_works()


def test_bad_expression_is_a_netlist_error():
    bad = NetlistCircuit("bad\nV1 a 0 10\nXCONTACT a b\nB1 b 0 I=V(b)*foo(\n")
    with pytest.raises(NetlistError, match="syntax error"):
        run_transient(bad, 1.0, 20e-6, options=OPTIONS)
    still_works()


def test_timestep_too_small_carries_time_and_node():
    # A current that oscillates at 1e12 rad/s with a huge gain: no step resolves it.
    wild = NetlistCircuit(
        "wild\nV1 a 0 1\nXCONTACT a b\nR1 b c 1\n"
        "B1 c 0 I=V(c) > 0.5 ? 1e9*(V(c)-0.5)*sin(1e12*time) : 0\nC1 c 0 1p\n"
    )
    started = time.monotonic()
    with pytest.raises(TimestepTooSmallError) as info:
        run_transient(wild, 100.0, 10e-6, options=OPTIONS)
    assert "Timestep too small" in info.value.ngspice_message
    assert "trouble with node" in info.value.ngspice_message
    assert "time = " in info.value.ngspice_message
    assert time.monotonic() - started < 10.0
    still_works()


def test_operating_point_failure_is_a_convergence_error():
    loop = NetlistCircuit("loop\nV1 a 0 1\nV2 a 0 2\nXCONTACT a b\nR1 b 0 1\n")
    with pytest.raises(ConvergenceError) as info:
        run_transient(loop, 1.0, 10e-6, options=OPTIONS)
    assert "source stepping failed" in info.value.ngspice_message
    still_works()


def test_exception_in_the_conductance_function_is_reraised_promptly():
    calls = []

    def broken(t):
        calls.append(t)
        if t > 5e-6:
            raise ZeroDivisionError("mechanics failed")
        return 1.0

    started = time.monotonic()
    with pytest.raises(ZeroDivisionError, match="mechanics failed"):
        run_transient(GOOD, broken, 1.0, options=OPTIONS)  # 1 s of circuit time: must stop early
    assert time.monotonic() - started < 5.0
    assert max(calls) < 20e-6
    still_works()


@pytest.mark.parametrize("value", [-1.0, math.nan, math.inf])
def test_invalid_conductance_values_are_rejected_with_the_time(value):
    with pytest.raises(ConductanceError, match="t = "):
        run_transient(GOOD, lambda t: value if t > 2e-6 else 1.0, 20e-6, options=OPTIONS)
    still_works()


def test_wall_clock_limit_aborts_a_slow_run():
    def slow(t):
        time.sleep(0.002)
        return 1.0

    started = time.monotonic()
    with pytest.raises(SimulationTimeout):
        run_transient(GOOD, slow, 1.0, options=SimulationOptions(max_step=1e-6, wall_timeout=0.2))
    assert time.monotonic() - started < 3.0
    still_works()


def test_a_failed_stepper_refuses_to_continue():
    with Stepper(GOOD, 100e-6, OPTIONS) as stepper:
        stepper.advance(10e-6, 1.0)
        with pytest.raises(ValueError, match="conductance"):
            stepper.advance(20e-6, -1.0)  # a negative constant is refused before running
        with pytest.raises(ConductanceError):
            stepper.advance(20e-6, lambda t: -1.0)
        with pytest.raises(RuntimeError, match="failed"):
            stepper.advance(30e-6, 1.0)
        assert stepper.results().time.iloc[-1] >= 10e-6
    still_works()


def test_library_lookup(monkeypatch, tmp_path):
    monkeypatch.delenv("NGSPICE_LIBRARY_PATH", raising=False)
    found = find_library()
    assert Path(found).is_file() and "ngspice" in Path(found).name
    monkeypatch.setenv("NGSPICE_LIBRARY_PATH", str(tmp_path / "missing.so"))
    with pytest.raises(LibraryNotFoundError, match="NGSPICE_LIBRARY_PATH"):
        find_library()
    monkeypatch.setenv("NGSPICE_LIBRARY_PATH", found)
    assert find_library() == found


def test_the_library_found_is_the_one_ldconfig_lists(monkeypatch):
    """find_library asks the dynamic loader (its own search, then the file it mapped); on a
    system whose ld.so cache lists libngspice.so.0, that is the same file as ldconfig's."""
    import os
    import shutil
    import subprocess

    monkeypatch.delenv("NGSPICE_LIBRARY_PATH", raising=False)
    exe = shutil.which("ldconfig") or next((p for p in ("/sbin/ldconfig", "/usr/sbin/ldconfig") if os.path.isfile(p)),
                                           None)
    if exe is None:
        pytest.skip("no ldconfig here")
    listed = [line.split("=>", 1)[1].strip() for line in subprocess.run([exe, "-p"], capture_output=True,
                                                                           text=True).stdout.splitlines()
              if line.strip().startswith("libngspice.so.0 ") and "=>" in line]
    if not listed:
        pytest.skip("ldconfig lists no libngspice.so.0")
    assert os.path.realpath(find_library()) == os.path.realpath(listed[0])


def test_a_fresh_process_prints_nothing():
    """No 'Unsupported Ngspice version', no spinit note, no PySpice error logging."""
    code = textwrap.dedent(
        """
        import logging, math
        logging.basicConfig(level=logging.WARNING)
        import circuit
        sc = circuit.SwitchCircuit(arc=circuit.ArcModel())
        s = circuit.ContactSchedule(((0.0, 20e-6), (40e-6, math.inf)))
        df = circuit.run_transient(sc, s, 60e-6)
        with circuit.Stepper(sc, 60e-6) as st:
            for k in range(1, 7):
                st.advance(k * 10e-6, s, s.breakpoints((k - 1) * 10e-6, k * 10e-6))
        """
    )
    repo = Path(__file__).resolve().parents[2]
    env = {k: v for k, v in os.environ.items() if k != "NGSPICE_LIBRARY_PATH"}
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=repo, env=env, capture_output=True, text=True, timeout=120
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout == ""
    assert done.stderr == ""


def test_ctrl_c_interrupts_a_run(sigint_raises):
    """ngspice swaps in its own SIGINT handler while it runs (it pauses); either way Python sees KeyboardInterrupt."""
    import signal

    sent = []

    def conductance(t):
        if t > 5e-6 and not sent:
            sent.append(t)
            os.kill(os.getpid(), signal.SIGINT)
        return 1.0

    started = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        run_transient(GOOD, conductance, 1.0, options=OPTIONS)
    assert time.monotonic() - started < 5.0
    still_works()
