"""Side by side with Exudyn, an independent flexible-multibody code, on the same scenes:
contact intervals per tip, peak normal force, rebound (centre-of-mass velocity) and wall
time, each code refined on its own until its metrics stop moving.

    .venv/bin/python benchmarks/accuracy_exudyn.py      (part 6 of `make accuracy`)

Exudyn is an optional benchmark extra (`pip install -e '.[bench]'`), never a dependency
of switchsim: without it this part writes a fragment saying how to install it and exits 0.

The Exudyn models are written here with Exudyn's public item interface, planar (x along
the block, y up): a rigid bar is an ObjectRigidBody2D, a flexible bar a chain of
ObjectANCFCable2D elements (cubic Hermite, Euler-Bernoulli bending and axial strain); each
tip's sphere centre carries an ObjectContactSphereTriangle against one large triangle in
the plane y = 0 with F = k y^1.5 (contactStiffnessExponent 1.5, no damping, no friction).
"""

from __future__ import annotations

import math
import statistics
import sys
import time

from accuracy_common import Section, dump, fmt, load_note, mech_scene, mech_tips, plt, run_mech

from coupling.app.accuracy import TOLERANCES, compare, contact_metrics, mismatch_time

# --- the scenes (SI units) --------------------------------------------------------------
BAR = dict(length=0.3, diameter=0.01, tip_radius=0.005, youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0)
BLOCK = dict(youngs_modulus=210e9, poisson_ratio=0.3)
HEIGHT = 1e-5  # m: lowest tip above the block at release
SPEED = 1.0  # m/s: falling speed at release
GRAVITY = 9.80665  # m/s^2
SCENES = {  # angle of the bar to the block (deg), flexible or rigid, simulated time (s)
    "rigid, vertical": dict(angle=90.0, flexible=False, t_end=3e-4),
    "rigid, 30 deg": dict(angle=30.0, flexible=False, t_end=3e-4),
    "flexible, vertical": dict(angle=90.0, flexible=True, t_end=4e-4),
    "flexible, 30 deg": dict(angle=30.0, flexible=True, t_end=1.1e-3),
}

# --- refinement ladders (coarse to fine; the last entry is the code's reference) ---------
SS_MODES = (3, 5, 7, 10, 14, 20, 28, 40)  # switchsim: modes per family, at SS_REF_RTOL
SS_RTOLS = (1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11)  # switchsim: rtol
SS_REF_RTOL = 1e-10  # flexible reference: 40 modes per family at this rtol (rigid: 1e-11)
EX_ELEMENTS = (4, 8, 16, 32, 64)  # Exudyn: ANCF elements, with generalized-alpha at EX_REF_STEP
EX_REF_STEP = {False: 6.25e-8, True: 1.25e-7}  # s: reference step (rigid, flexible)
EX_ROUTES = {  # Exudyn integrators and their ladders: fixed steps (s) or DOPRI5 tolerances
    "generalized-alpha": (1e-5, 5e-6, 2e-6, 1e-6, 5e-7, 2.5e-7, 1.25e-7, 6.25e-8),
    "RK44": (5e-6, 2e-6, 1e-6, 5e-7, 2.5e-7, 1.25e-7, 6.25e-8),
    "DOPRI5": (1e-4, 1e-6, 1e-8),
}
EX_MAX_STEP = 1e-6  # s: DOPRI5's largest step (Exudyn: t_end / numberOfSteps)
EX_LIMIT = 90.0  # s for one Exudyn run: its CPU-time limit, and the wall time its forked child gets
ENERGY_SANITY = 1e-2  # an Exudyn run whose energy drifts more than this (relative) is not used
VELOCITY_TOL = 1e-3  # m/s: the end velocity "did not move" within this (0.1 % of SPEED)
RATE_TOL = 1e-2  # rad/s: likewise the rigid bar's inclination rate
REPEATS = 3  # each code's matched run is timed at least this often, alternately (median reported),
TIMED = 0.5  # s: and until each code has run this long in total,
MAX_REPEATS = 30  # but at most this often


# --- physics ----------------------------------------------------------------------------

def hertz_stiffness(radius: float, e1: float, nu1: float, e2: float, nu2: float) -> float:
    """N/m^1.5: sphere of radius (m) on a half-space, k = (4/3) E* sqrt(R), 1/E* = sum (1 - nu^2)/E."""
    return 4.0 / 3.0 * math.sqrt(radius) / ((1.0 - nu1**2) / e1 + (1.0 - nu2**2) / e2)


def hertz_energy(k: float, penetration: float) -> float:
    """J stored in F = k y^1.5 at penetration y (m): 2/5 k y^2.5."""
    return 0.4 * k * max(penetration, 0.0) ** 2.5


def hermite_moment(pa, sa, pb, sb, h: float):
    """int_0^h r(x) dx of a cubic Hermite curve with end values pa, pb and end slopes sa, sb
    (per unit length) over an element of length h: h/2 (pa + pb) + h^2/12 (sa - sb)."""
    return [h / 2.0 * (a + b) + h * h / 12.0 * (c - d) for a, b, c, d in zip(pa, pb, sa, sb)]


def gap_intervals(t, gap) -> list[tuple[float, float]]:
    """[(start, end), ...] (s) where the sampled gap (m) is negative, each crossing placed by
    linear interpolation between samples; an interval open at the end closes at t[-1]."""
    out, start = [], None
    for i in range(1, len(t)):
        a, b = gap[i - 1], gap[i]
        if (a >= 0.0) != (b >= 0.0):
            tc = t[i - 1] + (t[i] - t[i - 1]) * a / (a - b)
            if b < 0.0:
                start = tc
            elif start is not None:
                out.append((start, tc))
                start = None
    if gap[0] < 0.0 and not out and start is None:
        start = t[0]
    if start is not None:
        out.append((start, t[-1]))
    return out


MASS = BAR["density"] * math.pi * BAR["diameter"] ** 2 / 4.0 * BAR["length"]
# the rigid bar's pitch inertia with the section's own, as switchsim's: m (L^2/12 + r^2/4)
INERTIA = MASS * (BAR["length"] ** 2 / 12.0 + BAR["diameter"] ** 2 / 16.0)
K_HERTZ = hertz_stiffness(BAR["tip_radius"], BAR["youngs_modulus"], BAR["poisson_ratio"],
                          BLOCK["youngs_modulus"], BLOCK["poisson_ratio"])


