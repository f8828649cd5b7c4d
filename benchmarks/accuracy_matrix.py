"""The stiff and extreme matrix: each case in its own process with a timeout
(benchmarks/accuracy_case.py), recorded as completed, flagged, rejected with a clear
error, failed, crashed or timed out, with its energy residual, run time and the physics
checks that failed silently (status ok, no flag, physically wrong).

    .venv/bin/python benchmarks/accuracy_matrix.py [--jobs 2]   (part 5 of `make accuracy`)
    .venv/bin/python benchmarks/accuracy_matrix.py --only changeover   (those groups; no document)

Device cases (``device``) run through this script's own ``--case`` (accuracy_case's checks,
then ``device_checks`` on the same run).
"""

from __future__ import annotations

import argparse
import copy
import json
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from accuracy_common import ROOT, Section, dump, fmt

TIMEOUT = 90.0  # s per case (a case still running then is recorded as a hang)

BASE = {  # mechanics: the default bar with 3 modes per family, 30 deg, 1 m/s down, 1 ms
    "bar": {"length": 0.3, "diameter": 0.01, "tip_radius": 0.005, "modes": 3},
    "initial": {"height": 1e-5, "angle_deg": 30.0, "velocity": [0.0, 0.0, -1.0]},
    "contact": {"restitution": 0.8},
    "solver": {"rtol": 1e-6, "t_end": 1e-3},
}


def mech(changes: dict, checks: dict | None = None) -> dict:
    doc = copy.deepcopy(BASE)
    for key, value in changes.items():
        section, name = key.split(".", 1)
        doc.setdefault(section, {})[name] = value
    return dict(doc=doc, checks=checks or {})


def coupled(changes: dict, checks: dict | None = None) -> dict:
    """The built-in free-drop scene (arc, 24 V, 12 ohm; 3 modes per family), 20 um above the block, 2 ms."""
    import tomllib

    from coupling.core.scene import builtin_scene_text

    doc = tomllib.loads(builtin_scene_text("free_drop"))
    doc["bar"]["modes"] = 3  # the count docs/accuracy/matrix.md was measured at (the scene is "auto" now)
    doc["initial"]["height"] = 2e-5
    doc["solver"]["t_end"] = 2e-3
    doc["output"] = {"plots": False, "csv": False, "parquet": False}
    for key, value in changes.items():
        parts = key.split(".")
        node = doc
        for p in parts[:-1]:
            node = node.setdefault(p, {})
        if value is None:
            node.pop(parts[-1], None)
        else:
            node[parts[-1]] = value
    return dict(doc=doc, checks=checks or {})


def device(source: str, changes: dict, checks: dict | None = None, t_end: float | None = None) -> dict:
    """A shipped device scene varied towards an extreme: ``source`` a built-in scene's name
    or an examples/*.toml; ``changes`` dotted keys as in ``coupled`` (``fixed.0.name`` indexes
    a table array; None removes a key); ``checks`` the device checks of ``device_checks``."""
    import tomllib

    from coupling.core.scene import builtin_scene_text

    text = (ROOT / source).read_text() if source.endswith(".toml") else builtin_scene_text(source)
    doc = tomllib.loads(text)
    if t_end is not None:
        doc["solver"]["t_end"] = t_end
    doc["output"] = {"plots": False, "csv": False, "parquet": False}
    for key, value in changes.items():
        parts = key.split(".")
        node = doc
        for p in parts[:-1]:
            node = node[int(p)] if isinstance(node, list) else node.setdefault(p, {})
        if value is None:
            node.pop(parts[-1], None)
        else:
            node[parts[-1]] = value
    return dict(doc=doc, checks=dict(checks or {}, device=True))


