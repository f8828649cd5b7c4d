"""The command line every example script shares: --fast, --out DIR, a printed summary."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Callable


def run(doc: str, name: str, main: Callable[..., dict], summary: Callable[[dict], str], argv=None,
        fast_help: str = "short run (a few seconds), looser tolerance") -> int:
    """Parse --fast and --out (default runs/examples/<name>), run main, print its summary."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--fast", action="store_true", help=fast_help)
    parser.add_argument("--out", default=None, help=f"output directory (default runs/examples/{name})")
    args = parser.parse_args(argv)
    out = Path(args.out) if args.out else Path("runs/examples") / name
    numbers = main(fast=args.fast, out=out)
    print(summary(numbers))
    print(f"written to {out}/")
    return 0