# --- switchsim ----------------------------------------------------------------------------

def switchsim_run(scene: dict, modes: int, rtol: float) -> dict:
    """One switchsim run of a scene: its metrics (module docstring) and wall time."""
    doc = {"bar": dict(BAR, modes=modes if scene["flexible"] else 0), "block": BLOCK,
           "initial": {"height": HEIGHT, "angle_deg": scene["angle"], "velocity": [0.0, 0.0, -SPEED]},
           "contact": {"damping": 0.0}, "friction": {"mu": 0.0}, "environment": {"gravity": GRAVITY},
           "solver": {"t_end": scene["t_end"]}}
    try:
        res, wall = run_mech(mech_scene(doc), rtol=rtol, limit=EX_LIMIT)
    except Exception as err:  # noqa: BLE001
        return dict(status=f"failed: {type(err).__name__}: {err}"[:200], wall=None)
    h = res.history
    c = res.contacts
    last = h.iloc[-1]
    # planar in x-z; the rigid bar's inclination to the block (tip 0 lowest) turns at -w_y
    return dict(status="ok", wall=wall, tips=mech_tips(res), peak_force=float(c.peak_force.max()) if len(c) else 0.0,
                v_end=(float(last.vx), float(last.vz)), rate_end=None if scene["flexible"] else -float(last.wy),
                energy_residual=float(res.energy["relative_residual"]), steps=int(res.solver["steps"]),
                stiffness=float(res.solver["stiffness"]),
                trace=(h.time.to_numpy(), h.normal_force_0.to_numpy(), h.normal_force_1.to_numpy()))


# --- Exudyn -------------------------------------------------------------------------------

def exudyn_model(exu, scene: dict, elements: int):
    """The scene as an Exudyn system (planar, y up, tip 0 lowest at the lower left).
    Returns (mbs, parts) with the node, body, tip-marker and sensor indices."""
    from exudyn.itemInterface import (LoadMassProportional, MarkerBodyMass, MarkerBodyRigid, NodeGenericData,
                                      NodePoint2DSlope1, NodeRigidBody2D, ObjectANCFCable2D,
                                      ObjectContactSphereTriangle, ObjectGround, ObjectRigidBody2D, SensorMarker,
                                      SensorObject)

    L, d, R = BAR["length"], BAR["diameter"], BAR["tip_radius"]
    rho_a = BAR["density"] * math.pi * d * d / 4.0
    th = math.radians(scene["angle"])
    e = (math.cos(th), math.sin(th))
    a = L / 2.0 - R  # centroid to sphere centre along the axis
    c = (0.0, R + HEIGHT + a * math.sin(th))
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    parts = dict(sc=sc, nodes=[], bodies=[], tips=[], sensors=[], elements=elements)
    if elements == 0:
        node = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[c[0], c[1], th], initialVelocities=[0.0, -SPEED, 0.0]))
        body = mbs.AddObject(ObjectRigidBody2D(mass=MASS, inertia=INERTIA, nodeNumber=node))
        parts["nodes"], parts["bodies"] = [node], [body]
        tip_points = [(body, [-a, 0.0, 0.0]), (body, [a, 0.0, 0.0])]
    else:
        h = L / elements
        for i in range(elements + 1):
            p = (c[0] + (i * h - L / 2.0) * e[0], c[1] + (i * h - L / 2.0) * e[1])
            parts["nodes"].append(mbs.AddNode(NodePoint2DSlope1(referenceCoordinates=[p[0], p[1], e[0], e[1]],
                                                               initialVelocities=[0.0, -SPEED, 0.0, 0.0])))
        ei = BAR["youngs_modulus"] * math.pi * d**4 / 64.0
        ea = BAR["youngs_modulus"] * math.pi * d * d / 4.0
        for i in range(elements):
            parts["bodies"].append(mbs.AddObject(ObjectANCFCable2D(
                nodeNumbers=[parts["nodes"][i], parts["nodes"][i + 1]], length=h, massPerLength=rho_a,
                bendingStiffness=ei, axialStiffness=ea)))

        def at(s):  # element and local coordinate of arc length s from tip 0's end
            i = min(int(s / h), elements - 1)
            return parts["bodies"][i], [s - i * h, 0.0, 0.0]

        tip_points = [at(R), at(L - R)]
    for b in parts["bodies"]:
        mbs.AddLoad(LoadMassProportional(markerNumber=mbs.AddMarker(MarkerBodyMass(bodyNumber=b)),
                                         loadVector=[0.0, -GRAVITY, 0.0]))
    ground = mbs.AddObject(ObjectGround())
    plane = mbs.AddMarker(MarkerBodyRigid(bodyNumber=ground, localPosition=[0.0, 0.0, 0.0]))
    # the block's surface: one triangle in y = 0, metres wide around the contact, edges off
    triangle = exu.Vector3DList([[-5.0, 0.0, -5.0], [5.0, 0.0, -5.0], [0.0, 0.0, 5.0]])
    for body, local in tip_points:
        tip = mbs.AddMarker(MarkerBodyRigid(bodyNumber=body, localPosition=local))
        data = mbs.AddNode(NodeGenericData(initialCoordinates=[0.1, 0.0, 0.0, 0.0], numberOfDataCoordinates=4))
        contact = mbs.AddObject(ObjectContactSphereTriangle(
            markerNumbers=[tip, plane], nodeNumber=data, sphereRadius=R, trianglePoints=triangle, includeEdges=0,
            contactStiffness=K_HERTZ, contactStiffnessExponent=1.5, contactDamping=0.0, dynamicFriction=0.0))
        parts["tips"].append(tip)
        parts["sensors"].append((
            mbs.AddSensor(SensorMarker(markerNumber=tip, storeInternal=True, writeToFile=False,
                                       outputVariableType=exu.OutputVariableType.Position)),
            mbs.AddSensor(SensorObject(objectNumber=contact, storeInternal=True, writeToFile=False,
                                       outputVariableType=exu.OutputVariableType.Force))))
    mbs.Assemble()
    return mbs, parts


