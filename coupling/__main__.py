"""``python -m coupling``: the ``switchsim`` command line."""

import sys

from coupling.app.cli import main

if __name__ == "__main__":
    sys.exit(main())
