"""Reading and checking an untrusted netlist before ngspice sees any of it (docs/circuit.md, threat model).

A netlist file, and every file it includes, is read here (never by ngspice): ``.include``
/ ``.inc`` and ``.lib FILE SECTION`` are inlined, paths taken relative to the folder of
the file that names them, with a depth limit, cycle detection and bounds on the files,
lines and bytes read in all (an include fan-out would otherwise read 10^depth files).
Every logical line (``+`` continuation lines joined, comments dropped) must then be on an
allow-list:

- element lines whose first letter is a SPICE device (``ELEMENT_LETTERS``) with at
  least the fields that device needs (a value or a model, not just nodes);
- dot-cards in ``ALLOWED_CARDS`` (model, subcircuit and parameter definitions);
- ``.options`` with names in ``ALLOWED_OPTIONS`` only.

No ``.func`` or ``.param`` may depend on itself (ngspice crashes on a recursive function
and ends its session on a circular parameter). Everything else is refused with
``NetlistInputError``: ``.control``/``.endc`` blocks and
``*#`` lines (ngspice runs them as commands, ``shell`` included), a ``*ng_script`` title
(it turns the whole deck into a command script), analysis and output cards, ``.title``,
XSPICE ``A`` devices (some read files), element names that are ngspice commands.

Error messages name the file, the line and what is wrong; they never repeat text from
the file (an included file may not be a netlist at all, e.g. ``/etc/passwd``).

``check_deck`` (circuit/deck_guard.py) is a second, independent guard run on every deck
right before it is handed to ngspice (``NgspiceSession.load``), whatever built it.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from .deck_guard import COMMAND_NAMES, DECK_TITLE
from .errors import NetlistInputError

#: Largest include depth (the netlist itself is depth 0).
MAX_INCLUDE_DEPTH = 8
#: Largest size of one netlist file and of all files read for one netlist, bytes (a file
#: included twice counts twice).
MAX_FILE_BYTES = 20_000_000
MAX_TOTAL_BYTES = 50_000_000
#: Most files read for one netlist, every ``.include``/``.lib`` reference counted (an include
#: fan-out, each file including the next ten times, would otherwise read 10^depth files).
MAX_INCLUDED_FILES = 1000
#: Most lines read for one netlist, all files together: checking costs ~4 us a line, so
#: this bounds the check to a few seconds.
MAX_TOTAL_LINES = 1_000_000

#: First letters of the SPICE element lines accepted, with the fewest fields each needs
#: (the name included): R1 a b 1k has 4.
ELEMENT_FIELDS = {
    "r": 4, "c": 4, "l": 4, "k": 4, "v": 4, "i": 4,
    "e": 4, "f": 4, "g": 4, "h": 4,  # E1 a b VALUE={...} / E1 a b c d 2 / F1 a b V1 2 / poly forms
    "b": 4,  # B1 a b V=expr
    "d": 4, "q": 5, "j": 5, "m": 6, "z": 5,
    "s": 6, "w": 5, "t": 5, "o": 6, "u": 5, "y": 6,
    "x": 2,
}
ELEMENT_LETTERS = "".join(sorted(ELEMENT_FIELDS))
_DEVICE_NAMES = {
    "r": "resistor", "c": "capacitor", "l": "inductor", "k": "coupling", "v": "voltage source",
    "i": "current source", "e": "VCVS", "f": "CCCS", "g": "VCCS", "h": "CCVS", "b": "behavioural source",
    "d": "diode", "q": "bipolar transistor", "j": "JFET", "m": "MOSFET", "z": "MESFET",
    "s": "voltage-controlled switch", "w": "current-controlled switch", "t": "transmission line",
    "o": "lossy transmission line", "u": "RC line", "y": "TXL line", "x": "subcircuit instance",
}
#: Devices whose model is named on the line: where it may sit (token indices).
_MODEL_POSITIONS = {"d": (3,), "q": (4, 5), "j": (4,), "z": (4,), "s": (5,), "w": (4,), "o": (5,), "u": (4,)}

#: Dot-cards a user netlist may hold (``.include``/``.inc``/``.lib``/``.endl`` are
#: inlined by ``read_netlist``; ``.end`` is dropped).
ALLOWED_CARDS = (".model", ".subckt", ".ends", ".param", ".func", ".global", ".ic", ".nodeset", ".end", ".options",
                 ".option", ".opt")
_INCLUDE_CARDS = (".include", ".inc", ".lib", ".endl")
#: Solver options a netlist may set; switchsim sets reltol, abstol, vntol, chgtol,
#: method and temp itself (SimulationOptions).
ALLOWED_OPTIONS = ("gmin", "gminsteps", "srcsteps", "itl1", "itl2", "itl4", "itl6", "trtol", "pivtol", "pivrel",
                   "rshunt", "cshunt", "tnom", "scale", "xmu", "maxord")
_SWITCHSIM_OPTIONS = ("reltol", "abstol", "vntol", "chgtol", "method", "temp", "noinit", "noacct")
#: Cards refused with a specific reason (checked by prefix, as ngspice matches them).
_REFUSED_PREFIXES = (
    (".control", "'.control' blocks run ngspice commands (shell, write, source...): not allowed in a netlist"),
    (".endc", "'.endc' closes a '.control' block: not allowed in a netlist"),
    (".exec", "'.exec' blocks run ngspice commands: not allowed in a netlist"),
    (".title", "'.title' is not allowed (the title is the first line; switchsim sets the deck's own)"),
    (".tran", "analysis lines are not allowed: the transient is set by t_end and the simulation options"),
    (".op", "analysis lines are not allowed: the transient is set by t_end and the simulation options"),
    (".ac", "analysis lines are not allowed"), (".dc", "analysis lines are not allowed"),
    (".noise", "analysis lines are not allowed"), (".tf", "analysis lines are not allowed"),
    (".disto", "analysis lines are not allowed"), (".sens", "analysis lines are not allowed"),
    (".pz", "analysis lines are not allowed"), (".sp", "analysis lines are not allowed"),
    (".pss", "analysis lines are not allowed"), (".meas", "'.meas' is not allowed (switchsim records the waveforms)"),
    (".save", "output cards (.save, .print, .plot, .probe, .four, .width) are not allowed"),
    (".print", "output cards are not allowed"), (".plot", "output cards are not allowed"),
    (".probe", "output cards are not allowed"), (".four", "output cards are not allowed"),
    (".width", "output cards are not allowed"),
    (".csparam", "'.csparam' passes values to ngspice commands: not allowed"),
)


@dataclass(frozen=True)
class NetlistLine:
    """One logical netlist line (continuations joined, comments removed) and where it starts."""

    text: str
    file: str
    line: int


def _where(file: str, line: int) -> str:
    return f"netlist {file} line {line}"


def _decode(data: bytes, file: str) -> str:
    if b"\x00" in data:
        line = data[: data.index(b"\x00")].count(b"\n") + 1
        raise NetlistInputError(f"{_where(file, line)}: NUL byte: this is not a text netlist")
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        line = data[: err.start].count(b"\n") + 1
        column = err.start - (data.rfind(b"\n", 0, err.start) + 1) + 1
        raise NetlistInputError(f"{_where(file, line)}, column {column}: not UTF-8 text "
                                "(save the netlist as UTF-8 or ASCII)") from None


def _physical_lines(text: str, file: str) -> list[tuple[str, int]]:
    """(line, number) of the non-comment lines, after the netlist rules ngspice applies."""
    out = []
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line:
            continue
        low = line.lower()
        if "ng_script" in low and low.lstrip("*").lstrip().startswith("ng_script"):
            raise NetlistInputError(f"{_where(file, number)}: '*ng_script' makes ngspice run the file as a "
                                    "command script: not allowed in a netlist")
        if line.startswith("*#"):
            raise NetlistInputError(f"{_where(file, number)}: '*#' lines are ngspice commands, not comments: "
                                    "not allowed in a netlist")
        if line.startswith(("*", ";", "//", "$")):
            continue
        if line.endswith("\\"):
            raise NetlistInputError(f"{_where(file, number)}: a line ending in '\\' (continuation) is not "
                                    "supported: continue a line with '+' at the start of the next")
        line = _strip_inline_comment(line)
        if line:
            out.append((line, number))
    return out


def _strip_inline_comment(line: str) -> str:
    # ngspice ends a netlist line at ' $', ';' or '//' (outside of expressions in braces
    # this is what its own comment stripping does).
    for mark in (" $", "\t$", ";", "//"):
        k = line.find(mark)
        if k >= 0:
            line = line[:k]
    return line.rstrip()


def logical_lines(text: str, file: str = "<text>", first_is_title: bool = True) -> list[NetlistLine]:
    """The logical lines of a netlist text (title first when ``first_is_title``), checked
    for script titles, ``*#`` command lines and continuations; no include handling."""
    lines: list[NetlistLine] = []
    raw_lines = text.splitlines()
    start = 0
    if first_is_title:
        # Skip leading blank lines as ngspice does; the first other line is the title.
        while start < len(raw_lines) and not raw_lines[start].strip():
            start += 1
        if start < len(raw_lines):
            title = raw_lines[start].strip()
            if title.lower().lstrip("*").lstrip().startswith("ng_script"):
                raise NetlistInputError(f"{_where(file, start + 1)}: a '*ng_script' title makes ngspice run the "
                                        "netlist as a command script: not allowed")
            lines.append(NetlistLine(title, file, start + 1))
            start += 1
    body = "\n".join([""] * start + raw_lines[start:])
    for line, number in _physical_lines(body, file):
        if line.startswith("+"):
            if not lines or (first_is_title and len(lines) == 1):
                raise NetlistInputError(f"{_where(file, number)}: a '+' continuation line with no line before it")
            prev = lines[-1]
            joined = prev.text + " " + line[1:].strip()
            lines[-1] = NetlistLine(joined.strip(), prev.file, prev.line)
            continue
        lines.append(NetlistLine(line, file, number))
    return lines