def exudyn_state(exu, mbs, parts) -> dict:
    """Energy (J: kinetic, elastic, gravity from y = 0, Hertz), centre-of-mass height (m) and
    velocity (m/s), inclination rate (rad/s, rigid) of the current state."""
    ov = exu.OutputVariableType
    tips_y = [mbs.GetMarkerOutput(m, ov.Position)[1] for m in parts["tips"]]
    contact = sum(hertz_energy(K_HERTZ, BAR["tip_radius"] - y) for y in tips_y)
    if parts["elements"] == 0:
        node = parts["nodes"][0]
        v = mbs.GetNodeOutput(node, ov.Velocity)
        w = mbs.GetNodeOutput(node, ov.AngularVelocity)[2]
        y = mbs.GetNodeOutput(node, ov.Position)[1]
        kinetic = 0.5 * MASS * (v[0] ** 2 + v[1] ** 2) + 0.5 * INERTIA * w * w
        return dict(energy=kinetic + MASS * GRAVITY * y + contact, y=y, v=(v[0], v[1]), rate=w)
    h = BAR["length"] / parts["elements"]
    rho_a = MASS / BAR["length"]
    kinetic = sum(mbs.GetObjectOutputBody(b, ov.KineticEnergy, localPosition=[0, 0, 0]) for b in parts["bodies"])
    elastic = sum(mbs.GetObjectOutputBody(b, ov.PotentialEnergy, localPosition=[0, 0, 0]) for b in parts["bodies"])
    pos, vel = [], []
    for n in parts["nodes"]:
        ref = mbs.GetNodeParameter(n, "referenceCoordinates")
        q = mbs.GetNodeOutput(n, ov.Coordinates)
        pos.append([r + x for r, x in zip(ref, q)])
        vel.append(list(mbs.GetNodeOutput(n, ov.Coordinates_t)))
    first = [0.0, 0.0]
    mom = [0.0, 0.0]
    for i in range(parts["elements"]):
        fa = hermite_moment(pos[i][:2], pos[i][2:], pos[i + 1][:2], pos[i + 1][2:], h)
        va = hermite_moment(vel[i][:2], vel[i][2:], vel[i + 1][:2], vel[i + 1][2:], h)
        first = [f + rho_a * x for f, x in zip(first, fa)]
        mom = [f + rho_a * x for f, x in zip(mom, va)]
    y = first[1] / MASS
    return dict(energy=kinetic + elastic + MASS * GRAVITY * y + contact, y=y, v=(mom[0] / MASS, mom[1] / MASS),
                rate=None)


def exudyn_run(exu, scene: dict, elements: int, route: str, setting: float, max_step: float = EX_MAX_STEP) -> dict:
    """One Exudyn run: route "generalized-alpha" or "RK44" with the fixed step `setting` (s),
    or "DOPRI5" with rtol = atol = `setting` and steps up to `max_step` (s). Metrics as
    switchsim_run's, plus a status: ok, failed (the solver's message), timeout, or unsound
    (energy drift)."""
    import numpy as np

    mbs, parts = exudyn_model(exu, scene, elements)
    t_end = scene["t_end"]
    ss = exu.SimulationSettings()
    ti = ss.timeIntegration
    ti.endTime = t_end
    ti.verboseMode = 0
    # Exudyn's default (True) takes each contact's recommended step, which ends the run at
    # the first contact with exponent 1.5 (re-checked below, "Known behaviour")
    ti.discontinuous.useRecommendedStepSize = False
    if route == "DOPRI5":
        ti.numberOfSteps = max(1, round(t_end / max_step))
        ti.automaticStepSize = True
        ti.relativeTolerance = ti.absoluteTolerance = setting
    else:
        ti.numberOfSteps = max(1, round(t_end / setting))
    if route == "generalized-alpha":
        # the default 1e-10 N is below round-off of the axial element forces from 32 elements
        # on (Newton stops there and the run fails); 1e-4 N against contact forces of kN
        ti.newton.absoluteTolerance = 1e-4
    ss.solution.file.write = False
    ss.solution.sensors.writePeriod = 1e-12  # every step
    solver_type = {"generalized-alpha": exu.DynamicSolverType.GeneralizedAlpha, "RK44": exu.DynamicSolverType.RK44,
                   "DOPRI5": exu.DynamicSolverType.DOPRI5}[route]
    start = exudyn_state(exu, mbs, parts)
    exu.special.solver.timeout = EX_LIMIT
    tick = time.perf_counter()
    try:
        ok = mbs.SolveDynamic(ss, solverType=solver_type)
        message = ""
    except Exception as err:  # noqa: BLE001
        ok, message = False, f"{err}"
    wall = time.perf_counter() - tick
    solver = mbs.sys.get("dynamicSolver")
    if solver is not None and not ok:
        message = (solver.GetErrorString() or message).strip()
    if solver is not None and solver.output.simulationTimeout:
        return dict(status=f"timeout ({EX_LIMIT:g} s CPU)", wall=wall, ok=ok)
    if not ok:
        return dict(status=f"failed: {message}"[:200], wall=wall, ok=ok)
    tips, peak, trace = {}, 0.0, [None, None, None]
    for i, (s_pos, s_force) in enumerate(parts["sensors"]):
        p = mbs.GetSensorStoredData(s_pos)
        f = mbs.GetSensorStoredData(s_force)
        tips[i] = gap_intervals(p[:, 0], p[:, 2] - BAR["tip_radius"])
        fn = np.linalg.norm(f[:, 1:], axis=1)
        peak = max(peak, float(np.max(fn)) if np.all(np.isfinite(fn)) else math.inf)
        trace[0], trace[1 + i] = f[:, 0], fn
    end = exudyn_state(exu, mbs, parts)
    scale = 0.5 * MASS * SPEED**2 + MASS * GRAVITY * (start["y"] - BAR["tip_radius"])
    residual = abs(end["energy"] - start["energy"]) / scale
    out = dict(status="ok", ok=ok, wall=wall, tips=tips, peak_force=peak, v_end=end["v"], rate_end=end["rate"],
               energy_residual=residual, steps=int(solver.it.currentStepIndex) if solver is not None else None,
               rejected=int(solver.it.rejectedAutomaticStepSizeSteps) if solver is not None else None,
               trace=tuple(trace))
    if not (math.isfinite(residual) and residual <= ENERGY_SANITY):
        out["status"] = f"unsound: SolveDynamic returned {ok}, energy drift {residual:.3g}"
    return out


