"""A user's own netlist with a named contact: the ``XCONTACT a b`` convention.

Write the circuit as an ordinary SPICE netlist (first line: title; no analysis lines,
no ``.end``) and mark the contact with one line::

    XCONTACT node_a node_b

switchsim replaces that line by its contact element (and the arc path, when an
``ArcModel`` is given). The contact voltage is V(node_a) - V(node_b). For the
``load_current`` column put a 0 V source in series with the load and name it (default
``VLOAD``, current positive from its + node to its - node)::

    my relay driver
    V1 supply 0 24
    R1 supply a 0.1
    XCONTACT a b
    Cpar a b 100p
    VLOAD b coil 0
    Rcoil coil c1 240
    Lcoil c1 0 50m

The netlist and the files it includes (``.include``, ``.lib FILE SECTION``, paths
relative to the including file's folder) are read and checked by switchsim before
ngspice sees them: see ``netlist_check`` and docs/circuit.md (threat model).

Several contacts: name each, ``XCONTACT_<name> node_a node_b`` (a letter, then letters
and digits: ``XCONTACT_NO``, ``XCONTACT_NC``); each becomes its own contact block with its
own conductance, gap, arc and result columns (``contact_voltage_no``, ...). A plain
``XCONTACT`` is the one unnamed contact and cannot be combined with named ones. A 0 V
source ``VLOAD_<name>`` (the load probe's name, then the contact's) in series with a
contact's own load (a changeover's throw) gives its load current, column
``load_current_<name>``, and the current its friction coefficient mu(I) follows (else the
supply's, ``VLOAD``'s: right for contacts in series, one current through all).

The relay's own coil (with ``coil_resistance`` and ``coil_current``, the magnet's current
law): one line ``XCOIL node_p node_n`` in the coil's drive circuit, replaced by the coil
block (circuit.blocks.CoilBlock: flux form, its gap an input channel ``coil.gap``).

Reserved (do not use): elements Vcontact*, Bcontact*, Varc*, Barc*, Iarc*, Rarc*, Vxcoil*,
Rxcoil*, Bxcoil*, Cxcoil*; nodes contact_s, contact_g, contact_geff (and contact_<name>_s, _g,
_geff), arc_*, xcoil_*.
"""

from __future__ import annotations

import dataclasses

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import ClassVar

from PySpice.Spice.Netlist import Circuit

from .arc import ArcModel, chopped_inductors
from .blocks import CoilBlock, ContactBlock
from .contact import DEFAULT_LEAKAGE, check_current_factor
from .errors import NetlistInputError
from .netlist_check import DECK_TITLE, NetlistLine, check_lines, logical_lines, param_spans, read_netlist
from .probes import Probes
from .validation import check_range, internal, scene_key

_RESERVED_ELEMENTS = re.compile(
    r"^(vcontact\w*|bcontact\w*|varc\w*|barc\w*|iarc\w*|rarc\w*|[vrbc]xcoil\w*)$", re.I)
_RESERVED_NODES = re.compile(r"^(contact_(\w+_)?(s|g|geff)|arc_\w+|xcoil_\w+)$", re.I)
# nodes of an element line after its name, by its letter (SPICE); others have two
_NODE_COUNTS = {"s": 4, "e": 4, "g": 4, "q": 3, "j": 3, "m": 4, "t": 4, "o": 4}
_CONTACT_LINE = re.compile(r"^xcontact(?:_(\w+))?$", re.I)
_COIL_LINE = re.compile(r"^xcoil$", re.I)