# ------------------------------------------------------------------------------------
# Reading a file with its includes


@dataclass
class _ReadState:
    total: int = 0
    files: int = 0
    lines: int = 0


def _read_bytes(path: Path, where: str, state: _ReadState) -> bytes:
    state.files += 1
    if state.files > MAX_INCLUDED_FILES:
        raise NetlistInputError(f"{where}: the netlist reads more than {MAX_INCLUDED_FILES} files "
                                "(every .include/.lib counted, repeats included)")
    try:
        if not path.is_file():
            kind = "a folder" if path.is_dir() else "not a regular file" if path.exists() else "no such file"
            raise NetlistInputError(f"{where}: {kind}: {str(path)!r}")
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            raise NetlistInputError(f"{where}: file {str(path)!r} is {size} bytes, more than the "
                                    f"{MAX_FILE_BYTES} allowed for a netlist")
        with open(path, "rb") as fh:
            data = fh.read(MAX_FILE_BYTES + 1)  # a file growing while it is read stops here
    except OSError as err:
        raise NetlistInputError(f"{where}: cannot read {str(path)!r} ({err.strerror or type(err).__name__})") from None
    if len(data) > MAX_FILE_BYTES:
        raise NetlistInputError(f"{where}: file {str(path)!r} is more than the {MAX_FILE_BYTES} bytes allowed "
                                "for a netlist")
    state.total += len(data)
    if state.total > MAX_TOTAL_BYTES:
        raise NetlistInputError(f"{where}: the netlist and its includes exceed {MAX_TOTAL_BYTES} bytes "
                                "(a file included several times counts each time)")
    state.lines += data.count(b"\n") + 1
    if state.lines > MAX_TOTAL_LINES:
        raise NetlistInputError(f"{where}: the netlist and its includes exceed {MAX_TOTAL_LINES} lines "
                                "(a file included several times counts each time)")
    return data


