"""How a circuit's blocks name their elements and nodes, so that one circuit can hold several.

A block (a contact, a coil) placed once without a name keeps the element and node names
every earlier circuit had (Vcontact, contact_g, Varc, ...); a named one carries its name
after the first word of each (Vcontact_no, contact_no_g, Varc_no, ...).
"""

from __future__ import annotations

import re

#: SPICE's names of the ground node (compared in lower case)
GROUND = ("0", "gnd")

#: A block's name: a letter, then letters and digits ("" is a circuit's one unnamed block of a kind).
BLOCK_NAME = re.compile(r"[A-Za-z][A-Za-z0-9]{0,15}")


def check_block_name(where: str, name) -> str:
    """A block's name: "" (the one unnamed block of its kind) or a letter then letters and digits."""
    if name == "" or (isinstance(name, str) and BLOCK_NAME.fullmatch(name)):
        return name
    raise ValueError(f"{where} = {name!r}: a name is a letter followed by up to 15 letters or digits "
                     "(e.g. 'no', 'nc', 'a'), or '' for a circuit's one contact or coil")


def named(base: str, name: str) -> str:
    """The element or node ``base`` of the block ``name``: ``base`` itself for the unnamed
    block (the names of every circuit before contacts had names), else ``base`` with
    ``_name`` inserted after its first word: Vcontact_g -> Vcontact_no_g, arc_on -> arc_no_on."""
    if not name:
        return base
    head, sep, tail = base.partition("_")
    return f"{head}_{name.lower()}{sep}{tail}"