def _exudyn_child(scene: dict, elements: int, route: str, setting: float, max_step: float) -> dict:
    import exudyn as exu

    return exudyn_run(exu, scene, elements, route, setting, max_step)


def exudyn_run_limited(exu, scene: dict, elements: int, route: str, setting: float,
                       max_step: float = EX_MAX_STEP) -> dict:
    """exudyn_run in a forked child stopped after EX_LIMIT s of wall time: Exudyn's own
    CPU-time limit (exudyn.special.solver.timeout) does not stop its DOPRI5 (measured: a
    32-element run at rtol 1e-8 still running after 20 min), and a hang must be recorded
    as one, not stop the report. The wall time reported is still the solver's own."""
    import multiprocessing

    del exu  # the child imports it (fork: already loaded)
    with multiprocessing.get_context("fork").Pool(1) as pool:
        pending = pool.apply_async(_exudyn_child, (scene, elements, route, setting, max_step))
        try:
            return pending.get(timeout=EX_LIMIT)
        except multiprocessing.TimeoutError:
            pool.terminate()
            return dict(status=f"timeout ({EX_LIMIT:g} s wall)", wall=EX_LIMIT, ok=False)


# --- comparison -----------------------------------------------------------------------------

def metrics(run: dict) -> dict:
    m = contact_metrics(run["tips"])
    m["peak_force"] = run["peak_force"]
    return m


def errors(run: dict, ref: dict) -> dict:
    """Errors of a run against a reference run: mismatch (s, both tips), count differences,
    relative peak force, end-velocity and inclination-rate differences, and `agrees`: within
    the `run --check` tolerances (coupling.app.accuracy.TOLERANCES) and VELOCITY_TOL, RATE_TOL."""
    if run.get("status") != "ok" or ref.get("status") != "ok":
        return dict(agrees=False)
    m, r = metrics(run), metrics(ref)
    verdict = compare(r, m, ref["tips"], run["tips"])
    dv = max(abs(a - b) for a, b in zip(run["v_end"], ref["v_end"]))
    drate = abs(run["rate_end"] - ref["rate_end"]) if run.get("rate_end") is not None and ref.get("rate_end") is not None else 0.0
    mism = sum(mismatch_time(run["tips"][i], ref["tips"][i]) for i in (0, 1))
    return dict(mismatch=mism, mismatch_fraction=mism / r["contact_time"] if r["contact_time"] else 0.0,
                contacts=m["contacts"] - r["contacts"], peak_force=abs(m["peak_force"] - r["peak_force"]) / r["peak_force"],
                dv=dv, drate=drate, moved=verdict["moved"] + (["v_end"] if dv > VELOCITY_TOL else [])
                + (["rate_end"] if drate > RATE_TOL else []),
                agrees=not verdict["moved"] and dv <= VELOCITY_TOL and drate <= RATE_TOL)


def coarsest_converged(runs: list[dict], ref: dict):
    """Index of the coarsest run of a ladder from which every finer run agrees with the
    reference, or None; the ladder's finest run is not evidence of itself, so the index is
    below the last entry, or the ladder has one entry that is not the reference."""
    for i in range(len(runs)):
        if all(errors(r, ref)["agrees"] for r in runs[i:]) and (i < len(runs) - 1 or runs[i] is not ref):
            return i
    return None


def label(code: str, disc, step) -> str:
    if code == "switchsim":
        return (f"{disc} modes, " if disc else "rigid, ") + f"rtol {step:g}"
    route, value = step
    what = f"rtol {value:g}" if route == "DOPRI5" else f"h {value * 1e6:g} us"
    return (f"{disc} el., " if disc else "rigid, ") + f"{route} {what}"