# the default relay, short: coil on at 0 (makes ~4.5 ms later at 12 V), off at 6 ms, 8 ms
RELAY = {"coil.on_time": 0.0, "coil.off_time": 6e-3}
RELAY_T = 8e-3
# examples/changeover_relay.toml: the blade settles on NC over the first 6 ms (its preload);
# the coil on at 6 ms transfers it to NO near 10.5 ms, off at 12 ms back to NC, 15 ms
CHANGEOVER = "examples/changeover_relay.toml"
CO = {"coil.off_time": 12e-3}
CO_T = 15e-3
# examples/bridge_contactor.toml's motion wired as a changeover, its left contact NO and its
# right one NC: the two rivets make and part apart (the actuator 1 mm off centre) and are
# closed together for a while (make before break), the arrangement that aborted with
# "timestep too small" before ngspice's stop margin
MBB = {"circuit.template": "changeover", "fixed.0.name": "NO", "fixed.1.name": "NC",
       "circuit.nc_load_resistance": 24.0}
BRIDGE = "examples/bridge_contactor.toml"


def device_cases(add) -> None:
    operates = {"operates": True, "releases": True}
    for sup in ("none", "diode", "zener", "rc"):
        # a diode lets the coil's current freewheel through the winding alone: the release comes late
        add("relay coil", f"default relay, suppression {sup}",
            device("default", {**RELAY, "coil.suppression": sup}, operates, 2 * RELAY_T if sup == "diode" else RELAY_T))
    add("relay coil", "coil 9 V (below pull-in, rated 12 V): no make",
        device("default", {**RELAY, "coil.voltage": 9.0}, {"operates": False, "contact": False}, RELAY_T))
    add("relay coil", "coil 10 V (just above pull-in)",
        device("default", {**RELAY, "coil.voltage": 10.0, "coil.off_time": 9e-3}, operates, 1.2e-2))
    add("relay coil", "coil 36 V (3x rated), diode",
        device("default", {**RELAY, "coil.voltage": 36.0, "coil.suppression": "diode"}, operates, 2.4e-2))
    add("relay coil", "coil 36 V (3x rated), zener",
        device("default", {**RELAY, "coil.voltage": 36.0, "coil.suppression": "zener"}, operates, 1.6e-2))
    for v in (5.0, 250.0):
        add("relay load", f"default relay, supply {v:g} V",
            device("default", {**RELAY, "circuit.voltage": v}, operates, RELAY_T))
    for r in (0.5, 1e3):
        add("relay load", f"default relay, load {r:g} ohm",
            device("default", {**RELAY, "circuit.load_resistance": r}, operates, RELAY_T))
    for inductance, flyback in ((1e-3, True), (1e-1, True), (1e-2, False)):
        how = "flyback" if flyback else "no flyback, breakdown 300 V"
        add("relay load", f"default relay, inductive {inductance * 1e3:g} mH, {how}",
            device("default", {**RELAY, "circuit.template": "inductive", "circuit.load_inductance": inductance,
                               "circuit.load_resistance": 24.0,
                               **({"circuit.flyback": True} if flyback else
                                  {"circuit.arc.breakdown_voltage": 300.0, "circuit.arc.breakdown_gradient": 3e6})},
                   operates, RELAY_T))
    add("relay load", "default relay, capacitive inrush (0.5 ohm, 100 uF)",
        device("default", {**RELAY, "circuit.template": "capacitive", "circuit.load_resistance": 0.5,
                           "circuit.load_capacitance": 1e-4}, operates, RELAY_T))
    add("relay load", "default relay, 250 V, 10 mH, breakdown (showering)",
        device("default", {**RELAY, "circuit.voltage": 250.0, "circuit.template": "inductive",
                           "circuit.load_resistance": 100.0, "circuit.load_inductance": 1e-2,
                           "circuit.arc.breakdown_voltage": 300.0, "circuit.arc.breakdown_gradient": 3e6},
               operates, RELAY_T))
    add("relay load", "default relay, Ayrton arc (carbon-arc C, D)",
        device("default", {**RELAY, "circuit.arc.characteristic": "ayrton", "circuit.arc.ayrton_c": 11.66,
                           "circuit.arc.ayrton_d": 1.054e4}, operates, RELAY_T))
    add("relay numerics", "default relay, RELTOL 1e-6",
        device("default", {**RELAY, "circuit.reltol": 1e-6}, operates, RELAY_T))
    for h in (1e-6, 2e-4):
        add("relay numerics", f"default relay, macro step {h * 1e6:g} us (grows to 1 ms)",
            device("default", {**RELAY, "coupling.macro_step": h, "coupling.max_macro_step": max(h, 1e-3)},
                   operates, RELAY_T))
    # the coil's audit integrates v i and R i^2 by the trapezoid rule on the recorded points,
    # which between events are macro steps grown up to max_macro_step: capped, it closes
    add("relay numerics", "default relay, macro steps at most 10 us",
        device("default", {**RELAY, "coupling.max_macro_step": 1e-5}, operates, RELAY_T))
    add("changeover", "changeover relay (examples), diode",
        device(CHANGEOVER, {**CO, "coil.suppression": "diode"}, operates, CO_T))
    add("changeover", "changeover relay, both throws 100 mH with flyback",
        device(CHANGEOVER, {**CO, "circuit.load_inductance": 0.1, "circuit.flyback": True}, operates, CO_T))
    add("changeover", "changeover relay, both throws 10 mH, no flyback, breakdown 300 V",
        device(CHANGEOVER, {**CO, "circuit.load_inductance": 1e-2,
                            "circuit.arc.breakdown_voltage": 300.0, "circuit.arc.breakdown_gradient": 3e6},
               operates, CO_T))
    add("changeover", "changeover relay, 250 V, NO 1 kohm, NC 0.5 ohm",
        device(CHANGEOVER, {**CO, "circuit.voltage": 250.0, "circuit.load_resistance": 1e3,
                            "circuit.nc_load_resistance": 0.5}, operates, CO_T))
    add("changeover", "make-before-break (bridge motion as changeover)", device(BRIDGE, MBB))
    add("changeover", "make-before-break, both throws 10 mH with flyback",
        device(BRIDGE, {**MBB, "circuit.load_inductance": 1e-2, "circuit.flyback": True}))
    add("changeover", "make-before-break, 5 V, RELTOL 1e-6", device(BRIDGE, {**MBB, "circuit.voltage": 5.0,
                                                                           "circuit.reltol": 1e-6}))
    add("bridge", "bridge contactor (examples)", device(BRIDGE, {}))
    add("bridge", "bridge, inductive 10 mH with flyback",
        device(BRIDGE, {"circuit.template": "bridge", "circuit.load_inductance": 1e-2, "circuit.flyback": True}))
    add("bridge", "bridge, 250 V, 1 kohm, breakdown 300 V",
        device(BRIDGE, {"circuit.voltage": 250.0, "circuit.load_resistance": 1e3,
                        "circuit.arc.breakdown_voltage": 300.0}))
    add("bridge", "bridge, macro step 200 us", device(BRIDGE, {"coupling.macro_step": 2e-4}))
    add("solenoid", "plunger solenoid 12 V, 10 ms",
        device("examples/plunger_solenoid.toml", {}, {"contact": False}, 1e-2))
    add("solenoid", "plunger solenoid 36 V, off at 5 ms, zener",
        device("examples/plunger_solenoid.toml", {"coil.voltage": 36.0, "coil.off_time": 5e-3,
                                                  "coil.suppression": "zener"}, {"contact": False}, 1e-2))
    add("coil-load arc", "relay_coil_arc (24 ohm, 2 mH, breakdown), 4 ms",
        device("examples/relay_coil_arc.toml", {}, {}, 4e-3))
    add("coil-load arc", "relay_coil_arc, 100 mH, 250 V, RELTOL 1e-6",
        device("examples/relay_coil_arc.toml", {"circuit.load_inductance": 0.1, "circuit.voltage": 250.0,
                                               "circuit.load_resistance": 250.0, "circuit.reltol": 1e-6},
               {}, 4e-3))


