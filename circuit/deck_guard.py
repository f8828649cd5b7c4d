"""The last guard before ngspice: every deck, whoever built it (a template, a netlist file,
a PySpice circuit), passes ``check_deck`` right before ``NgspiceSession.load`` hands it to
ngspice (docs/circuit.md, threat model). A module of its own: a run from a template loads
it without the netlist-file reader (circuit/netlist_check.py: its two dataclasses and six
patterns, ~2 ms of every start).
"""

from __future__ import annotations

import re

from .errors import NetlistInputError

#: ngspice commands that run programs, read or write files, or load code; an element
#: line whose name is one of these is refused (it would be a command in a script).
COMMAND_NAMES = frozenset({
    "shell", "source", "write", "wrdata", "wrs2p", "wrnodev", "codemodel", "osdi", "load", "save", "set", "setcs",
    "unset", "exec", "echo", "run", "listing", "edit", "rusage", "sysinfo", "quit", "exit", "cd", "aspice",
    "jobs", "rspice", "hardcopy", "print", "plot", "destroy", "remcirc", "reset", "alter", "altermod", "let",
    "define", "alias", "eprint", "eprvcd", "snsave", "snload", "inventory", "option", "options", "circbyline",
    "mc_source", "bg_run", "stop", "resume", "step", "trace", "iplot", "version", "history", "meas", "gnuplot",
    "fourier", "spec", "linearize", "compose", "setplot", "settype", "strcmp", "wrpd", "psd",
})


#: Title line of every deck handed to ngspice.
DECK_TITLE = "* switchsim deck"
_DECK_REFUSED = re.compile(r"^\s*(\.control|\.endc|\.exec|\.inc|\.lib|\.title|\.csparam|\*#|pre_|@)", re.I)


def check_deck(lines: list[str]) -> list[str]:
    """The deck with switchsim's own title; raises NetlistInputError if any line could make
    ngspice run a command or read a file (whoever built the deck)."""
    if not lines:
        raise NetlistInputError("empty deck")
    out = [DECK_TITLE]
    for k, line in enumerate(lines[1:], start=2):
        if "\n" in line or "\r" in line or "\x00" in line:
            raise NetlistInputError(f"deck line {k}: embedded line break or NUL")
        stripped = line.strip()
        low = stripped.lower()
        if _DECK_REFUSED.match(low) or "ng_script" in low or low.rstrip().endswith("\\"):
            raise NetlistInputError(f"deck line {k}: refused before ngspice (command, script or include card)")
        head = low.split(None, 1)[0] if low else ""
        if head in COMMAND_NAMES:
            raise NetlistInputError(f"deck line {k}: refused before ngspice (an ngspice command name)")
        out.append(line)
    return out