def study(exu, name: str, scene: dict, log) -> dict:
    """Both codes' ladders, references, converged settings and timed matched runs for a scene."""
    flex = scene["flexible"]
    out = dict(name=name, scene=scene, runs={"switchsim": [], "Exudyn": []})

    def keep(code, disc, step, run, ladder):
        run.update(code=code, disc=disc, step=step, ladder=ladder, label=label(code, disc, step))
        out["runs"][code].append(run)
        log(f"{name}: {code} {run['label']}: {run['status']}, {fmt(run.get('wall'))} s")
        return run

    # switchsim: modes at the reference rtol, then rtol at the converged mode count
    ss_rtol = SS_REF_RTOL if flex else SS_RTOLS[-1]
    modes = SS_MODES if flex else (0,)
    disc = [keep("switchsim", n, ss_rtol, switchsim_run(scene, n, ss_rtol), "modes") for n in modes]
    ss_ref = disc[-1]
    i = coarsest_converged(disc, ss_ref) if flex else len(disc) - 1
    ss_modes = modes[-1 if i is None else i]
    rungs = [ss_ref if (ss_modes == modes[-1] and r == ss_rtol) else
             keep("switchsim", ss_modes, r, switchsim_run(scene, ss_modes, r), "rtol") for r in SS_RTOLS]
    j = coarsest_converged(rungs, ss_ref)
    ss_match = (ss_modes, rungs[j]["step"] if j is not None else ss_rtol)

    # Exudyn: elements with generalized-alpha at the reference step, then each route's ladder
    ref_step = EX_REF_STEP[flex]
    elements = EX_ELEMENTS if flex else (0,)
    disc = [keep("Exudyn", n, ("generalized-alpha", ref_step), exudyn_run_limited(exu, scene, n, "generalized-alpha", ref_step),
                 "elements") for n in elements]
    ex_ref = disc[-1]
    i = coarsest_converged(disc, ex_ref) if flex else len(disc) - 1
    ex_elements = elements[-1 if i is None else i]
    candidates = []
    for route, ladder in EX_ROUTES.items():
        if route == "generalized-alpha":
            ladder = [h for h in ladder if h >= ref_step]
        rungs = [ex_ref if (route == "generalized-alpha" and h == ref_step and ex_elements == elements[-1]) else
                 keep("Exudyn", ex_elements, (route, h), exudyn_run_limited(exu, scene, ex_elements, route, h), route)
                 for h in ladder]
        j = coarsest_converged(rungs, ex_ref)
        if j is not None:
            candidates.append(rungs[j])
    ex_best = min(candidates, key=lambda r: r["wall"]) if candidates else None
    out.update(ss_ref=ss_ref, ex_ref=ex_ref, ss_converged_modes=ss_modes if flex else None,
               ex_converged_elements=ex_elements if flex else None,
               ss_shown_converged=j is not None, ex_shown_converged=ex_best is not None)

    # the matched runs, timed alternately
    ss_walls, ex_walls, ss_m, ex_m = [], [], None, None
    while len(ss_walls) < MAX_REPEATS and (len(ss_walls) < REPEATS or sum(ss_walls) < TIMED
                                           or (ex_best is not None and sum(ex_walls) < TIMED)):
        ss_m = switchsim_run(scene, *ss_match)
        ss_walls.append(ss_m.get("wall") or math.nan)
        if ex_best is not None:
            ex_m = exudyn_run_limited(exu, scene, ex_elements, *ex_best["step"])
            ex_walls.append(ex_m.get("wall") or math.nan)
    ss_m.update(code="switchsim", disc=ss_match[0], step=ss_match[1], label=label("switchsim", *ss_match),
                wall=statistics.median(ss_walls), walls=ss_walls)
    if ex_m is not None:
        ex_m.update(code="Exudyn", disc=ex_elements, step=ex_best["step"],
                    label=label("Exudyn", ex_elements, ex_best["step"]), wall=statistics.median(ex_walls), walls=ex_walls)
    out.update(ss_match=ss_m, ex_match=ex_m, load=load_note())
    log(f"{name}: matched switchsim {ss_m['label']} {fmt(ss_m['wall'])} s; Exudyn "
        f"{ex_m['label'] if ex_m else '-'} {fmt(ex_m['wall']) if ex_m else '-'} s")
    return out


# --- known behaviour, re-checked --------------------------------------------------------------

def known_behaviour(exu, results, log) -> list[str]:
    """Re-measure the facts noted on this machine before: the recommended step size with
    exponent 1.5, a diverged explicit run reported as a success, and two wall times."""
    lines = []
    from exudyn.itemInterface import ObjectContactSphereTriangle  # noqa: F401  (the object checked)

    scene = SCENES["rigid, 30 deg"]
    for route, value in (("RK44", 1e-7), ("DOPRI5", 1e-6), ("generalized-alpha", 1e-7)):
        mbs, parts = exudyn_model(exu, scene, 0)
        ss = exu.SimulationSettings()
        ti = ss.timeIntegration
        ti.endTime = scene["t_end"]
        ti.verboseMode = 0
        ss.solution.file.write = False
        if route == "DOPRI5":
            ti.numberOfSteps = round(scene["t_end"] / 1e-6)
            ti.automaticStepSize = True
            ti.relativeTolerance = ti.absoluteTolerance = value
        else:
            ti.numberOfSteps = round(scene["t_end"] / value)
        exu.special.solver.timeout = EX_LIMIT
        try:
            ok = mbs.SolveDynamic(ss, solverType=getattr(exu.DynamicSolverType, route.replace("generalized-alpha",
                                                                                              "GeneralizedAlpha")))
            what = f"returned {ok}"
        except Exception as err:  # noqa: BLE001
            what = f"raised {type(err).__name__}: {err}"
        solver = mbs.sys.get("dynamicSolver")
        t_stop = solver.it.currentTime if solver is not None else math.nan
        reason = (solver.GetErrorString().strip() if solver is not None else "") or "-"
        lines.append(f"- `useRecommendedStepSize = True` (Exudyn's default), rigid 30 deg, {route}: {what} at "
                     f"t = {t_stop * 1e6:.3g} us (first contact at {HEIGHT / SPEED * 1e6:.3g} us); solver message: "
                     f"\"{reason}\".")
        log(lines[-1])
    run = exudyn_run(exu, SCENES["flexible, 30 deg"], 32, "RK44", 5e-7)
    lines.append(f"- A diverged explicit run: flexible 30 deg, 32 elements, RK44 at h = 0.5 us: status {run['status']} "
                 f"(SolveDynamic returned {run.get('ok')}; peak \"contact force\" {fmt(run.get('peak_force'))} N). "
                 "Every Exudyn run here is therefore checked by its energy balance (kinetic + elastic + gravity + "
                 f"Hertz, from Exudyn's own body outputs) and not used above a drift of {ENERGY_SANITY:g}.")
    log(lines[-1])
    for res in results:
        walls = [(r["wall"], r["label"]) for r in res["runs"]["Exudyn"] if r["disc"] == 8 and r.get("wall")]
        if walls:
            lo, hi = min(walls), max(walls)
            lines.append(f"- Exudyn with 8 elements, {res['name']} ({res['scene']['t_end'] * 1e3:g} ms): "
                         f"{fmt(lo[0])} s ({lo[1]}) to {fmt(hi[0])} s ({hi[1]}) in this run.")
    long = dict(SCENES["rigid, 30 deg"], t_end=0.05)
    ss = switchsim_run(long, 0, 1e-6)
    for max_step in (1e-6, 5e-5):
        ex = exudyn_run_limited(exu, long, 0, "DOPRI5", 1e-6, max_step=max_step)
        e = errors(ex, ss)
        lines.append(f"- Wall time, rigid 30 deg drop over 50 ms at rtol 1e-6 (one run each, {load_note()}): Exudyn "
                     f"DOPRI5 with steps up to {max_step * 1e6:g} us {fmt(ex.get('wall'))} s ({ex['status']}, "
                     f"{ex.get('steps')} steps; against switchsim: {'within' if e.get('agrees') else 'outside'} the "
                     f"tolerances, moved: {', '.join(e.get('moved', [])) or 'none'}), switchsim "
                     f"{fmt(ss.get('wall'))} s ({ss['status']}, {ss.get('steps')} steps).")
        log(lines[-1])
    return lines