def cases() -> list[tuple[str, str, dict]]:
    out = []
    add = lambda group, label, case: out.append((group, label, case))  # noqa: E731
    for e in (1e7, 1e9, 1e13, 1e16):
        add("stiffness", f"bar and block E = {e:g} Pa", mech({"bar.youngs_modulus": e, "block.youngs_modulus": e}))
    add("stiffness", "block E = 1e16 Pa (steel bar)", mech({"block.youngs_modulus": 1e16}))
    add("stiffness", "contact stiffness 1e16 N/m^1.5", mech({"contact.stiffness": 1e16}))
    add("tip radius", "tip 1 mm (2 mm bar, 0.1 m)",
        mech({"bar.tip_radius": 1e-3, "bar.diameter": 2e-3, "bar.length": 0.1}))
    add("tip radius", "tip 0.1 mm (0.2 mm wire, 20 mm)",
        mech({"bar.tip_radius": 1e-4, "bar.diameter": 2e-4, "bar.length": 0.02}))
    for v in (1e-3, 0.1, 10.0, 30.0):
        height = min(1e-5, v * 1e-4)
        add("speed", f"impact speed {v:g} m/s",
            mech({"initial.velocity": [0.0, 0.0, -v], "initial.height": height,
                  "solver.t_end": height / v + 1e-3}))
    for angle in (90.0, 89.5, 0.5, 0.0):
        add("incidence", f"bar at {angle:g} deg", mech({"initial.angle_deg": angle}))
    for label, velocity in (("0.5 deg from the normal", [0.00873, 0.0, -1.0]),
                            ("89.5 deg from the normal (grazing)", [1.0, 0.0, -0.00873])):
        add("incidence", f"velocity {label}, mu = 0.3",
            mech({"initial.velocity": velocity, "initial.height": 1e-6, "friction.mu": 0.3}))
    # sliding impacts: mu up to and past the jam (Painleve) range, bare Coulomb (max_ratio inf)
    for mu in (0.0, 0.3, 1.0, 3.0, 10.0):
        for vx in (1.0, -1.0):
            add("friction", f"mu = {mu:g}, sliding {'+' if vx > 0 else '-'}x at 1 m/s, 60 deg",
                mech({"initial.angle_deg": 60.0, "initial.velocity": [vx, 0.0, -0.5],
                      "friction.mu": mu, "friction.max_ratio": "inf"}))
    for gamma in (0.0, 0.99):
        add("friction", f"gamma = {gamma:g}, mu = 0.3", mech({"friction.mu": 0.3, "friction.gamma": gamma,
                                                              "initial.velocity": [0.5, 0.0, -1.0]}))
    # without gravity: the calibration's target is the gravity-free restitution (with gravity
    # a 1 cm/s rebound of a tip still ~10 um inside the block is caught by the bar's weight
    # and the bar comes to rest standing on its tip: a physical outcome, not an error)
    for e in (0.01, 0.05, 0.1, 0.5, 1.0):
        add("restitution", f"restitution {e:g} (rigid bar, upright, no gravity, 5 ms)",
            mech({"bar.modes": 0, "initial.angle_deg": 90.0, "contact.restitution": e, "solver.t_end": 5e-3,
                  "environment.gravity": 0.0}, {"restitution_target": e}))
    add("rest", "coming to rest: 2 deg, 1 mm drop, e = 0.5, mu = 0.3, 1 s",
        mech({"initial.angle_deg": 2.0, "initial.height": 1e-3, "contact.restitution": 0.5,
              "friction.mu": 0.3, "solver.t_end": 1.0}, {"at_rest": True}))
    add("rest", "coming to rest, rigid bar: 2 deg, 1 mm drop, e = 0.5, mu = 0.3, 3 s",
        mech({"bar.modes": 0, "initial.angle_deg": 2.0, "initial.height": 1e-3, "contact.restitution": 0.5,
              "friction.mu": 0.3, "solver.t_end": 3.0}, {"at_rest": True}))
    for rtol in (1e-3, 1e-11):
        add("rtol", f"rtol {rtol:g} (friction 0.3)", mech({"solver.rtol": rtol, "friction.mu": 0.3,
                                                          "initial.velocity": [0.5, 0.0, -1.0]}))
    for v in (1.0, 1000.0):
        add("circuit", f"supply {v:g} V", coupled({"circuit.voltage": v}))
    for r in (0.01, 1e6):
        add("circuit", f"load {r:g} ohm", coupled({"circuit.load_resistance": r}))
    add("circuit", "wiring 10 mH", coupled({"circuit.wiring_inductance": 1e-2}))
    add("circuit", "inductive load 12 ohm, 10 mH, with arc",
        coupled({"circuit.template": "inductive", "circuit.load_inductance": 1e-2}))
    add("circuit", "inductive load 12 ohm, 10 mH, arc with breakdown at 300 V",
        coupled({"circuit.template": "inductive", "circuit.load_inductance": 1e-2,
                 "circuit.arc": {"column_gradient": 2000.0, "breakdown_voltage": 300.0}}))
    add("circuit", "inductive load 12 ohm, 10 mH, no arc",
        coupled({"circuit.template": "inductive", "circuit.load_inductance": 1e-2, "circuit.arc": False}))
    fine = {"reference_changes": {"coupling.macro_step": 2.5e-6}}
    add("circuit", "macro step 200 us (longer than a contact)",
        coupled({"coupling.macro_step": 2e-4}, fine))
    add("circuit", "macro step 200 us, jacobi", coupled({"coupling.macro_step": 2e-4, "coupling.scheme": "jacobi"},
                                                       fine))
    device_cases(add)
    return out


