"""The application: the ``switchsim`` command line, result folders and plots, sweeps, the
accuracy check and the tribometer-fit command. Built on ``coupling.core`` and
``coupling.laws``; nothing there imports this room.
"""

import os as _os


def usable_cpus() -> int:
    """The CPUs this process may use (its affinity where the system says, else the machine's):
    a local sweep's workers, and whether ``switchsim run`` has a CPU for its table writer."""
    try:
        return max(1, len(_os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, _os.cpu_count() or 1)
