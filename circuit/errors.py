"""Exceptions raised by the circuit package; ngspice's own messages are carried verbatim."""

from __future__ import annotations


class NgspiceError(RuntimeError):
    """ngspice reported a failure.

    ``ngspice_message`` holds the lines ngspice printed (errors, the failing node,
    the last accepted time), unedited, so that a user can search for them in the
    ngspice manual.
    """

    def __init__(self, summary: str, ngspice_message: str = ""):
        self.summary = summary
        self.ngspice_message = ngspice_message
        text = summary if not ngspice_message else f"{summary}\nngspice said:\n{ngspice_message}"
        super().__init__(text)


class NetlistError(NgspiceError, ValueError):
    """ngspice could not parse the netlist (unknown element or model, bad value...).

    Also a ValueError: the netlist is bad input, reported as such (exit status 2 from
    the command line), not as a failure of the simulation."""


class TimestepTooSmallError(NgspiceError):
    """The transient aborted with ngspice's 'Timestep too small'."""


class ConvergenceError(NgspiceError):
    """No convergence: the operating point (gmin and source stepping) failed."""


class SimulationAborted(NgspiceError):
    """The transient stopped early for a reason ngspice did not classify."""


class SimulationTimeout(NgspiceError):
    """A run or a step exceeded its wall-clock limit (``SimulationOptions.wall_timeout``)."""


class LibraryNotFoundError(RuntimeError):
    """The ngspice shared library (libngspice.so.0) could not be located."""


class SessionBusyError(RuntimeError):
    """The single ngspice of this process is in use by another open Stepper or thread."""


class ConductanceError(ValueError):
    """The contact conductance callable returned a value that is not finite and >= 0."""


class GapError(ValueError):
    """The gap-distance callable returned a value that is not finite and >= 0 (m)."""


class NetlistInputError(ValueError):
    """A netlist (or a file it includes) was refused before ngspice saw it: a construct
    that could run a command or read a file, or a line that is not valid input. The
    message names the file and line, never the line's text."""