def _include_target(line: NetlistLine, tokens: list[str]) -> str:
    rest = line.text.split(None, 1)[1].strip() if len(tokens) > 1 else ""
    if not rest:
        raise NetlistInputError(f"{_where(line.file, line.line)}: {tokens[0].lower()} needs a file name")
    if rest[0] in "\"'":
        end = rest.find(rest[0], 1)
        if end < 0:
            raise NetlistInputError(f"{_where(line.file, line.line)}: unterminated quoted file name")
        return rest[1:end]
    return rest.split()[0]


def read_netlist(path: str | Path, max_depth: int = MAX_INCLUDE_DEPTH) -> list[NetlistLine]:
    """Read a netlist file and inline its ``.include``/``.lib`` files; returns checked logical lines.

    The first line of ``path`` is the title. Relative include paths are taken against the
    folder of the file that names them (not the working directory). Raises
    ``NetlistInputError`` (a ValueError) naming the file and line for anything refused.
    """
    path = Path(path)
    state = _ReadState()
    data = _read_bytes(path, f"netlist {str(path)!r}", state)
    top = logical_lines(_decode(data, path.name), path.name)
    if not top:
        raise NetlistInputError(f"netlist {path.name}: the file is empty")
    out = [top[0]]
    out += _expand(top[1:], path.resolve(), (path.resolve(),), 0, max_depth, state, section=None)
    check_lines(out)
    return out


