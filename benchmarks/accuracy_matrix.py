"""The stiff and extreme matrix: each case in its own process with a timeout
(benchmarks/accuracy_case.py), recorded as completed, flagged, rejected with a clear
error, failed, crashed or timed out, with its energy residual, run time and the physics
checks that failed silently (status ok, no flag, physically wrong).

    .venv/bin/python benchmarks/accuracy_matrix.py [--jobs 2]   (part 5 of `make accuracy`)
"""

from __future__ import annotations

import argparse
import copy
import json
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

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
    return out


def run_case(case: dict) -> dict:
    tick = time.perf_counter()
    try:
        proc = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "accuracy_case.py"), json.dumps(case)],
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
    args = ap.parse_args()
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
            "happens, and per case the target restitution (within 0.05) or coming to rest.", "")
    todo = cases()
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
                          ("peak_contact_voltage", "peak V"), ("arc_energy", "arc J"), ("bounces", "bounces")):
            if r.get(key) is not None:
                extra.append(f"{name} {fmt(r[key], 3)}")
        rows.append([group, label, r["status"], fmt(r.get("wall"), 3), fmt(r.get("energy_residual"), 2),
                     r.get("contacts", "-"), r.get("events", "-"), ", ".join(extra),
                     detail.replace("|", "/").replace("\n", " ")[:300]])
        if r["status"] in ("crash", "timeout") or r.get("silent"):
            findings.append(f"- **{label}** ({group}): {r['status']}"
                            + (f"; silent: {'; '.join(r['silent'])}" if r.get("silent") else "")
                            + (f"; {r.get('message', '')[:300]}" if r["status"] in ("crash", "timeout", "failed")
                               else ""))
        print(f"{label}: {r['status']} {r.get('wall')}", file=sys.stderr)
    sec.table(["group", "case", "status", "run (s)", "energy residual", "contacts", "events", "results",
               "error / flags / silent failures"], rows)
    sec.add("### Findings (crashes, hangs and silent failures)", "")
    sec.add(*(findings or ["none"]), "")
    dump("matrix", [dict(group=g, case=l, **r) for (g, l, _), r in zip(todo, results)])
    sec.write()


if __name__ == "__main__":
    main()
