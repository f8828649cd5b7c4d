"""The build of the ahead-of-time module (mech.aot), run only in its child process.

``compile_into(DEST)``: warm up on numba's just-in-time route (small representative runs
through the Python side, so every entry point of ``mech.compiled.ENTRY_POINTS`` is compiled
for the argument types the solver really passes), collect those signatures, and compile
every entry point with numba.pycc into DEST, with the signatures' argument kinds beside it
(mech.aot.SIGNATURES) for the loader's checks. mech.aot starts this in a child process with
``SWITCHSIM_JIT=1``; nothing else imports this module, so the loader never loads the solver.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
from numba.core import types  # (the build child loads numba anyway: it compiles with it)

from . import compiled as jit
from .aot import FORCE_JIT, MODULE, SIGNATURES
from .damping_calibration import calibrate_damping
from .jit import borrowing_violations
from .kernel_layout import NAUX
from .scene import scene_from_dict
from .solver import ImpactSolver


def warm_up() -> None:
    """Call every entry point through the Python side on small representative models."""
    steel = dict(youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)
    bar3d = dict(length=0.1, diameter=0.006, tip_radius=0.003, modes=2, **steel)
    short = dict(t_end=3e-4)
    scenes = [
        # 3D free bar, exact friction, restitution calibrated; a stick on the block
        {"bar": bar3d, "initial": dict(height=1e-4, angle_deg=30.0, velocity=[0.3, 0.1, -1.0]),
         "friction": dict(model="exact", mu=0.8), "contact": dict(restitution=0.5), "solver": short},
        # planar free bar, regularized friction
        {"bar": bar3d, "initial": dict(height=1e-4, angle_deg=30.0, velocity=[0.0, 0.0, -1.0]),
         "friction": dict(model="regularized", mu=0.3), "solver": short},
        # no friction, the paper's law
        {"bar": bar3d, "initial": dict(height=1e-4, angle_deg=30.0, velocity=[0.0, 0.0, -1.0]),
         "friction": dict(mu=0.0), "contact": dict(law="paper", restitution=0.8), "solver": short},
        # a clamped blade with a rivet under a force ramp
        {"bar": dict(length=0.02, width=0.003, thickness=0.0003, tip_radius=0.0016, modes={"axial": 1, "bending": 3},
                     modal_damping=0.05, **steel),
         "mount": dict(kind="clamp", position=0.02), "rivet": [dict(position=0.0015, offset=0.0, radius=0.0015)],
         "force": [dict(position=0.01, time=[0.0, 0.001], value=[0.0, 3.0])],
         "initial": dict(height=2e-5), "friction": dict(model="exact", mu=0.3), "solver": dict(t_end=1e-3)},
        # a pivoted rigid arm on a spring
        {"bar": dict(length=0.05, diameter=0.005, tip_radius=0.0025, modes=0, **steel),
         "mount": dict(kind="pivot", position=0.05, stiffness=1.0, preload_torque=0.01),
         "spring": [dict(anchor=[0.01, 0.0, 0.01], position=0.01, stiffness=50.0, damping=0.01)],
         "initial": dict(height=1e-5), "solver": dict(t_end=5e-4)},
    ]
    for k, doc in enumerate(scenes):
        solver = ImpactSolver(scene_from_dict(doc), keep_dense=True)
        segment = solver.advance(doc["solver"]["t_end"] * 0.5)
        t = 0.5 * (segment.t_start + segment.t_end)
        segment.contact(t)
        segment.tip_forces(t)
        segment.state(t)
        solver.advance(doc["solver"]["t_end"])
        solver.contact_series(np.linspace(segment.t_start, solver.t, 5))
        result = solver.result()
        result.energy_table  # noqa: B018  (the compiled energy table)
        jit.energies(solver.y, solver.arrays, solver.work, np.empty(5), solver.arm)  # (as a hold calls it)
        result.contacts  # noqa: B018  (dense contact evaluation where the solver asks for it)
        if k == 0:  # the scipy backends hand the right-hand side views of their own arrays
            for method in ("RK45", "Radau", "BDF", "LSODA"):
                ImpactSolver(scene_from_dict(doc), backend=f"scipy:{method}").run()
        # the drive channels, every kind given, one ramped (a free bar with the input-work
        # quadrature for its repulsion; a held one has it anyway)
        driven = ImpactSolver(scene_from_dict(doc), keep_dense=True, input_work=True)
        names = driven.drive_names
        segment = driven.advance(doc["solver"]["t_end"], {name: (0.0, 0.1) if name.startswith("repulsion.")
                                                          else 0.2 for name in names})
        segment.tip_forces(0.5 * (segment.t_start + segment.t_end))
        driven.result().energy_table  # noqa: B018
    # the armature: alone (a bar-less model) with a gain table, and driving a clamped
    # blade through its card; its dense output, history table and events
    armature = dict(kind="plunger", mass=0.02, travel=1e-3, stop_stiffness=1e9, stop_damping=20.0,
                    spring_rate=100.0, spring_preload=0.1, damping=0.01)
    alone = {"armature": dict(armature, force_gain=dict(position=[0.0, 5e-4, 1e-3], gain=[1.0, 1.5, 3.0])),
             "solver": dict(t_end=5e-3)}
    card = {"bar": dict(length=0.02, width=0.003, thickness=0.0003, tip_radius=0.0016,
                        modes={"axial": 1, "bending": 3}, **steel),
            "mount": dict(kind="clamp", position=0.02), "rivet": [dict(position=0.0015, radius=0.0015)],
            "armature": dict(armature, card_position=0.01, card_lever=1.0, card_free_travel=2e-4,
                             card_stiffness=1e5, card_damping=0.1),
            "initial": dict(height=2e-4), "contact": dict(reference_speed=0.5), "solver": dict(t_end=4e-3)}
    # contact pairs ([[fixed]]): a changeover's blade between an NO contact below and a
    # spherical NC stop above it, three pairs (a row of quadratures beyond the first two)
    blade = dict(length=0.02, width=0.003, thickness=0.0003, tip_radius=0.0016, modes={"axial": 1, "bending": 3},
                 **steel)
    changeover = {"bar": blade, "mount": dict(kind="clamp", position=0.02),
                  "rivet": [dict(position=0.0015, offset=-0.0003, radius=0.001, name="low"),
                            dict(position=0.0015, offset=0.0003, radius=0.001, name="high"),
                            dict(position=0.004, offset=-0.0003, radius=0.001, name="aux")],
                  "fixed": [dict(point="low", name="NO", gap=2e-5),
                            dict(point="high", name="NC", facing="down", gap=0.0, shape="sphere", radius=0.002),
                            dict(point="aux", name="stop", gap=3e-5, electrical=False)],
                  "force": [dict(position=0.01, time=[0.0, 1e-3], value=[0.5, -2.0])],
                  "friction": dict(mu=0.3), "solver": dict(t_end=2e-3)}
    solver = ImpactSolver(scene_from_dict(changeover), keep_dense=True)
    segment = solver.advance(1e-3)
    segment.pair_forces(0.5 * (segment.t_start + segment.t_end))
    segment.tip_forces(0.5 * (segment.t_start + segment.t_end))
    solver.advance(2e-3)
    solver.contact_series(np.linspace(0.0, 2e-3, 5))
    solver.result().energy_table  # noqa: B018
    for doc in (alone, card):
        solver = ImpactSolver(scene_from_dict(doc), keep_dense=True)
        t_end = doc["solver"]["t_end"]
        segment = solver.advance(0.5 * t_end, {"armature.force": (0.0, 3.0)})
        t = 0.5 * (segment.t_start + segment.t_end)
        segment.armature(t)
        segment.tip_forces(t)
        segment.contact(t)
        solver.armature_now()
        solver.advance(t_end, {"armature.force": 3.0})
        solver.contact_series(np.linspace(0.0, t_end, 5))
        result = solver.result()
        result.history_columns  # noqa: B018  (the compiled armature table)
        result.energy_table  # noqa: B018
        # the stick projection with an armature (reached only when a contact of such a
        # model comes to rest: called here directly)
        jit.project_to_stick(solver.t, solver.y.copy(), solver.arrays, solver.regime, solver.eref,
                             np.empty((2, NAUX)), solver.work, solver.arm)
    calibrate_damping("hunt_crossley", 0.7, 1.0, 1e10, 0.01)


def signatures() -> dict:
    """export name -> numba Signature of each entry point as the warm-up compiled it; a
    function compiled for array arguments of several layouts is exported for any layout
    ('A'). A VARIANTS entry point is exported twice: for its last argument None (a model
    without an armature) under its name, for the armature's arrays as "<name>_armature"."""
    out = {}
    for name in jit.ENTRY_POINTS:
        sigs = getattr(jit, name).nopython_signatures
        groups = {name: sigs}
        if name in jit.VARIANTS:
            groups = {name: [s for s in sigs if s.args[-1] == types.none],
                      name + jit.ARMATURE_SUFFIX: [s for s in sigs if s.args[-1] != types.none]}
        for export, group in groups.items():
            if not group:
                raise RuntimeError(f"the warm-up never called {export}: add a model that reaches it to "
                                   "mech.aot_build.warm_up")
            out[export] = _merge_layouts(export, group) if len(group) > 1 else group[0]
    return out