# --- the fragment -----------------------------------------------------------------------------

def not_installed(sec: Section, err: Exception) -> None:
    sec.add(f"Exudyn is not importable here ({type(err).__name__}: {err}), so this part was not run. It is an "
            "optional benchmark extra, never a dependency of switchsim: install it into the project's virtualenv "
            "with `.venv/bin/python -m pip install -e '.[bench]'` (`make accuracy` does this first) and run "
            "`.venv/bin/python benchmarks/accuracy_exudyn.py`.", "")


def usec(x) -> str:
    """s as us with 0.1 us resolution (intervals are compared at that level)."""
    return "-" if x is None else f"{x * 1e6:.1f}"


def interval_table(sec: Section, res: dict) -> None:
    ss, ex = res["ss_ref"], res["ex_ref"]
    rows = []
    for tip in (0, 1):
        a, b = ss["tips"][tip], ex["tips"][tip] if ex["status"] == "ok" else []
        for k in range(max(len(a), len(b))):
            sa = a[k] if k < len(a) else (None, None)
            sb = b[k] if k < len(b) else (None, None)
            diff = [usec(x - y) if x is not None and y is not None else "-" for x, y in zip(sb, sa)]
            rows.append([tip, k + 1, usec(sa[0]), usec(sa[1]), usec(sb[0]), usec(sb[1]), diff[0], diff[1]])
    if rows:
        sec.table(["tip", "contact", "switchsim start (us)", "switchsim end (us)", "Exudyn start (us)",
                   "Exudyn end (us)", "start diff (us)", "end diff (us)"], rows)


def summary_rows(results: list[dict]) -> list[list]:
    rows = []
    for res in results:
        ss, ex = res["ss_ref"], res["ex_ref"]
        cross = errors(ex, ss) if ex["status"] == "ok" else {}
        for code, r in (("switchsim", ss), ("Exudyn", ex)):
            ok = r["status"] == "ok"
            m = metrics(r) if ok else {}
            rows.append([res["name"], code, r["label"], m.get("contacts", "-"), fmt(r.get("peak_force"), 5),
                         fmt(r["v_end"][1], 6) if ok else "-", fmt(r["v_end"][0], 3) if ok else "-",
                         fmt(r.get("rate_end"), 5), fmt(r.get("energy_residual"), 2),
                         usec(cross.get("mismatch")) if code == "Exudyn" else "",
                         fmt(cross.get("peak_force"), 2) if code == "Exudyn" else "",
                         fmt(cross.get("dv"), 2) if code == "Exudyn" else ""])
    return rows


def figure(sec: Section, results: list[dict]) -> None:
    from matplotlib.ticker import NullFormatter

    p = plt()
    fig, axes = p.subplots(2, 2, figsize=(13, 8.5))
    for ax, name in zip(axes[0], ("flexible, 30 deg", "flexible, vertical")):
        res = next(r for r in results if r["name"] == name)
        for code, run, style in (("switchsim", res["ss_ref"], "-"), ("Exudyn", res["ex_ref"], "--")):
            if run.get("status") != "ok":
                continue
            t, f0, f1 = run["trace"]
            ax.plot(t * 1e3, f0, style, lw=1.2, label=f"{code}, tip 0 ({run['label']})")
            if f1 is not None and max(f1) > 0:
                ax.plot(t * 1e3, f1, style, lw=1.0, label=f"{code}, tip 1")
        ax.set_xlabel("time (ms)")
        ax.set_ylabel("normal force (N)")
        ax.set_title(f"{name}: references")
        ax.legend(fontsize=7)
        ax.grid(True, alpha=0.3)
    markers = {"modes": "o", "rtol": "s", "elements": "^", "generalized-alpha": "v", "RK44": "D", "DOPRI5": "P"}
    for ax, name in zip(axes[1], ("flexible, 30 deg", "flexible, vertical")):
        res = next(r for r in results if r["name"] == name)
        for code in ("switchsim", "Exudyn"):
            ref = res["ss_ref"] if code == "switchsim" else res["ex_ref"]
            for ladder, mk in markers.items():
                pts = [(r["wall"], max(errors(r, ref).get("mismatch_fraction", math.nan), 1e-6))
                       for r in res["runs"][code] if r["ladder"] == ladder and r["status"] == "ok" and r is not ref]
                if pts:
                    ax.loglog(*zip(*pts), mk, color="C0" if code == "switchsim" else "C3", alpha=0.8,
                              label=f"{code}: {ladder}")
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("wall time of the run (s)")
        ax.set_ylabel("contact-state mismatch / contact time")
        ax.set_title(f"{name}: error against own reference (1e-6: none)")
        ax.axhline(TOLERANCES["mismatch_fraction"], color="k", lw=0.8, ls=":")
        ax.legend(fontsize=7)
        ax.grid(True, which="both", alpha=0.3)
    sec.figure(fig, "exudyn_comparison",
               "switchsim and Exudyn: normal forces of the converged references (top) and each code's error against its "
               "own reference over wall time (bottom; blue switchsim, red Exudyn; dotted: the 2 % tolerance; the rigid scenes "
               "are in the table)")


def main() -> None:
    sec = Section("exudyn", "6. Side by side with Exudyn (an independent flexible-multibody code)",
                  ".venv/bin/python benchmarks/accuracy_exudyn.py")
    try:
        import exudyn as exu
    except Exception as err:  # noqa: BLE001
        not_installed(sec, err)
        sec.write()
        return

    def log(msg):
        print(msg, file=sys.stderr, flush=True)

    warm = switchsim_run(SCENES["flexible, 30 deg"], 3, 1e-5)  # loads the compiled kernel before any timing
    k_ss = warm.get("stiffness")
    results = [study(exu, name, scene, log) for name, scene in SCENES.items()]
    facts = known_behaviour(exu, results, log)
    describe(sec, exu, k_ss, results, facts)
    figure(sec, results)
    dump("exudyn", [{k: v for k, v in r.items() if k not in ("runs", "ss_ref", "ex_ref", "ss_match", "ex_match")}
                    | {"switchsim_reference": strip(r["ss_ref"]), "exudyn_reference": strip(r["ex_ref"]),
                       "switchsim_matched": strip(r["ss_match"]), "exudyn_matched": strip(r["ex_match"]),
                       "runs": [strip(x) for c in r["runs"].values() for x in c]} for r in results])
    sec.write()