def current_bound(scene) -> tuple[float, float | None] | None:
    """A, the most the load supply (and the coil's driver) can drive through any branch:
    V / (source + wiring + the smallest load path: a changeover's two throws in parallel,
    made before break), and V_coil / R_coil; None for a netlist. Inductance and capacitance
    only store what the resistances let through (a capacitive load's resistor is in series
    with its capacitor, so its inrush obeys the same bound)."""
    circ = getattr(getattr(scene, "circuit", None), "circuit", None)
    coil = None
    drive = getattr(circ, "coil", None)
    try:
        load = float(circ.load.load_resistance)
        nc = getattr(circ, "nc_load_resistance", None)
        if getattr(circ, "arrangement", None) == "changeover":
            nc = load if nc is None else float(nc)
            load = load * nc / (load + nc)
        series = float(circ.source.source_resistance + circ.wiring.wiring_resistance) + load
        bound = float(circ.source.voltage) / series
    except AttributeError:
        return None
    if drive is not None and getattr(drive, "resistance", None):
        coil = float(drive.voltage) / float(drive.resistance)
    return bound, coil


def device_checks(result, scene, checks: dict) -> tuple[dict, list[str]]:
    """The device-level checks (module docstring of accuracy_case for the rest): the coil's
    energy audit within solver.energy_tolerance of what went into the coil; an operate (and
    release) time where the coil switches and the case says the contact follows; every arc
    energy finite and >= 0; every current within what the supply can drive (current_bound)."""
    import math

    info, bad = {}, []
    relay = result.relay if result.waveform_columns is not None else None
    if relay:
        e = relay.get("energy") or {}
        rel = e.get("relative_residual")
        info.update(coil_residual=rel, operate_time=relay.get("operate_time"), release_time=relay.get("release_time"))
        tol = scene.mech.solver.energy_tolerance
        if rel is None or not math.isfinite(rel) or rel > tol:
            bad.append(f"coil energy residual {rel} of what went into the coil, above solver.energy_tolerance "
                       f"{tol:g}")
        if checks.get("operates") and relay.get("operate_time") is None:
            bad.append("the coil switched on but no operate time (the contact never made after it)")
        if checks.get("operates") is False and relay.get("operate_time") is not None:
            bad.append(f"operate time {relay['operate_time']:.4g} s although the coil is below pull-in")
        if checks.get("releases") and relay.get("release_time") is None:
            bad.append("the coil switched off but no release time (the contact never broke after it)")
    bounces = [("", result.bounce)] + [(f" ({name})", per["bounce"]) for name, per in
                                        (result.contact_results or {}).items()]
    for where, b in bounces:
        energies = [b.get("arc_energy")] + [o.get("arc_energy") for o in b.get("openings", [])]
        for a in energies:
            if a is not None and not (math.isfinite(a) and a >= -1e-12):
                bad.append(f"arc energy {a} J{where}: not finite or negative")
                break
    bounds = current_bound(result.scene)
    w = result.waveform_columns
    if bounds is not None and w is not None and len(w["time"]):
        # the load's current (a changeover's common lead: both throws) may overshoot once as a
        # passive loop rings (coupling.core.soundness.RINGING_FACTOR); the coil, driven across
        # its own R-L, cannot exceed V / R. A contact's or an arc's branch current is not
        # bounded so: the contact capacitance discharges through it at a make or an ignition.
        from coupling.core.soundness import RINGING_FACTOR

        load, coil = bounds
        for name, limit in (("load_current", RINGING_FACTOR * load), ("coil_current", coil)):
            if name not in w or limit is None:
                continue
            peak = float(np.nanmax(np.abs(np.asarray(w[name], float))))
            info[f"peak_{name}"] = peak
            if peak > 1.01 * limit + 1e-6:
                bad.append(f"|{name}| reaches {peak:.4g} A, above the {limit:.4g} A the supply can drive")
    return info, bad