def _expand(lines: list[NetlistLine], path: Path, chain: tuple[Path, ...], depth: int, max_depth: int,
            state: _ReadState, section: str | None) -> list[NetlistLine]:
    out: list[NetlistLine] = []
    in_section: str | None = None
    for line in lines:
        tokens = line.text.split()
        head = tokens[0].lower()
        if head == ".endl":
            if in_section is None:
                raise NetlistInputError(f"{_where(line.file, line.line)}: '.endl' without a '.lib' section")
            in_section = None
            continue
        if head == ".lib" and len(tokens) == 2:  # a section definition: .lib NAME ... .endl
            if in_section is not None:
                raise NetlistInputError(f"{_where(line.file, line.line)}: '.lib' section inside another section")
            in_section = tokens[1].lower()
            continue
        wanted = section is None or in_section == section
        if in_section is not None and section is None:
            wanted = False  # sections are read only through a '.lib FILE SECTION' reference
        if not wanted:
            continue
        if head in (".include", ".inc", ".lib"):
            if head == ".lib":
                if len(tokens) != 3:
                    raise NetlistInputError(f"{_where(line.file, line.line)}: '.lib' needs a file and a section "
                                            "name ('.lib FILE SECTION'), or one name to start a section")
                target, sub = tokens[1].strip("\"'"), tokens[2].lower()
            else:
                target, sub = _include_target(line, tokens), None
            where = _where(line.file, line.line)
            if depth + 1 > max_depth:
                raise NetlistInputError(f"{where}: includes nested deeper than {max_depth} levels")
            child = Path(target).expanduser()
            child = (child if child.is_absolute() else path.parent / child).resolve()
            if child in chain:
                raise NetlistInputError(f"{where}: include cycle ({child.name} includes itself, directly or not)")
            data = _read_bytes(child, f"{where}: {head} {target!r}", state)
            shown = child.name
            lines_child = logical_lines(_decode(data, shown), shown, first_is_title=False)
            inner = _expand(lines_child, child, chain + (child,), depth + 1, max_depth, state, sub)
            if sub is not None and not any(True for _ in inner) and not _has_section(lines_child, sub):
                raise NetlistInputError(f"{where}: {shown} has no '.lib' section of that name")
            out += inner
            continue
        out.append(line)
    if in_section is not None:
        raise NetlistInputError(f"netlist {lines[-1].file}: a '.lib' section is not closed by '.endl'")
    return out


