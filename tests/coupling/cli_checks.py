"""Shared by the command line's tests: small scenes (DROP, FAR), and the command line run
in-process for input tests with the simulation replaced by an assertion."""

from __future__ import annotations

import contextlib
import io
import textwrap
from unittest import mock

import coupling.core.master
from coupling.app.cli import main


# A rigid bar dropped on one tip: mechanics only, no plots, a few ms of compute.
DROP = textwrap.dedent("""
    [bar]
    modes = 0
    [initial]
    height = 0.0002
    angle_deg = 90.0
    velocity = [0.0, 0.0, -0.5]
    [solver]
    t_end = 0.001
    [output]
    plots = false
    """)


# A rigid bar falling 0.5 m/s from 1 mm above the block for 0.1 ms: it travels 50 um and
# never touches (the cheapest scene that runs; input tests add their sections to it).
FAR = textwrap.dedent("""
    [bar]
    modes = 0
    [initial]
    height = 1e-3
    angle_deg = 90.0
    velocity = [0, 0, -0.5]
    [solver]
    t_end = 1e-4
    """)


def no_run(*_args, **_kwargs):
    raise AssertionError("a bad scene reached the simulation")


def run_cli(argv) -> tuple[int, str]:
    """main(argv) with the simulation replaced by an assertion: (exit code, stderr)."""
    err = io.StringIO()
    with mock.patch.object(coupling.core.master, "run", no_run), contextlib.redirect_stderr(err), \
            contextlib.redirect_stdout(io.StringIO()):
        rc = main(argv)
    return rc, err.getvalue()


def assert_one_line_error(rc: int, err: str) -> str:
    """The one error line of exit code 2 (no traceback, nothing else on stderr)."""
    lines = err.strip().splitlines()
    assert rc == 2, err
    assert len(lines) == 1 and lines[0].startswith("switchsim: error: "), err
    assert "Traceback" not in err
    return lines[0]
