"""Switch-circuit templates: validated parameter dataclasses that build a PySpice ``Circuit``.

One module per family, each imported when one of its names is first asked for (PEP 562):
a run creates only the dataclasses of its template (dataclasses writes and compiles six
methods per frozen class, ~0.85 ms each)::

    switch.py         Wiring, SwitchCircuit: the one-contact loop (its topology there)

``from circuit.templates import X`` and ``circuit.X`` give every name as before.
"""

from __future__ import annotations

# module -> its public names (classes, aliases, constants)
_FAMILIES = {
    "switch": ("DCSource", "CurrentSource", "Source", "BOLTZMANN_OVER_CHARGE", "CLAMP_TEMPERATURE",
               "CLAMP_SATURATION_CURRENT", "CLAMP_MODEL",
               "ResistiveLoad", "InductiveLoad", "CapacitiveLoad", "Load", "Snubber", "FlybackDiode",
               "Wiring", "SwitchCircuit", "NODE_A", "NODE_B", "LOAD_PROBE", "SUPPLY_NODE",
               "BridgeCircuit", "BRIDGE_NODE",
               "ChangeoverCircuit",
               "McuInput", "PULLS", "MCU_PIN", "MCU_SWITCH_NODE", "MCU_SUPPLY_NODE",
               "ShortCircuit", "FAULT_NODE", "FAULT_OFF"),
}
_LAZY = {name: module for module, names in _FAMILIES.items() for name in names}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value  # (kept: the next use does not come here)
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_LAZY))

