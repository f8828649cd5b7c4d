"""A benchmark's generated block in a docs page: the text between its begin and end markers."""

from __future__ import annotations

import os
import re
import shlex
import sys
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


def command_line(env: tuple[str, ...] = ()) -> str:
    """The command that is running this script, as the docs give it:
    ``.venv/bin/python benchmarks/NAME ARGS`` (``--no-write`` left out, since a block is only
    written without it), preceded by those of the environment variables ``env`` that are set."""
    prefix = [f"{name}={shlex.quote(os.environ[name])}" for name in env if name in os.environ]
    args = [a for a in sys.argv[1:] if a != "--no-write"]
    return " ".join([*prefix, ".venv/bin/python", f"benchmarks/{Path(sys.argv[0]).name}", *map(shlex.quote, args)])


def load_line(bullet: bool = True) -> str:
    """The load average at the end of a run, as the blocks end: this machine is shared."""
    return f"{'- ' if bullet else ''}Load average at the end of the run: {os.getloadavg()[0]:.1f} (2 cores)."


def publish(path: Path, begin: str, end: str, lines: list[str], write: bool = True) -> None:
    """Print a benchmark's block and, if ``write``, put it between its markers in ``path``."""
    text = "\n".join(lines)
    print(text)
    if write:
        write_block(path, begin, end, text)
        print(f"written to {path}")
