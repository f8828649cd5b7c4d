"""Untrusted netlists and folders cannot make ngspice run a command or read a file (docs/circuit.md, threat model).

Each reproduction of the audit is here: a control block in an included file or a .lib
section, a '*ng_script' title, '*#' command lines, a .spiceinit in the working
directory or home, .include /etc/passwd (no line of it may be echoed), and relative
includes resolved against the netlist's own folder.
"""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from PySpice.Spice.Netlist import Circuit

from circuit import NetlistCircuit, SimulationOptions, add_contact, run_transient
from circuit.errors import NetlistInputError
from circuit.deck_guard import check_deck
from circuit.netlist_check import MAX_INCLUDE_DEPTH

REPO = Path(__file__).resolve().parents[2]
OPTIONS = SimulationOptions(max_step=1e-6)
MAIN = "relay\nV1 s 0 12\nR1 s a 1\nXCONTACT a b\nVLOAD b c 0\n{extra}\n"
EVIL = ".control\nshell touch {pwned}\n.endc\n"


def write(folder: Path, name: str, text: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / name
    path.write_text(text)
    return path


def refused(path: Path, *needles: str) -> str:
    with pytest.raises(NetlistInputError) as info:
        NetlistCircuit.from_file(path)
    message = str(info.value)
    assert "\n" not in message
    for needle in needles:
        assert needle in message
    return message


def test_control_block_in_an_included_file_is_refused_with_file_and_line(tmp_path):
    pwned = tmp_path / "PWNED"
    write(tmp_path, "evil.cir", "* models\nRx 1 0 1\n" + EVIL.format(pwned=pwned))
    main = write(tmp_path, "main.cir", MAIN.format(extra="Rl c 0 11\n.include evil.cir"))
    message = refused(main, "evil.cir line 3", ".control")
    assert "touch" not in message and str(pwned) not in message
    assert not pwned.exists()


def test_control_block_in_a_lib_section_is_refused(tmp_path):
    pwned = tmp_path / "PWNED"
    write(tmp_path, "evil.lib", ".lib good\nRx 1 0 1\n.endl\n.lib sec\n" + EVIL.format(pwned=pwned) + ".endl\n")
    main = write(tmp_path, "main.cir", MAIN.format(extra="Rl c 0 11\n.lib evil.lib sec"))
    refused(main, "evil.lib line 5", ".control")
    assert not pwned.exists()


def test_lib_sections_are_inlined_by_name_only(tmp_path):
    # the unused section would be refused (an analysis card), the used one is inlined
    write(tmp_path, "models.lib", ".lib other\n.tran 1u 1m\n.endl\n.lib loads\nRl c 0 11\n.endl\n")
    main = write(tmp_path, "main.cir", MAIN.format(extra=".lib models.lib loads"))
    circuit = NetlistCircuit.from_file(main)
    assert "Rl c 0 11" in circuit.netlist() and ".tran" not in circuit.netlist()
    df = run_transient(circuit, 1000.0, 5e-6, options=OPTIONS)
    assert df.load_current.iloc[-1] == pytest.approx(12.0 / 12.0, rel=1e-3)


@pytest.mark.parametrize("title", ["*ng_script", "*NG_SCRIPT my script", "  * ng_script"])
def test_script_title_is_refused(tmp_path, title):
    pwned = tmp_path / "PWNED"
    main = write(tmp_path, "main.cir", f"{title}\nshell touch {pwned}\nXCONTACT a b\nR1 a b 1\n")
    refused(main, "main.cir line 1", "ng_script")
    assert not pwned.exists()


def test_star_hash_command_lines_are_refused(tmp_path):
    pwned = tmp_path / "PWNED"
    main = write(tmp_path, "main.cir", MAIN.format(extra=f"Rl c 0 11\n*#shell touch {pwned}"))
    refused(main, "main.cir line 7", "'*#'")
    assert not pwned.exists()


@pytest.mark.parametrize("line", ["shell touch PWNED", "source evil.cir", "write out.raw", "pre_osdi x.osdi",
                                  ".exec", ".csparam a=1", ".title *ng_script", "codemodel /tmp/x.cm"])
def test_commands_and_command_cards_are_refused(line):
    with pytest.raises(NetlistInputError):
        NetlistCircuit(MAIN.format(extra="Rl c 0 11\n" + line))


def test_include_of_a_system_file_echoes_none_of_it(tmp_path):
    passwd = Path("/etc/passwd")
    if not passwd.is_file():
        pytest.skip("no /etc/passwd")
    main = write(tmp_path, "main.cir", MAIN.format(extra="Rl c 0 11\n.include /etc/passwd"))
    message = refused(main, "passwd line 1")
    for line in passwd.read_text(errors="replace").splitlines():
        assert line not in message and line.split(":")[0] + ":" not in message


@pytest.mark.parametrize("secret", ["AKIA-s3cr3t-T0KEN", "R1 a b AKIA-s3cr3t-T0KEN", "Vx AKIA-s3cr3t-T0KEN 0",
                                    "XCONTACT AKIA-s3cr3t-T0KEN", ".param AKIA-s3cr3t-T0KEN"])
def test_include_of_a_secret_file_echoes_none_of_it(tmp_path, secret):
    write(tmp_path, "secret.txt", f"{secret}\nAKIA-line-two\n")
    main = write(tmp_path, "main.cir", MAIN.format(extra="Rl c 0 11\n.include secret.txt"))
    with pytest.raises(NetlistInputError) as info:
        NetlistCircuit.from_file(main)
    assert "AKIA" not in str(info.value)


def test_relative_include_resolves_against_the_netlists_folder(tmp_path, monkeypatch):
    folder = tmp_path / "shared"
    write(folder / "sub", "load.inc", "Rl c 0 11\n.include deeper.inc\n")
    write(folder / "sub", "deeper.inc", "Cl c 0 1n\n")
    main = write(folder, "main.cir", MAIN.format(extra=".include sub/load.inc"))
    # a decoy with the same relative name in the working directory must not be read
    cwd = tmp_path / "elsewhere"
    write(cwd / "sub", "load.inc", "Rl c 0 1\n")
    monkeypatch.chdir(cwd)
    circuit = NetlistCircuit.from_file(main)
    assert "Rl c 0 11" in circuit.netlist() and "Cl c 0 1n" in circuit.netlist()
    df = run_transient(circuit, 1000.0, 5e-6, options=OPTIONS)
    assert df.load_current.iloc[-1] == pytest.approx(12.0 / 12.0, rel=1e-3)


def test_include_cycle_and_depth_limit(tmp_path):
    write(tmp_path, "a.inc", ".include b.inc\n")
    write(tmp_path, "b.inc", ".include a.inc\n")
    refused(write(tmp_path, "main.cir", MAIN.format(extra=".include a.inc")), "cycle", "b.inc line 1")
    for k in range(MAX_INCLUDE_DEPTH + 1):
        write(tmp_path, f"d{k}.inc", f".include d{k + 1}.inc\n")
    write(tmp_path, f"d{MAX_INCLUDE_DEPTH + 1}.inc", "Rl c 0 11\n")
    refused(write(tmp_path, "deep.cir", MAIN.format(extra=".include d0.inc")), f"deeper than {MAX_INCLUDE_DEPTH}")


def test_missing_include_and_folder_include_are_named(tmp_path):
    refused(write(tmp_path, "m1.cir", MAIN.format(extra=".include nope.inc")), "m1.cir line 6", "no such file")
    refused(write(tmp_path, "m2.cir", MAIN.format(extra=f".include {tmp_path}")), "a folder")


def test_pyspice_circuit_with_a_control_block_is_stopped_at_the_deck_guard(tmp_path):
    pwned = tmp_path / "PWNED"
    c = Circuit("t")
    c.V(1, "a", c.gnd, 1)
    add_contact(c, "a", "b")
    c.R(1, "b", c.gnd, 1)
    c.raw_spice = EVIL.format(pwned=pwned)
    with pytest.raises(NetlistInputError, match="refused before ngspice"):
        run_transient(c, 1.0, 1e-6)
    assert not pwned.exists()


def test_deck_guard_replaces_the_title():
    assert check_deck(["*ng_script", "R1 a 0 1", ".end"])[0] == "* switchsim deck"
    for line in (".control", " .ENDC", "*#shell ls", ".inc x", ".lib x y", "pre_set x", "shell ls", "R1 a b 1 \\"):
        with pytest.raises(NetlistInputError):
            check_deck(["t", line, ".end"])


RUN = textwrap.dedent("""
    from circuit import NetlistCircuit, SimulationOptions, run_transient
    df = run_transient(NetlistCircuit("t\\nV1 a 0 10\\nXCONTACT a b\\nVLOAD b c 0\\nR1 c 0 10\\n"), 1.0, 20e-6,
                       options=SimulationOptions(max_step=1e-6))
    import os
    print("LOAD", df.load_current.iloc[-1], os.getcwd())
""")


def test_spiceinit_in_the_working_directory_or_home_runs_nothing(tmp_path):
    """A real circuit run in a fresh process (ngspice initializes there) from a folder
    holding a .spiceinit that runs 'shell touch', with $HOME holding another."""
    work, home = tmp_path / "work", tmp_path / "home"
    write(work, ".spiceinit", f"shell touch {work / 'PWNED'}\necho PWNED-ECHO\n")
    write(home, ".spiceinit", f"shell touch {home / 'PWNED'}\n")
    env = {**os.environ, "HOME": str(home), "PYTHONPATH": str(REPO)}
    done = subprocess.run([sys.executable, "-c", RUN], cwd=work, env=env, capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    load, cwd = done.stdout.split("LOAD", 1)[1].split()
    assert float(load) == pytest.approx(10.0 / 11.0, rel=1e-6)
    assert Path(cwd) == work  # the working directory is restored after ngspice started
    assert not (work / "PWNED").exists() and not (home / "PWNED").exists()
    assert "PWNED-ECHO" not in done.stdout + done.stderr


@pytest.mark.parametrize("extra, needle", [
    ("Rl c", "line 6: resistor line with 2 field(s)"),
    ("R2 c 0", "line 6: resistor line with 3 field(s)"),
    ("R1 c 0 5", "line 6: an element of this name is already defined"),
    ("D1 c 0 nodiode", "line 6: the diode names a model that no '.model' line"),
    ("X1 c 0 nosub", "line 6: the subcircuit instance names a subcircuit that no '.subckt'"),
    (".tran 1u 1m", "analysis lines are not allowed"),
    (".options reltol=1e-3", "option reltol is set by switchsim"),
])
def test_dubious_netlist_lines_are_named_errors(tmp_path, extra, needle):
    main = write(tmp_path, "main.cir", MAIN.format(extra=extra))
    refused(main, needle)


def test_defined_models_and_subcircuits_are_accepted():
    # a reverse-biased diode (no current) and the 11 ohm load inside a subcircuit: 12 V / 12 ohm
    text = MAIN.format(extra=".model dm D(is=1e-14)\nD1 0 c dm\n.subckt load p n\nR1 p n 11\n.ends\nX1 c 0 load")
    circuit = NetlistCircuit(text)
    df = run_transient(circuit, 1000.0, 5e-6, options=OPTIONS)
    assert df.load_current.iloc[-1] == pytest.approx(1.0, rel=1e-3)


def test_zero_contact_capacitance_with_series_inductance_is_refused():
    from circuit import InductiveLoad, ResistiveLoad, Snubber, SwitchCircuit, Wiring

    with pytest.raises(ValueError, match="contact_capacitance = 0 F with 1e-06 H"):
        SwitchCircuit(contact_capacitance=0.0)
    with pytest.raises(ValueError, match="contact_capacitance = 0 F"):
        SwitchCircuit(load=InductiveLoad(), wiring=Wiring(0.0, 0.0), contact_capacitance=0.0)
    # no inductance in series, or a snubber across the contact: allowed
    SwitchCircuit(load=ResistiveLoad(), wiring=Wiring(0.0, 0.0), contact_capacitance=0.0)
    SwitchCircuit(contact_capacitance=0.0, snubber=Snubber())


def test_isolated_start_restores_the_working_directory_and_home_even_on_error(tmp_path, monkeypatch):
    from circuit.ngspice import isolated_start

    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    with pytest.raises(RuntimeError):
        with isolated_start() as folder:
            assert Path.cwd() == Path(folder) and os.environ["HOME"] == folder
            assert (Path(folder) / ".spiceinit").read_text().startswith("*")  # a comment: no command
            assert sorted(p.name for p in Path(folder).iterdir()) == [".spiceinit"]
            raise RuntimeError("boom")
    assert Path.cwd() == tmp_path and os.environ["HOME"] == str(tmp_path / "home")
    assert not Path(folder).exists()
