"""Co-simulation of mechanics and circuit: scenes, tribometer fits, the `switchsim` command.

Scenario scripts::

    from coupling import default_scene, load_scene, run
    scene = default_scene().set("initial.angle_deg", 45).set("circuit.load_resistance", 6.0)
    result = run(scene)
    result.waveforms        # pandas: time, contact_voltage, contact_current, ..., normal_force, mu
    result.mechanics.contacts, result.summary["bounce"]
    result.save("out/")     # summary.json, waveforms.csv/.parquet, PNG plots
"""

__all__ = ["CoSimulation", "CoupledResult", "CoupledRunError", "Scene", "builtin_scene", "default_scene",
           "load_scene", "run", "scene_from_dict"]

# Imported on first use (PEP 562): `import coupling.core.scene` or the CLI's argument parsing
# must not pay for the solvers, pandas or numba.
_LAZY = {"CoSimulation": "core.master", "CoupledRunError": "core.master", "run": "core.master",
         "CoupledResult": "core.results",
         "Scene": "core.scene", "builtin_scene": "core.scene", "default_scene": "core.scene", "load_scene": "core.scene",
         "scene_from_dict": "core.scene"}


def lazy_attributes(package: str, table: dict[str, str]):
    """A module ``__getattr__`` (PEP 562) for ``package``: a name in ``table`` is taken from
    the submodule ``table[name]``, imported on first use, and kept in the package."""
    def getattr_(name: str):
        if name in table:
            import importlib
            import sys

            value = getattr(importlib.import_module(f".{table[name]}", package), name)
            setattr(sys.modules[package], name, value)
            return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return getattr_


__getattr__ = lazy_attributes(__name__, _LAZY)


def __dir__():
    return sorted(set(globals()) | set(__all__))