def _has_section(lines: list[NetlistLine], section: str) -> bool:
    return any(len(t) == 2 and t[0].lower() == ".lib" and t[1].lower() == section
               for t in (line.text.split() for line in lines))


# ------------------------------------------------------------------------------------
# The allow-list


def _is_param(token: str) -> bool:
    return "=" in token


_EXPRESSION = re.compile(r"\{([^{}]*)\}|'([^']*)'")
_IDENTIFIER = re.compile(r"(?<![\w.])([A-Za-z_]\w*)\s*(\()?")
_ASSIGNED = re.compile(r"([A-Za-z_]\w*)\s*=(?!=)")
#: Names an ngspice expression may use without a .param: constants and circuit variables.
EXPRESSION_CONSTANTS = frozenset({"pi", "e", "temper", "hertz", "time", "boltz", "echarge", "kelvin", "planck",
                                  "amu", "true", "false", "yes", "no", "gmin"})
_PROBE_CALL = re.compile(r"(?<![\w.])[vi]\s*\([^()]*\)")  # v(node), i(source): names, not parameters


def _check_expressions(lines: list[NetlistLine]) -> None:
    """Every name used in a {...} or '...' expression must be defined by the netlist (.param,
    .subckt params, .func and its arguments, instance parameters) or be a constant: ngspice
    ends its session ('cannot recover') on an undefined parameter."""
    defined: set[str] = set(EXPRESSION_CONSTANTS)
    for line in lines[1:]:
        low = line.text.lower()
        head = low.split(None, 1)[0]
        if head in (".param", ".subckt") or head.startswith("x"):
            defined.update(m.group(1) for m in _ASSIGNED.finditer(low))
        if head == ".func":
            defined.update(m.group(1) for m in _IDENTIFIER.finditer(low.split(None, 1)[1] if " " in low else ""))
    for line in lines[1:]:
        low = line.text.lower()
        head = low.split(None, 1)[0]
        if head == ".func":
            continue
        for match in _EXPRESSION.finditer(low):
            body = match.group(1) if match.group(1) is not None else match.group(2)
            body = _PROBE_CALL.sub("0", body)
            for ident in _IDENTIFIER.finditer(body):
                if ident.group(2) is None and ident.group(1) not in defined:
                    raise NetlistInputError(f"{_where(line.file, line.line)}: an expression uses a parameter that "
                                            "no '.param' line defines")


_FUNC = re.compile(r"\.func\s+([a-z_]\w*)\s*\(([^()]*)\)\s*=?\s*(.*)$")
_MASKED = re.compile(r"\{[^{}]*\}|'[^']*'")


def _assignments(text: str) -> list[tuple[str, str]]:
    """(name, value) of each top-level ``name = value`` of a .param or .subckt line (text in
    braces or quotes is a value, never an assignment)."""
    masked = _MASKED.sub(lambda m: " " * len(m.group(0)), text)
    found = list(_ASSIGNED.finditer(masked))
    return [(m.group(1), text[m.end(): found[k + 1].start() if k + 1 < len(found) else len(text)])
            for k, m in enumerate(found)]


def param_spans(text: str) -> list[tuple[str, int, int]]:
    """(name, start, end) of each ``name = value`` of a ``.param`` line: the value is
    text[start:end] (braces and quotes masked, as in ``_assignments``); [] for any other line."""
    head = text.split(None, 1)[0].lower() if text.strip() else ""
    if head != ".param":
        return []
    masked = _MASKED.sub(lambda m: " " * len(m.group(0)), text)
    offset = text.lower().index(".param") + len(".param")
    found = [m for m in _ASSIGNED.finditer(masked, offset)]
    return [(m.group(1), m.end(), found[k + 1].start() if k + 1 < len(found) else len(text))
            for k, m in enumerate(found)]


