"""Switch circuits in real ngspice (shared library, through PySpice).

The contact is a time-varying conductance driven from Python. SI units throughout. A
circuit holds one or more contacts, each a block (``ContactBlock``) with its own input
channels (``<label>.conductance`` S, ``<label>.gap`` m) and result columns.

- ``Stepper``: co-simulation stepping (advance to t_next with G(t) and breakpoints).
- ``run_transient`` / ``run_pwl_reference``: one-shot runs.
- ``ContactSchedule``: prescribed make/break instants.
- ``SwitchCircuit`` and its parts, ``BridgeCircuit`` (a double-break bridge: two contacts
  in series), ``ChangeoverCircuit`` (form C: NO and NC, each throw with its own load),
  ``McuInput`` (a switch read by a microcontroller pin),
  ``NetlistCircuit``: the circuit.
- ``ArcModel``: arc/breakdown of the opening gap (optionally growing with the gap distance).
"""

from .arc import ArcModel, add_arc
from .blocks import ContactBlock
from .channels import ConstantChannel, TableChannel
from .contact import add_contact, left_limited
from .errors import (
    ConductanceError,
    ConvergenceError,
    GapError,
    LibraryNotFoundError,
    NetlistError,
    NetlistInputError,
    NgspiceError,
    SessionBusyError,
    SimulationAborted,
    SimulationTimeout,
    TimestepTooSmallError,
)
from .ngspice import find_library, get_session
from .options import SimulationOptions
from .probes import COLUMNS, Probes
from .stepping import StepResult, Stepper

# Imported on first use (PEP 562): the circuits' dataclasses besides the coil drive (the
# templates, a netlist file's circuit) and the one-shot runs with their schedule. A run
# whose circuit is a coil drive alone (examples/plunger_solenoid.toml) uses none of them,
# and their classes cost ~10 ms of its start (dataclasses writes and compiles each
# generated method: the templates' thirteen classes ~11 ms). circuit/templates/ in turn
# imports each family of templates on first use: a run creates only its template's classes.
_LAZY = {
    "NetlistCircuit": "netlist",
    "ContactSchedule": "schedule",
    "run_pwl_reference": "transient", "run_transient": "transient",
    **dict.fromkeys(("BridgeCircuit", "ChangeoverCircuit", "CapacitiveLoad", "CurrentSource", "DCSource",
                     "FlybackDiode", "InductiveLoad", "McuInput", "ResistiveLoad", "Snubber", "ShortCircuit",
                     "SwitchCircuit", "Wiring"), "templates"),
}


def _lazy_attributes(package: str, table: dict[str, str]):
    """A package's ``__getattr__`` and ``__dir__`` (PEP 562): a name of ``table`` is taken from
    the submodule ``table[name]``, imported on first use, and kept in the package (the next use
    does not come here). circuit/templates/ uses them too."""
    import sys

    def getattr_(name: str):
        if name in table:
            import importlib

            value = getattr(importlib.import_module(f".{table[name]}", package), name)
            setattr(sys.modules[package], name, value)
            return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def dir_():
        return sorted(set(vars(sys.modules[package])) | set(table))

    return getattr_, dir_


__getattr__, __dir__ = _lazy_attributes(__name__, _LAZY)


__all__ = [
    "ArcModel",
    "BridgeCircuit",
    "ChangeoverCircuit",
    "COLUMNS",
    "CapacitiveLoad",
    "ConstantChannel",
    "CurrentSource",
    "ConductanceError",
    "ContactBlock",
    "ContactSchedule",
    "ConvergenceError",
    "DCSource",
    "FlybackDiode",
    "GapError",
    "InductiveLoad",
    "LibraryNotFoundError",
    "McuInput",
    "NetlistCircuit",
    "NetlistError",
    "NetlistInputError",
    "NgspiceError",
    "Probes",
    "ResistiveLoad",
    "SessionBusyError",
    "SimulationAborted",
    "SimulationOptions",
    "SimulationTimeout",
    "Snubber",
    "StepResult",
    "Stepper",
    "ShortCircuit",
    "SwitchCircuit",
    "TableChannel",
    "TimestepTooSmallError",
    "Wiring",
    "add_arc",
    "add_contact",
    "find_library",
    "get_session",
    "left_limited",
    "run_pwl_reference",
    "run_transient",
]