def strip(run):
    return None if run is None else {k: v for k, v in run.items() if k != "trace"}


def describe(sec: Section, exu, k_ss, results, facts) -> None:
    sec.add(
        f"Exudyn {exu.__version__} (installed by the `bench` extra) against switchsim on four scenes: a steel bar "
        f"{BAR['length']} m long, {BAR['diameter'] * 1e3:g} mm round, {BAR['tip_radius'] * 1e3:g} mm spherical tips "
        f"(E = {BAR['youngs_modulus'] / 1e9:g} GPa, nu = {BAR['poisson_ratio']}, {BAR['density']:g} kg/m^3, "
        f"m = {MASS * 1e3:.4g} g), released {HEIGHT * 1e6:g} um above a steel block, falling at {SPEED:g} m/s under "
        f"g = {GRAVITY} m/s^2, upright (vertical) or at 30 deg, rigid (switchsim `modes = 0`) or flexible; elastic "
        "contact (no damping), no friction.", "",
        "**What is matched.** The same geometry, mass, gravity and initial state; the same Hertz law "
        f"F = k y^1.5 with k = (4/3) E* sqrt(R) = {K_HERTZ:.6g} N/m^1.5 computed here from E, nu and R "
        f"(switchsim's own: {fmt(k_ss, 6)}); the sphere centre of each tip on the bar's axis "
        f"{BAR['tip_radius'] * 1e3:g} mm from its end, the contact against a plane. The rigid bar's inertia is "
        "m (L^2/12 + r^2/4) in both. Both are planar here (switchsim chooses its planar model itself).", "",
        "**What differs.**",
        "- *Bending and elasticity.* switchsim: the floating-frame bar with linear Euler-Bernoulli free-free modes, "
        "truncated to n per family (axial and bending). Exudyn: ANCF cable elements (`ObjectANCFCable2D`, cubic "
        "Hermite positions and slopes), geometrically nonlinear Euler-Bernoulli with axial strain, refined in the "
        "element count; no rotary inertia of the section anywhere in the cable, so its pitch inertia is m L^2/12, "
        f"{3 * (BAR['diameter'] / 2) ** 2 / BAR['length'] ** 2 * 100:.2g} % below switchsim's flexible bar's.",
        "- *Contact state.* switchsim stops its integrator at each contact start and end (events). Exudyn's "
        "`ObjectContactSphereTriangle` decides whether the contact is closed from the gap stored after the last "
        "step (its data node); the implicit solver iterates a step until that state is consistent (discontinuous "
        "iteration), the explicit ones take it one step late. The contact intervals below are read from each "
        "code's tip gap (Exudyn: the sampled sphere-centre height minus R, zero crossings interpolated).",
        "- *Plane.* Exudyn has no sphere-plane contact: the block is one triangle 10 m wide in y = 0 (edge contact "
        "off), whose distance from the sphere centre is exactly the plane's.",
        "- *Not compared.* Damping (Exudyn's Hunt-Crossley form takes v0 from each contact's own impact speed, "
        "switchsim's from the scene's reference speed) and friction (Exudyn regularizes Coulomb friction below a "
        "speed; switchsim switches stick/slip exactly), so both are off here.", "",
        "**Matched accuracy.** Each code is refined on its own: switchsim in modes per family "
        f"({', '.join(map(str, SS_MODES))}, at rtol {SS_REF_RTOL:g}) and then in rtol ({', '.join(f'{r:g}' for r in SS_RTOLS)}) "
        f"at the converged mode count, against {SS_MODES[-1]} modes at rtol {SS_REF_RTOL:g} (rigid: rtol {SS_RTOLS[-1]:g}); "
        f"Exudyn in elements ({', '.join(map(str, EX_ELEMENTS))}, generalized-alpha at h = {EX_REF_STEP[True] * 1e6:g} us) "
        "and then, at the converged element count, in the step of generalized-alpha (Exudyn's default solver, "
        f"spectral radius 0.9) and RK44 and in the tolerance of DOPRI5 (rtol = atol, steps up to {EX_MAX_STEP * 1e6:g} us), "
        f"against {EX_ELEMENTS[-1]} elements at "
        f"h = {EX_REF_STEP[True] * 1e6:g} us (rigid: h = {EX_REF_STEP[False] * 1e6:g} us). A setting is converged when it "
        "and every finer one agree with the code's reference within the tolerances of `switchsim run --check` "
        "(contact-state mismatch <= 2 % of the contact time, equal contact and bounce counts, makes within "
        f"max(1 us, 1 % of the contact span), peak force within 2 %) and the end velocity within {VELOCITY_TOL * 1e3:g} mm/s "
        f"(rigid: inclination rate within {RATE_TOL:g} rad/s). The matched run is the coarsest converged setting "
        "(for Exudyn the cheapest of its integrators), timed alternately with the other code's, at least "
        f"{REPEATS} times and until each code has run {TIMED:g} s (at most {MAX_REPEATS} times; median). Wall time is "
        "the integration alone "
        "(switchsim `ImpactSolver.run`, its compiled kernel loaded before; Exudyn `SolveDynamic` after `Assemble`), "
        f"both recording every step; Exudyn runs stop after {EX_LIMIT:g} s (of CPU time, or of wall time where its CPU limit does not act).", "")

    sec.add("### The converged references side by side", "",
            "End velocity: the centre of mass at the end of the scene (vertical and horizontal, m/s); inclination "
            "rate: d(angle to the block)/dt of the rigid bar at the end (rad/s). Energy residual: switchsim's own "
            "audit; Exudyn's from its body outputs (kinetic + elastic) plus gravity and the Hertz energy, both "
            "relative to the initial kinetic energy plus m g (centre height - R). Last three columns: Exudyn's "
            "reference against switchsim's.", "")
    sec.table(["scene", "code", "setting", "contacts", "peak force (N)", "end v_vertical (m/s)",
               "end v_horizontal (m/s)", "inclination rate (rad/s)", "energy residual", "mismatch vs switchsim (us)",
               "peak force rel. diff", "end velocity diff (m/s)"], summary_rows(results))
    for res in results:
        sec.add(f"**{res['name']}** ({res['scene']['t_end'] * 1e3:g} ms): contact intervals of the references", "")
        interval_table(sec, res)

    sec.add("### Matched accuracy: the settings each code needs, and their wall time", "")
    rows = []
    for res in results:
        for code, m, ref in (("switchsim", res["ss_match"], res["ss_ref"]), ("Exudyn", res["ex_match"], res["ex_ref"])):
            if m is None:
                rows.append([res["name"], code, "none converged", "-", "-", "-", "-", "-", "-"])
                continue
            e = errors(m, ref)
            other = errors(m, res["ex_ref"] if code == "switchsim" else res["ss_ref"])
            cost = sum(r["wall"] or 0.0 for r in res["runs"][code])
            rows.append([res["name"], code, m["label"], fmt(m["wall"], 3), ", ".join(fmt(w, 3) for w in m["walls"]),
                         usec(e.get("mismatch")), "yes" if e.get("agrees") else "no: " + ", ".join(e.get("moved", [])),
                         usec(other.get("mismatch")), fmt(cost, 3)])
        ratio = (res["ex_match"]["wall"] / res["ss_match"]["wall"]) if res["ex_match"] and res["ss_match"]["wall"] else None
        res["ratio"] = ratio
    sec.table(["scene", "code", "matched setting", "wall (s, median)", "walls (s)", "mismatch vs own ref (us)",
               "within tolerance of own ref", "mismatch vs other code's ref (us)", "whole refinement study (s)"], rows)
    sec.add("Exudyn / switchsim wall time at matched accuracy: "
            + "; ".join(f"{r['name']} {fmt(r['ratio'], 3)}x" for r in results) + f" ({load_note()} after the runs).", "")

    sec.add("### Error against wall time, every run", "",
            "Errors against the code's own reference and, last column, the contact-state mismatch against the other "
            "code's reference. `ladder`: what the run refines.", "")
    rows = []
    for res in results:
        for code in ("switchsim", "Exudyn"):
            ref = res["ss_ref"] if code == "switchsim" else res["ex_ref"]
            other = res["ex_ref"] if code == "switchsim" else res["ss_ref"]
            for r in res["runs"][code]:
                e = errors(r, ref) if r is not ref else dict(mismatch=0.0, peak_force=0.0, dv=0.0, contacts=0, agrees=True)
                o = errors(r, other) if other.get("status") == "ok" else {}
                rows.append([res["name"], code, r["ladder"], r["label"] + (" (reference)" if r is ref else ""),
                             fmt(r.get("wall"), 3), r["status"] if r["status"] != "ok" else
                             ("ok" + (f", {r['steps']} steps" if r.get("steps") else "")),
                             e.get("contacts", "-"), usec(e.get("mismatch")), fmt(e.get("peak_force"), 2),
                             fmt(e.get("dv"), 2), fmt(r.get("energy_residual"), 2),
                             "yes" if e.get("agrees") else "no", usec(o.get("mismatch"))])
    sec.table(["scene", "code", "ladder", "setting", "wall (s)", "status", "contacts diff", "mismatch (us)",
               "peak force rel. err", "end velocity err (m/s)", "energy residual", "converged", "mismatch vs other (us)"],
              rows)
    sec.add("### Known behaviour, re-checked", "", *facts, "")
    sec.add("### Reading", "", *reading(results), "")