def _check_definitions(lines: list[NetlistLine]) -> None:
    """No '.func' or '.param' may depend on itself, directly or through others: ngspice
    expands a recursive function until its stack overflows (a segmentation fault that ends
    the process, even when the function is never used) and ends its session on a circular
    parameter ('cannot recover'). Definitions inside a subcircuit are local to it."""
    defined: dict[tuple[str, str], NetlistLine] = {}
    uses: dict[tuple[str, str], set[str]] = {}
    scope = ""
    for line in lines[1:]:
        low = line.text.lower()
        head = low.split(None, 1)[0]
        if head == ".subckt":
            tokens = low.split()
            scope = tokens[1] if len(tokens) > 1 else "?"
            pairs = _assignments(low)
        elif head == ".ends":
            scope = ""
            continue
        elif head == ".param":
            pairs = _assignments(low[len(".param"):])
        elif head == ".func":
            match = _FUNC.match(low)
            if match is None:
                raise NetlistInputError(f"{_where(line.file, line.line)}: a '.func' line is "
                                        "'.func name(arguments) {expression}'")
            arguments = {a.strip() for a in match.group(2).split(",")}
            names = {m.group(1) for m in _IDENTIFIER.finditer(_PROBE_CALL.sub("0", match.group(3)))} - arguments
            key = (scope, match.group(1))
            defined.setdefault(key, line)
            uses.setdefault(key, set()).update(names)
            continue
        else:
            continue
        for name, value in pairs:
            key = (scope, name)
            defined.setdefault(key, line)
            uses.setdefault(key, set()).update(m.group(1) for m in _IDENTIFIER.finditer(_PROBE_CALL.sub("0", value)))

    def resolve(scope: str, name: str) -> tuple[str, str] | None:
        for key in ((scope, name), ("", name)):
            if key in defined:
                return key
        return None

    edges = {key: [r for n in names if (r := resolve(key[0], n)) is not None] for key, names in uses.items()}
    state: dict[tuple[str, str], int] = {}  # 1: on the current path, 2: done
    for root in edges:
        if root in state:
            continue
        path, stack = [root], [iter(edges[root])]
        state[root] = 1
        while stack:
            child = next(stack[-1], None)
            if child is None:
                state[path.pop()] = 2
                stack.pop()
                continue
            if state.get(child) == 1:
                cycle = path[path.index(child):]
                first = defined[cycle[0]]
                others = ", ".join(dict.fromkeys(f"{defined[k].file} line {defined[k].line}" for k in cycle[1:]
                                                 if defined[k] is not first))
                kind = "'.func'" if first.text.lower().startswith(".func") else "parameter"
                raise NetlistInputError(
                    f"{_where(first.file, first.line)}: this {kind} depends on itself"
                    f"{f' (through the definitions at {others})' if others else ''}: recursive functions crash "
                    "ngspice and circular parameters end its session; not allowed")
            if child not in state:
                state[child] = 1
                path.append(child)
                stack.append(iter(edges[child]))


