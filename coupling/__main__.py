"""``python -m coupling``: the ``switchsim`` command line.

With ``-m`` Python puts the working folder first on ``sys.path``: a ``tomllib.py`` (or
``numpy.py``, ...) there would be imported, and run, in place of the library. The working
folder is untrusted (docs/circuit.md, threat model), so its entry is dropped before
anything else is imported (``coupling/__init__`` imports nothing; ``os`` and ``sys`` are
loaded by the interpreter before the working folder is on the path).
"""

import os
import sys


def drop_working_folder() -> None:
    """Remove the entry ``-m`` put first on sys.path: '' or the working folder. With
    PYTHONSAFEPATH (``-P``) Python put none there: the first entry is then the user's own
    (PYTHONPATH's first, which may well be the working folder) and stays."""
    if sys.flags.safe_path:
        return
    if sys.path and (sys.path[0] == "" or os.path.realpath(sys.path[0]) == os.path.realpath(os.getcwd())):
        del sys.path[0]


if __name__ == "__main__":
    drop_working_folder()
    from coupling.app.cli import entry

    entry()