def reading(results) -> list[str]:
    """What the numbers say, each statement computed from them."""
    out = []
    for res in results:
        ss, ex = res["ss_ref"], res["ex_ref"]
        if ex.get("status") != "ok" or ss.get("status") != "ok":
            out.append(f"- {res['name']}: no comparison (switchsim {ss['status']}, Exudyn {ex['status']}).")
            continue
        e = errors(ex, ss)
        ct = metrics(ss)["contact_time"]
        agree = "agree within the tolerances of `run --check`" if e["agrees"] else \
            "differ beyond the tolerances of `run --check` in " + ", ".join(e["moved"])
        out.append(f"- {res['name']}: the two references {agree}: {metrics(ss)['contacts']} vs {metrics(ex)['contacts']} "
                   f"contacts, contact-state mismatch {usec(e['mismatch'])} us ({fmt(100 * e['mismatch'] / ct, 2)} % of "
                   f"{usec(ct)} us of contact), peak force {fmt(100 * e['peak_force'], 2)} % apart, end velocity "
                   f"{fmt(e['dv'] * 1e3, 2)} mm/s apart"
                   + (f", inclination rate {fmt(e['drate'], 2)} rad/s apart" if ss.get("rate_end") is not None and
                      ex.get("rate_end") is not None else "")
                   + (f"; matched wall time Exudyn / switchsim {fmt(res['ratio'], 3)}x" if res.get("ratio") else "") + ".")
    flex = [r for r in results if r["scene"]["flexible"]]
    for res in flex:
        out.append(f"- {res['name']}: switchsim converged at {res['ss_converged_modes']} modes per family "
                   f"({res['ss_converged_modes'] * 2} elastic coordinates, planar), Exudyn at "
                   f"{res['ex_converged_elements']} ANCF elements ({4 * (res['ex_converged_elements'] + 1) - 3} elastic "
                   "coordinates): modes are the free bar's exact shapes, so few carry the contact's low-frequency "
                   "content, while cubic elements need several per wavelength of the highest mode that matters.")
    out.append("- Where they differ: the ANCF cable is geometrically nonlinear and has no section rotary inertia; "
               "switchsim is linear in the floating frame with truncated modes; Exudyn's explicit routes switch the "
               "contact force on one step late (its contact state is stored per step), which the step ladder "
               "has to refine away, and RK44 is bounded by the stability of the stiffest element (a run past it "
               "diverges but reports success, see above).")
    return out


if __name__ == "__main__":
    main()