def device_case(arg: str) -> dict:
    """accuracy_case.main on the case, then device_checks on its (first) run."""
    import accuracy_case

    import coupling

    seen: list = []
    plain = coupling.run

    def recorded(scene, *a, **k):
        try:
            result = plain(scene, *a, **k)
        except coupling.CoupledRunError as err:
            seen.append((scene, err.partial))
            raise
        seen.append((scene, result))
        return result

    coupling.run = recorded
    out = accuracy_case.main(arg)
    if not seen or seen[0][1] is None or out["status"] == "crash":
        return out
    # each contact's resistance is inf while it is open (a single contact's column is
    # already left out of accuracy_case's finiteness check)
    if "non-finite values in the waveforms" in out["silent"] + out.get("flagged_failures", []):
        w = seen[0][1].waveforms
        numeric = w.select_dtypes("number").drop(columns=[c for c in w if c.startswith("contact_resistance")])
        if bool(np.isfinite(numeric.to_numpy()).all()):
            for key in ("silent", "flagged_failures"):
                if "non-finite values in the waveforms" in out.get(key, []):
                    out[key].remove("non-finite values in the waveforms")
    scene, result = seen[0]
    try:
        info, bad = device_checks(result, scene, json.loads(arg).get("checks", {}))
    except Exception as err:  # noqa: BLE001 - a check that cannot be computed is a crash of the metrics
        info, bad = {}, [f"device checks raised {type(err).__name__}: {err}"]
    out.update(info)
    if bad:  # as accuracy_case does: what a flagged result fails is reported, not silent
        (out.setdefault("flagged_failures", []) if out.get("flags") else out["silent"]).extend(bad)
    return out


