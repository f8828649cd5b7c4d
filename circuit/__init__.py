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
from .netlist import NetlistCircuit
from .ngspice import find_library, get_session
from .options import SimulationOptions
from .probes import COLUMNS, Probes
from .schedule import ContactSchedule
from .stepping import StepResult, Stepper
from .templates import (
    BridgeCircuit,
    ChangeoverCircuit,
    CapacitiveLoad,
    CurrentSource,
    DCSource,
    FlybackDiode,
    InductiveLoad,
    McuInput,
    ResistiveLoad,
    Snubber,
    ShortCircuit,
    SwitchCircuit,
    Wiring,
)
from .transient import run_pwl_reference, run_transient

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
