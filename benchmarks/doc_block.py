"""A benchmark's generated block in a docs page: the text between its begin and end markers."""

from __future__ import annotations

import re
from pathlib import Path


def write_block(path: Path, begin: str, end: str, text: str, heading: str = "") -> None:
    """Replace what stands between the markers ``begin`` and ``end`` in the page ``path`` by
    ``text``; a page without them gets ``heading`` and the marked block appended."""
    doc = path.read_text() if path.exists() else ""
    block = f"{begin}\n{text}\n{end}"
    if begin in doc and end in doc:
        doc = re.sub(re.escape(begin) + r".*?" + re.escape(end), lambda _: block, doc, count=1, flags=re.S)
    else:
        doc = doc.rstrip("\n") + ("\n\n" if doc else "") + heading + block + "\n"
    path.write_text(doc)