def _merge_layouts(name: str, sigs):
    first = sigs[0]
    args = list(first.args)
    for sig in sigs[1:]:
        if len(sig.args) != len(args) or sig.return_type != first.return_type:
            raise RuntimeError(f"{name} was compiled for different argument kinds: {sigs}")
        for i, (a, b) in enumerate(zip(args, sig.args)):
            if a == b:
                continue
            if isinstance(a, types.Array) and isinstance(b, types.Array) and (a.dtype, a.ndim) == (b.dtype, b.ndim):
                args[i] = a.copy(layout="A")
            else:
                raise RuntimeError(f"{name} was compiled for different argument types: {a} and {b}")
    return first.return_type(*args)


def compile_into(dest) -> None:
    """Warm up on the JIT route, then compile every entry point into ``dest`` (a folder)."""
    warnings.filterwarnings("ignore", message=".*pycc.*")
    # (numba.pycc is imported here, after its deprecation warning is silenced: only the
    # build uses it)
    from numba.pycc import CC

    if jit.ROUTE != "jit":
        raise RuntimeError(f"the build must run on the just-in-time route (set {FORCE_JIT}=1)")
    warm_up()
    leaks = borrowing_violations()
    if leaks:
        raise RuntimeError("compiled without reference counts (mech.jit.njit_borrowing) but returning a "
                           "reference-counted value: " + "; ".join(leaks))
    cc = CC(MODULE, source_module=__name__)
    cc.output_dir = str(dest)
    cc.target_cpu = "host"  # built where it runs: the same instructions the JIT would use
    sigs = signatures()
    for name, sig in sigs.items():
        cc.export(name, sig)(getattr(jit, name.removesuffix(jit.ARMATURE_SUFFIX)).py_func)
    cc.compile()
    (Path(dest) / SIGNATURES).write_text(json.dumps({name: [_kind(a) for a in sig.args]
                                                     for name, sig in sigs.items()}, indent=1))


def _kind(t):
    """What an argument of numba type ``t`` must be for the exported function (JSON):
    ["array", dtype, ndim, layout], ["tuple", [kinds]] or ["scalar", name]."""
    if isinstance(t, types.Array):
        return ["array", str(t.dtype), t.ndim, t.layout]
    if isinstance(t, types.BaseTuple):
        return ["tuple", [_kind(e) for e in t.types]]
    return ["scalar", str(t)]