@dataclass(frozen=True)
class NetlistCircuit:
    """A user netlist (text) with its contact lines (``XCONTACT a b``, or ``XCONTACT_<name> a b``
    per contact). See the module docstring.

    load_probe: name of the 0 V source in series with the load, or None.
    arc: optional ArcModel across the contact.
    leakage_conductance: open-contact conductance, S.
    contact_current_factor: optional ngspice expression g(I) of the contact current I (A);
        the contact conductance is then G(t)/g(I) (see contact.py).
    params: new values of the netlist's own top-level ``.param`` definitions, {name: number}
        or (name, number) pairs (None: the netlist's own values)
        (names as SPICE reads them, case-insensitive; units as the netlist uses them, SI):
        each definition's value is replaced by the number before the netlist is checked, so
        the checks see the netlist as ngspice will. A name the netlist does not define at
        its top level (outside ``.subckt``) is refused.
    coil_resistance, coil_current: the relay coil's copper resistance (ohm) and current law
        (an ngspice expression of PSI, Wb, and GAP, m: circuit.blocks.CoilBlock) for an
        ``XCOIL p n`` line; both or neither.
    origins: (file, line) where each line of ``text`` starts, for messages (set by
        ``from_file``; ``text`` is then the inlined netlist).
    """

    SECTION: ClassVar[str] = "circuit"
    text: str = internal()  # the netlist read from [circuit] netlist (a file name)
    load_probe: str | None = scene_key(
        "VLOAD", unit="-",
        doc='template "netlist": the 0 V source in series with the load (its current is the load current)')
    arc: ArcModel | None = scene_key(
        None, unit="-", doc="the arc model: true (its defaults) or a table: [circuit.arc]; omitted or false: none")
    leakage_conductance: float = scene_key(DEFAULT_LEAKAGE, unit="S", doc="open-contact insulation")
    contact_current_factor: str | None = internal(None)
    origins: tuple[tuple[str, int], ...] | None = field(default=None, compare=False, repr=False, metadata={"internal": True})
    coil_resistance: float | None = internal(None)
    coil_current: str | None = internal(None)
    params: tuple[tuple[str, float], ...] | None = scene_key(
        None, unit="-",
        doc='template "netlist": new values of the netlist\'s own `.param` definitions, `{ RF = 10e3, CF = 1e-9 '
            "}` (numbers, in the netlist's units; SPICE names ignore case): [circuit.params]; a name the netlist "
            "does not define at its top level is refused")

    def __post_init__(self) -> None:
        object.__setattr__(self, "params", _param_values(self.params) if self.params else None)
        if not isinstance(self.text, str) or not self.text.strip():
            raise ValueError("NetlistCircuit.text: must be a non-empty netlist string")
        if self.arc is not None and not isinstance(self.arc, ArcModel):
            raise ValueError(f"NetlistCircuit.arc = {self.arc!r}: must be an ArcModel or None")
        if self.load_probe is not None and not (isinstance(self.load_probe, str)
                                                and re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", self.load_probe)):
            raise ValueError(f"{self.SECTION}.load_probe = {self.load_probe!r}: the name of a voltage source "
                             "(letters, digits, _) or None")
        check_range(self.SECTION, "leakage_conductance", self.leakage_conductance, "S", 0.0, 1e-3)
        check_current_factor("NetlistCircuit", self.contact_current_factor)
        if (self.coil_resistance is None) != (self.coil_current is None):
            raise ValueError("NetlistCircuit.coil_resistance and NetlistCircuit.coil_current: give both (a coil) "
                             "or neither")
        lines, placed, _, _ = self._parse()  # fail early, before anything runs
        if self.arc is not None:
            _check_arc_chop(lines, placed)

    @classmethod
    def from_file(cls, path: str | Path, **kwargs) -> "NetlistCircuit":
        """Read a netlist file, inlining its includes (relative to the file's folder), and check it."""
        lines = read_netlist(path)
        return cls("\n".join(line.text for line in lines), origins=tuple((l.file, l.line) for l in lines), **kwargs)

    def _lines(self) -> list[NetlistLine]:
        if self.origins is None:
            lines = logical_lines(self.text, "<text>")
        else:
            texts = self.text.split("\n")
            if len(texts) != len(self.origins):
                raise ValueError("NetlistCircuit.origins: one (file, line) per line of text")
            lines = [NetlistLine(t, f, n) for t, (f, n) in zip(texts, self.origins)]
        lines = _with_params(lines, self.params)
        # the text was checked when read; checked again since the object may be built by hand
        # and the parameters' values are new text
        check_lines(lines)
        return lines

    def _parse(self) -> tuple[list[NetlistLine], list[tuple[int, ContactBlock]], list[tuple[int, CoilBlock]], bool]:
        """The checked lines, each contact line's and coil line's row and block, and whether the
        load probe is there."""
        lines = self._lines()
        placed: list[tuple[int, ContactBlock]] = []
        coils: list[tuple[int, CoilBlock]] = []
        has_load_probe = False
        heads: set[str] = set()
        for i, line in enumerate(lines):
            if i == 0:
                continue
            tokens = line.text.split()
            head = tokens[0]
            where = f"netlist {line.file} line {line.line}"
            match = _CONTACT_LINE.match(head)
            if match:
                if len(tokens) != 3:
                    raise NetlistInputError(f"{where}: the contact line is '{head} node_a node_b'")
                name = (match.group(1) or "").lower()
                try:
                    block = ContactBlock(name, tokens[1], tokens[2], self.leakage_conductance,
                                         self.contact_current_factor, self.arc)
                except ValueError as err:
                    raise NetlistInputError(f"{where}: {head}: {err}") from None
                if any(b.name == name for _, b in placed):
                    raise NetlistInputError(f"{where}: a second contact line {head}: each contact is placed once")
                placed.append((i, block))
                continue
            if _COIL_LINE.match(head):
                if len(tokens) != 3:
                    raise NetlistInputError(f"{where}: the coil line is 'XCOIL node_p node_n'")
                if self.coil_current is None:
                    raise NetlistInputError(f"{where}: an XCOIL line, but no coil is given (the scene's [coil] and "
                                            "[magnet] sections make it)")
                if coils:
                    raise NetlistInputError(f"{where}: a second XCOIL line: the netlist holds one coil")
                try:
                    coils.append((i, CoilBlock("", tokens[1], tokens[2], self.coil_resistance, self.coil_current)))
                except ValueError as err:
                    raise NetlistInputError(f"{where}: XCOIL: {err}") from None
                continue
            if _RESERVED_ELEMENTS.match(head):
                raise NetlistInputError(f"{where}: element name {head} is reserved by switchsim")
            if head[0].isalpha() and any(_RESERVED_NODES.match(t) for t in tokens[1:3]):
                raise NetlistInputError(f"{where}: node names contact_s, contact_g, arc_*, xcoil_* are reserved")
            if self.load_probe is not None and head.lower() == self.load_probe.lower():
                has_load_probe = True
            heads.add(head.lower())
        if not placed:
            raise NetlistInputError(
                "the netlist must contain a contact line, 'XCONTACT node_a node_b' (or one 'XCONTACT_<name> "
                "node_a node_b' per contact; found none); the first line is the title"
            )
        if self.coil_current is not None and not coils:
            raise NetlistInputError("a coil is given (the scene's [coil] and [magnet]) but the netlist has no "
                                    "'XCOIL node_p node_n' line to place it")
        if len(placed) > 1 and any(not b.name for _, b in placed):
            raise NetlistInputError("a netlist with several contacts names each one, 'XCONTACT_<name> node_a node_b' "
                                    "(a plain XCONTACT is the one contact of a single-contact netlist)")
        if self.load_probe is not None:
            # a named contact's own load probe, <load_probe>_<name> (VLOAD_NO): its load current,
            # the current its mu(I) follows (a changeover's throws, as the template's)
            placed = [(i, dataclasses.replace(b, load_probe=f"{self.load_probe}_{b.name}".lower())
                       if b.name and f"{self.load_probe}_{b.name}".lower() in heads else b) for i, b in placed]
        return lines, placed, coils, has_load_probe

    @property
    def contacts(self) -> tuple[ContactBlock, ...]:
        """The netlist's contacts, as blocks, in the order of their lines."""
        return tuple(block for _, block in self._parse()[1])

    @property
    def arrangement(self) -> str | None:
        """"series" when the netlist's several contacts are in series in one loop (a double-break
        bridge: XCONTACT_A a m, XCONTACT_B m b): the contacts form one chain whose inner nodes
        join two contacts and nothing else but elements across one of them (its stray
        capacitance, a snubber); None otherwise (one contact, or an arrangement not inferred)."""
        lines, placed, coils, _ = self._parse()
        if len(placed) < 2:
            return None
        degree: dict[str, int] = {}
        for _, block in placed:
            a, b = block.node_a.lower(), block.node_b.lower()
            if a == b:
                return None
            for node in (a, b):
                degree[node] = degree.get(node, 0) + 1
        inner = {n for n, d in degree.items() if d == 2}
        ends = [n for n, d in degree.items() if d == 1]
        if any(d > 2 for d in degree.values()) or len(ends) != 2 or len(inner) != len(placed) - 1 or "0" in inner:
            return None  # (not one chain: a contact in parallel with another, a branch, a loop)
        spans = [{block.node_a.lower(), block.node_b.lower()} for _, block in placed]
        rows = {row for row, _ in placed + coils}
        depth = 0
        for i, line in enumerate(lines):
            tokens = line.text.lower().split()
            if i == 0 or i in rows or not tokens:
                continue
            if tokens[0].startswith(".subckt"):
                depth += 1
            elif tokens[0].startswith(".ends"):
                depth -= 1
            if depth or tokens[0][0] in ".*+":
                continue
            letter = tokens[0][0]
            count = _NODE_COUNTS.get(letter, 2)
            nodes = set(t for t in tokens[1:-1] if "=" not in t) if letter == "x" else set(tokens[1:1 + count])
            touched = nodes & inner
            if touched and not any(nodes <= span for span in spans):
                return None  # an inner node reaches outside its two contacts
        return "series"

    @property
    def coils(self) -> tuple[CoilBlock, ...]:
        """The netlist's coil (a block), if it places one."""
        return tuple(block for _, block in self._parse()[2])

    @property
    def probes(self) -> Probes:
        _, placed, coils, has_load_probe = self._parse()
        return Probes(tuple(block for _, block in placed),
                      load_current=f"{self.load_probe}#branch" if has_load_probe else None,
                      coils=tuple(block for _, block in coils))

    def netlist(self) -> str:
        """The checked netlist with each contact line expanded (switchsim's own title first,
        comments dropped, no analysis, no .end)."""
        lines, placed, coils, _ = self._parse()
        texts = [line.text for line in lines]
        for row, block in placed + coils:
            scratch = Circuit("contact")
            block.add_to(scratch)
            texts[row] = "\n".join(line for line in str(scratch).splitlines()[1:] if line.strip())
        expanded = [DECK_TITLE] + texts[1:]
        return "\n".join(part for text in expanded for part in text.split("\n") if part.strip().lower() != ".end")


def _check_arc_chop(lines: list[NetlistLine], placed: list[tuple[int, ContactBlock]]) -> None:
    """Refuse a contact whose arc, going out, would chop an inductor's current (arc.chopped_inductors)."""
    elements, depth = [], 0
    for line in lines[1:]:
        tokens = line.text.split()
        head = tokens[0].lower() if tokens else "*"
        depth += head.startswith(".subckt") - head.startswith(".ends")
        if not depth and head[0].isalpha():
            elements.append(tokens)
    for row, block in placed:
        head = lines[row].text.split()[0]
        others = [t for t in elements if t[0].lower() != head.lower()]
        chopped = chopped_inductors(others, block.node_a, block.node_b)
        if chopped:
            where = f"netlist {lines[row].file} line {lines[row].line}"
            raise NetlistInputError(
                f"{where}: {head} {block.node_a} {block.node_b} with the arc model: when its arc goes out it "
                f"chops the current of {', '.join(chopped)}, which has no other path across the contact (an "
                "inductor's current cannot jump: ngspice stops with 'timestep too small'); add the contact's "
                f"stray capacitance across it, e.g. 'C{head[1:]} {block.node_a} {block.node_b} 100p' (the "
                "templates' default), or a snubber")


def _param_values(params) -> tuple[tuple[str, float], ...]:
    """``params`` ({name: number} or (name, number) pairs) as checked pairs."""
    if isinstance(params, dict):
        params = tuple(params.items())
    if not isinstance(params, (tuple, list)) or not all(isinstance(p, (tuple, list)) and len(p) == 2 for p in params):
        raise ValueError(f"circuit.params = {params!r:.200}: expected a table of name = number")
    out = []
    for name, value in params:
        if not (isinstance(name, str) and re.fullmatch(r"[A-Za-z_]\w*", name)):
            raise ValueError(f"circuit.params: {name!r:.60} is not a parameter name (a letter or _, then "
                             "letters, digits, _)")
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                or abs(value) > PARAM_MAX:
            raise ValueError(f"circuit.params.{name} = {value!r:.60}: expected a finite number, "
                             f"|value| <= {PARAM_MAX:g}")
        out.append((name, float(value)))
    lowered = [name.lower() for name, _ in out]
    for name in out:
        if lowered.count(name[0].lower()) > 1:
            raise ValueError(f"circuit.params.{name[0]}: given twice (SPICE names ignore case)")
    return tuple(out)


#: Largest magnitude of a parameter value set from the scene (ngspice reads doubles; this
#: keeps products of parameters finite).
PARAM_MAX = 1e30


def _with_params(lines: list[NetlistLine], params: tuple[tuple[str, float], ...] | None) -> list[NetlistLine]:
    """The lines with each top-level ``.param`` definition of a name in ``params`` given the
    new value (every definition of it: ngspice would take the last); a name the netlist does
    not define at its top level is refused, naming it and the ones it defines."""
    if not params:
        return lines
    wanted = {name.lower(): (name, value) for name, value in params}
    seen: set[str] = set()
    defined: list[str] = []
    out = []
    depth = 0
    for k, line in enumerate(lines):
        head = line.text.split(None, 1)[0].lower() if k and line.text.strip() else ""
        depth += head == ".subckt"
        depth -= head == ".ends" and depth > 0
        spans = param_spans(line.text) if k and depth == 0 else []
        text = line.text
        for name, start, end in reversed(spans):
            defined.append(name)
            hit = wanted.get(name.lower())
            if hit is not None:
                seen.add(name.lower())
                text = f"{text[:start]} {hit[1]!r} {text[end:].lstrip()}".rstrip()
        out.append(line if text == line.text else NetlistLine(text, line.file, line.line))
    for key, (name, value) in wanted.items():
        if key not in seen:
            from difflib import get_close_matches

            names = sorted(dict.fromkeys(defined[::-1]), key=str.lower)
            lowered = {n.lower(): n for n in names}
            close = get_close_matches(key, list(lowered), n=1, cutoff=0.5)
            hint = f"; did you mean {lowered[close[0]]!r}?" if close else ""
            raise ValueError(f"circuit.params.{name} = {value!r}: the netlist has no '.param {name}' at its "
                             f"top level{hint} (its parameters: {', '.join(names) or 'none'})")
    return out
