"""One case of the stiff and extreme matrix, run in its own process (so a hang is only a
timeout): ``python benchmarks/accuracy_case.py '<json>'`` prints one JSON line.

The JSON holds ``doc`` (a scene document, SI) and optional ``checks``:
    restitution_target: e   the first complete contact's energetic restitution must be within 0.05
    at_rest: true           the bar must end at rest (final kinetic energy < 1e-3 of the initial)
    contact: true           at least one contact must happen (default true)
Besides them every run is checked for: finite history and waveforms, energetic
restitution <= 1 in every complete contact, Hertz penetration < 10 % of the tip radius
(beyond it the law is outside its validity), energy residual within
solver.energy_tolerance unless the result flags it.

status: "ok" | "ok, flagged" (the result carries flags or warnings) | "unsound" (the
soundness bounds of coupling.core.soundness fail: switchsim run's exit 3) | "rejected" (a clear
error before the run) | "failed" (a run error with a message) | "crash" (an unexpected
exception: a bug) ; "silent" lists physics checks that failed while the result carries
no flag at all ("flagged_failures" those of a flagged result).
"""

from __future__ import annotations

import json
import math
import sys
import time
import traceback
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def main(arg: str) -> dict:
    case = json.loads(arg)
    doc, checks = case["doc"], case.get("checks", {})
    out: dict = dict(status=None, wall=None, silent=[], flags=[])
    from coupling import CoupledRunError, run, scene_from_dict

    try:
        scene = scene_from_dict(doc, name="case")
    except (ValueError, FileNotFoundError) as err:
        out.update(status="rejected", message=str(err))
        return out
    tick = time.perf_counter()
    result = None
    try:
        result = run(scene)
        out["status"] = "ok"
    except CoupledRunError as err:
        out.update(status="failed", message=str(err))
        result = err.partial
    except Exception as err:  # noqa: BLE001 - a crash is what we are looking for
        tb = traceback.format_exc().strip().splitlines()
        out.update(status="crash", message=f"{type(err).__name__}: {err}", traceback=tb[-6:])
    out["wall"] = time.perf_counter() - tick
    if result is None:
        return out
    mr = result.mechanics
    silent = out["silent"]
    if mr is not None:
        try:
            summary = mr.to_summary()
        except Exception as err:  # noqa: BLE001
            out.update(status="crash", message=f"summary: {type(err).__name__}: {err}")
            return out
        # the result's flags and its warnings (coupling.core.diagnostics: printed by switchsim run)
        out["flags"] = list(result.summary.get("flags", summary["flags"])) + list(result.warnings)
        if out["status"] == "ok":
            from coupling.core.soundness import assess

            problems = assess(result)["problems"]
            if problems:  # what switchsim run reports as "unsound" (exit 3)
                out.update(status="unsound", message="; ".join(problems))
        c = mr.contacts
        out["contacts"] = int(len(c))
        out["events"] = int(mr.stats.get("events", 0))
        out["steps"] = int(mr.stats.get("steps", 0))
        res = summary["energy"]["relative_residual"]
        out["energy_residual"] = res
        h = mr.history
        numeric = h.select_dtypes("number")
        if not bool(numeric.apply(lambda s: s.map(math.isfinite)).all().all()):
            silent.append("non-finite values in the history")
        er = c.energetic_restitution[c.complete]
        if len(er) and float(er.max()) > 1.0 + 1e-3:
            silent.append(f"energetic restitution {float(er.max()):.4f} > 1 (energy created in a contact)")
        if scene.mech.bar is not None:  # (an armature alone has no tip to sink)
            radius = scene.mech.bar.tip_radius
            pen = max(float(h.penetration_0.max()), float(h.penetration_1.max()))
            out["max_penetration_over_radius"] = pen / radius
            if pen > 0.1 * radius:
                silent.append(f"penetration {pen:.3g} m = {pen / radius:.2f} tip radii: Hertz contact far outside "
                              "its validity (small strain, y << R)")
        if res is None or not (res <= scene.mech.solver.energy_tolerance):
            if not any("energy residual" in f for f in out["flags"]):
                silent.append(f"energy residual {res} above tolerance without a flag")
        if checks.get("contact", True) and len(c) == 0:
            silent.append("no contact although the bar reaches the block")
        target = checks.get("restitution_target")
        if target is not None:
            done = c[c.complete]
            got = float(done.energetic_restitution.iloc[0]) if len(done) else math.nan
            out["restitution"] = got
            if not abs(got - target) <= 0.05:
                silent.append(f"first energetic restitution {got:.4f}, target {target:g}")
        if checks.get("at_rest"):
            en = mr.energy_table
            ke0 = float(en.kinetic.iloc[0] + en.elastic.iloc[0])
            ke1 = float(en.kinetic.iloc[-1] + en.elastic.iloc[-1])
            out["final_energy_fraction"] = ke1 / ke0 if ke0 > 0 else math.nan
            if not ke1 <= 1e-3 * ke0:
                silent.append(f"not at rest at the end: kinetic+elastic {ke1 / ke0:.3g} of the initial")
    w = result.waveforms
    if w is not None and scene.circuit is not None:
        arc = getattr(scene.circuit.circuit, "arc", None)
        arc_on = arc is not None and getattr(arc, "breakdown_voltage", None) is None
        supply = float(doc.get("circuit", {}).get("voltage", 24.0))
        peak = result.bounce.get("peak_contact_voltage") or 0.0
        if arc_on and peak > max(10.0 * supply, 300.0):
            silent.append(f"{peak:.4g} V across the opening contact with the arc model on ({supply:g} V supply) but "
                          "no arc.breakdown_voltage: a gap of micrometres would break down and re-ignite")
    reference = checks.get("reference_changes")
    if reference is not None and w is not None and out["status"] == "ok":
        # the same scene with a fine, trusted setting: the case must agree with it
        from coupling.app.accuracy import metrics_of, mismatch_time, tip_intervals

        ref = run(scene.update(reference))
        a, b = metrics_of(result), metrics_of(ref)
        mism = sum(mismatch_time(tip_intervals(result)[i], tip_intervals(ref)[i]) for i in (0, 1))
        out["reference_arc_energy"] = b["arc_energy"]
        if a["bounces"] != b["bounces"]:
            silent.append(f"bounces {a['bounces']}, {b['bounces']} with {reference}")
        if not abs((a["arc_energy"] or 0.0) - (b["arc_energy"] or 0.0)) <= 0.05 * abs(b["arc_energy"] or 0.0) + 1e-6:
            silent.append(f"arc energy {a['arc_energy']:.3g} J, {b['arc_energy']:.3g} J with {reference}")
        if mism > 0.05 * b["contact_time"]:
            silent.append(f"contact-state mismatch {mism * 1e6:.3g} us against {reference}")
    if w is not None:
        numeric = w.select_dtypes("number").drop(columns=["contact_resistance"], errors="ignore")
        if not bool(numeric.apply(lambda s: s.map(math.isfinite)).all().all()):
            silent.append("non-finite values in the waveforms")
        b = result.bounce
        out["bounces"] = b.get("bounces")
        out["peak_contact_voltage"] = b.get("peak_contact_voltage")
        out["arc_energy"] = b.get("arc_energy")
    if out["status"] == "ok" and out["flags"]:
        out["status"] = "ok, flagged"
    if out["flags"] and silent:
        # the result warns: what the checks found is reported, not silent
        out["flagged_failures"], out["silent"] = list(silent), []
    return out


if __name__ == "__main__":
    try:
        result = main(sys.argv[1])
    except Exception as err:  # noqa: BLE001
        result = dict(status="crash", message=f"{type(err).__name__}: {err}",
                      traceback=traceback.format_exc().strip().splitlines()[-6:], silent=[], flags=[])
    print("CASE-RESULT " + json.dumps(result, default=float))