def run_case(case: dict) -> dict:
    tick = time.perf_counter()
    command = ([sys.executable, str(ROOT / "benchmarks" / "accuracy_matrix.py"), "--case"]
               if case.get("checks", {}).get("device") else
               [sys.executable, str(ROOT / "benchmarks" / "accuracy_case.py")])
    try:
        proc = subprocess.run(command + [json.dumps(case)],
                              capture_output=True, text=True, timeout=TIMEOUT, cwd=ROOT)
    except subprocess.TimeoutExpired:
        return dict(status="timeout", message=f"no answer within {TIMEOUT:g} s (hang or too slow)",
                    wall=None, silent=[], flags=[], process=time.perf_counter() - tick)
    line = [x for x in proc.stdout.splitlines() if x.startswith("CASE-RESULT ")]
    if not line:
        return dict(status="crash", message=f"exit code {proc.returncode}: {proc.stderr.strip()[-300:]}",
                    wall=None, silent=[], flags=[], process=time.perf_counter() - tick)
    out = json.loads(line[-1][len("CASE-RESULT "):])
    out["process"] = time.perf_counter() - tick
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--case", help="(internal) run one device case given as JSON and print its CASE-RESULT line")
    ap.add_argument("--only", help="run only the groups whose name contains this (no document written)")
    args = ap.parse_args()
    if args.case:
        try:
            result = device_case(args.case)
        except Exception as err:  # noqa: BLE001
            import traceback

            result = dict(status="crash", message=f"{type(err).__name__}: {err}",
                          traceback=traceback.format_exc().strip().splitlines()[-6:], silent=[], flags=[])
        print("CASE-RESULT " + json.dumps(result, default=float))
        return
    sec = Section("matrix", "5. The stiff and extreme matrix", ".venv/bin/python benchmarks/accuracy_matrix.py")
    sec.add("Each case runs in its own process (timeout "
            f"{TIMEOUT:g} s: a hang is recorded as such), {args.jobs} at a time. Mechanics cases start from the "
            "default bar (10 mm steel, 0.3 m, 5 mm tips, 3 modes per family) 10 um above a steel block at 30 deg, "
            "1 m/s down, restitution 0.8, rtol 1e-6, 1 ms, and change what the case names; circuit cases start "
            "from the built-in free-drop scene (24 V, 12 ohm, arc) 20 um above the block, 2 ms. "
            "Status: ok / ok, flagged (the result carries a flag or a warning) / unsound (a soundness bound "
            "fails: switchsim run's exit 3) / rejected (a clear error before the run) / "
            "failed (a run error with a message) / crash (an unexpected exception) / timeout. "
            "Silent: physics checks that failed with no flag: finite output, energetic restitution <= 1, "
            "penetration < 10 % of the tip radius, energy residual within tolerance or flagged, a contact "
            "happens, and per case the target restitution (within 0.05) or coming to rest. "
            "Device cases start from a shipped device scene (the built-in default relay with its coil on at 0 "
            "and off at 6 ms; examples/changeover_relay.toml; examples/bridge_contactor.toml, also wired as a "
            "make-before-break changeover; examples/plunger_solenoid.toml; examples/relay_coil_arc.toml) and "
            "are checked besides for: the coil's energy audit (relay.energy.relative_residual) within "
            "solver.energy_tolerance, an operate and a release time where the coil switches (none below "
            "pull-in), every arc energy finite and >= 0, the load current within the soundness bound "
            "2 V / (R_source + R_wiring + R_load) (a changeover: its two loads in parallel) and the coil "
            "current within V_coil / R_coil (a contact's or an arc's own branch current is not bounded: the "
            "contact capacitance discharges through it).", "")
    todo = [c for c in cases() if args.only is None or args.only in c[0]]
    with ThreadPoolExecutor(max_workers=args.jobs) as pool:
        results = list(pool.map(lambda c: run_case(c[2]), todo))
    rows, findings = [], []
    for (group, label, case), r in zip(todo, results):
        detail = r.get("message", "") or ""
        if r.get("flags"):
            more = f" (+{len(r['flags']) - 1} more flags)" if len(r["flags"]) > 1 else ""
            detail = (detail + "; flag: " if detail else "flag: ") + r["flags"][0][:200] + more
        if r.get("silent"):
            detail = "SILENT: " + "; ".join(r["silent"]) + (f" ({detail})" if detail else "")
        elif r.get("flagged_failures"):
            detail = "flagged, and: " + "; ".join(r["flagged_failures"]) + f" ({detail})"
        extra = []
        for key, name in (("restitution", "e"), ("final_energy_fraction", "final energy"),
                          ("peak_contact_voltage", "peak V"), ("arc_energy", "arc J"), ("bounces", "bounces"),
                          ("coil_residual", "coil residual")):
            if r.get(key) is not None:
                extra.append(f"{name} {fmt(r[key], 3)}")
        rows.append([group, label, r["status"], fmt(r.get("wall"), 3), fmt(r.get("energy_residual"), 2),
                     r.get("contacts", "-"), r.get("events", "-"), ", ".join(extra),
                     detail.replace("|", "/").replace("\n", " ")[:300]])
        if r["status"] in ("crash", "timeout", "failed") or r.get("silent"):
            findings.append(f"- **{label}** ({group}): {r['status']}"
                            + (f"; silent: {'; '.join(r['silent'])}" if r.get("silent") else "")
                            + (f"; {r.get('message', '')[:300]}" if r["status"] in ("crash", "timeout", "failed")
                               else ""))
        print(f"{label}: {r['status']} {r.get('wall')}", file=sys.stderr)
    sec.table(["group", "case", "status", "run (s)", "energy residual", "contacts", "events", "results",
               "error / flags / silent failures"], rows)
    sec.add("### Findings (crashes, hangs and silent failures)", "")
    sec.add(*(findings or ["none"]), "")
    if args.only is not None:
        print("\n".join(" | ".join(map(str, r)) for r in rows))
        return
    dump("matrix", [dict(group=g, case=l, **r) for (g, l, _), r in zip(todo, results)])
    sec.write()


if __name__ == "__main__":
    main()