def check_lines(lines: list[NetlistLine]) -> None:
    """Check logical lines (title first) against the allow-list; raises NetlistInputError.

    Also checks that every device that needs a model, and every subcircuit instance,
    names one defined by a ``.model`` or ``.subckt`` line of the netlist.
    """
    models: set[str] = set()
    subckts: set[str] = set()
    uses: list[tuple[NetlistLine, str, tuple[int, ...] | None]] = []
    scope = ""  # the subcircuit being defined: element names are local to it
    seen: set[tuple[str, str]] = set()
    for line in lines[1:]:
        tokens = line.text.split()
        head = tokens[0].lower()
        where = _where(line.file, line.line)
        if head.startswith("."):
            _check_card(head, tokens, where)
            if head == ".subckt":
                scope = tokens[1].lower() if len(tokens) > 1 else "?"
            elif head == ".ends":
                scope = ""
            if head == ".model" and len(tokens) >= 2:
                models.add(tokens[1].lower())
            elif head == ".subckt" and len(tokens) >= 2:
                subckts.add(tokens[1].lower())
            continue
        letter = head[0]
        if letter not in ELEMENT_FIELDS:
            if letter == "a":
                raise NetlistInputError(f"{where}: XSPICE 'A' devices are not allowed (some code models read files)")
            raise NetlistInputError(f"{where}: not an element line (first letter must be one of "
                                    f"{', '.join(ELEMENT_LETTERS.upper())}) nor an allowed dot-card "
                                    f"({', '.join(c for c in ALLOWED_CARDS)})")
        if head in COMMAND_NAMES or head.startswith("pre_"):
            raise NetlistInputError(f"{where}: the element name is an ngspice command; rename the element")
        if not re.fullmatch(r"[a-z0-9_.+\-#]+", head):
            raise NetlistInputError(f"{where}: an element name may hold letters, digits and _ . + - # only")
        if re.fullmatch(r"x(contact|coil)(_\w*)?", head):
            continue  # a contact's or a coil's block line: NetlistCircuit checks its form and names
        if (scope, head) in seen:
            raise NetlistInputError(f"{where}: an element of this name is already defined (names must be unique)")
        seen.add((scope, head))
        needed = ELEMENT_FIELDS[letter]
        if len(tokens) < needed:
            raise NetlistInputError(
                f"{where}: {_DEVICE_NAMES[letter]} line with {len(tokens)} field(s), it needs at least {needed} "
                f"(name, nodes and a value or model): is the value missing?")
        if letter in _MODEL_POSITIONS:
            uses.append((line, "model", _MODEL_POSITIONS[letter]))
        elif letter == "m":
            uses.append((line, "model", tuple(range(5, len(tokens)))))
        elif letter == "x":
            uses.append((line, "subckt", None))
    _check_expressions(lines)
    _check_definitions(lines)
    for line, kind, positions in uses:
        tokens = line.text.split()
        where = _where(line.file, line.line)
        if kind == "subckt":
            body = tokens[1:]
            lowered = [t.lower() for t in body]
            if "params:" in lowered:
                body = body[: lowered.index("params:")]
            plain = [t for t in body if not _is_param(t)]
            if not plain or plain[-1].lower() not in subckts:
                raise NetlistInputError(f"{where}: the subcircuit instance names a subcircuit that no '.subckt' "
                                        "line of the netlist defines")
            continue
        names = [tokens[k].lower() for k in positions if k < len(tokens) and not _is_param(tokens[k])]
        if not any(name in models for name in names):
            raise NetlistInputError(f"{where}: the {_DEVICE_NAMES[line.text[0].lower()]} names a model that no "
                                    "'.model' line of the netlist defines")


def _check_card(head: str, tokens: list[str], where: str) -> None:
    if head in _INCLUDE_CARDS:
        raise NetlistInputError(f"{where}: {head} is only allowed in a netlist read from a file "
                                "(NetlistCircuit.from_file inlines it)")
    if head in ALLOWED_CARDS:
        if head in (".options", ".option", ".opt"):
            for token in tokens[1:]:
                name = token.split("=", 1)[0].lower()
                if name in _SWITCHSIM_OPTIONS:
                    raise NetlistInputError(f"{where}: option {name} is set by switchsim (SimulationOptions / "
                                            "the scene's [circuit] keys): remove it from the netlist")
                if name not in ALLOWED_OPTIONS:
                    raise NetlistInputError(f"{where}: option not allowed in a netlist; allowed: "
                                            f"{', '.join(ALLOWED_OPTIONS)}")
        return
    for prefix, reason in _REFUSED_PREFIXES:
        if head.startswith(prefix):
            raise NetlistInputError(f"{where}: {reason}")
    raise NetlistInputError(f"{where}: dot-card not allowed; allowed: {', '.join(ALLOWED_CARDS)} "
                            "(and .include/.lib in a netlist file)")
