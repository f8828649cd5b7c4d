"""Switch-circuit templates: validated parameter dataclasses that build a PySpice ``Circuit``.

One module per family, each imported when one of its names is first asked for (PEP 562):
a run creates only the dataclasses of its template (dataclasses writes and compiles six
methods per frozen class, ~0.85 ms each)::

    switch.py         Wiring, SwitchCircuit: the one-contact loop (its topology there);
                      it imports sources.py and loads.py (its defaults), not suppression.py
    sources.py        DCSource, CurrentSource
    loads.py          ResistiveLoad, InductiveLoad, CapacitiveLoad
    suppression.py    Snubber, FlybackDiode
    bridge.py         BridgeCircuit(SwitchCircuit): a double-break bridge
    changeover.py     ChangeoverCircuit(SwitchCircuit): form C, NO and NC
    short_circuit.py  ShortCircuit(SwitchCircuit): the load shorted at a time
    mcu_input.py      McuInput: a switch read by a microcontroller pin

``from circuit.templates import X`` and ``circuit.X`` give every name as before.
"""

from __future__ import annotations

import sys

from .. import _lazy_attributes

# module -> its public names (classes, aliases, constants)
_FAMILIES = {
    "sources": ("DCSource", "CurrentSource", "Source", "BOLTZMANN_OVER_CHARGE", "CLAMP_TEMPERATURE",
                "CLAMP_SATURATION_CURRENT", "CLAMP_MODEL"),
    "loads": ("ResistiveLoad", "InductiveLoad", "CapacitiveLoad", "Load"),
    "suppression": ("Snubber", "FlybackDiode"),
    "switch": ("Wiring", "SwitchCircuit", "NODE_A", "NODE_B", "LOAD_PROBE", "SUPPLY_NODE"),
    "bridge": ("BridgeCircuit", "BRIDGE_NODE"),
    "changeover": ("ChangeoverCircuit",),
    "mcu_input": ("McuInput", "PULLS", "MCU_PIN", "MCU_SWITCH_NODE", "MCU_SUPPLY_NODE"),
    "short_circuit": ("ShortCircuit", "FAULT_NODE", "FAULT_OFF"),
}
_LAZY = {name: module for module, names in _FAMILIES.items() for name in names}
__all__ = list(_LAZY)  # (a star import loads every family)


__getattr__, __dir__ = _lazy_attributes(__name__, _LAZY)


def loaded(*names: str) -> tuple[type, ...]:
    """The classes of ``names`` whose family is imported already, for an isinstance check that
    imports no family: an object can be an instance of a class only once its module has run."""
    modules = (sys.modules.get(f"{__name__}.{_LAZY[name]}") for name in names)
    return tuple(cls for module, name in zip(modules, names) if (cls := getattr(module, name, None)) is not None)
