"""Co-simulation of mechanics and circuit: scenes, tribometer fits, the `switchsim` command.

Scenario scripts::

    from coupling import default_scene, load_scene, run
    scene = default_scene().set("initial.angle_deg", 45).set("circuit.load_resistance", 6.0)
    result = run(scene)
    result.waveforms        # pandas: time, contact_voltage, contact_current, ..., normal_force, mu
    result.mechanics.contacts, result.summary["bounce"]
    result.save("out/")     # summary.json, waveforms.csv/.parquet, PNG plots
"""

from .master import CoSimulation, CoupledRunError, run
from .results import CoupledResult
from .scene import Scene, builtin_scene, default_scene, load_scene, scene_from_dict

__all__ = ["CoSimulation", "CoupledResult", "CoupledRunError", "Scene", "builtin_scene", "default_scene", "load_scene",
           "run", "scene_from_dict"]
